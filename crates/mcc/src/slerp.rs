//! Spherical interpolation of unit directions (docs/design/mcc.md §5.7; §5.5, §6).
//!
//! `acos(a·b)` loses all precision near 0 and π, and glam's `Vec3::slerp` is 1.5e-2 rad off at
//! θ = 3.14; opposite eye rays are normal in a collage (two cameras facing each other), so this
//! module uses the accurate form: θ = 2·atan2(|a − b|, |a + b|), u the unit vector ⟂ a in the plane
//! of a and b, result a·cos(tθ) + u·sin(tθ).
//!
//! * u is built from whichever of a − b and a + b is shorter (both give b − a(a·b), but the shorter
//!   one is computed without cancellation), so it is accurate for nearly parallel and nearly
//!   opposite inputs alike.
//! * Exactly opposite inputs span no plane; u is then the deterministic choice
//!   `a.any_orthonormal_vector()` (Duff et al. 2017's basis, +y for a = +z).
//! * Below θ = 0.01 the normalised lerp is used: it deviates from slerp by at most 0.016·θ³
//!   ≤ 1.6e-8 rad, under f32 resolution, and costs no trigonometry (the lens reader's neighbouring
//!   pixels are almost always this close).
//! * t = 0 and t = 1 return the inputs bit for bit (pixel centres must be exact); the result
//!   is never NaN for finite, non-zero inputs.
//! * Every path is written without branches ([`nlerp`], [`arc`] and [`along`] around the sin
//!   and cos of the angle): the scalar [`slerp`] only branches to skip the paths it does not
//!   take, and the remapper's burp, which runs eight pixels in SIMD lanes, computes every path
//!   and selects, with the same operations, so the two give the same bits.

use crate::lanes::{normalize_or, select, select3};
use crate::ray_file::StoredRay;
use glam::Vec3;

/// Squared chord |a − b|² below which normalised lerp replaces slerp (θ < 0.01 rad).
pub(crate) const NLERP_CHORD_SQUARED: f32 = 1e-4;

/// The angle between unit vectors `a` and `b`, accurate over the whole range [0, π].
#[inline]
pub fn angle_between(a: Vec3, b: Vec3) -> f32 {
    2.0 * (a - b).length().atan2((a + b).length())
}

/// Slerp of unit vectors: the unit vector at fraction `t` ∈ [0, 1] of the great-circle arc from
/// `a` to `b` (see the module notes for accuracy and the opposite-vector rule).
#[inline]
pub fn slerp(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    if t == 0.0 {
        return a;
    }
    if t == 1.0 {
        return b;
    }
    let d = b - a;
    let d2 = d.length_squared();
    if d2 < NLERP_CHORD_SQUARED {
        return nlerp(a, d, t);
    }
    slerp_wide(a, b, d, d2, t)
}

/// The normalised lerp a + t·(b − a) (`d` = b − a), or `a` should it vanish.
#[inline(always)]
pub(crate) fn nlerp(a: Vec3, d: Vec3, t: f32) -> Vec3 {
    normalize_or(a + d * t, a)
}

/// The trigonometric path of [`slerp`], for θ ≥ 0.01.
#[inline(never)]
fn slerp_wide(a: Vec3, b: Vec3, d: Vec3, d2: f32, t: f32) -> Vec3 {
    let (u, angle) = arc(a, b, d, d2, t);
    let (sin, cos) = angle.sin_cos();
    along(a, u, sin, cos)
}

/// The first half of the trigonometric path, branch-free (`d` = b − a, `d2` = |d|²): the unit
/// vector u ⟂ a towards b on the great circle, and the angle t·θ to turn by.
#[inline(always)]
pub(crate) fn arc(a: Vec3, b: Vec3, d: Vec3, d2: f32, t: f32) -> (Vec3, f32) {
    let s = a + b;
    let s2 = s.length_squared();
    let theta = 2.0 * half_angle(d2.sqrt(), s2.sqrt());
    // b − a(a·b) from the shorter of d = b − a and s = a + b: d − a(a·d) = s − a(a·s).
    let shorter = d2 <= s2;
    let (v, v2) = (select3(shorter, d, s), select(shorter, d2, s2));
    let p = v - a * a.dot(v);
    // For exactly unit inputs |p|/|v| = sin(θ/2) or cos(θ/2) ≥ 0.7 on the side taken; less
    // means v lies along a, i.e. the inputs are opposite to within their rounding and a + b is
    // mostly their length errors. p is then a small difference, and a's own length error
    // (|a|² = 1 ± 2.4e-7) left a share of a in it ~1e-7·|v|/|p| — measured 1.2e-5 rad off
    // perpendicular (tests/stress_mcc.rs). A second projection removes it.
    let p = select3(p.length_squared() < 0.25 * v2, p - a * a.dot(p), p);
    // Exactly opposite: any perpendicular is a great circle through both; pick a fixed one.
    let q = a.any_orthonormal_vector();
    let u = normalize_or(p, normalize_or(q - a * a.dot(q), q));
    (u, t * theta)
}

