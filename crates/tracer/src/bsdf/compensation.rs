//! Multiple-scattering energy compensation for the GGX lobe (Turquin, "Practical multiple
//! scattering compensation for microfacet models", 2019): single-scattering GGX loses the energy
//! of light that bounces more than once between microfacets (up to 60 % for a rough white
//! metal; docs/design.md §3.10: Blender scenes 2.5 % darker, 5.5 % on metals). Scaling the lobe by
//! 1 + F·(1 − E(μo))/E(μo), with E the lobe's directional albedo for F = 1, restores it.
//!
//! For the dielectric layer the tables also give what Blender's Principled BSDF layers with
//! (docs/design.md §3.10): the lobe's albedo with Schlick's Fresnel, E_F = F0·E + (1 − F0)·E₅
//! (Schlick is linear in F0, so one more table, E₅, of the (1 − h·wo)⁵ part does), and the
//! multiple-scattering Fresnel of Kulla & Conty 2017, F_ms = F_avg·E_avg / (1 − F_avg·(1 − E_avg)).
//!
//! E and E₅ (μ, roughness) are tabulated once per process (32 × 32, computed in a few
//! milliseconds by visible-normal sampling, deterministic) and interpolated bilinearly.

use super::ggx::Ggx;
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

const N: usize = 32;

/// Per (roughness, μ) cell: E, the directional albedo of the single-scattering GGX lobe with
/// F = 1, and E₅, its part weighted by (1 − h·wo)⁵; per roughness, E_avg = 2∫E(μ)μ dμ.
struct Tables {
    e: [[f32; N]; N],
    e5: [[f32; N]; N],
    e_avg: [f32; N],
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = Tables { e: [[0.0; N]; N], e5: [[0.0; N]; N], e_avg: [0.0; N] };
        // Stratified 32 × 32 samples per cell: ample for a smooth function of two variables.
        const S: usize = 32;
        for ri in 0..N {
            let ggx = Ggx::from_roughness(ri as f32 / (N - 1) as f32);
            for mi in 0..N {
                let mu = (mi as f32 / (N - 1) as f32).max(1e-3);
                let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let (mut sum, mut sum5) = (0.0f64, 0.0f64);
                for i in 0..S {
                    for j in 0..S {
                        let u = Vec2::new((i as f32 + 0.5) / S as f32, (j as f32 + 0.5) / S as f32);
                        let h = ggx.sample_visible_normal(wo, u);
                        let wi = 2.0 * wo.dot(h) * h - wo;
                        if wi.z > 0.0 {
                            // f cos / pdf = G2 / G1 for visible-normal sampling.
                            let w = (ggx.g2(wo, wi) / ggx.g1(wo)) as f64;
                            sum += w;
                            sum5 += w * ((1.0 - wo.dot(h).clamp(0.0, 1.0)) as f64).powi(5);
                        }
                    }
                }
                t.e[ri][mi] = (sum / (S * S) as f64) as f32;
                t.e5[ri][mi] = (sum5 / (S * S) as f64) as f32;
            }
            // E_avg = 2∫₀¹ E(μ) μ dμ, by the trapezoid rule on the table's row.
            let h = 1.0 / (N - 1) as f64;
            let f = |mi: usize| t.e[ri][mi] as f64 * (mi as f64 * h);
            let inner: f64 = (1..N - 1).map(f).sum();
            t.e_avg[ri] = (2.0 * h * (inner + 0.5 * (f(0) + f(N - 1)))) as f32;
        }
        t
    })
}

/// A table bilinear in (μ, roughness).
fn lookup(e: &[[f32; N]; N], mu: f32, roughness: f32) -> f32 {
    let x = (mu.clamp(0.0, 1.0) * (N - 1) as f32).min((N - 1) as f32 - 1e-4);
    let y = (roughness.clamp(0.0, 1.0) * (N - 1) as f32).min((N - 1) as f32 - 1e-4);
    let (x0, y0) = (x as usize, y as usize);
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let top = e[y0][x0] * (1.0 - fx) + e[y0][x0 + 1] * fx;
    let bottom = e[y0 + 1][x0] * (1.0 - fx) + e[y0 + 1][x0 + 1] * fx;
    top * (1.0 - fy) + bottom * fy
}

/// E(μ, roughness), bilinear in the table.
pub fn albedo(mu: f32, roughness: f32) -> f32 {
    lookup(&tables().e, mu, roughness)
}

/// E_avg(roughness), linear in the table.
fn average_albedo(roughness: f32) -> f32 {
    let t = &tables().e_avg;
    let y = (roughness.clamp(0.0, 1.0) * (N - 1) as f32).min((N - 1) as f32 - 1e-4);
    let (y0, fy) = (y as usize, y - y.floor());
    t[y0] * (1.0 - fy) + t[y0 + 1] * fy
}

/// The factor that scales a GGX lobe with Fresnel F0 seen at cos θo = `mu` (the metal's lobe).
#[inline]
pub fn factor(f0: Vec3, mu: f32, roughness: f32) -> Vec3 {
    let e = albedo(mu, roughness).max(1e-3);
    Vec3::ONE + f0 * ((1.0 - e) / e)
}

/// The dielectric layer's compensation at cos θo = `mu` for Schlick's Fresnel with `f0`, as
/// Blender's Principled BSDF computes it: the lobe's factor 1 + F_ms·(1 − E)/E, and the
/// compensated lobe's directional albedo E_F·factor, which the diffuse base beneath it loses.
#[inline]
pub fn dielectric(f0: Vec3, mu: f32, roughness: f32) -> (Vec3, Vec3) {
    let e = albedo(mu, roughness).max(1e-3);
    let e5 = lookup(&tables().e5, mu, roughness);
    let e_avg = average_albedo(roughness);
    // Schlick's hemispherical average: F0 + (1 − F0)·2∫(1 − μ)⁵μ dμ = F0 + (1 − F0)/21.
    let f_avg = f0 + (Vec3::ONE - f0) / 21.0;
    let f_ms = f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg));
    let factor = Vec3::ONE + f_ms * ((1.0 - e) / e);
    let albedo = (f0 * e + (Vec3::ONE - f0) * e5) * factor;
    (factor, albedo)
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

    /// The split tables against a direct estimate of the Schlick-Fresnel lobe's albedo, and the
    /// layer's albedo within [F0, 1]: a white Fresnel (F0 = 1) is the whole compensated lobe, 1.
    #[test]
    fn dielectric_albedo() {
        let (roughness, mu) = (0.8f32, 0.6f32);
        let ggx = Ggx::from_roughness(roughness);
        let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let f0 = 0.04f32;
        let mut sum = 0.0f64;
        let n = 256;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let h = ggx.sample_visible_normal(wo, u);
                let wi = 2.0 * wo.dot(h) * h - wo;
                if wi.z > 0.0 {
                    let f = f0 + (1.0 - f0) * (1.0 - wo.dot(h)).powi(5);
                    sum += (f * ggx.g2(wo, wi) / ggx.g1(wo)) as f64;
                }
            }
        }
        let direct = (sum / (n * n) as f64) as f32;
        let (factor, albedo) = dielectric(Vec3::splat(f0), mu, roughness);
        assert!((albedo.x / factor.x - direct).abs() < 2e-3, "{} vs {direct}", albedo.x / factor.x);
        assert!(factor.x > 1.0 && albedo.x > f0 && albedo.x < 0.2, "{factor} {albedo}");
        let (_, white) = dielectric(Vec3::ONE, mu, roughness);
        assert!((white.x - 1.0).abs() < 0.01, "{white}");
    }
}
