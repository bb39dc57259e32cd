//! The sheen: the microfibre lobe of Zeltner, Burley & Chiang 2022 ("Practical
//! Multiple-Scattering Sheen Using Linearly Transformed Cosines"), as Cycles' Principled BSDF
//! renders it ("Sheen", which Blender's glTF importer sets from `KHR_materials_sheen`).
//!
//! The reference is a layer of fibres standing along the normal: a unit-thick, white
//! volume of fibre-like SGGX microflakes whose cross-section is the roughness squared, over
//! nothing. The light it reflects is fitted, per (cos θo, roughness), by a linearly transformed
//! cosine (Heitz et al. 2016) whose inverse matrix is [[a, 0, b], [0, a, 0], [0, 0, 1]] in the
//! frame whose x axis leans toward wo, scaled by the layer's directional albedo R:
//!
//!   f·cos(wi) = R · D(wi),  D(ω) = z a² / (π ‖M⁻¹ω‖⁴),
//!
//! reciprocal only as far as the fit is (the reference is). D is normalised, so it is sampled
//! exactly (a cosine-distributed direction through M) and its density is D itself. The table
//! (`sheen_table.rs`) is produced by tools/sheen-fit, which simulates the layer and fits each
//! cell; it is read bilinearly with grid points i/31, roughness clamped to [10⁻³, 1] as in
//! Cycles.
//!
//! Layering (Cycles' `closure_layering_weight`): the sheen of colour c (weight × tint) reflects
//! c·R·D and leaves the layers below 1 − max(c·R) of the light.

use super::compensation;
use super::sheen_table;
use crate::sampling::{Frame, sample_uniform_disk_concentric};
use glam::{Vec2, Vec3};

/// The sheen lobe at one shading point, with wo fixed.
#[derive(Clone, Copy, Debug)]
pub struct Sheen {
    /// The sheen's frame: z the normal (on wo's side), x toward wo.
    frame: Frame,
    /// The LTC's inverse-matrix entries.
    a: f32,
    b: f32,
    /// Colour × the layer's directional albedo for wo.
    scale: Vec3,
}

impl Sheen {
    /// The sheen of colour `color` (weight × tint, each channel ≥ 0) and roughness `roughness`
    /// on unit normal `n` (either side), geometric normal `ng` facing wo, seen from world
    /// direction `wo`.
    #[inline]
    pub fn new(color: Vec3, roughness: f32, n: Vec3, ng: Vec3, wo: Vec3) -> Self {
        let n = if n.dot(ng) < 0.0 { -n } else { n };
        let mu = wo.dot(n).clamp(0.0, 1.0);
        // x: wo's part along the surface; head-on any tangent does (b is 0 there).
        let t = wo - mu * n;
        let frame = if t.length_squared() > 1e-12 {
            let x = t.normalize();
            Frame { x, y: n.cross(x), z: n }
        } else {
            Frame::from_z(n)
        };
        let roughness = roughness.clamp(1e-3, 1.0);
        let a = compensation::lookup(&sheen_table::A, mu, roughness).max(1e-4);
        let b = compensation::lookup(&sheen_table::B, mu, roughness);
        let r = compensation::lookup(&sheen_table::R, mu, roughness).clamp(0.0, 1.0);
        Self { frame, a, b, scale: color * r }
    }

    /// The share of light the sheen takes from the layers below for this wo: the largest
    /// channel of colour × albedo, at most 1.
    #[inline]
    pub fn albedo(&self) -> f32 {
        self.scale.max_element().min(1.0)
    }

    /// This lobe with its value scaled by `k` > 0 (its density unchanged).
    #[inline]
    pub fn scaled(self, k: f32) -> Self {
        Self { scale: self.scale * k, ..self }
    }

    /// D(ω) for local unit ω above the surface.
    #[inline]
    fn d(&self, w: Vec3) -> f32 {
        let (a, b) = (self.a, self.b);
        let x = a * w.x + b * w.z;
        let y = a * w.y;
        let len2 = x * x + y * y + w.z * w.z;
        std::f32::consts::FRAC_1_PI * w.z * (a / len2) * (a / len2)
    }

