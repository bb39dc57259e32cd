//! The GGX (Trowbridge–Reitz) microfacet distribution with Smith's height-correlated masking–
//! shadowing (Heitz, "Understanding the Masking-Shadowing Function", JCGT 3(2), 2014) and
//! visible-normal sampling by spherical caps (Dupuy & Benyoub, "Sampling Visible GGX Normals
//! with Spherical Caps", HPG 2023). Directions are in the local shading frame (+z = normal).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The smallest α used: below it the lobe is so narrow that f32 densities overflow.
pub const MIN_ALPHA: f32 = 1e-3;

/// An isotropic GGX distribution of microfacet normals.
#[derive(Clone, Copy, Debug)]
pub struct Ggx {
    alpha: f32,
}

impl Ggx {
    /// The distribution for a glTF perceptual roughness (α = roughness²).
    #[inline]
    pub fn from_roughness(roughness: f32) -> Self {
        Self { alpha: (roughness * roughness).max(MIN_ALPHA) }
    }

    /// α.
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// D(h): density of microfacet normals (projected-area normalised).
    #[inline]
    pub fn d(&self, h: Vec3) -> f32 {
        let a2 = self.alpha * self.alpha;
        let t = h.z * h.z * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    /// Smith's Λ(w).
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        if z2 == 0.0 {
            return f32::INFINITY;
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
        let wo_std = Vec3::new(wo.x * self.alpha, wo.y * self.alpha, wo.z).normalize();
        let z = (1.0 - u.y) * (1.0 + wo_std.z) - wo_std.z;
        let sin_theta = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
        let (s, c) = crate::sampling::sin_cos_turn(u.x);
        let h_std = Vec3::new(sin_theta * c, sin_theta * s, z) + wo_std;
        Vec3::new(h_std.x * self.alpha, h_std.y * self.alpha, h_std.z.max(0.0)).normalize_or(Vec3::Z)
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
