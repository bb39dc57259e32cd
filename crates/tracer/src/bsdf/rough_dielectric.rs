//! A rough dielectric interface (frosted glass): GGX microfacet reflection and refraction
//! (Walter et al., "Microfacet Models for Refraction through Rough Surfaces", EGSR 2007), sampled
//! by visible normals (`ggx.rs`) with reflection or refraction chosen by the microfacet's
//! Fresnel, as pbrt-v4's `DielectricBxDF` and Cycles' `microfacet_ggx_glass` do.
//!
//! Single-scattering GGX loses the light that bounces between microfacets; Cycles restores it for
//! glass by scaling both lobes by 1 / E(μo, roughness, η), E the lobe's directional albedo (its
//! `ggx_glass_E` table, `microfacet_ggx_preserve_energy` with F_ss = 1). The same table is
//! computed here once per η slice (`glass_albedo`), on Cycles' 16³ grid.
//!
//! Directions are in the local frame of the shading normal turned to wo's side (+z), so wo.z > 0;
//! `eta` is the index of the far side (−z) over wo's side. Values are in radiance mode: a
//! refraction into the denser side compresses radiance by η² (pbrt-v4 §9.5.2), as the smooth
//! [`Dielectric`](super::dielectric::Dielectric) has it, so the two lobes may meet on one surface
//! (a roughness texture with smooth texels). A thin wall (`thin`) transmits the reflected
//! direction mirrored through the surface: rough, but not bent (the glTF spec's thin wall).

use super::compensation::{M, grid_slice, trilinear};
use super::dielectric::{fresnel, refract};
use super::ggx::Ggx;
use glam::{Vec2, Vec3};
use std::sync::OnceLock;

/// The rough glass lobe of one hit, with wo fixed (local frame).
#[derive(Clone, Copy, Debug)]
pub struct RoughDielectric {
    ggx: Ggx,
    /// Relative index: the far side's over wo's side.
    eta: f32,
    /// Cycles' energy compensation 1 / E for this wo.
    scale: f32,
    /// Transmittance of a refraction (the base colour).
    tint: Vec3,
    /// A thin wall: transmission leaves unbent, mirrored through the surface.
    thin: bool,
}

/// A direction sampled from the rough glass lobe.
#[derive(Clone, Copy, Debug)]
pub struct RoughSample {
    /// Incident direction, local frame, unit length.
    pub wi: Vec3,
    /// f · |cos θi| / pdf.
    pub weight: Vec3,
    /// Solid-angle density of `wi`.
    pub pdf: f32,
}

impl RoughDielectric {
    /// The lobe of perceptual `roughness` (α = roughness²) between wo's side and a medium of
    /// relative index `eta` (≥ 1 entering, < 1 leaving), for wo (local, z > 0), refractions tinted
    /// `tint`; `thin`: a thin wall.
    #[inline]
    pub fn new(roughness: f32, eta: f32, wo: Vec3, tint: Vec3, thin: bool) -> Self {
        Self::with_ggx(Ggx::from_roughness(roughness), roughness, eta, wo, tint, thin)
    }

    /// The lobe of an anisotropic distribution: α_x along the local x axis (the anisotropy
    /// direction), α_y across it (each clamped to [`MIN_ALPHA`](super::ggx::MIN_ALPHA), 1),
    /// compensated at the roughness of the mean α √(α_x·α_y), as Cycles reads its tables for
    /// an anisotropic lobe (and as the opaque base does).
    #[inline]
    pub fn anisotropic(alpha_x: f32, alpha_y: f32, eta: f32, wo: Vec3, tint: Vec3, thin: bool) -> Self {
        let ggx = Ggx::anisotropic(alpha_x, alpha_y);
        let (ax, ay) = ggx.alphas();
        Self::with_ggx(ggx, (ax * ay).sqrt().sqrt(), eta, wo, tint, thin)
    }

    /// The lobe of distribution `ggx`, compensated as a lobe of perceptual roughness
    /// `roughness`.
    #[inline]
    fn with_ggx(ggx: Ggx, roughness: f32, eta: f32, wo: Vec3, tint: Vec3, thin: bool) -> Self {
        let e = if thin { 1.0 } else { glass_albedo(wo.z, roughness, eta) };
        Self { ggx, eta, scale: 1.0 / e.max(0.05), tint, thin }
    }

