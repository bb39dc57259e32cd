//! Per-pixel mathematics of the in-betweener: the frame-domain Hermite weights, the key tangents,
//! and the smooth direction curve (see the parent module for why it is C1 and safe).
//!
//! Everything here is a pure function of its arguments: a pixel's result depends on nothing else,
//! so frames are bit-identical whatever the thread count.

use crate::lanes::{avx2_twins, half_angle, perpendicular, select, select3, sin_cos};
use crate::ray_file::StoredRay;
use glam::{DVec3, Vec3};

/// The cubic Hermite basis of one frame, in the frame domain: for a segment from key k (time
/// t_k) to key k + 1 (time t_k + h) and s = (t − t_k)/h, a value is
/// `p_k + (p_{k+1} − p_k)·h01 + m_k·c0 + m_{k+1}·c1` with m the tangents in units per frame,
/// h01 = 3s² − 2s³, c0 = h·(s − 2s² + s³) and c1 = h·(s³ − s²). Computed once per frame in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Hermite {
    pub h01: f32,
    pub c0: f32,
    pub c1: f32,
}

impl Hermite {
    /// The weights at fraction `s` ∈ (0, 1) of a segment `h` frames long.
    pub fn new(s: f64, h: f64) -> Self {
        let r = 1.0 - s;
        Self {
            h01: (s * s * (3.0 - 2.0 * s)) as f32,
            c0: (h * s * r * r) as f32,
            c1: (-h * s * s * r) as f32,
        }
    }
}

/// The tangent (velocity per frame) of key k from its neighbours, Catmull–Rom in the frame
/// domain: origins (p_{k+1} − p_{k−1}) / (t_{k+1} − t_{k−1}); directions the same difference of
/// the sphere's logarithm at d_k, (log_{d_k} d_{k+1} − log_{d_k} d_{k−1}) / (t_{k+1} − t_{k−1}),
/// a vector in the tangent plane of d_k. Computed in f64 and stored as a [`StoredRay`] whose
/// `origin` and `direction` hold the two velocities.
pub(super) fn tangent(prev: &StoredRay, key: &StoredRay, next: &StoredRay, span: f64) -> StoredRay {
    let origin = (next.origin.as_dvec3() - prev.origin.as_dvec3()) / span;
    let d = key.direction.as_dvec3().normalize();
    let forward = log_map(d, next.direction.as_dvec3().normalize());
    let backward = log_map(d, prev.direction.as_dvec3().normalize());
    StoredRay { origin: origin.as_vec3(), direction: ((forward - backward) / span).as_vec3() }
}

/// The sphere's logarithm at unit `a`: the tangent vector at `a` along the great-circle arc to
/// unit `b`, as long as the arc (≤ π). The arc's direction is chosen as [`ArcFrame`] chooses it.
pub(super) fn log_map(a: DVec3, b: DVec3) -> DVec3 {
    let (d, s) = (b - a, a + b);
    let (d2, s2) = (d.length_squared(), s.length_squared());
    let theta = 2.0 * d2.sqrt().atan2(s2.sqrt());
    let p = if d2 <= s2 { d - a * a.dot(d) } else { s - a * a.dot(s) };
    let u = p.try_normalize().unwrap_or_else(|| perpendicular(a.as_vec3()).as_dvec3());
    u * theta
}

/// The great circle from unit `a` to unit `b`, as an orthonormal frame: `u` ⟂ `a` in the plane of
/// `a` and `b` (towards `b`), `w` = a × u its normal, `theta` the arc length, and `u_end` the
/// circle's unit tangent at `b` (= u cos θ − a sin θ).
pub(super) struct ArcFrame {
    pub u: Vec3,
    pub w: Vec3,
    pub theta: f32,
    pub u_end: Vec3,
}

impl ArcFrame {
    #[inline(always)]
    pub fn new(a: Vec3, b: Vec3) -> Self {
        let (d, s) = (b - a, a + b);
        let (d2, s2) = (d.dot(d), s.dot(s));
        let (dl, sl) = (d2.sqrt(), s2.sqrt());
        let theta = 2.0 * half_angle(dl, sl);
        // b − a(a·b) from the shorter of d = b − a and s = a + b (no cancellation near 0 or π),
        // as slerp does: d − a(a·d) = s − a(a·s).
        let shorter = select3(d2 <= s2, d, s);
        let p = shorter - a * a.dot(shorter);
        let p2 = p.dot(p);
        // Equal or exactly opposite: no plane; the deterministic perpendicular (computed for
        // every pixel, so that the loop has no branch).
        let spans = p2 > 1e-30;
        let u = select3(spans, p * (1.0 / select(spans, p2, 1.0).sqrt()), perpendicular(a));
        let w = a.cross(u);
        // cos θ and sin θ without trigonometry: |d| = 2 sin(θ/2), |s| = 2 cos(θ/2) and
        // |d|² + |s|² = 4 (for unit a, b; dividing by the sum keeps the pair unit regardless).
        let inv_sum = 1.0 / (s2 + d2);
        let (cos, sin) = ((s2 - d2) * inv_sum, 2.0 * dl * sl * inv_sum);
        Self { u, w, theta, u_end: u * cos - a * sin }
    }
}

