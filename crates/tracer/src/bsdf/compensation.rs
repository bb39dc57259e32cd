//! Multiple-scattering energy compensation for the GGX lobe (Turquin, "Practical multiple
//! scattering compensation for microfacet models", 2019): single-scattering GGX loses the energy
//! of light that bounces more than once between microfacets (up to 60 % for a rough white
//! metal; docs/design.md §3.10: Blender scenes 2.5 % darker, 5.5 % on metals). Scaling the lobe by
//! 1 + F0·(1 − E(μo))/E(μo), with E the lobe's directional albedo for F = 1, restores it.
//!
//! E(μ, roughness) is tabulated once per process (32 × 32, computed in a few milliseconds by
//! visible-normal sampling, deterministic) and interpolated bilinearly.

use super::ggx::Ggx;
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

const N: usize = 32;

/// E(μ, roughness): directional albedo of the single-scattering GGX lobe with F = 1.
struct AlbedoTable([[f32; N]; N]);

fn table() -> &'static AlbedoTable {
    static TABLE: OnceLock<AlbedoTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut e = [[0.0f32; N]; N];
        // Stratified 32 × 32 samples per cell: ample for a smooth function of two variables.
        const S: usize = 32;
        for (ri, row) in e.iter_mut().enumerate() {
            let ggx = Ggx::from_roughness(ri as f32 / (N - 1) as f32);
            for (mi, cell) in row.iter_mut().enumerate() {
                let mu = (mi as f32 / (N - 1) as f32).max(1e-3);
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let mut sum = 0.0f64;
                for i in 0..S {
                    for j in 0..S {
                        let u = Vec2::new((i as f32 + 0.5) / S as f32, (j as f32 + 0.5) / S as f32);
                        let h = ggx.sample_visible_normal(wo, u);
                        let wi = 2.0 * wo.dot(h) * h - wo;
                        if wi.z > 0.0 {
                            // f cos / pdf = G2 / G1 for visible-normal sampling.
                            sum += (ggx.g2(wo, wi) / ggx.g1(wo)) as f64;
                        }
                    }
                }
                *cell = (sum / (S * S) as f64) as f32;
            }
        }
        AlbedoTable(e)
    })
}

/// E(μ, roughness), bilinear in the table.
pub fn albedo(mu: f32, roughness: f32) -> f32 {
    let e = &table().0;
    let x = (mu.clamp(0.0, 1.0) * (N - 1) as f32).min((N - 1) as f32 - 1e-4);
    let y = (roughness.clamp(0.0, 1.0) * (N - 1) as f32).min((N - 1) as f32 - 1e-4);
    let (x0, y0) = (x as usize, y as usize);
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let top = e[y0][x0] * (1.0 - fx) + e[y0][x0 + 1] * fx;
    let bottom = e[y0 + 1][x0] * (1.0 - fx) + e[y0 + 1][x0 + 1] * fx;
    top * (1.0 - fy) + bottom * fy
}

/// The factor that scales a GGX lobe with Fresnel F0 seen at cos θo = `mu`.
#[inline]
pub fn factor(f0: Vec3, mu: f32, roughness: f32) -> Vec3 {
    let e = albedo(mu, roughness).max(1e-3);
    Vec3::ONE + f0 * ((1.0 - e) / e)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At roughness 1 and normal incidence the table matches the closed form 1 − ln 2.
    #[test]
    fn table_matches_closed_form() {
        let e = albedo(1.0, 1.0);
        assert!((e - (1.0 - std::f32::consts::LN_2)).abs() < 2e-3, "{e}");
        // Smooth surfaces lose nothing.
        assert!(albedo(0.8, 0.0) > 0.99);
    }
}