    /// The transmitted direction for a microfacet normal `h` (wo·h > 0), or `None` under total
    /// internal reflection.
    #[inline]
    fn transmit(&self, wo: Vec3, h: Vec3) -> Option<Vec3> {
        if self.thin {
            let r = 2.0 * wo.dot(h) * h - wo;
            Some(Vec3::new(r.x, r.y, -r.z))
        } else {
            refract(wo, h, self.eta)
        }
    }

    /// Radiance compression of a refraction: 1/η² through a solid interface, none through a thin
    /// wall (which is crossed twice).
    #[inline]
    fn transmit_factor(&self) -> f32 {
        if self.thin { 1.0 } else { 1.0 / (self.eta * self.eta) }
    }

    /// Samples wi for wo (local, z > 0): a visible microfacet normal, then reflection with its
    /// Fresnel's probability (`u_lobe` < F), refraction otherwise. `None` when the direction
    /// ends on the wrong side of the macro surface (the path ends, as in Cycles).
    #[inline]
    pub fn sample(&self, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<RoughSample> {
        let h = self.ggx.sample_visible_normal(wo, u);
        let cos_oh = wo.dot(h);
        if cos_oh <= 0.0 {
            return None;
        }
        let f =
            if self.thin { fresnel(cos_oh, self.eta.max(1.0 / self.eta)) } else { fresnel(cos_oh, self.eta) };
        let (wi, factor) = if u_lobe < f {
            let wi = 2.0 * cos_oh * h - wo;
            if wi.z <= 0.0 {
                return None;
            }
            (wi, Vec3::ONE)
        } else {
            let wi = self.transmit(wo, h)?;
            if wi.z >= 0.0 {
                return None;
            }
            (wi, self.tint * self.transmit_factor())
        };
        // f·cos/pdf = G2/G1 for visible-normal sampling, the Fresnel choice cancelling F or 1 − F.
        let weight = factor * (self.scale * self.ggx.g2(wo, wi) / self.ggx.g1(wo));
        // The density is for callers that weigh by MIS; at η = 1 Walter's half vector of an
        // unbent refraction is undefined (pdf 0) while the weight above stays exact.
        let (_, pdf) = self.eval(wo, wi);
        weight.is_finite().then_some(RoughSample { wi, weight, pdf })
    }

    /// f(wo, wi) (without the cosine) and the density [`RoughDielectric::sample`] gives wi, for
    /// wo, wi local (wo.z > 0; wi below the surface is a transmission).
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o <= 0.0 || cos_i == 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let reflect = cos_i > 0.0;
        let (h, jacobian) = if reflect {
            let h = (wo + wi).normalize_or_zero();
            (h, 1.0 / (4.0 * wo.dot(h).abs()))
        } else if self.thin {
            // The mirrored reflection: the half vector of wo and wi flipped back above.
            let w = Vec3::new(wi.x, wi.y, -wi.z);
            let h = (wo + w).normalize_or_zero();
            (h, 1.0 / (4.0 * wo.dot(h).abs()))
        } else {
            // Walter's generalised half vector (pbrt-v4: wm = wi·η + wo), turned above.
            let h = (wi * self.eta + wo).normalize_or_zero();
            let h = if h.z < 0.0 { -h } else { h };
            let denom = wi.dot(h) + wo.dot(h) / self.eta;
            (h, wi.dot(h).abs() / (denom * denom))
        };
        if h == Vec3::ZERO || h.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let (cos_oh, cos_ih) = (wo.dot(h), wi.dot(h));
        // Back-facing microfacets: wo must see h from above; a refraction crosses it.
        if cos_oh <= 0.0 || (!self.thin && !reflect && cos_ih >= 0.0) || (reflect && cos_ih <= 0.0) {
            return (Vec3::ZERO, 0.0);
        }
        let eta_f = if self.thin { self.eta.max(1.0 / self.eta) } else { self.eta };
        let fr = fresnel(cos_oh, eta_f);
        let (p_lobe, value) = if reflect {
            (fr, Vec3::splat(fr))
        } else {
            (1.0 - fr, self.tint * ((1.0 - fr) * self.transmit_factor()))
        };
        if p_lobe <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let d = self.ggx.d(h);
        let pdf = self.ggx.g1(wo) * d * cos_oh / cos_o * jacobian * p_lobe;
        let w_ggx = if reflect || !self.thin { wi } else { Vec3::new(wi.x, wi.y, -wi.z) };
        let g2 = self.ggx.g2(wo, w_ggx);
        // f = value · D · G2 · |wo·h| · J / (|cos θo| |cos θi|): 1/(4 cos cos) for a reflection,
        // Walter's |wi·h||wo·h| / (cos cos denom²) for a refraction.
        let f = value * (self.scale * d * g2 * cos_oh * jacobian / (cos_o * cos_i.abs()));
        (f, pdf)
    }
}

