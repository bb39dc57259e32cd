//! A smooth dielectric interface (glass, `KHR_materials_transmission` with
//! `KHR_materials_ior`; pbrt-v4 §9.5): exact unpolarised Fresnel reflection and Snell
//! refraction, both delta lobes, chosen in proportion to their Fresnel weights
//! ([`Dielectric::sample`]).

use glam::Vec3;

/// The glass lobe of one hit, with wo fixed: a smooth interface between the outside (the
/// geometric normal's side) and a medium of index `ior`.
#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// The shading normal, turned to wo's side of the interface.
    n: Vec3,
    /// The geometric normal (front face).
    ng: Vec3,
    /// The direction back along the incoming ray (unit).
    wo: Vec3,
    /// wo is on the geometric normal's side: the ray enters the medium.
    entering: bool,
    /// Relative index: the far side's over wo's side.
    eta: f32,
    /// cos θ between `n` and wo (kept just above 0).
    cos_o: f32,
    /// Transmittance of a refraction (the base colour).
    tint: Vec3,
}

/// A direction sampled from the glass lobe.
#[derive(Clone, Copy, Debug)]
pub struct DielectricSample {
    /// Incident direction, world space, unit length.
    pub wi: Vec3,
    /// f · |cos θ| / pdf: 1 for a reflection, the tint over η² for a refraction.
    pub weight: Vec3,
}

impl Dielectric {
    /// The interface at a hit with shading normal `ns` and geometric normal `ng` (unit, `ng` the
    /// front face's, `ns` facing either way), seen from world direction `wo`, into a medium of
    /// index `ior` whose refractions are tinted `tint`.
    #[inline(always)]
    pub fn new(ns: Vec3, ng: Vec3, wo: Vec3, ior: f32, tint: Vec3) -> Self {
        let entering = ng.dot(wo) > 0.0;
        let mut n = if ns.dot(ng) < 0.0 { -ns } else { ns };
        let mut eta = ior;
        if !entering {
            n = -n;
            eta = 1.0 / eta;
        }
        let cos_o = n.dot(wo).max(1e-6);
        Self { n, ng, wo, entering, eta, cos_o, tint }
    }

    /// Reflects with the Fresnel reflectance's probability (`u` < F), refracts otherwise
    /// (reflecting under total internal reflection). `None` when the direction would leave on
    /// the wrong side of the geometry (a reflection must stay on wo's side, a refraction cross
    /// it): the shading normal lied, and the path ends.
    #[inline(always)]
    pub fn sample(&self, u: f32) -> Option<DielectricSample> {
        let (n, wo, cos_o, eta) = (self.n, self.wo, self.cos_o, self.eta);
        let reflection = DielectricSample { wi: 2.0 * cos_o * n - wo, weight: Vec3::ONE };
        let s = if u < fresnel(cos_o, eta) {
            reflection
        } else {
            match refract(wo, n, eta) {
                // Radiance is compressed by η² crossing into the denser side.
                Some(wi) => DielectricSample { wi, weight: self.tint / (eta * eta) },
                None => reflection,
            }
        };
        let reflected = s.wi.dot(n) > 0.0;
        ((s.wi.dot(self.ng) > 0.0) == (self.entering == reflected)).then_some(s)
    }
}