    /// f(wo, wi) times cos(sheen normal, wi) / `cos_s` (the integrator weighs f by the cosine
    /// of the shading normal, `cos_s` > 0), and the density of sampling `wi` (world, unit)
    /// from this lobe.
    #[inline]
    pub fn eval(&self, wi: Vec3, cos_s: f32) -> (Vec3, f32) {
        let w = self.frame.to_local(wi);
        if w.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let d = self.d(w);
        (self.scale * (d / cos_s), d)
    }

    /// A direction sampled in proportion to D (world, unit).
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<Vec3> {
        let p = sample_uniform_disk_concentric(u);
        let z = (1.0 - p.length_squared()).max(0.0).sqrt();
        let w = Vec3::new((p.x - z * self.b) / self.a, p.y / self.a, z).normalize_or_zero();
        (w.z > 0.0).then(|| self.frame.from_local(w).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::base::tests::halton;

    fn at(cos_o: f32) -> Vec3 {
        Vec3::new((1.0 - cos_o * cos_o).max(0.0).sqrt(), 0.0, cos_o)
    }

    /// ∫ D over the hemisphere by stratified uniform sampling, and E[f·cos/pdf] by importance
    /// sampling: both estimate what the lobe reflects.
    fn integrals(s: &Sheen, n: u32) -> (f64, Vec3) {
        let mut uniform = 0.0f64;
        let mut is = Vec3::ZERO;
        for i in 0..n {
            let u = Vec2::new(halton(i, 2), halton(i, 3));
            // Uniform hemisphere.
            let z = u.x;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * u.y;
            let w = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let (_, pdf) = s.eval(w, 1.0);
            uniform += pdf as f64 * std::f64::consts::TAU;
            if let Some(wi) = s.sample(u) {
                let (f, pdf) = s.eval(wi, 1.0);
                assert!(f.is_finite() && pdf.is_finite() && pdf > 0.0, "{wi} {f} {pdf}");
                is += f / pdf;
            }
        }
        (uniform / n as f64, is / n as f32)
    }

    /// Furnace: a white sheen reflects what the table's albedo says, at most 1, never NaN, at
    /// roughness 0 and 1 and between, head-on and grazing; D integrates to 1 over the
    /// hemisphere (the density is normalised, so the sampler's estimate equals R).
    #[test]
    fn sheen_furnace() {
        for roughness in [0.0f32, 0.1, 0.3, 0.5, 0.8, 1.0] {
            for cos_o in [1.0f32, 0.7, 0.3, 0.05, 1e-4, 0.0] {
                let s = Sheen::new(Vec3::ONE, roughness, Vec3::Z, Vec3::Z, at(cos_o));
                let r = s.scale.x;
                assert!((0.0..=1.0).contains(&r), "{roughness} {cos_o}: albedo {r}");
                let (norm, is) = integrals(&s, 1 << 14);
                assert!((norm - 1.0).abs() < 0.03, "{roughness} {cos_o}: ∫D = {norm}");
                // f·cos/pdf is R for every sample; a few at the horizon are lost to rounding.
                assert!((is.x - r).abs() <= 1e-3 * r, "{roughness} {cos_o}: {is} vs {r}");
                assert!(is.max_element() <= 1.0);
            }
        }
    }

    /// The table is what a microfibre layer does: rough fibres reflect more head-on than smooth
    /// ones; grazing light is reflected more than head-on light; smooth fibres standing
    /// straight reflect (almost) nothing head-on.
    #[test]
    fn the_albedo_has_the_fibre_layer_shape() {
        let r = |rough: f32, mu: f32| Sheen::new(Vec3::ONE, rough, Vec3::Z, Vec3::Z, at(mu)).albedo();
        assert!(r(1.0, 1.0) > r(0.5, 1.0) && r(0.5, 1.0) > r(0.2, 1.0), "{} {}", r(1.0, 1.0), r(0.5, 1.0));
        for rough in [0.2f32, 0.5, 1.0] {
            assert!(r(rough, 0.05) > r(rough, 1.0) + 0.2, "{rough}");
        }
        assert!(r(0.0, 1.0) < 1e-3, "{}", r(0.0, 1.0));
        // Colour scales the reflection, and the largest channel is what it takes from below.
        let c = Sheen::new(Vec3::new(0.9, 0.2, 0.1), 0.3, Vec3::Z, Vec3::Z, at(0.2));
        assert!((c.albedo() - 0.9 * r(0.3, 0.2)).abs() < 1e-6);
    }

    /// The sampler's histogram matches D: in 8 × 8 cells of (cos θ, φ) the share of samples
    /// agrees with ∫D over the cell (a chi-square test with 63 degrees of freedom).
    #[test]
    fn sampling_matches_the_density() {
        for (roughness, cos_o) in [(0.3f32, 0.8f32), (0.6, 0.2), (1.0, 0.5), (0.15, 0.05)] {
            let s = Sheen::new(Vec3::ONE, roughness, Vec3::Z, Vec3::Z, at(cos_o));
            const K: usize = 8;
            let n = 1usize << 16;
            let mut counts = [[0f64; K]; K];
            for i in 0..n as u32 {
                let wi = s.sample(Vec2::new(halton(i, 2), halton(i, 3))).expect("above");
                let phi = wi.y.atan2(wi.x).rem_euclid(std::f32::consts::TAU);
                let (ci, pi) =
                    ((wi.z * K as f32) as usize, (phi / std::f32::consts::TAU * K as f32) as usize);
                counts[ci.min(K - 1)][pi.min(K - 1)] += 1.0;
            }
            // Expected: ∫ over each cell by a fine midpoint rule in (cos θ, φ) (dω = dz dφ).
            let m = 24;
            let mut chi2 = 0.0;
            for (ci, row) in counts.iter().enumerate() {
                for (pi, &observed) in row.iter().enumerate() {
                    let mut e = 0.0f64;
                    for a in 0..m {
                        for b in 0..m {
                            let z = (ci as f32 + (a as f32 + 0.5) / m as f32) / K as f32;
                            let phi =
                                (pi as f32 + (b as f32 + 0.5) / m as f32) / K as f32 * std::f32::consts::TAU;
                            let r = (1.0 - z * z).sqrt();
                            let (_, pdf) = s.eval(Vec3::new(r * phi.cos(), r * phi.sin(), z), 1.0);
                            e += pdf as f64;
                        }
                    }
                    let expected = e / (m * m) as f64 * (std::f64::consts::TAU / (K * K) as f64) * n as f64;
                    if expected > 5.0 {
                        chi2 += (observed - expected).powi(2) / expected;
                    }
                }
            }
            // 63 degrees of freedom: the 0.1 % quantile is about 104.
            assert!(chi2 < 104.0, "{roughness} {cos_o}: χ² = {chi2}");
        }
    }

    /// Grazing and degenerate views give finite values: wo in the plane, wo along the normal,
    /// wo below a shading normal tilted away.
    #[test]
    fn degenerate_views_stay_finite() {
        let ns = Vec3::new(0.3, 0.0, 0.95).normalize();
        for (n, wo) in [
            (Vec3::Z, Vec3::X),
            (Vec3::Z, Vec3::Z),
            (ns, Vec3::new(-0.999, 0.0, 0.04).normalize()),
            (-Vec3::Z, Vec3::new(0.0, 0.6, 0.8)),
        ] {
            for roughness in [0.0, 0.5, 1.0] {
                let s = Sheen::new(Vec3::ONE, roughness, n, Vec3::Z, wo);
                assert!(s.albedo().is_finite() && s.a.is_finite() && s.b.is_finite());
                for i in 0..256 {
                    if let Some(wi) = s.sample(Vec2::new(halton(i, 2), halton(i, 3))) {
                        let (f, pdf) = s.eval(wi, 0.5);
                        assert!(f.is_finite() && pdf.is_finite(), "{n} {wo} {roughness}: {f} {pdf}");
                    }
                }
            }
        }
    }
}