/// One η slice of E: [μ][roughness] for z = √((η − 1)/(η + 1)) = k / 15 (η ≥ 1; `inside`: the
/// table of 1/η, wo in the denser medium), as Cycles' `ggx_glass_E` / `ggx_glass_inv_E` lay it
/// out, computed when first needed.
fn e_slice(k: usize, inside: bool) -> &'static [[f32; M]; M] {
    static SLICES: [[OnceLock<[[f32; M]; M]>; M]; 2] = [const { [const { OnceLock::new() }; M] }; 2];
    SLICES[inside as usize][k].get_or_init(|| {
        grid_slice(k, |ior, wo, roughness| {
            let eta = if inside { 1.0 / ior } else { ior };
            let lobe = RoughDielectric {
                ggx: Ggx::from_roughness(roughness),
                eta,
                scale: 1.0,
                tint: Vec3::ONE,
                thin: false,
            };
            // Stratified 32 × 32 directions, with the Fresnel choice from a third stratified axis.
            const S: usize = 32;
            let mut sum = 0.0f64;
            for i in 0..S {
                for j in 0..S {
                    let u = Vec2::new((i as f32 + 0.5) / S as f32, (j as f32 + 0.5) / S as f32);
                    let u_lobe = ((i * S + j) as f32 * 0.618_034).fract();
                    if let Some(s) = lobe.sample(wo, u, u_lobe) {
                        // E counts transmission without the radiance compression (Cycles'
                        // convention: the albedo of the interface, ≤ 1).
                        let back = if s.wi.z < 0.0 { eta * eta } else { 1.0 };
                        sum += (s.weight.x * back) as f64;
                    }
                }
            }
            (sum / (S * S) as f64) as f32
        })
    })
}

