//! The BVH's nodes as traversal reads them. obvhs builds a compressed wide BVH8 (Ylitie, Karras
//! & Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG 2017);
//! its 8-bit quantised child boxes save a GPU memory bandwidth, but cost a CPU ray a
//! dequantisation of 48 planes at every node, which with obvhs's traversal bookkeeping was most
//! of a query's cost (docs/performance.md, ledger: "own uncompressed traversal"). We keep
//! obvhs's tree and store each node's eight children as exact f32 boxes, structure of arrays,
//! tested four children at a time with SSE2 (x86-64 baseline).

use crate::triangle::{gamma, safe_reciprocal};
use glam::Vec3;

/// A ray prepared for node tests: origin, reciprocal direction and which plane of each axis
/// is entered first.
#[derive(Clone, Copy, Debug)]
pub(super) struct NodeRay {
    pub origin: [f32; 3],
    pub inv_dir: [f32; 3],
    /// Per axis a: index into [`WideNode::planes`] of the entry plane (2a for a positive
    /// direction, 2a + 1 for a negative one) and of the exit plane.
    pub near: [usize; 3],
    pub far: [usize; 3],
}

impl NodeRay {
    /// The node ray of `origin` + t·`direction`.
    #[inline(always)]
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        // +0.0 turns −0.0 into +0.0 (and leaves everything else alone), so the slab order and
        // the reciprocal's sign agree (obvhs's own test misses everything on a −0.0).
        let direction = direction + Vec3::ZERO;
        let inv_dir = safe_reciprocal(direction);
        let d = direction.to_array();
        let near = [0, 1, 2].map(|a| 2 * a + (d[a] < 0.0) as usize);
        Self { origin: origin.to_array(), inv_dir, near, far: near.map(|i| i ^ 1) }
    }
}

/// Slab exits are scaled by 1 + 2γ₃ (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013): the
/// rounding of (plane − origin) · (1/d) can then never make a ray miss a box it touches, e.g.
/// at the edge of a flat box around an axis-aligned wall.
const EXIT_WIDENING: f32 = 1.0 + 2.0 * gamma(3);

/// One node: eight child boxes and what each child is.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct WideNode {
    /// `planes[2a]` holds the children's box minima on axis a, `planes[2a + 1]` the maxima.
    /// An empty slot holds the inverted box (+∞ … −∞), which no ray enters.
    pub planes: [[f32; 8]; 6],
    /// An inner child's node index, or a leaf child's first triangle slot.
    pub index: [u32; 8],
    /// A leaf child's triangle count (1 to 3).
    pub count: [u8; 8],
    /// Bit c set: child c is an inner node.
    pub inner: u8,
    /// Bit c set: child c is a leaf.
    pub leaves: u8,
}

impl WideNode {
    /// A node with eight empty slots.
    pub const EMPTY: Self = Self {
        planes: [
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
        ],
        index: [0; 8],
        count: [0; 8],
        inner: 0,
        leaves: 0,
    };

    /// Sets child `c`'s box.
    pub fn set_box(&mut self, c: usize, lo: Vec3, hi: Vec3) {
        for a in 0..3 {
            self.planes[2 * a][c] = lo[a];
            self.planes[2 * a + 1][c] = hi[a];
        }
    }

