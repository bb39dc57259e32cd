//! The glTF specification's sheen (`KHR_materials_sheen` in the specification's reading, for
//! files Blender did not write): the "Charlie" microfibre distribution of Estevez & Kulla 2017
//! ("Production Friendly Microfacet Sheen BRDF") with the same paper's visibility, whose Λ is
//! the fitted curve the extension's text gives (as the Khronos sample renderer evaluates it):
//!
//!   D(h) = (2 + 1/α) sin^{1/α}θh / (2π),   α = roughness²,
//!   V = 1 / ((1 + Λ(μo) + Λ(μi)) · 4 μo μi), at most 1 (as the sample renderer clamps it),
//!   f = colour · D · V.
//!
//! D is normalised (∫D cos θh dω = 1), and sampled by its half vector in proportion to
//! D cos θh (sin θh = u^{α/(1 + 2α)}, φ uniform), wi being wo reflected about it; half vectors
//! that send wi below the surface end the sample (their density stays counted, so what is
//! sampled is exactly the density reported). The roughness is at least 0.07 (α ≥ 0.0049), as
//! three.js clamps it: below it the fibres' lobe is a sliver at the horizon that f32 no longer
//! resolves.
//!
//! Layering (the extension's albedo scaling): the layers below keep 1 − max(colour)·E(μo), E
//! the white lobe's directional albedo, integrated once (the first time a Charlie sheen is
//! built) into a 32 × 32 table over (√μo, roughness), read bilinearly (√μo: E changes fastest
//! at grazing). Seen within a few degrees of grazing, a smooth Charlie lobe with its clamped
//! visibility reflects more than it receives (E up to 1.6 at roughness 0.07 and μo 0.005; above
//! 1 for roughness below ~0.17 and μo below ~0.04): there its value is scaled by 1/E, so that
//! it reflects all it receives and no more.

use super::compensation;
use crate::sampling::Frame;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};
use std::sync::OnceLock;

/// The smallest roughness the lobe takes (three.js's clamp).
pub const MIN_ROUGHNESS: f32 = 0.07;

/// The Charlie sheen at one shading point, with wo fixed.
#[derive(Clone, Copy, Debug)]
pub struct Charlie {
    /// z the sheen normal on wo's side.
    frame: Frame,
    /// wo in `frame`.
    wo: Vec3,
    /// α = roughness².
    alpha: f32,
    /// Λ(μo).
    lambda_o: f32,
    /// The colour (weight × tint), times any scale.
    color: Vec3,
    /// max(colour) · E(μo): the share it takes from the layers below.
    albedo: f32,
}

/// The fitted ln Λ of Estevez & Kulla, between its two roughness ends by (1 − α)².
#[inline]
fn lambda_fit(x: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |rough: f32, smooth: f32| rough + (smooth - rough) * t;
    let (a, b, c) = (mix(21.5473, 25.3245), mix(3.82987, 3.32435), mix(0.19823, 0.16801));
    let (d, e) = (mix(-1.97760, -1.27393), mix(-4.32054, -4.85967));
    a / (1.0 + b * x.powf(c)) + d * x + e
}

/// Λ(cos θ) (cos θ in [0, 1]): the fit below ½, its mirror above.
#[inline]
fn lambda(cos: f32, alpha: f32) -> f32 {
    if cos < 0.5 {
        lambda_fit(cos, alpha).exp()
    } else {
        (2.0 * lambda_fit(0.5, alpha) - lambda_fit(1.0 - cos, alpha)).exp()
    }
}

/// D(h) for a unit local half vector with cos θh = `cos_h`.
#[inline]
fn distribution(cos_h: f32, alpha: f32) -> f32 {
    let sin2 = (1.0 - cos_h * cos_h).max(0.0);
    (2.0 + 1.0 / alpha) * sin2.powf(0.5 / alpha) * (0.5 * FRAC_1_PI)
}

/// The visibility for μo, μi > 0 with Λ(μo) = `lambda_o`.
#[inline]
fn visibility(lambda_o: f32, mu_o: f32, mu_i: f32, alpha: f32) -> f32 {
    (1.0 / ((1.0 + lambda_o + lambda(mu_i, alpha)) * (4.0 * mu_o * mu_i))).min(1.0)
}

/// The half vector for numbers `u` (local, above), in proportion to D cos θh.
#[inline]
fn sample_half(u: Vec2, alpha: f32) -> Vec3 {
    let sin = u.x.powf(alpha / (1.0 + 2.0 * alpha)).min(1.0);
    let cos = (1.0 - sin * sin).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    Vec3::new(sin * c, sin * s, cos)
}

/// Where `roughness` falls in the albedo table's span, in [0, 1].
#[inline]
fn table_row(roughness: f32) -> f32 {
    (roughness.clamp(MIN_ROUGHNESS, 1.0) - MIN_ROUGHNESS) / (1.0 - MIN_ROUGHNESS)
}