/// The second half: a turned towards u by the angle whose sine and cosine are given, normalised
/// (or `a` should that fail).
#[inline(always)]
pub(crate) fn along(a: Vec3, u: Vec3, sin: f32, cos: f32) -> Vec3 {
    normalize_or(a * cos + u * sin, a)
}

/// atan2(y, x) for y, x ≥ 0 (not both 0), i.e. half the angle between unit vectors whose
/// difference and sum have lengths y and x. Cephes' `atanf` reduction and polynomial (relative
/// error under 2e-7) without libm's special-case handling: the burp of a many-camera collage
/// spends much of its time here (docs/performance.md, ledger: "polynomial atan in slerp").
/// Branch-free: both sides of each choice are the same operations a branch would run.
#[inline(always)]
fn half_angle(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};
    // atan of a ratio in [0, 1]; the larger side is the denominator.
    let le = y <= x;
    let ratio = select(le, y, x) / select(le, x, y);
    let (base, sign) = (select(le, 0.0, FRAC_PI_2), select(le, 1.0, -1.0));
    // atan(z) = π/4 + atan((z − 1)/(z + 1)) brings z above tan(π/8) back under it.
    let big = ratio > 0.414_213_57;
    let z = select(big, (ratio - 1.0) / (ratio + 1.0), ratio);
    let offset = select(big, FRAC_PI_4, 0.0);
    let z2 = z * z;
    let poly = ((0.080_537_446 * z2 - 0.138_776_85) * z2 + 0.199_777_11) * z2 - 0.333_329_5;
    let atan = offset + (poly * z2 * z + z);
    base + sign * atan
}