    /// Which children's boxes the ray overlaps within [0, t_max] (bit c for child c), and the
    /// entry distance of each (exits widened by [`EXIT_WIDENING`]).
    ///
    /// t = (plane − origin) · (1/d) cannot be NaN: the planes and origin are finite (or a
    /// plane is ±∞ in an empty slot, with a finite origin), and 1/d is finite and non-zero
    /// (`safe_reciprocal`). An empty slot's entry is +∞ and its exit −∞, so it is never hit.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn intersect(&self, ray: &NodeRay, t_max: f32) -> (u32, [f32; 8]) {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of the x86-64 baseline that every x86-64 CPU has, and every
        // load reads four floats at offset 0 or 4 of a `[f32; 8]` it borrows.
        unsafe {
            let load = |p: &[f32; 8]| (_mm_loadu_ps(p.as_ptr()), _mm_loadu_ps(p.as_ptr().add(4)));
            let (mut near0, mut near1) = (_mm_setzero_ps(), _mm_setzero_ps());
            let (mut far0, mut far1) = (_mm_set1_ps(f32::INFINITY), _mm_set1_ps(f32::INFINITY));
            for a in 0..3 {
                let o = _mm_set1_ps(ray.origin[a]);
                let inv = _mm_set1_ps(ray.inv_dir[a]);
                let (n0, n1) = load(&self.planes[ray.near[a]]);
                let (f0, f1) = load(&self.planes[ray.far[a]]);
                near0 = _mm_max_ps(near0, _mm_mul_ps(_mm_sub_ps(n0, o), inv));
                near1 = _mm_max_ps(near1, _mm_mul_ps(_mm_sub_ps(n1, o), inv));
                far0 = _mm_min_ps(far0, _mm_mul_ps(_mm_sub_ps(f0, o), inv));
                far1 = _mm_min_ps(far1, _mm_mul_ps(_mm_sub_ps(f1, o), inv));
            }
            let (widen, t_max) = (_mm_set1_ps(EXIT_WIDENING), _mm_set1_ps(t_max));
            far0 = _mm_min_ps(_mm_mul_ps(far0, widen), t_max);
            far1 = _mm_min_ps(_mm_mul_ps(far1, widen), t_max);
            let lo = _mm_movemask_ps(_mm_cmple_ps(near0, far0)) as u32;
            let hi = _mm_movemask_ps(_mm_cmple_ps(near1, far1)) as u32;
            let mut t_near = [0.0f32; 8];
            _mm_storeu_ps(t_near.as_mut_ptr(), near0);
            _mm_storeu_ps(t_near.as_mut_ptr().add(4), near1);
            (lo | (hi << 4), t_near)
        }
    }

    /// Portable version of the same test.
    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    pub fn intersect(&self, ray: &NodeRay, t_max: f32) -> (u32, [f32; 8]) {
        let mut t_near = [0.0f32; 8];
        let mut t_far = [f32::INFINITY; 8];
        for a in 0..3 {
            let (near, far) = (&self.planes[ray.near[a]], &self.planes[ray.far[a]]);
            for c in 0..8 {
                t_near[c] = t_near[c].max((near[c] - ray.origin[a]) * ray.inv_dir[a]);
                t_far[c] = t_far[c].min((far[c] - ray.origin[a]) * ray.inv_dir[a]);
            }
        }
        let t_far = t_far.map(|t| (t * EXIT_WIDENING).min(t_max));
        ((0..8).filter(|&c| t_near[c] <= t_far[c]).fold(0, |m, c| m | (1 << c)), t_near)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slab test against boxes checked by hand: entry distances, t_max, rays starting
    /// inside a box, boxes behind the ray, flat boxes, axis-parallel and −x rays, empty slots.
    #[test]
    fn child_boxes_hit_as_expected() {
        let mut node = WideNode::EMPTY;
        node.set_box(0, Vec3::new(2.0, -1.0, -1.0), Vec3::new(3.0, 1.0, 1.0)); // ahead on +x
        node.set_box(1, Vec3::new(-3.0, -1.0, -1.0), Vec3::new(-2.0, 1.0, 1.0)); // behind
        node.set_box(2, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0)); // around the origin
        node.set_box(3, Vec3::new(5.0, -1.0, -1.0), Vec3::new(5.0, 1.0, 1.0)); // flat, at x = 5
        node.set_box(4, Vec3::new(2.0, 2.0, -1.0), Vec3::new(3.0, 3.0, 1.0)); // off to the side
        let along_x = NodeRay::new(Vec3::ZERO, Vec3::X);
        let (mask, t) = node.intersect(&along_x, f32::INFINITY);
        assert_eq!(mask, 0b1101, "children 0, 2, 3");
        assert_eq!((t[0], t[2], t[3]), (2.0, 0.0, 5.0));
        assert_eq!(node.intersect(&along_x, 4.0).0, 0b0101, "t_max cuts off the flat box");
        assert_eq!(node.intersect(&along_x, 1.5).0, 0b0100);
        let back = NodeRay::new(Vec3::ZERO, -Vec3::X);
        let (mask, t) = node.intersect(&back, f32::INFINITY);
        assert_eq!(mask, 0b0110, "children 1 and 2");
        assert_eq!(t[1], 2.0);
        let diagonal = NodeRay::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0).normalize());
        assert_eq!(node.intersect(&diagonal, f32::INFINITY).0, 0b10100, "children 2 and 4");
        assert_eq!(WideNode::EMPTY.intersect(&diagonal, f32::INFINITY).0, 0, "empty slots never hit");
    }
}