/// The Fresnel reflectance of an unpolarised wave at an interface with relative index `eta`
/// (inside over outside) for cos θi = `cos_i` (> 0: arriving from outside).
#[inline]
pub fn fresnel(cos_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_i < 0.0 { (-cos_i, 1.0 / eta) } else { (cos_i, eta) };
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Refracts `wo` (unit, pointing away from the surface on the side of `n`) through the
/// interface with relative index `eta` (the far side's index over `wo`'s side). `None` under
/// total internal reflection.
#[inline]
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = n.dot(wo);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + (cos_i / eta - cos_t) * n).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_known_values() {
        // Normal incidence: ((η − 1)/(η + 1))² = 0.04 for glass.
        assert!((fresnel(1.0, 1.5) - 0.04).abs() < 1e-6);
        // Grazing: everything reflects.
        assert!(fresnel(1e-4, 1.5) > 0.99);
        // From inside beyond the critical angle (41.8°): total internal reflection.
        assert_eq!(fresnel(-(50f32.to_radians().cos()), 1.5), 1.0);
        // Symmetric at normal incidence from either side.
        assert!((fresnel(-1.0, 1.5) - 0.04).abs() < 1e-6);
    }

    /// Snell's law: sin θt = sin θi / η, on the far side of the surface.
    #[test]
    fn refraction_obeys_snell() {
        let theta_i = 30f32.to_radians();
        let wo = Vec3::new(theta_i.sin(), 0.0, theta_i.cos());
        let wi = refract(wo, Vec3::Z, 1.5).unwrap();
        assert!(wi.z < 0.0);
        assert!((wi.x.abs() - theta_i.sin() / 1.5).abs() < 1e-6);
        assert!(wi.x < 0.0, "continues across the normal");
        assert!(refract(Vec3::new(0.8, 0.0, 0.6), Vec3::Z, 1.0 / 1.5).is_none(), "total internal reflection");
    }

    /// From outside at 30°: a share F of stratified numbers reflects (about the normal, weight
    /// 1), the rest refracts by Snell's law into the glass with weight tint / η²; the shading
    /// normal's orientation does not matter.
    #[test]
    fn glass_lobe_from_outside() {
        let tint = Vec3::new(1.0, 0.5, 0.25);
        let theta = 30f32.to_radians();
        let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
        let f = fresnel(theta.cos(), 1.5);
        for ns in [Vec3::Z, -Vec3::Z] {
            let glass = Dielectric::new(ns, Vec3::Z, wo, 1.5, tint);
            let n = 1000;
            let mut reflected = 0;
            for i in 0..n {
                let s = glass.sample((i as f32 + 0.5) / n as f32).expect("a flat interface never lies");
                if s.wi.z > 0.0 {
                    reflected += 1;
                    assert!((s.wi - Vec3::new(-wo.x, 0.0, wo.z)).length() < 1e-6, "mirror: {}", s.wi);
                    assert_eq!(s.weight, Vec3::ONE);
                } else {
                    assert!((s.wi.x + theta.sin() / 1.5).abs() < 1e-6, "Snell: {}", s.wi);
                    assert!((s.weight - tint / 2.25).abs().max_element() < 1e-7);
                }
            }
            let share = reflected as f32 / n as f32;
            assert!((share - f).abs() <= 1.0 / n as f32, "{share} reflected, F = {f}");
        }
    }

    /// From inside beyond the critical angle every number reflects, back into the glass; below
    /// it, refractions leave the glass with weight η² (the index seen from inside is 1/η).
    #[test]
    fn glass_lobe_from_inside() {
        let steep = 50f32.to_radians();
        let wo = Vec3::new(steep.sin(), 0.0, -steep.cos());
        let glass = Dielectric::new(Vec3::Z, Vec3::Z, wo, 1.5, Vec3::ONE);
        for u in [0.0, 0.5, 0.999] {
            let s = glass.sample(u).unwrap();
            assert!(s.wi.z < 0.0 && s.weight == Vec3::ONE, "total internal reflection: {s:?}");
        }
        let shallow = 20f32.to_radians();
        let wo = Vec3::new(shallow.sin(), 0.0, -shallow.cos());
        let s = Dielectric::new(Vec3::Z, Vec3::Z, wo, 1.5, Vec3::ONE).sample(0.999).unwrap();
        assert!(s.wi.z > 0.0, "leaves the glass: {}", s.wi);
        assert!((s.wi.x + shallow.sin() * 1.5).abs() < 1e-6, "Snell: {}", s.wi);
        assert!((s.weight - Vec3::splat(2.25)).abs().max_element() < 1e-5, "{}", s.weight);
    }

    /// A shading normal tilted far from the geometric one can mirror wo below the surface it
    /// arrived on: the lobe then gives no direction rather than one through the wrong side.
    #[test]
    fn glass_lobe_rejects_what_the_shading_normal_lies_about() {
        let ns = Vec3::new(0.6, 0.0, 0.8);
        let wo = Vec3::new(-0.5, 0.0, 0.75f32.sqrt());
        // Mirrored about ns, wo would leave at wi ≈ (0.97, 0, −0.24), below the geometry.
        let glass = Dielectric::new(ns, Vec3::Z, wo, 1.5, Vec3::ONE);
        assert!(glass.sample(0.0).is_none());
        // With the geometric normal as the shading normal the same numbers reflect.
        assert!(Dielectric::new(Vec3::Z, Vec3::Z, wo, 1.5, Vec3::ONE).sample(0.0).is_some());
    }
}