/// Interpolates two rays: origins lerp, directions [`slerp`]. `t = 0` and `t = 1` return the
/// inputs bit for bit.
#[inline]
pub fn lerp_rays(a: &StoredRay, b: &StoredRay, t: f32) -> StoredRay {
    if t == 0.0 {
        return *a;
    }
    if t == 1.0 {
        return *b;
    }
    StoredRay { origin: a.origin + (b.origin - a.origin) * t, direction: slerp(a.direction, b.direction, t) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::Rng;
    use glam::DVec3;

    /// Accurate angle in f64.
    fn angle(a: Vec3, b: Vec3) -> f64 {
        let (a, b) = (a.as_dvec3(), b.as_dvec3());
        2.0 * (a - b).length().atan2((a + b).length())
    }

    /// A pair of unit vectors θ apart around a random axis.
    fn pair(rng: &mut Rng, theta: f64) -> (Vec3, Vec3) {
        let a = rng.direction().as_dvec3().normalize();
        let p = (rng.direction().as_dvec3() - a * a.dot(rng.direction().as_dvec3())).normalize();
        let p = (p - a * a.dot(p)).normalize();
        ((a).as_vec3(), (a * theta.cos() + p * theta.sin()).as_vec3())
    }

    #[test]
    fn accurate_over_the_whole_range() {
        use std::f64::consts::PI;
        let mut rng = Rng::new(11);
        for theta in [0.0, 1e-7, 1e-3, 0.0099, 0.0101, PI / 2.0, PI - 1e-3, PI - 1e-6, PI] {
            for _ in 0..200 {
                let (a, mut b) = pair(&mut rng, theta);
                if theta == PI {
                    b = -a;
                }
                let actual = angle(a, b);
                for t in [0.0, 1e-6, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0 - 1e-6, 1.0] {
                    let r = slerp(a, b, t as f32);
                    assert!(r.is_finite(), "NaN at θ={theta} t={t}");
                    assert!((r.as_dvec3().length() - 1.0).abs() <= 1e-6, "length at θ={theta} t={t}: {r}");
                    let want = t * actual;
                    assert!((angle(a, r) - want).abs() <= 1e-5, "θ={theta} t={t}: {} vs {want}", angle(a, r));
                    assert!((angle(r, b) - (actual - want)).abs() <= 1e-5, "θ={theta} t={t} to b");
                }
                assert_eq!(slerp(a, b, 0.0), a);
                assert_eq!(slerp(a, b, 1.0), b);
            }
        }
    }

    /// Opposite to within f32 rounding, with a not quite unit (|a| = 1 + 1.2e-7): a + b is
    /// mostly along a, and one projection left u 1.2e-5 rad off perpendicular to a.
    #[test]
    fn nearly_opposite_inputs_off_unit_length() {
        let a = Vec3::new(-0.866_131_9, 0.455_334_3, 0.206_122_38);
        let b = Vec3::new(0.866_131_8, -0.455_334_25, -0.206_122_35);
        for t in [0.25f32, 0.5, 0.75] {
            let r = slerp(a, b, t);
            let want = t as f64 * angle(a, b);
            assert!((angle(a, r) - want).abs() <= 1e-6, "t = {t}: {} vs {want}", angle(a, r));
        }
    }

    #[test]
    fn half_angle_is_atan2() {
        for k in 0..=100_000 {
            let phi = k as f64 / 100_000.0 * std::f64::consts::FRAC_PI_2;
            let (y, x) = (phi.sin() as f32, phi.cos() as f32);
            let want = (y as f64).atan2(x as f64);
            assert!((half_angle(y, x) as f64 - want).abs() <= 2.5e-7 * want.max(1e-3), "φ = {phi}");
        }
        assert_eq!(half_angle(0.0, 1.0), 0.0);
        assert!((half_angle(1.0, 0.0) - std::f32::consts::FRAC_PI_2).abs() < 1e-7);
    }

    #[test]
    fn opposite_vectors_take_a_fixed_great_circle() {
        let r = slerp(Vec3::Z, -Vec3::Z, 0.5);
        assert!((r - Vec3::Y).length() < 1e-6, "{r}");
        let mut rng = Rng::new(5);
        for _ in 0..100 {
            let a = rng.direction();
            let r1 = slerp(a, -a, 0.3);
            assert_eq!(r1, slerp(a, -a, 0.3), "deterministic");
            assert!((angle(a, r1) - 0.3 * std::f64::consts::PI).abs() < 1e-5);
        }
    }

    #[test]
    fn stays_in_the_plane_and_agrees_with_reference_forms() {
        let mut rng = Rng::new(3);
        for _ in 0..2000 {
            let theta = 0.02 + rng.unit() as f64 * 3.0;
            let (a, b) = pair(&mut rng, theta);
            let t = rng.unit();
            let r = slerp(a, b, t);
            let n = a.as_dvec3().cross(b.as_dvec3()).normalize();
            assert!(r.as_dvec3().dot(n).abs() < 1e-6, "out of plane");
            // The textbook form, in f64, is accurate away from 0 and π.
            let th = angle(a, b);
            let (ad, bd) = (a.as_dvec3(), b.as_dvec3());
            let want: DVec3 = (ad * ((1.0 - t as f64) * th).sin() + bd * (t as f64 * th).sin()) / th.sin();
            assert!((r.as_dvec3() - want).length() < 2e-6, "θ={theta}: {r} vs {want}");
            // glam's slerp uses an approximate acos: agree with it where it is accurate (≤ 2.5 rad).
            if theta < 2.5 {
                assert!((r - a.slerp(b, t)).length() < 1e-3, "glam θ={theta}");
            }
        }
    }

    #[test]
    fn lerp_rays_is_exact_at_the_ends() {
        let a = StoredRay::new(Vec3::new(-0.0, 1.0, 2.0), Vec3::X);
        let b = StoredRay::new(Vec3::new(4.0, 5.0, 6.0), Vec3::Y);
        assert_eq!(bytemuck::bytes_of(&lerp_rays(&a, &b, 0.0)), bytemuck::bytes_of(&a));
        assert_eq!(bytemuck::bytes_of(&lerp_rays(&a, &b, 1.0)), bytemuck::bytes_of(&b));
        let m = lerp_rays(&a, &b, 0.5);
        assert_eq!(m.origin, Vec3::new(2.0, 3.0, 4.0));
        assert!((m.direction - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6);
    }
}