/// E(μ, roughness, η): the single-scattering glass lobe's directional albedo (reflection plus
/// transmission, without the η² compression), trilinear on Cycles' grid.
pub fn glass_albedo(mu: f32, roughness: f32, eta: f32) -> f32 {
    let inside = eta < 1.0;
    let ior = if inside { 1.0 / eta } else { eta };
    let z = ((ior - 1.0) / (ior + 1.0)).abs().sqrt();
    trilinear(|k| e_slice(k, inside), roughness, mu, z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::sample_uniform_sphere;

    fn radical_inverse(mut i: u32, b: u32) -> f32 {
        let (mut f, mut r) = (1.0f64, 0.0f64);
        while i > 0 {
            f /= b as f64;
            r += f * (i % b) as f64;
            i /= b;
        }
        r as f32
    }

    fn wo_at(mu: f32) -> Vec3 {
        Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu)
    }

    /// The lobe without Cycles' compensation (single scattering only).
    fn uncompensated(roughness: f32, eta: f32, thin: bool) -> RoughDielectric {
        RoughDielectric { ggx: Ggx::from_roughness(roughness), eta, scale: 1.0, tint: Vec3::ONE, thin }
    }

    /// The anisotropic lobe (α_x, α_y) without Cycles' compensation, solid interface.
    fn uncompensated_anisotropic(ax: f32, ay: f32, eta: f32) -> RoughDielectric {
        RoughDielectric { ggx: Ggx::anisotropic(ax, ay), eta, scale: 1.0, tint: Vec3::ONE, thin: false }
    }

    /// A direction at polar angle acos(`mu`) and azimuth `phi`.
    fn direction(mu: f32, phi: f32) -> Vec3 {
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), mu)
    }

    /// The albedo with transmission counted without its radiance compression (the reciprocal,
    /// importance-mode albedo, which a white interface keeps at 1), by the lobe's own sampling.
    fn albedo(lobe: &RoughDielectric, wo: Vec3, n: u32) -> f32 {
        let mut sum = 0.0f64;
        for i in 0..n {
            let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
            if let Some(s) = lobe.sample(wo, u, radical_inverse(i, 5)) {
                assert!(s.weight.is_finite() && s.pdf.is_finite() && s.pdf > 0.0, "{s:?}");
                let back = if s.wi.z < 0.0 { 1.0 / lobe.transmit_factor() } else { 1.0 };
                sum += (s.weight.x * back) as f64;
            }
        }
        (sum / n as f64) as f32
    }

    /// White furnace: uncompensated the interface keeps at most all the light and loses some
    /// when rough; with Cycles' compensation it keeps all of it (to the table's interpolation),
    /// from outside and inside, at roughness 0 and 1 and between.
    #[test]
    fn white_furnace() {
        for eta in [1.5f32, 1.0 / 1.5, 1.33] {
            for roughness in [0.0f32, 0.3, 0.6, 1.0] {
                for mu in [0.95f32, 0.6, 0.3, 0.1] {
                    let wo = wo_at(mu);
                    let single = albedo(&uncompensated(roughness, eta, false), wo, 1 << 14);
                    assert!(single <= 1.0 + 1e-3, "single {single}: η {eta} r {roughness} μ {mu}");
                    let full =
                        albedo(&RoughDielectric::new(roughness, eta, wo, Vec3::ONE, false), wo, 1 << 14);
                    assert!((full - 1.0).abs() < 0.03, "compensated {full}: η {eta} r {roughness} μ {mu}");
                    if roughness == 1.0 && mu < 0.5 {
                        assert!(single < 0.95, "rough glass loses light to multiple scattering: {single}");
                    }
                }
            }
        }
    }

    /// Every sampled direction's weight is the lobe's own f·|cos|/pdf (sampling and evaluation
    /// agree), and the density integrates over the sphere to the share of samples kept.
    #[test]
    fn sampling_matches_evaluation_and_the_density_integrates() {
        let tint = Vec3::new(1.0, 0.5, 0.25);
        let wo = wo_at(0.7);
        let isotropic = [(0.3f32, 1.5f32, false), (0.7, 1.0 / 1.5, false), (0.5, 1.5, true)].map(
            |(roughness, eta, thin)| {
                (RoughDielectric::new(roughness, eta, wo, tint, thin), roughness, eta, thin)
            },
        );
        let anisotropic =
            [((0.5f32, 0.15f32), 1.5f32, false), ((0.1, 0.4), 1.0 / 1.5, false), ((0.4, 0.2), 1.5, true)]
                .map(|((ax, ay), eta, thin)| {
                    (RoughDielectric::anisotropic(ax, ay, eta, wo, tint, thin), ax, eta, thin)
                });
        for (lobe, roughness, eta, thin) in isotropic.into_iter().chain(anisotropic) {
            let n = 1 << 14;
            let mut kept = 0;
            for i in 0..n {
                let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
                let Some(s) = lobe.sample(wo, u, radical_inverse(i, 5)) else { continue };
                kept += 1;
                let (f, pdf) = lobe.eval(wo, s.wi);
                assert!((pdf - s.pdf).abs() <= 1e-4 * pdf, "{pdf} vs {}", s.pdf);
                let w = f * s.wi.z.abs() / pdf;
                assert!(
                    (w - s.weight).abs().max_element() <= 2e-3 * s.weight.max_element(),
                    "{w} vs {}",
                    s.weight
                );
            }
            // ∫ pdf dω by uniform directions over the sphere.
            let m = 1 << 20;
            let integral: f64 = (0..m)
                .map(|i| {
                    let wi = sample_uniform_sphere(Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3)));
                    lobe.eval(wo, wi).1 as f64
                })
                .sum::<f64>()
                * 4.0
                * std::f64::consts::PI
                / m as f64;
            let share = kept as f64 / n as f64;
            assert!(
                (integral - share).abs() < 0.02,
                "∫pdf {integral} vs kept {share} ({roughness}, {eta}, {thin})"
            );
        }
    }

    /// Brute force: the albedo by uniform directions over the sphere (∫ f |cos| dω, from the
    /// lobe's values alone) equals the albedo its sampling estimates.
    #[test]
    fn brute_force_albedo_matches_sampling() {
        for (roughness, eta) in [(0.4f32, 1.5f32), (0.8, 1.0 / 1.33)] {
            let wo = wo_at(0.5);
            let lobe = RoughDielectric::new(roughness, eta, wo, Vec3::ONE, false);
            let m = 1 << 20;
            let brute: f64 = (0..m)
                .map(|i| {
                    let wi = sample_uniform_sphere(Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3)));
                    (lobe.eval(wo, wi).0.x * wi.z.abs()) as f64
                })
                .sum::<f64>()
                * 4.0
                * std::f64::consts::PI
                / m as f64;
            let n = 1 << 15;
            let sampled: f64 = (0..n)
                .filter_map(|i| {
                    let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
                    lobe.sample(wo, u, radical_inverse(i, 5)).map(|s| s.weight.x as f64)
                })
                .sum::<f64>()
                / n as f64;
            assert!((brute - sampled).abs() < 0.02 * sampled, "brute {brute} vs sampled {sampled}");
        }
    }

    /// Reciprocity, corrected for radiance mode (Veach 1997, eq. 5.14): f(wo, wi)/η_wo² =
    /// f(wi, wo)/η_wi² for refraction (each direction's side's index), f symmetric for reflection.
    #[test]
    fn reciprocity() {
        // The frame turned to the other side: a rotation by π about x.
        let turn = |v: Vec3| Vec3::new(v.x, -v.y, -v.z);
        let eta = 1.5;
        let isotropic =
            [0.2f32, 0.6, 1.0].map(|r| (uncompensated(r, eta, false), uncompensated(r, 1.0 / eta, false)));
        // Anisotropic: the turn maps y to −y, under which D and Λ are even.
        let anisotropic = [(0.3f32, 0.05f32), (0.05, 0.6), (1.0, 0.2)].map(|(ax, ay)| {
            (uncompensated_anisotropic(ax, ay, eta), uncompensated_anisotropic(ax, ay, 1.0 / eta))
        });
        for (a, b) in isotropic.into_iter().chain(anisotropic) {
            for i in 0..256 {
                let wo = sample_uniform_sphere(Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3)));
                let wi = sample_uniform_sphere(Vec2::new(radical_inverse(i, 5), radical_inverse(i, 7)));
                let wo = Vec3::new(wo.x, wo.y, wo.z.abs().max(0.05)).normalize();
                let forward = a.eval(wo, wi).0.x;
                let backward = if wi.z < 0.0 {
                    b.eval(turn(wi), turn(wo)).0.x / (eta * eta)
                } else {
                    a.eval(wi, wo).0.x
                };
                assert!((forward - backward).abs() <= 1e-3 * forward.max(1e-3), "{forward} vs {backward}");
            }
        }
    }

    /// At grazing incidence and at roughness 0 and 1 every sample is finite.
    #[test]
    fn no_nan_at_grazing_angles() {
        for roughness in [0.0f32, 0.05, 1.0] {
            for eta in [1.5f32, 1.0 / 1.5] {
                for thin in [false, true] {
                    for mu in [1e-6f32, 1e-3, 1.0] {
                        let wo = wo_at(mu);
                        let lobe = RoughDielectric::new(roughness, eta, wo, Vec3::ONE, thin);
                        for i in 0..1024 {
                            let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
                            if let Some(s) = lobe.sample(wo, u, radical_inverse(i, 5)) {
                                assert!(s.weight.is_finite() && s.pdf.is_finite(), "{s:?}");
                                let (f, pdf) = lobe.eval(wo, s.wi);
                                assert!(f.is_finite() && pdf.is_finite());
                            }
                        }
                    }
                }
            }
        }
    }

    /// A thin wall does not bend: transmitted directions scatter about −wo (their mean points
    /// along it); a solid interface bends them by Snell's law towards the normal.
    #[test]
    fn thin_wall_transmits_unbent() {
        let wo = wo_at(0.6);
        let (mut thin_sum, mut solid_sum) = (Vec3::ZERO, Vec3::ZERO);
        let thin = RoughDielectric::new(0.2, 1.5, wo, Vec3::ONE, true);
        let solid = RoughDielectric::new(0.2, 1.5, wo, Vec3::ONE, false);
        for i in 0..4096 {
            let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
            if let Some(s) = thin.sample(wo, u, 0.999) {
                thin_sum += s.wi;
            }
            if let Some(s) = solid.sample(wo, u, 0.999) {
                solid_sum += s.wi;
            }
        }
        let (thin_dir, solid_dir) = (thin_sum.normalize(), solid_sum.normalize());
        assert!(thin_dir.dot(-wo) > 0.99, "thin {thin_dir}");
        let snell = refract(wo, Vec3::Z, 1.5).unwrap();
        assert!(solid_dir.dot(snell) > 0.99 && solid_dir.dot(-wo) < 0.98, "solid {solid_dir}");
    }

    /// Anisotropic glass keeps at most all the light, uncompensated (single scattering) and
    /// compensated at the mean α (the isotropic table read at √(α_x·α_y), as Cycles does), for
    /// every azimuth of wo, from outside and inside, down to α 1e-3 against 1; from outside and
    /// moderately stretched (α ≥ 0.08) the compensation restores all but ≤ 6 % (0.949 at α
    /// (0.6, 0.25), wo along the rough axis at 81°). The mean α
    /// undercounts what a strong stretch loses: α (1e-3, 1) keeps 0.69–0.99 from outside and
    /// 0.49–0.64 from inside (total internal reflection), α (0.3, 0.08) from inside 0.89–1.01.
    #[test]
    fn anisotropic_energy_is_at_most_one() {
        for (ax, ay) in [(0.3f32, 0.08f32), (0.08, 0.3), (0.6, 0.25), (1.0, 1e-3), (1e-3, 1.0)] {
            for eta in [1.5f32, 1.0 / 1.5] {
                for mu in [0.95f32, 0.5, 0.15] {
                    for phi in [0.0f32, 0.7, std::f32::consts::FRAC_PI_2] {
                        let wo = direction(mu, phi);
                        let what = format!("α ({ax}, {ay}) η {eta} μ {mu} φ {phi}");
                        let single = albedo(&uncompensated_anisotropic(ax, ay, eta), wo, 1 << 13);
                        assert!(single <= 1.0 + 2e-3, "single {single}: {what}");
                        let full = albedo(
                            &RoughDielectric::anisotropic(ax, ay, eta, wo, Vec3::ONE, false),
                            wo,
                            1 << 13,
                        );
                        // The table's interpolation, as in `white_furnace`.
                        assert!(
                            full <= 1.03 && full >= single,
                            "compensated {full}, single {single}: {what}"
                        );
                        if eta > 1.0 && ax.min(ay) >= 0.08 {
                            assert!(full > 0.94, "compensated {full}: {what}");
                        }
                    }
                }
            }
        }
    }

    /// The anisotropic sampler's directions follow its density over the whole sphere, both
    /// halves: a χ² test of 2^18 samples in (cos θ, φ) bins against the density integrated over
    /// each bin (a 10 × 10 sub-grid), for both stretches, outside and inside, thin wall too.
    #[test]
    fn anisotropic_sampling_passes_chi_square() {
        const NZ: usize = 32;
        const NP: usize = 24;
        const SUB: usize = 10;
        let n = 1u32 << 18;
        let cases = [
            ((0.5f32, 0.15f32), 1.5f32, false, 0.6f32, 0.4f32),
            ((0.15, 0.5), 1.0 / 1.5, false, 0.8, 1.9),
            ((0.6, 0.3), 1.5, true, 0.4, 2.8),
        ];
        for ((ax, ay), eta, thin, mu, phi) in cases {
            let wo = direction(mu, phi);
            let lobe = RoughDielectric::anisotropic(ax, ay, eta, wo, Vec3::ONE, thin);
            let bin = |w: Vec3| {
                let z = (((w.z + 1.0) * 0.5 * NZ as f32) as usize).min(NZ - 1);
                let p = w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU;
                (z, ((p * NP as f32) as usize).min(NP - 1))
            };
            let mut counts = vec![[0u32; NP]; NZ];
            for i in 0..n {
                let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
                if let Some(s) = lobe.sample(wo, u, radical_inverse(i, 5)) {
                    let (z, p) = bin(s.wi);
                    counts[z][p] += 1;
                }
            }
            let (mut chi2, mut dof) = (0.0f64, 0usize);
            let area = 2.0 * std::f64::consts::TAU / (NZ * NP * SUB * SUB) as f64;
            for (zi, row) in counts.iter().enumerate() {
                for (pi, &count) in row.iter().enumerate() {
                    let mut p = 0.0f64;
                    for a in 0..SUB {
                        for b in 0..SUB {
                            let z = (zi as f32 + (a as f32 + 0.5) / SUB as f32) / NZ as f32 * 2.0 - 1.0;
                            let phi = (pi as f32 + (b as f32 + 0.5) / SUB as f32) / NP as f32
                                * std::f32::consts::TAU;
                            p += lobe.eval(wo, direction(z, phi)).1 as f64;
                        }
                    }
                    let expected = p * area * n as f64;
                    if expected >= 20.0 {
                        chi2 += (count as f64 - expected).powi(2) / expected;
                        dof += 1;
                    }
                }
            }
            let what = format!("α ({ax}, {ay}) η {eta} thin {thin}");
            assert!(dof > 40, "{what}: {dof} bins");
            // χ² of `dof` degrees of freedom: mean dof, deviation √(2 dof), plus a little for the
            // sub-grid quadrature.
            let limit = dof as f64 + 6.0 * (2.0 * dof as f64).sqrt();
            assert!(chi2 < limit, "{what}: χ² {chi2:.0} over {dof} bins (limit {limit:.0})");
        }
    }

    /// α_x = α_y through the anisotropic constructor is the isotropic lobe: the same samples and
    /// values, bit for bit (the distribution keeps its isotropic arithmetic).
    #[test]
    fn anisotropic_with_equal_alphas_is_the_isotropic_lobe() {
        for roughness in [0.05f32, 0.4, 1.0] {
            for eta in [1.5f32, 1.0 / 1.5] {
                let wo = wo_at(0.6);
                let alpha = roughness * roughness;
                let iso = RoughDielectric::new(roughness, eta, wo, Vec3::ONE, false);
                let aniso = RoughDielectric::with_ggx(
                    Ggx::anisotropic(alpha, alpha),
                    roughness,
                    eta,
                    wo,
                    Vec3::ONE,
                    false,
                );
                for i in 0..512 {
                    let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
                    let (a, b) = (
                        iso.sample(wo, u, radical_inverse(i, 5)),
                        aniso.sample(wo, u, radical_inverse(i, 5)),
                    );
                    assert_eq!(format!("{a:?}"), format!("{b:?}"));
                    let wi = sample_uniform_sphere(u);
                    assert_eq!(iso.eval(wo, wi), aniso.eval(wo, wi));
                }
            }
        }
    }

    /// At α 1e-3 and 1 on either axis, grazing or not, every sample and value is finite.
    #[test]
    fn anisotropic_is_finite_at_the_alpha_bounds() {
        for (ax, ay) in [(1e-3f32, 1.0f32), (1.0, 1e-3), (1e-3, 1e-3), (1.0, 1.0), (1e-4, 2.0)] {
            for eta in [1.5f32, 1.0 / 1.5] {
                for thin in [false, true] {
                    for mu in [1e-6f32, 1e-3, 0.5, 1.0] {
                        let wo = direction(mu, 0.3);
                        let lobe = RoughDielectric::anisotropic(ax, ay, eta, wo, Vec3::ONE, thin);
                        for i in 0..1024 {
                            let u = Vec2::new(radical_inverse(i, 2), radical_inverse(i, 3));
                            if let Some(s) = lobe.sample(wo, u, radical_inverse(i, 5)) {
                                assert!(s.weight.is_finite() && s.pdf.is_finite(), "{s:?}");
                            }
                            let (f, pdf) = lobe.eval(wo, sample_uniform_sphere(u));
                            assert!(f.is_finite() && pdf.is_finite(), "α ({ax}, {ay}) μ {mu}");
                        }
                    }
                }
            }
        }
    }
}
