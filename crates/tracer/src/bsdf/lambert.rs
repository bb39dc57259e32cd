//! The Lambertian (ideal diffuse) lobe: f = ρ/π, sampled by the cosine-weighted hemisphere.

use crate::sampling::sample_cosine_hemisphere;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Cosine-weighted direction on the local +z hemisphere.
#[inline]
pub fn sample(u: Vec2) -> Vec3 {
    sample_cosine_hemisphere(u)
}

/// Density of [`sample`] for local `wi`.
#[inline]
pub fn pdf(wi: Vec3) -> f32 {
    wi.z.max(0.0) * FRAC_1_PI
}
