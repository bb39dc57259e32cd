//! The GGX (Trowbridge–Reitz) microfacet distribution with Smith's height-correlated masking–
//! shadowing (Heitz, "Understanding the Masking-Shadowing Function", JCGT 3(2), 2014) and
//! visible-normal sampling by spherical caps (Dupuy & Benyoub, "Sampling Visible GGX Normals
//! with Spherical Caps", HPG 2023). Directions are in the local shading frame (+z = normal,
//! +x = the tangent along which an anisotropic distribution has its roughness α_x).
//!
//! The distribution is anisotropic when α_x ≠ α_y (`KHR_materials_anisotropy`, Blender's
//! Anisotropic input): D and Λ then take the ellipsoidal forms of Heitz 2014 §5.2, and the
//! visible-normal sampling stretches x and y by their own α. The isotropic case keeps its own
//! arithmetic, so a material without anisotropy gets the same bits as before.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The smallest α used: below it the lobe is so narrow that f32 densities overflow.
pub const MIN_ALPHA: f32 = 1e-3;

/// A GGX distribution of microfacet normals, α_x along the local x axis, α_y along y.
#[derive(Clone, Copy, Debug)]
pub struct Ggx {
    alpha: f32,
    /// α_y; equal to `alpha` (α_x) for an isotropic distribution.
    alpha_y: f32,
}

impl Ggx {
    /// The isotropic distribution for a glTF perceptual roughness (α = roughness²).
    #[inline]
    pub fn from_roughness(roughness: f32) -> Self {
        let alpha = (roughness * roughness).max(MIN_ALPHA);
        Self { alpha, alpha_y: alpha }
    }

    /// The distribution with roughness α_x along the tangent (local x) and α_y across it
    /// (each at least [`MIN_ALPHA`], at most 1).
    #[inline]
    pub fn anisotropic(alpha_x: f32, alpha_y: f32) -> Self {
        Self { alpha: alpha_x.clamp(MIN_ALPHA, 1.0), alpha_y: alpha_y.clamp(MIN_ALPHA, 1.0) }
    }

    /// α (α_x for an anisotropic distribution).
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// (α_x, α_y).
    #[inline]
    pub fn alphas(&self) -> (f32, f32) {
        (self.alpha, self.alpha_y)
    }

    /// True when α_x ≠ α_y.
    #[inline]
    pub fn is_anisotropic(&self) -> bool {
        self.alpha != self.alpha_y
    }

    /// D(h): density of microfacet normals (projected-area normalised).
    #[inline]
    pub fn d(&self, h: Vec3) -> f32 {
        if self.is_anisotropic() {
            return self.d_anisotropic(h);
        }
        let a2 = self.alpha * self.alpha;
        let t = h.z * h.z * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    /// D(h) = 1 / (π α_x α_y (x²/α_x² + y²/α_y² + z²)²).
    #[inline(never)]
    fn d_anisotropic(&self, h: Vec3) -> f32 {
        let (ax, ay) = (self.alpha, self.alpha_y);
        let (x, y) = (h.x / ax, h.y / ay);
        let t = x * x + y * y + h.z * h.z;
        1.0 / (PI * ax * ay * t * t)
    }

    /// Smith's Λ(w).
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        if z2 == 0.0 {
            return f32::INFINITY;
        }
        if self.is_anisotropic() {
            // α² tan²θ with α in the direction of w's projection (Heitz 2014, eq. 80).
            let (x, y) = (w.x * self.alpha, w.y * self.alpha_y);
            return 0.5 * ((1.0 + (x * x + y * y) / z2).sqrt() - 1.0);
        }
        let tan2 = (w.x * w.x + w.y * w.y) / z2;
        0.5 * ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0)
    }

    /// Masking G1(w).
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking–shadowing G2(wo, wi).
    #[inline]
    pub fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// A microfacet normal distributed as the normals visible from `wo` (wo.z > 0).
    #[inline]
    pub fn sample_visible_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        // Stretch to the unit-roughness configuration, sample a spherical cap, unstretch.
        let wo_std = Vec3::new(wo.x * self.alpha, wo.y * self.alpha_y, wo.z).normalize();
        let z = (1.0 - u.y) * (1.0 + wo_std.z) - wo_std.z;
        let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
        let (s, c) = crate::sampling::sin_cos_turn(u.x);
        let h_std = Vec3::new(sin_theta * c, sin_theta * s, z) + wo_std;
        Vec3::new(h_std.x * self.alpha, h_std.y * self.alpha_y, h_std.z.max(0.0)).normalize_or(Vec3::Z)
    }

    /// The solid-angle density of reflected `wi` when h is sampled by
    /// [`Ggx::sample_visible_normal`] from `wo`: D_wo(h) / (4 |wo·h|) = G1(wo) D(h) / (4 wo.z).
    #[inline]
    pub fn pdf_reflection(&self, wo: Vec3, h: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * self.d(h) / (4.0 * wo.z)
    }
}

