//! A smooth dielectric interface (glass, `KHR_materials_transmission` with
//! `KHR_materials_ior`; pbrt-v4 §9.5): exact unpolarised Fresnel reflection and Snell
//! refraction, both delta lobes, chosen in proportion to their Fresnel weights.

use glam::Vec3;

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
}
