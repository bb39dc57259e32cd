//! The dielectric layer's Fresnel as Blender's Principled BSDF has it (Cycles'
//! `generalized_schlick_fresnel` with a negative exponent; docs/design/tracer.md §3.10): the exact
//! Fresnel of the index of refraction η, remapped from [F0(η), 1] onto [F0, 1], F0 the layer's
//! (tinted) reflectance at normal incidence. Untinted, it is the exact dielectric Fresnel; for
//! η = 1.5 it is brighter than Schlick's F0 = 0.04 curve between about 40° and 75° and averages
//! 0.092 over the hemisphere instead of 0.086.

use super::dielectric::fresnel;
use glam::Vec3;

/// Reflectance at normal incidence of an interface of relative index `eta`.
#[inline]
pub fn f0_of_ior(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// The Fresnel of one dielectric layer: F(cos) = F0 + (1 − F0)·s(cos), s the exact Fresnel of η
/// rescaled to run from 0 at normal incidence to 1 at grazing.
#[derive(Clone, Copy, Debug)]
pub struct LayerFresnel {
    /// Reflectance at normal incidence, per channel.
    pub f0: Vec3,
    /// Index of refraction that shapes the curve.
    pub eta: f32,
    /// F0(η), where s is zero.
    f0_eta: f32,
    /// 1 / (1 − F0(η)).
    inv_range: f32,
}

impl LayerFresnel {
    /// The layer of reflectance `f0` (clamped to 1) whose curve is that of index `eta` (≥ 1).
    #[inline]
    pub fn new(f0: Vec3, eta: f32) -> Self {
        let f0_eta = f0_of_ior(eta);
        Self { f0: f0.min(Vec3::ONE), eta, f0_eta, inv_range: 1.0 / (1.0 - f0_eta) }
    }

    /// The interpolation factor s between F0 and 1 for cos θ = `cos` (between the half vector and
    /// wo), in [0, 1].
    #[inline]
    pub fn s(&self, cos: f32) -> f32 {
        ((fresnel(cos.max(0.0), self.eta) - self.f0_eta) * self.inv_range).clamp(0.0, 1.0)
    }

    /// F(cos).
    #[inline]
    pub fn eval(&self, cos: f32) -> Vec3 {
        self.mix(self.s(cos))
    }

    /// F0 + (1 − F0)·s.
    #[inline]
    pub fn mix(&self, s: f32) -> Vec3 {
        self.f0 + (Vec3::ONE - self.f0) * s
    }

    /// The hemispherical average 2∫F(μ)μ dμ, through Kulla & Conty's fit of the exact Fresnel's
    /// average (2017, "Revisiting Physically Based Shading at Imageworks"), as Cycles computes it
    /// (`fresnel_dielectric_Fss`) for the layer's multiple-scattering compensation.
    #[inline]
    pub fn average(&self) -> Vec3 {
        let f_avg = (self.eta - 1.0) / (4.08567 + 1.00071 * self.eta);
        self.mix(((f_avg - self.f0_eta) * self.inv_range).clamp(0.0, 1.0))
    }

    /// z = F0(η)^¼, the coordinate of η in the layer-albedo table (`compensation.rs`).
    #[inline]
    pub fn table_z(&self) -> f32 {
        self.f0_eta.sqrt().sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Untinted, the layer's Fresnel is the exact one; its average is the closed-form integral
    /// to the fit's accuracy, and above Schlick's (F0 = 0.04: 0.04 + 0.96/21).
    #[test]
    fn exact_fresnel_and_its_average() {
        let layer = LayerFresnel::new(Vec3::splat(0.04), 1.5);
        for cos in [1.0f32, 0.8, 0.5, 0.2, 0.01] {
            assert!((layer.eval(cos).x - fresnel(cos, 1.5)).abs() < 1e-6, "{cos}");
        }
        let n = 100_000;
        let exact: f64 = (0..n)
            .map(|i| {
                let mu = (i as f64 + 0.5) / n as f64;
                2.0 * mu * fresnel(mu as f32, 1.5) as f64 / n as f64
            })
            .sum();
        let fit = layer.average().x as f64;
        assert!((fit - exact).abs() < 3e-3, "{fit} vs {exact}");
        assert!(exact > 0.04 + 0.96 / 21.0 + 5e-3, "{exact}");
        // A tint scales F0 and leaves grazing incidence at 1.
        let tinted = LayerFresnel::new(Vec3::new(0.02, 0.04, 0.08), 1.5);
        assert!((tinted.eval(1.0) - Vec3::new(0.02, 0.04, 0.08)).abs().max_element() < 1e-6);
        assert!((tinted.eval(0.0) - Vec3::ONE).abs().max_element() < 1e-6);
    }
}