/// The smooth (C1) ray between keys `a` and `b` with tangents `ma` and `mb` (velocities per
/// frame; zero at the end keys) and the frame's Hermite weights. Branch-free, so that a row of
/// pixels vectorises (see [`smooth_row`]).
///
/// Origins: the cubic Hermite curve. Directions: the same cubic Hermite curve in the spherical
/// coordinates (φ, ψ) of the great circle from `a` to `b` (φ along it from `a`, ψ across it),
/// n(φ, ψ) = cos ψ·(a cos φ + u sin φ) + w sin ψ, with φ running 0 → θ and ψ 0 → 0, and the end
/// derivatives the key tangents written in that chart's orthonormal bases ({u, w} at `a`,
/// {u_end, w} at `b`).
#[inline(always)]
pub(super) fn smooth(a: &StoredRay, b: &StoredRay, ma: &StoredRay, mb: &StoredRay, h: Hermite) -> StoredRay {
    let origin = a.origin + (b.origin - a.origin) * h.h01 + ma.origin * h.c0 + mb.origin * h.c1;
    let da = a.direction;
    let f = ArcFrame::new(da, b.direction);
    let (va, vb) = (ma.direction, mb.direction);
    let phi = f.theta * h.h01 + va.dot(f.u) * h.c0 + vb.dot(f.u_end) * h.c1;
    let psi = va.dot(f.w) * h.c0 + vb.dot(f.w) * h.c1;
    let (sin_phi, cos_phi) = sin_cos(phi);
    let (sin_psi, cos_psi) = sin_cos(psi);
    let n = (da * cos_phi + f.u * sin_phi) * cos_psi + f.w * sin_psi;
    // n is unit by construction (a, u, w orthonormal); normalising only removes rounding (and
    // the ≤ 1e-4 non-unit slack a stored key may have), so every output is unit to f32
    // precision. A non-finite n cannot arise from finite keys; falling back to `a` is belt and
    // braces.
    let n2 = n.dot(n);
    let good = n2 > 1e-30 && n2 < f32::INFINITY;
    StoredRay { origin, direction: select3(good, n * (1.0 / select(good, n2, 1.0).sqrt()), da) }
}

#[inline(always)]
fn smooth_row_body(
    a: &[StoredRay],
    b: &[StoredRay],
    ma: &[StoredRay],
    mb: &[StoredRay],
    h: Hermite,
    out: &mut [StoredRay],
) {
    for ((((o, a), b), ma), mb) in out.iter_mut().zip(a).zip(b).zip(ma).zip(mb) {
        *o = smooth(a, b, ma, mb, h);
    }
}

avx2_twins! {
    /// [`smooth`] over a row (all slices as long as `out`). The loop vectorises (SSE2, or AVX2
    /// where the CPU has it: chosen at run time). Both are the same IEEE operations lane by lane —
    /// no FMA is enabled, and Rust never contracts `a * b + c` — so a pixel's bits do not depend
    /// on the CPU features, its position in the row, or the thread that computes it.
    pub(super) fn smooth_row | smooth_row_baseline | smooth_row_avx2(
        a: &[StoredRay], b: &[StoredRay], ma: &[StoredRay], mb: &[StoredRay],
        h: Hermite, out: &mut [StoredRay],
    ) => smooth_row_body
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_frame_is_orthonormal_and_reaches_the_end() {
        let a = Vec3::new(0.3, -0.4, 0.866_025_4).normalize();
        let near = |v: Vec3| (v + a.any_orthonormal_vector() * 1e-6).normalize();
        for b in [a, -a, Vec3::X, (-a + Vec3::new(1e-4, 0.0, 0.0)).normalize(), near(a), near(-a)] {
            let f = ArcFrame::new(a, b);
            for (x, y) in [(a, f.u), (a, f.w), (f.u, f.w), (b, f.u_end), (b, f.w)] {
                assert!(x.dot(y).abs() < 1e-6, "{x} · {y}");
            }
            for e in [f.u, f.w, f.u_end] {
                assert!((e.length() - 1.0).abs() < 1e-6);
            }
            let (s, c) = sin_cos(f.theta);
            assert!((a * c + f.u * s - b).length() < 1e-6, "{b}");
        }
        // Exactly opposite and equal keys use slerp's perpendicular.
        let want = a.any_orthonormal_vector();
        assert!((ArcFrame::new(a, -a).u - want).length() < 1e-6);
        assert!((ArcFrame::new(a, a).u - want).length() < 1e-6);
        for z in [0.0f32, -0.0, 1.0, -1.0] {
            let v = Vec3::new(0.6, 0.0, 0.8 * z.signum()).normalize();
            assert!((perpendicular(v) - v.any_orthonormal_vector()).length() < 1e-6);
        }
    }

    #[test]
    fn the_vector_paths_give_the_same_bits_as_one_pixel_at_a_time() {
        use crate::test_util::Rng;
        let mut rng = Rng::new(21);
        let mut ray = |s: f32| StoredRay::new(rng.direction() * s, rng.direction());
        let n = 203; // not a multiple of any vector width: covers the scalar epilogue
        let (a, b): (Vec<_>, Vec<_>) = (0..n).map(|_| (ray(5.0), ray(5.0))).unzip();
        let (ma, mb): (Vec<_>, Vec<_>) = (0..n).map(|_| (ray(0.02), ray(0.02))).unzip();
        let mut b = b;
        b[7].direction = -a[7].direction;
        b[8].direction = a[8].direction;
        let h = Hermite::new(0.37, 120.0);
        let bits = |r: &[StoredRay]| r.iter().map(|r| bytemuck::cast::<_, [u32; 6]>(*r)).collect::<Vec<_>>();
        let one: Vec<StoredRay> =
            (0..n).map(|i| std::hint::black_box(smooth(&a[i], &b[i], &ma[i], &mb[i], h))).collect();
        let mut row = vec![StoredRay::default(); n];
        smooth_row_baseline(&a, &b, &ma, &mb, h, &mut row);
        assert_eq!(bits(&row), bits(&one), "baseline row");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let mut row = vec![StoredRay::default(); n];
            // SAFETY: the CPU has AVX2.
            unsafe { smooth_row_avx2(&a, &b, &ma, &mb, h, &mut row) };
            assert_eq!(bits(&row), bits(&one), "AVX2 row");
        }
    }
}
