//! A point light (`KHR_lights_punctual` point): radiant intensity I [W/sr] in every direction;
//! irradiance I·cos θ / d² at a receiver. A delta light: reached only by light sampling.

use super::bounds::LightBounds;
use glam::Vec3;

/// An isotropic point light.
#[derive(Clone, Copy, Debug)]
pub struct PointLight {
    /// Position.
    pub position: Vec3,
    /// Radiant intensity, W/sr per channel.
    pub intensity: Vec3,
}

impl PointLight {
    /// Emitted power by luminance (the weight for choosing among lights).
    pub fn power(&self) -> f64 {
        4.0 * std::f64::consts::PI * super::triangle::luminance(self.intensity) as f64
    }

    /// Its bounds for the light tree: a point emitting its intensity every way.
    pub fn bounds(&self) -> LightBounds {
        LightBounds {
            lo: self.position,
            hi: self.position,
            w: Vec3::Z,
            intensity: super::triangle::luminance(self.intensity),
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        }
    }
}