/// α of perceptual `roughness` (clamped to [`MIN_ROUGHNESS`], 1).
#[inline]
fn alpha_of(roughness: f32) -> f32 {
    let r = roughness.clamp(MIN_ROUGHNESS, 1.0);
    r * r
}

/// The white lobe's directional albedo E(μo) at α, by quadrature over the half-vector sampler's
/// numbers (`n` × `n` midpoints; φ over half the circle, the lobe being symmetric about the
/// plane of wo and the normal): f·μi / pdf = 4 V μi (wo·h) / cos θh.
fn directional_albedo(mu_o: f32, alpha: f32, n: usize) -> f64 {
    let mu_o = mu_o.max(1e-4);
    let wo = Vec3::new((1.0 - mu_o * mu_o).sqrt(), 0.0, mu_o);
    let lambda_o = lambda(mu_o, alpha);
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, 0.5 * (j as f32 + 0.5) / n as f32);
            let h = sample_half(u, alpha);
            let cos_oh = wo.dot(h);
            let wi = 2.0 * cos_oh * h - wo;
            if cos_oh > 0.0 && wi.z > 0.0 && h.z > 0.0 {
                sum += (4.0 * visibility(lambda_o, mu_o, wi.z, alpha) * wi.z * cos_oh / h.z) as f64;
            }
        }
    }
    sum / (n * n) as f64
}

/// E over [roughness][√μ], grid points i/31 of √μ and of the roughness's span
/// [`MIN_ROUGHNESS`], 1 (`table_row`).
fn albedo_table() -> &'static [[f32; 32]; 32] {
    static TABLE: OnceLock<[[f32; 32]; 32]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [[0.0; 32]; 32];
        for (ri, row) in t.iter_mut().enumerate() {
            let alpha = alpha_of(MIN_ROUGHNESS + (1.0 - MIN_ROUGHNESS) * ri as f32 / 31.0);
            for (mi, e) in row.iter_mut().enumerate() {
                let s = mi as f32 / 31.0;
                *e = directional_albedo(s * s, alpha, 96) as f32;
            }
        }
        t
    })
}

impl Charlie {
    /// The sheen of colour `color` (weight × tint, each channel ≥ 0) and roughness `roughness`
    /// on unit normal `n` (either side), geometric normal `ng` facing wo, seen from world
    /// direction `wo`.
    #[inline]
    pub fn new(color: Vec3, roughness: f32, n: Vec3, ng: Vec3, wo: Vec3) -> Self {
        let n = if n.dot(ng) < 0.0 { -n } else { n };
        let frame = Frame::from_z(n);
        let mut wo = frame.to_local(wo);
        wo.z = wo.z.clamp(1e-4, 1.0);
        let alpha = alpha_of(roughness);
        let e = compensation::lookup(albedo_table(), wo.z.sqrt(), table_row(roughness));
        // Where the lobe would reflect more than it receives, it is scaled to reflect all.
        let color = if e > 1.0 { color / e } else { color };
        let albedo = (color.max_element() * e).min(1.0);
        Self { frame, wo, alpha, lambda_o: lambda(wo.z, alpha), color, albedo }
    }

    /// The share of light the sheen takes from the layers below for this wo: max(colour) ×
    /// the white lobe's albedo, at most 1.
    #[inline]
    pub fn albedo(&self) -> f32 {
        self.albedo
    }

    /// This lobe with its value scaled by `k` > 0 (its density and albedo share unchanged).
    #[inline]
    pub fn scaled(self, k: f32) -> Self {
        Self { color: self.color * k, ..self }
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
        let h = (self.wo + w).normalize_or_zero();
        let cos_oh = self.wo.dot(h);
        if h.z <= 0.0 || cos_oh <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let d = distribution(h.z, self.alpha);
        let v = visibility(self.lambda_o, self.wo.z, w.z, self.alpha);
        let pdf = d * h.z / (4.0 * cos_oh);
        (self.color * (d * v * w.z / cos_s), pdf)
    }

    /// A direction sampled by the half vector (world, unit), or `None` when the reflection
    /// leaves below the surface.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<Vec3> {
        let h = sample_half(u, self.alpha);
        let cos_oh = self.wo.dot(h);
        let wi = 2.0 * cos_oh * h - self.wo;
        // Far from the horizon a smooth lobe's D underflows to 0 (u = 0 gives h = z): such a
        // direction has no density, and is not returned.
        let valid = cos_oh > 0.0 && wi.z > 0.0 && distribution(h.z, self.alpha) > 0.0;
        valid.then(|| self.frame.from_local(wi).normalize())
    }
}

#[cfg(test)]
mod tests;
