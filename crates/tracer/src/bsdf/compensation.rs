//! Multiple-scattering energy compensation for the GGX lobe (Turquin, "Practical multiple
//! scattering compensation for microfacet models", 2019): single-scattering GGX loses the energy
//! of light that bounces more than once between microfacets (up to 60 % for a rough white
//! metal; docs/design/tracer.md §3.10: Blender scenes 2.5 % darker, 5.5 % on metals). Scaling the lobe by
//! 1 + F·(1 − E(μo))/E(μo), with E the lobe's directional albedo for F = 1, restores it.
//!
//! For the dielectric layer (`fresnel.rs`) the module gives what Blender's Principled BSDF layers
//! with (docs/design/tracer.md §3.10), as Cycles computes it: the multiple-scattering Fresnel of Kulla &
//! Conty 2017, F_ms = F_avg·E_avg / (1 − F_avg·(1 − E_avg)), and the compensated layer's albedo
//! (E + F_ms·(1 − E))·(F0 + (1 − F0)·s̄), s̄(μ, roughness, η) the layer Fresnel's interpolation
//! factor averaged over the visible normals (a reflection below the horizon counting 0), as
//! Cycles' `ggx_gen_schlick_ior_s` table holds it.
//!
//! E (μ, roughness) is tabulated once per process (32 × 32, computed in a few milliseconds by
//! visible-normal sampling, deterministic) and interpolated bilinearly; s̄ on Cycles' grid of 16
//! roughnesses × 16 μ × 16 η, one η slice computed when first needed, interpolated trilinearly.

use super::fresnel::LayerFresnel;
use super::ggx::Ggx;
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

const N: usize = 32;