#[cfg(test)]
mod tests {
    use super::super::base::tests::halton;
    use super::*;

    /// Anisotropic (α_x, α_y) pairs the tests run over: both orientations, a strong stretch, the
    /// lower bound against 1.
    const PAIRS: [(f32, f32); 5] = [(0.3, 0.08), (0.08, 0.3), (0.6, 0.25), (1.0, 0.2), (0.15, 0.45)];

    fn unit(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    fn reflect(wo: Vec3, h: Vec3) -> Vec3 {
        2.0 * wo.dot(h) * h - wo
    }

    /// ∫ D(h) cos θh dωh = 1 (projected-area normalisation), by a midpoint rule in
    /// s = tan θ / (α_max + tan θ), which packs the grid where a narrow lobe lives.
    #[test]
    fn anisotropic_d_is_normalised() {
        for (ax, ay) in PAIRS {
            let ggx = Ggx::anisotropic(ax, ay);
            let a = ax.max(ay) as f64;
            let (ns, nphi) = (4000, 256);
            let mut sum = 0.0f64;
            for i in 0..ns {
                let s = (i as f64 + 0.5) / ns as f64;
                let tan = a * s / (1.0 - s);
                let theta = tan.atan();
                // dθ/ds = (dθ/dtan)(dtan/ds) = a / (1 − s)² / (1 + tan²)
                let dtheta = a / ((1.0 - s) * (1.0 - s)) / (1.0 + tan * tan) / ns as f64;
                for j in 0..nphi {
                    let phi = (j as f64 + 0.5) / nphi as f64 * std::f64::consts::TAU;
                    let h = unit(theta as f32, phi as f32);
                    sum += ggx.d(h) as f64 * theta.cos() * theta.sin() * dtheta * std::f64::consts::TAU
                        / nphi as f64;
                }
            }
            assert!((sum - 1.0).abs() < 2e-3, "({ax}, {ay}): ∫D cos = {sum}");
        }
    }

    /// The sampled reflection directions follow `pdf_reflection`: a histogram over (cos θ, φ)
    /// of 2^18 samples against the density integrated over each bin (a chi-square test), and
    /// the density's integral over the upper hemisphere equals the share of samples above it.
    #[test]
    fn sampling_matches_the_density() {
        const NZ: usize = 16;
        const NP: usize = 24;
        const SUB: usize = 12;
        let n = 1u32 << 18;
        for (ax, ay) in [(0.3f32, 0.08f32), (0.6, 0.25), (0.15, 0.45)] {
            let ggx = Ggx::anisotropic(ax, ay);
            for wo in [Vec3::Z, unit(1.0, 0.4), unit(1.4, 2.0)] {
                let mut counts = [[0u32; NP]; NZ];
                let mut above = 0u32;
                for i in 0..n {
                    let h = ggx.sample_visible_normal(wo, Vec2::new(halton(i, 2), halton(i, 3)));
                    let wi = reflect(wo, h);
                    if wi.z > 0.0 {
                        above += 1;
                        let z = ((wi.z * NZ as f32) as usize).min(NZ - 1);
                        let phi = wi.y.atan2(wi.x).rem_euclid(std::f32::consts::TAU);
                        let p = ((phi / std::f32::consts::TAU * NP as f32) as usize).min(NP - 1);
                        counts[z][p] += 1;
                    }
                }
                // The expected share of each bin: the density integrated on a sub-grid (uniform in
                // z and φ, so dω = dz dφ).
                let (mut chi2, mut dof, mut total) = (0.0f64, 0usize, 0.0f64);
                for (zi, row) in counts.iter().enumerate() {
                    for (pi, &count) in row.iter().enumerate() {
                        let mut p = 0.0f64;
                        for a in 0..SUB {
                            for b in 0..SUB {
                                let z = (zi as f32 + (a as f32 + 0.5) / SUB as f32) / NZ as f32;
                                let phi = (pi as f32 + (b as f32 + 0.5) / SUB as f32) / NP as f32
                                    * std::f32::consts::TAU;
                                let wi = unit(z.acos(), phi);
                                let h = (wo + wi).normalize();
                                p += ggx.pdf_reflection(wo, h) as f64;
                            }
                        }
                        let area = std::f64::consts::TAU / (NZ * NP * SUB * SUB) as f64;
                        let expected = p * area * n as f64;
                        total += p * area;
                        if expected >= 20.0 {
                            chi2 += (count as f64 - expected).powi(2) / expected;
                            dof += 1;
                        }
                    }
                }
                assert!(dof > 20, "({ax}, {ay}) {wo}: {dof} bins");
                // χ² of `dof` degrees of freedom: mean dof, deviation √(2 dof); the sub-grid
                // quadrature adds a little of its own.
                let limit = dof as f64 + 6.0 * (2.0 * dof as f64).sqrt();
                assert!(chi2 < limit, "({ax}, {ay}) {wo}: χ² {chi2:.0} over {dof} bins");
                let share = above as f64 / n as f64;
                assert!((total - share).abs() < 5e-3, "({ax}, {ay}) {wo}: ∫pdf {total} vs {share}");
            }
        }
    }

    /// The single-scattering lobe reflects at most what falls on it: its albedo
    /// ∫ D·G2 / (4 cos θo) dωi, by visible-normal sampling (G2 / G1 per sample) and by uniform
    /// sampling of the hemisphere (for the broad pairs), is ≤ 1 and the two agree.
    #[test]
    fn anisotropic_lobe_energy_is_at_most_one() {
        for (ax, ay) in PAIRS.into_iter().chain([(1.0, 1e-3), (1e-3, 1.0)]) {
            let ggx = Ggx::anisotropic(ax, ay);
            for wo in [
                Vec3::Z,
                unit(0.8, 0.3),
                unit(1.3, 1.9),
                unit(1.5607, 0.0),
                unit(1.5607, std::f32::consts::FRAC_PI_2),
            ] {
                let n = 1u32 << 16;
                let (mut by_sampling, mut uniform) = (0.0f64, 0.0f64);
                for i in 0..n {
                    let u = Vec2::new(halton(i, 2), halton(i, 3));
                    let wi = reflect(wo, ggx.sample_visible_normal(wo, u));
                    if wi.z > 0.0 {
                        by_sampling += (ggx.g2(wo, wi) / ggx.g1(wo)) as f64;
                    }
                    let wi = unit(u.x.acos(), u.y * std::f32::consts::TAU);
                    let h = (wo + wi).normalize();
                    uniform += (ggx.d(h) * ggx.g2(wo, wi) / (4.0 * wo.z)) as f64 * std::f64::consts::TAU;
                }
                let (is, uni) = (by_sampling / n as f64, uniform / n as f64);
                assert!(is <= 1.0 + 1e-6 && is > 0.3, "({ax}, {ay}) {wo}: {is}");
                if ax.min(ay) >= 0.2 && wo.z > 0.1 {
                    assert!((is - uni).abs() < 0.02, "({ax}, {ay}) {wo}: {is} vs {uni}");
                }
            }
        }
    }

    /// The single-scattering lobe D·G2 / (4 cos θo cos θi) is reciprocal.
    #[test]
    fn anisotropic_lobe_is_reciprocal() {
        for (ax, ay) in PAIRS {
            let ggx = Ggx::anisotropic(ax, ay);
            let f = |wo: Vec3, wi: Vec3| {
                let h = (wo + wi).normalize();
                ggx.d(h) * ggx.g2(wo, wi) / (4.0 * wo.z * wi.z)
            };
            for i in 0..512 {
                let wo = unit(halton(i, 2) * 1.5, halton(i, 3) * std::f32::consts::TAU);
                let wi = unit(halton(i, 5) * 1.5, halton(i, 7) * std::f32::consts::TAU);
                let (a, b) = (f(wo, wi), f(wi, wo));
                assert!(
                    a.is_finite() && (a - b).abs() <= 1e-5 * a.max(1.0),
                    "({ax}, {ay}) {wo} {wi}: {a} vs {b}"
                );
            }
        }
    }

    /// α_x = α_y is the isotropic lobe bit for bit; a nearly isotropic pair evaluates the
    /// anisotropic forms, which must agree with the isotropic ones to rounding; swapping α_x
    /// and α_y is the lobe turned by 90°; the lobe is wider along the larger α.
    #[test]
    fn isotropic_case_and_symmetries() {
        for r in [0.0f32, 0.1, 0.5, 1.0] {
            let iso = Ggx::from_roughness(r);
            let same = Ggx::anisotropic(iso.alpha(), iso.alpha());
            assert!(!same.is_anisotropic());
            let near = Ggx::anisotropic(iso.alpha(), iso.alpha() * (1.0 + 1e-6) + 1e-7);
            assert!(near.is_anisotropic() || r == 1.0);
            for i in 0..256 {
                let wo = unit(halton(i, 2) * 1.55, halton(i, 3) * std::f32::consts::TAU);
                let wi = unit(halton(i, 5) * 1.55, halton(i, 7) * std::f32::consts::TAU);
                let h = (wo + wi).normalize();
                let u = Vec2::new(halton(i, 11), halton(i, 13));
                assert_eq!(iso.d(h).to_bits(), same.d(h).to_bits());
                assert_eq!(iso.g2(wo, wi).to_bits(), same.g2(wo, wi).to_bits());
                let (a, b) = (iso.sample_visible_normal(wo, u), same.sample_visible_normal(wo, u));
                assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits));
                let rel = |x: f32, y: f32| (x - y).abs() / x.abs().max(1e-6);
                // (At α = 10⁻³ the isotropic form's h.z²(α² − 1) + 1 cancels to a few digits.)
                if r >= 0.1 {
                    assert!(rel(iso.d(h), near.d(h)) < 1e-3, "{r}: D {} vs {}", iso.d(h), near.d(h));
                    assert!(rel(iso.g2(wo, wi), near.g2(wo, wi)) < 1e-4, "{r}: G2");
                }
            }
        }
        for (ax, ay) in PAIRS {
            let (a, b) = (Ggx::anisotropic(ax, ay), Ggx::anisotropic(ay, ax));
            let turn = |v: Vec3| Vec3::new(-v.y, v.x, v.z);
            let (mut spread_x, mut spread_y) = (0.0, 0.0);
            for i in 0..256 {
                let wo = unit(halton(i, 2) * 1.5, halton(i, 3) * std::f32::consts::TAU);
                let h = unit(halton(i, 5) * 1.2, halton(i, 7) * std::f32::consts::TAU);
                assert!((a.d(h) - b.d(turn(h))).abs() <= 1e-4 * a.d(h).max(1.0));
                assert!((a.g1(wo) - b.g1(turn(wo))).abs() <= 1e-5);
                let s = a.sample_visible_normal(Vec3::Z, Vec2::new(halton(i, 11), halton(i, 13)));
                (spread_x, spread_y) = (spread_x + s.x.abs(), spread_y + s.y.abs());
            }
            assert_eq!(spread_x > spread_y, ax > ay, "({ax}, {ay}): spread {spread_x} / {spread_y}");
        }
    }

    /// Grazing directions, α at its bounds (10⁻³ against 1) and every pair give finite values.
    #[test]
    fn anisotropic_lobe_stays_finite_at_grazing_angles() {
        for (ax, ay) in PAIRS.into_iter().chain([(1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.0, 0.0)]) {
            let ggx = Ggx::anisotropic(ax, ay);
            for cos in [1e-6f32, 1e-3, 0.05] {
                for k in 0..16 {
                    let phi = k as f32 / 16.0 * std::f32::consts::TAU;
                    let wo = Vec3::new(
                        (1.0 - cos * cos).sqrt() * phi.cos(),
                        (1.0 - cos * cos).sqrt() * phi.sin(),
                        cos,
                    );
                    for i in 0..64 {
                        let h = ggx.sample_visible_normal(wo, Vec2::new(halton(i, 2), halton(i, 3)));
                        assert!(h.is_finite() && h.z >= 0.0, "({ax}, {ay}) {wo}: h {h}");
                        let wi = reflect(wo, h);
                        let pdf = ggx.pdf_reflection(wo, h);
                        assert!(pdf.is_finite() && pdf >= 0.0, "({ax}, {ay}) {wo}: pdf {pdf}");
                        if wi.z > 0.0 {
                            let f = ggx.d(h) * ggx.g2(wo, wi) / (4.0 * wo.z * wi.z);
                            assert!(f.is_finite(), "({ax}, {ay}) {wo} {wi}: f {f}");
                        }
                    }
                }
            }
        }
    }
}
