//! Spot lights (`KHR_lights_punctual` spot): a point light whose intensity fades from the inner
//! to the outer cone, by Blender Cycles' falloff (what Blender-exported scenes were lit with) or
//! the glTF specification's recommended one (docs/design/tracer.md §3.10).

use super::bounds::{LightBounds, cos_down};
use crate::scene::SpotFalloff;
use glam::Vec3;

/// A spot light with precomputed cone terms.
#[derive(Clone, Copy, Debug)]
pub struct SpotLight {
    /// Position.
    pub position: Vec3,
    /// Unit axis of the cone.
    pub direction: Vec3,
    /// Radiant intensity on the axis, W/sr.
    pub intensity: Vec3,
    cos_outer: f32,
    cos_inner: f32,
    /// Blender's b = 1 − inner/outer (angles): the share of the cone that fades.
    blend: f32,
    falloff: SpotFalloff,
}

impl SpotLight {
    /// A spot light at `position` pointing along `direction` (unit).
    pub fn new(
        position: Vec3,
        direction: Vec3,
        intensity: Vec3,
        inner_cone: f32,
        outer_cone: f32,
        falloff: SpotFalloff,
    ) -> Self {
        let blend = if outer_cone > 0.0 { (1.0 - inner_cone / outer_cone).clamp(0.0, 1.0) } else { 0.0 };
        Self {
            position,
            direction,
            intensity,
            cos_outer: outer_cone.cos(),
            cos_inner: inner_cone.cos(),
            blend,
            falloff,
        }
    }

    /// The fraction of the on-axis intensity emitted towards unit direction `w` (from the light).
    #[inline]
    pub fn falloff(&self, w: Vec3) -> f32 {
        let cos = self.direction.dot(w);
        if cos <= self.cos_outer {
            return 0.0;
        }
        match self.falloff {
            SpotFalloff::Blender => {
                if self.blend == 0.0 {
                    return 1.0;
                }
                let x = ((cos - self.cos_outer) / ((1.0 - self.cos_outer) * self.blend)).clamp(0.0, 1.0);
                x * x * (3.0 - 2.0 * x)
            }
            SpotFalloff::Gltf => {
                let scale = 1.0 / (self.cos_inner - self.cos_outer).max(0.001);
                let t = ((cos - self.cos_outer) * scale).clamp(0.0, 1.0);
                t * t
            }
        }
    }

    /// Its bounds for the light tree: full intensity within θo of the axis (where the falloff
    /// reaches 1), fading out over θe more, to the outer cone.
    pub fn bounds(&self) -> LightBounds {
        let cos_outer = self.cos_outer as f64;
        let cos_full = match self.falloff {
            SpotFalloff::Blender => cos_outer + (1.0 - cos_outer) * self.blend as f64,
            SpotFalloff::Gltf => cos_outer + (self.cos_inner as f64 - cos_outer).max(0.001),
        };
        let theta_o = cos_full.clamp(-1.0, 1.0).acos();
        let theta_e = (cos_outer.clamp(-1.0, 1.0).acos() - theta_o).max(0.0);
        LightBounds {
            lo: self.position,
            hi: self.position,
            w: self.direction,
            intensity: super::triangle::luminance(self.intensity),
            cos_theta_o: cos_down(theta_o),
            cos_theta_e: cos_down(theta_e),
            two_sided: false,
        }
    }

    /// Emitted power by luminance, integrating the falloff over the cone numerically.
    pub fn power(&self) -> f64 {
        // ∫ falloff dω over the cone = 2π ∫ falloff(cos) d(cos); 256 midpoint steps.
        let n = 256;
        let lo = self.cos_outer as f64;
        let step = (1.0 - lo) / n as f64;
        let mut solid_angle = 0.0;
        for k in 0..n {
            let c = lo + (k as f64 + 0.5) * step;
            let s = (1.0 - c * c).max(0.0).sqrt();
            let w = self.direction * c as f32 + perpendicular(self.direction) * s as f32;
            solid_angle += self.falloff(w) as f64 * step;
        }
        2.0 * std::f64::consts::PI * solid_angle * super::luminance(self.intensity) as f64
    }
}

fn perpendicular(d: Vec3) -> Vec3 {
    crate::sampling::Frame::from_z(d).x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cycles' falloff at known angles of a 17°/20° cone (docs/design/tracer.md §3.10's example), and
    /// glTF's.
    #[test]
    fn falloff_at_known_angles() {
        let (inner, outer) = (17f32.to_radians(), 20f32.to_radians());
        let at = |deg: f32| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        let blender = SpotLight::new(Vec3::ZERO, Vec3::Z, Vec3::ONE, inner, outer, SpotFalloff::Blender);
        let gltf = SpotLight { falloff: SpotFalloff::Gltf, ..blender };
        assert_eq!(blender.falloff(at(0.0)), 1.0);
        assert_eq!(blender.falloff(at(20.5)), 0.0);
        assert_eq!(gltf.falloff(at(16.0)), 1.0);
        for deg in [17.5f32, 18.5, 19.5] {
            let cos = deg.to_radians().cos();
            let (co, ci) = (outer.cos(), inner.cos());
            let b = 1.0 - inner / outer;
            let x = ((cos - co) / ((1.0 - co) * b)).clamp(0.0, 1.0);
            let want_blender = x * x * (3.0 - 2.0 * x);
            let t = ((cos - co) / (ci - co)).clamp(0.0, 1.0);
            assert!((blender.falloff(at(deg)) - want_blender).abs() < 1e-5, "{deg}");
            assert!((gltf.falloff(at(deg)) - t * t).abs() < 1e-5, "{deg}");
        }
    }

    /// A hard-edged cone (inner = outer) has power I · 2π(1 − cos θ).
    #[test]
    fn power_of_a_hard_cone() {
        let a = 30f32.to_radians();
        let s = SpotLight::new(Vec3::ZERO, Vec3::Y, Vec3::ONE, a, a, SpotFalloff::Blender);
        let want = 2.0 * std::f64::consts::PI * (1.0 - (a as f64).cos());
        assert!((s.power() - want).abs() < 2e-3 * want, "{} vs {want}", s.power());
    }
}