/// Per (roughness, μ) cell E, the directional albedo of the single-scattering GGX lobe with
/// F = 1; per roughness E_avg = 2∫E(μ)μ dμ.
struct Tables {
    e: [[f32; N]; N],
    e_avg: [f32; N],
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = Tables { e: [[0.0; N]; N], e_avg: [0.0; N] };
        // Stratified 32 × 32 samples per cell: ample for a smooth function of two variables.
        const S: usize = 32;
        for ri in 0..N {
            let ggx = Ggx::from_roughness(ri as f32 / (N - 1) as f32);
            for mi in 0..N {
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
                t.e[ri][mi] = (sum / (S * S) as f64) as f32;
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

/// A 32 × 32 table [roughness][μ] (grid points i/31) read bilinearly in (μ, roughness), as
/// Cycles' `lookup_table_read_2D` reads its tables.
pub(super) fn lookup(e: &[[f32; N]; N], mu: f32, roughness: f32) -> f32 {
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

/// Cycles' grid of the layer-albedo table: 16 points per axis.
pub(super) const M: usize = 16;

/// One η slice of s̄: [μ][roughness] at μ, roughness = i / 15 (clamped to ≥ 1e-4), for
/// z = F0(η)^¼ = k / 15 (clamped to [1e-4, 0.99]), as Cycles' `cycles_precompute` lays it out.
fn s_slice(k: usize) -> &'static [[f32; M]; M] {
    static SLICES: [OnceLock<[[f32; M]; M]>; M] = [const { OnceLock::new() }; M];
    SLICES[k].get_or_init(|| {
        grid_slice(k, |ior, wo, roughness| {
            let layer = LayerFresnel::new(Vec3::ZERO, ior);
            let ggx = Ggx::from_roughness(roughness);
            // Stratified 32 × 32 samples per cell, as for E.
            const S: usize = 32;
            let mut sum = 0.0f64;
            for i in 0..S {
                for j in 0..S {
                    let u = Vec2::new((i as f32 + 0.5) / S as f32, (j as f32 + 0.5) / S as f32);
                    let h = ggx.sample_visible_normal(wo, u);
                    if (2.0 * wo.dot(h) * h - wo).z >= 0.0 {
                        sum += layer.s(wo.dot(h)) as f64;
                    }
                }
            }
            (sum / (S * S) as f64) as f32
        })
    })
}

/// One slice of a table on Cycles' 16³ grid, as its `cycles_precompute` lays them out:
/// [μ][roughness] of `cell(ior, wo, roughness)` at μ = i / 15 (≥ 1e-4; wo in the xz plane) and
/// roughness = j / 15 (≥ 1e-4), for ior = (1 + z²)/(1 − z²), z = k / 15 clamped to [1e-4, 0.99]
/// (z = F0(ior)^¼).
pub(super) fn grid_slice(k: usize, cell: impl Fn(f32, Vec3, f32) -> f32) -> [[f32; M]; M] {
    let z = (k as f32 / (M - 1) as f32).clamp(1e-4, 0.99);
    let r = z * z; // √F0
    let ior = (1.0 + r) / (1.0 - r);
    let mut t = [[0.0f32; M]; M];
    for (mi, row) in t.iter_mut().enumerate() {
        let mu = (mi as f32 / (M - 1) as f32).max(1e-4);
        let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        for (ri, value) in row.iter_mut().enumerate() {
            *value = cell(ior, wo, (ri as f32 / (M - 1) as f32).max(1e-4));
        }
    }
    t
}

/// s̄(μ, roughness, z), trilinear on the grid (Cycles' `lookup_table_read_3D`).
fn layer_s(mu: f32, roughness: f32, z: f32) -> f32 {
    trilinear(s_slice, roughness, mu, z)
}

/// A table of Cycles' 16³ grid read trilinearly (its `lookup_table_read_3D`): `slice(k)` is the
/// [y][x] table at z = k / 15; x, y, z in [0, 1].
pub(super) fn trilinear(slice: impl Fn(usize) -> &'static [[f32; M]; M], x: f32, y: f32, z: f32) -> f32 {
    let at = |v: f32| {
        let t = v.clamp(0.0, 1.0) * (M - 1) as f32;
        let i = (t as usize).min(M - 2);
        (i, t - i as f32)
    };
    let ((x0, fx), (y0, fy), (z0, fz)) = (at(x), at(y), at(z));
    let read = |k: usize| {
        let t = slice(k);
        let row = |y: usize| t[y][x0] * (1.0 - fx) + t[y][x0 + 1] * fx;
        row(y0) * (1.0 - fy) + row(y0 + 1) * fy
    };
    if fz == 0.0 { read(z0) } else { read(z0) * (1.0 - fz) + read(z0 + 1) * fz }
}

/// The dielectric layer's compensation at cos θo = `mu`, as Blender's Principled BSDF computes it
/// (Cycles' `microfacet_ggx_preserve_energy`, `bsdf_microfacet_estimate_albedo`): the lobe's
/// factor 1 + F_ms·(1 − E)/E, and the compensated layer's albedo, which the diffuse base beneath
/// it loses.
#[inline]
pub fn dielectric(layer: &LayerFresnel, mu: f32, roughness: f32) -> (Vec3, Vec3) {
    let e = albedo(mu, roughness).max(1e-3);
    let e_avg = average_albedo(roughness);
    let f_avg = layer.average();
    let f_ms = f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg));
    let factor = Vec3::ONE + f_ms * ((1.0 - e) / e);
    let albedo = factor * e * layer.mix(layer_s(mu, roughness, layer.table_z()));
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

    /// The layer-albedo table against Cycles' own (`table_ggx_gen_schlick_ior_s` in Cycles'
    /// `src/scene/shader.tables`, 2²⁰ samples per cell) at grid points (roughness, μ, z) × 15,
    /// across roughness, angle and η (z 6: η 1.381, z 7: η 1.557).
    #[test]
    fn layer_table_matches_cycles() {
        for ((x, y, z), cycles) in [
            ((12, 8, 7), 0.018803),
            ((6, 3, 7), 0.186114),
            ((15, 15, 6), 0.00111),
            ((12, 1, 7), 0.071426),
            ((15, 2, 6), 0.03316),
        ] {
            let ours = layer_s(y as f32 / 15.0, x as f32 / 15.0, z as f32 / 15.0);
            assert!((ours - cycles).abs() < 1e-3 + 0.02 * cycles, "{x} {y} {z}: {ours} vs {cycles}");
        }
    }

    /// The layer's albedo is small for F0 = 0.04 (below F0 itself where rough reflections leave
    /// through the horizon, as in Cycles' estimate), and a white Fresnel (F0 = 1) is the whole
    /// compensated lobe: 1 at every angle.
    #[test]
    fn dielectric_albedo() {
        for (roughness, mu) in [(0.8f32, 0.6f32), (0.4, 0.2), (0.1, 0.9)] {
            let layer = LayerFresnel::new(Vec3::splat(0.04), 1.5);
            let (factor, albedo) = dielectric(&layer, mu, roughness);
            assert!(factor.x >= 1.0 && albedo.x > 0.02 && albedo.x < 0.2, "{factor} {albedo}");
            let (_, white) = dielectric(&LayerFresnel::new(Vec3::ONE, 1.5), mu, roughness);
            assert!((white.x - 1.0).abs() < 1e-5, "{white}");
        }
    }
}
