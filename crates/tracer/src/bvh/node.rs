//! The ray–node test for obvhs's compressed 8-wide nodes (Ylitie, Karras & Laine, "Efficient
//! Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG 2017), written here
//! rather than taken from obvhs for two reasons:
//! - obvhs clamps every box's entry distance to 1e-4 (its `EPSILON`), silently culling nearby
//!   geometry in small scenes; this test uses 0;
//! - obvhs converts the 48 quantised child planes to floats one scalar at a time; here each
//!   group of eight bytes is widened and converted with a handful of SSE2 instructions (x86-64
//!   baseline).
//! The returned hit mask has exactly obvhs's layout, so obvhs's `traverse!` macro drives it.

use obvhs::cwbvh::node::{CwBvhNode, extract_byte64};

/// A traversal ray prepared for node tests: origin, reciprocal direction and which slab of
/// each axis is entered first (from the sign of the direction, the same sign the reciprocal
/// has, so the two can never disagree as they can with −0.0 in obvhs's own test).
#[derive(Clone, Copy, Debug)]
pub(super) struct NodeRay {
    pub origin: [f32; 3],
    pub inv_dir: [f32; 3],
    pub negative: [bool; 3],
}

/// Which children of `node` the ray enters within (0, t_max), in obvhs's hit-mask layout
/// (internal children in the top byte by traversal priority, leaf primitives below).
#[inline(always)]
pub(super) fn intersect(node: &CwBvhNode, ray: &NodeRay, t_max: f32, oct_inv4: u32) -> u32 {
    let child_mask = child_hits(node, ray, t_max);
    if child_mask == 0 {
        return 0;
    }
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let mut hit_mask = 0u32;
    let mut m = child_mask;
    while m != 0 {
        let c = m.trailing_zeros() as usize;
        hit_mask |= extract_byte64(child_bits8, c) << extract_byte64(bit_index8, c);
        m &= m - 1;
    }
    hit_mask
}

/// Per-axis slab parameters in the node's quantised frame: t = (q · extent + offset) · inv.
///
/// The plane is placed in world units first and only then divided by the direction: the
/// shorter q · (extent · inv) + offset · inv overflowed extent · inv to ∞ for axis-parallel
/// rays (inv clamped to 1e30) once a node quantum passed ~3e8 (scenes past ~1e11 across), and
/// q = 0 then gave 0 · ∞ = NaN, silently culling the child. Here the plane is finite and inv
/// finite and non-zero, so t is finite or ±∞, never NaN.
#[inline(always)]
fn axis(node: &CwBvhNode, ray: &NodeRay, a: usize) -> (f32, f32, f32) {
    let extent = f32::from_bits((node.e[a] as u32) << 23);
    (extent, node.p[a] - ray.origin[a], ray.inv_dir[a])
}

/// Bit c set when child c's box overlaps the ray's (0, t_max) span. (An empty slot's box is
/// the node's corner point; if it is "hit", its zero meta byte adds no bits to the mask.)
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn child_hits(node: &CwBvhNode, ray: &NodeRay, t_max: f32) -> u32 {
    use std::arch::x86_64::*;
    // SAFETY: value-only SSE2 intrinsics (no pointers); SSE2 is part of the x86-64 baseline
    // that every x86-64 CPU has. (A `#[target_feature]` function would be safe to write but
    // cannot be inlined, which costs more than the test itself.)
    unsafe {
        // Eight quantised planes → two vectors of four f32.
        let planes = |q: &[u8; 8]| {
            let zero = _mm_setzero_si128();
            let words = _mm_unpacklo_epi8(_mm_cvtsi64_si128(i64::from_le_bytes(*q)), zero);
            (
                _mm_cvtepi32_ps(_mm_unpacklo_epi16(words, zero)),
                _mm_cvtepi32_ps(_mm_unpackhi_epi16(words, zero)),
            )
        };
        let lo_hi = [
            (&node.child_min_x, &node.child_max_x),
            (&node.child_min_y, &node.child_max_y),
            (&node.child_min_z, &node.child_max_z),
        ];
        let mut near = (_mm_setzero_ps(), _mm_setzero_ps());
        let mut far = (_mm_set1_ps(t_max), _mm_set1_ps(t_max));
        for (a, (lo, hi)) in lo_hi.into_iter().enumerate() {
            let (near_q, far_q) = if ray.negative[a] { (hi, lo) } else { (lo, hi) };
            let (extent, offset, inv) = axis(node, ray, a);
            let (extent, offset, inv) = (_mm_set1_ps(extent), _mm_set1_ps(offset), _mm_set1_ps(inv));
            let slab = |q| _mm_mul_ps(_mm_add_ps(_mm_mul_ps(q, extent), offset), inv);
            let (n0, n1) = planes(near_q);
            let (f0, f1) = planes(far_q);
            near.0 = _mm_max_ps(near.0, slab(n0));
            near.1 = _mm_max_ps(near.1, slab(n1));
            far.0 = _mm_min_ps(far.0, slab(f0));
            far.1 = _mm_min_ps(far.1, slab(f1));
        }
        let lo = _mm_movemask_ps(_mm_cmple_ps(near.0, far.0)) as u32;
        let hi = _mm_movemask_ps(_mm_cmple_ps(near.1, far.1)) as u32;
        lo | (hi << 4)
    }
}

/// Portable version of the same test.
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn child_hits(node: &CwBvhNode, ray: &NodeRay, t_max: f32) -> u32 {
    let lo_hi = [
        (&node.child_min_x, &node.child_max_x),
        (&node.child_min_y, &node.child_max_y),
        (&node.child_min_z, &node.child_max_z),
    ];
    let mut t_near = [0.0f32; 8];
    let mut t_far = [t_max; 8];
    for (a, (lo, hi)) in lo_hi.into_iter().enumerate() {
        let (near_q, far_q) = if ray.negative[a] { (hi, lo) } else { (lo, hi) };
        let (extent, offset, inv) = axis(node, ray, a);
        for c in 0..8 {
            t_near[c] = t_near[c].max((near_q[c] as f32 * extent + offset) * inv);
            t_far[c] = t_far[c].min((far_q[c] as f32 * extent + offset) * inv);
        }
    }
    (0..8).filter(|&c| t_near[c] <= t_far[c]).fold(0, |m, c| m | (1 << c))
}
