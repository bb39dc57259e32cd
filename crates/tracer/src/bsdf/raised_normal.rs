//! Blender's bump-map correction for the specular lobes (Cycles'
//! `ensure_valid_specular_reflection`, on by default in every Blender material;
//! docs/design/tracer.md §3.10): where a shading normal (normal map, interpolated normals) would mirror
//! wo below the surface, the specular lobes use a normal raised towards the geometric one just
//! enough that the mirror direction leaves at a height of min(0.9·(wo·ng), 0.01). The diffuse
//! lobe keeps the shading normal.

use glam::Vec3;

/// The raised normal for unit geometric normal `ng` (on wo's side), unit `wo` and unit shading
/// normal `n` (on ng's side); `None` when `n` mirrors wo high enough already.
#[inline]
pub fn raised(ng: Vec3, wo: Vec3, n: Vec3) -> Option<Vec3> {
    let r = 2.0 * n.dot(wo) * n - wo;
    let iz = wo.dot(ng).max(0.0);
    let threshold = (0.9 * iz).min(0.01);
    if ng.dot(r) >= threshold {
        return None;
    }
    // In the frame (x, ·, ng) with n in the x–ng plane, the raised normal n' = (√(1 − z²), 0, z)
    // solves 2(n'·wo)·z − wo·ng = threshold: 4a z⁴ − 2b z² + c = 0, one root valid (Cycles'
    // derivation).
    let x = (n - n.dot(ng) * ng).normalize_or(n);
    let ix = wo.dot(x);
    let a = ix * ix + iz * iz;
    let b = 2.0 * (a + iz * threshold);
    let c = (threshold + iz) * (threshold + iz);
    let root = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let z2 = if ix < 0.0 { 0.25 * (b + root) / a } else { 0.25 * (b - root) / a };
    Some((1.0 - z2).max(0.0).sqrt() * x + z2.max(0.0).sqrt() * ng)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A normal tilted away from a grazing wo is raised until wo's mirror direction leaves at
    /// the threshold height; an untilted normal, or one that mirrors high enough, is kept.
    #[test]
    fn raises_just_enough() {
        let ng = Vec3::Z;
        let wo = Vec3::new(0.8, 0.0, 0.6);
        assert!(raised(ng, wo, ng).is_none());
        let tilt = 35f32.to_radians();
        let toward = Vec3::new(tilt.sin(), 0.0, tilt.cos());
        assert!(raised(ng, wo, toward).is_none());
        let away = Vec3::new(-tilt.sin(), 0.0, tilt.cos());
        let n = raised(ng, wo, away).expect("raised");
        assert!((n.length() - 1.0).abs() < 1e-5, "{n}");
        let r = 2.0 * n.dot(wo) * n - wo;
        assert!((r.z - 0.01).abs() < 1e-4, "{r}");
        // Raised towards ng, in the plane of n and ng, between them.
        assert!(n.z > away.z && n.x < 0.0 && n.y.abs() < 1e-6, "{n}");
    }
}
