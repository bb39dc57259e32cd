//! The BSDF at a surface point: a stack of lobes as Blender's Principled BSDF stacks them
//! (Cycles' `svm_node_closure_bsdf`), top to bottom:
//!
//! 1. the sheen (`KHR_materials_sheen`: Cycles' "First layer: Sheen", over the coat too), the
//!    lobe of the file's reading ([`sheen_layer::SheenLayer`]: Cycles' [`sheen::Sheen`] or the
//!    specification's [`charlie::Charlie`]),
//! 2. the coat ([`coat::Coat`], `KHR_materials_clearcoat`),
//! 3. the base ([`base::Base`]): metal m beside the dielectric specular layer over the diffuse
//!    lobe, or over transmission.
//!
//! Each layer scales everything below it by 1 − its directional albedo for wo (Cycles'
//! `closure_layering_weight`): [`Bsdf::with_coat`] attenuates the base it covers,
//! [`Bsdf::with_sheen`] the coat and the base. A material builds only the layers it has:
//! without a coat or a sheen the stack is the base alone, bit for bit, and the Lambert-only
//! path ([`Bsdf::lambert`]) builds nothing else.
//!
//! Transmission (glass) is the integrator's choice, not a lobe here: [`dielectric::Dielectric`]
//! when smooth, [`rough_dielectric::RoughDielectric`] when rough or a thin wall, taken with
//! probability (1 − metallic)·transmission; what is not glass is this stack with the metalness
//! [`BsdfParams::opaque_metallic`] gives, so that metal, glass and the dielectric over diffuse
//! keep the weights of Cycles' Principled BSDF (the coat lies over the opaque part alone). The
//! sheen lies over the glass too, as in Cycles: where the glass is chosen, the sheen is taken
//! alone with probability its albedo a ([`Bsdf::sheen_over_glass`], weighed 1 / a), the glass
//! otherwise, whose weight (1 − a) / (1 − a) is then 1.
//!
//! Sampling picks a layer in proportion to an estimate of its albedo for wo, then a lobe
//! within it, and reports the whole stack's mixture density.

pub mod base;
pub mod charlie;
pub mod coat;
pub mod compensation;
pub mod dielectric;
pub mod fresnel;
pub mod ggx;
pub mod lambert;
pub mod raised_normal;
pub mod rough_dielectric;
pub mod sheen;
pub mod sheen_layer;
mod sheen_table;

use crate::material::{AnisotropyMapping, Material, SheenModel};
use crate::sampling::Frame;
use base::Base;
use coat::Coat;
use glam::{Vec2, Vec3};
use sheen_layer::SheenLayer;

/// A sampled incident direction with its BSDF value and density.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Incident direction, world space, unit length.
    pub wi: Vec3,
    /// f(wo, wi).
    pub f: Vec3,
    /// Solid-angle density of `wi`.
    pub pdf: f32,
    /// |cos θ| between `wi` and the shading normal.
    pub cos: f32,
}

/// The parameters of the opaque BSDF at one shading point (material factors × textures).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfParams {
    /// Base colour.
    pub base_color: Vec3,
    /// Metalness.
    pub metallic: f32,
    /// Perceptual roughness.
    pub roughness: f32,
    /// Dielectric specular weight (`KHR_materials_specular`).
    pub specular: f32,
    /// Dielectric specular tint.
    pub specular_color: Vec3,
    /// Index of refraction that shapes the dielectric layer's Fresnel curve.
    pub ior: f32,
    /// `KHR_materials_anisotropy` strength (0: isotropic): the specular lobes' roughness
    /// stretched along the shading frame's x axis, as `anisotropy_mapping` says.
    pub anisotropy: f32,
    /// How the strength stretches the roughness (the file's reading).
    pub anisotropy_mapping: AnisotropyMapping,
}

impl BsdfParams {
    /// True when these parameters leave the Lambert lobe alone: no metallic and no specular
    /// weight, so [`Bsdf::lambert`] builds the same BSDF as [`Bsdf::with_frame`]. (A coat is
    /// not part of these parameters: see [`Bsdf::with_coat`].)
    pub fn is_lambert(&self) -> bool {
        self.metallic == 0.0 && self.specular == 0.0
    }

    /// The untextured parameters of `material`. The dielectric layer keeps its weight whatever
    /// its tint: `KHR_materials_specular` scales F0 by the colour but not F90 (= the factor), so
    /// a black `specularColorFactor` still leaves the grazing rim.
    pub fn of(material: &Material) -> Self {
        Self {
            base_color: material.base_color,
            metallic: material.metallic,
            roughness: material.roughness,
            specular: material.specular,
            specular_color: material.specular_color,
            ior: material.ior,
            anisotropy: material.anisotropy.map_or(0.0, |a| a.strength),
            anisotropy_mapping: material.anisotropy.map_or_else(AnisotropyMapping::default, |a| a.mapping),
        }
    }

    /// The metalness of the opaque BSDF that stands for everything but the glass of a material
    /// with metalness `metallic` and transmission `transmission`. Cycles' Principled BSDF weighs
    /// metal m, glass (1 − m)·T and the dielectric over diffuse (1 − m)·(1 − T); the integrator
    /// takes the glass with probability (1 − m)·T, so the opaque rest, taken with probability
    /// q = 1 − (1 − m)·T, is metal m / q and dielectric (1 − m)·(1 − T) / q. With T = 0 (and
    /// with m = 0) this is `metallic` exactly.
    #[inline]
    pub fn opaque_metallic(metallic: f32, transmission: f32) -> f32 {
        if transmission == 0.0 {
            return metallic;
        }
        let q = 1.0 - (1.0 - metallic) * transmission;
        // q = 0 only for pure glass, whose opaque part is never taken.
        if q > 0.0 { (metallic / q).min(1.0) } else { metallic }
    }
}

/// The stack of lobes at one shading point, with wo fixed (module docs: the order).
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    base: Base,
    /// The coat over the base, with the probability of sampling it; `None` without a coat.
    coat: Option<(Coat, f32)>,
    /// The sheen over both, with the probability of sampling it; `None` without a sheen.
    sheen: Option<(SheenLayer, f32)>,
}

impl Bsdf {
    /// The base of `material` at a point with shading normal `ns` and geometric normal `ng`
    /// (both unit, any orientation), seen from world direction `wo`, with the material's coat
    /// (on `ns`) if it has one.
    #[inline]
    #[cfg(any(test, feature = "test-support"))]
    pub fn new(material: &Material, ns: Vec3, ng: Vec3, wo: Vec3) -> Self {
        let bsdf = Self::with_frame(&BsdfParams::of(material), Frame::from_z(ns), ng, wo);
        let bsdf = if material.coat > 0.0 {
            bsdf.with_coat(material.coat, material.coat_roughness, ns, wo)
        } else {
            bsdf
        };
        if material.sheen != Vec3::ZERO {
            bsdf.with_sheen(material.sheen_model, material.sheen, material.sheen_roughness, ns, wo)
        } else {
            bsdf
        }
    }

    /// The base with parameters `p` (e.g. textured) in the shading frame `shading` (z: the unit
    /// shading normal, facing either way; `Frame::from_z`, or a triangle's precomputed frame),
    /// with geometric normal `ng`, seen from world direction `wo`.
    #[inline(always)]
    pub fn with_frame(p: &BsdfParams, shading: Frame, ng: Vec3, wo: Vec3) -> Self {
        Self { base: Base::with_frame(p, shading, ng, wo), coat: None, sheen: None }
    }

    /// The Lambert lobe alone, of albedo `base_color`: the same BSDF, bit for bit, as
    /// [`Bsdf::with_frame`] for parameters with no metallic and no specular weight
    /// ([`BsdfParams::is_lambert`]), without setting up the lobes that then weigh nothing.
    #[inline(always)]
    pub fn lambert(base_color: Vec3, shading: Frame, ng: Vec3, wo: Vec3) -> Self {
        Self { base: Base::lambert(base_color, shading, ng, wo), coat: None, sheen: None }
    }

    /// At a glass vertex of a material with a `model` sheen of colour `color` and roughness
    /// `roughness` on unit normal `n`: with `u` (uniform in [0, 1)) below the sheen's albedo a
    /// for `wo`, the sheen alone (nothing below it), weighed 1 / a, the probability of taking
    /// it; otherwise `None`, and the glass below it is taken with weight 1 (module docs).
    /// `shading` and `ng` as for [`Bsdf::with_frame`].
    #[inline]
    pub fn sheen_over_glass(
        model: SheenModel,
        color: Vec3,
        roughness: f32,
        n: Vec3,
        (shading, ng): (Frame, Vec3),
        wo: Vec3,
        u: f32,
    ) -> Option<Self> {
        let base = Base::lambert(Vec3::ZERO, shading, ng, wo);
        let sheen = SheenLayer::new(model, color, roughness, n, base.geometric_normal(), wo);
        let a = sheen.albedo();
        (u < a).then(|| Self { base, coat: None, sheen: Some((sheen.scaled(1.0 / a), 1.0)) })
    }

    /// This BSDF of a normal-mapped surface whose smoothed normal without the map is `smooth`:
    /// the base's diffuse lobe is shadowed as Blender does it ([`Base::with_bump`]).
    #[inline]
    pub fn with_bump(self, smooth: Vec3) -> Self {
        Self { base: self.base.with_bump(smooth), ..self }
    }

    /// This stack under a coat of weight `weight` and perceptual roughness `roughness` on unit
    /// normal `n` (either side), seen from `wo` (the stack's): the base keeps 1 − the coat's
    /// albedo for wo, and the coat is sampled in proportion to its albedo against an estimate
    /// of the base's.
    #[inline]
    pub fn with_coat(mut self, weight: f32, roughness: f32, n: Vec3, wo: Vec3) -> Self {
        let coat = Coat::new(weight, roughness, n, self.base.geometric_normal(), wo);
        let below = 1.0 - coat.albedo();
        self.base.attenuate(below);
        let base = self.base.albedo_estimate();
        let p = if coat.albedo() + base > 0.0 { coat.albedo() / (coat.albedo() + base) } else { 1.0 };
        // The base is always sampled a little: a coat's albedo under 5 % head-on would
        // otherwise starve a bright base, and the base's own lobes need the rest.
        self.coat = Some((coat, p.clamp(0.0, 0.9)));
        self
    }

    /// This stack (base and coat) under a `model` sheen of colour `color` (weight × tint) and
    /// roughness `roughness` on unit normal `n` (either side), seen from `wo` (the stack's):
    /// what lies below keeps 1 − the sheen's albedo for wo, and the sheen is sampled in
    /// proportion to its albedo against an estimate of the rest's. (The top layer: build it
    /// last.)
    #[inline]
    pub fn with_sheen(mut self, model: SheenModel, color: Vec3, roughness: f32, n: Vec3, wo: Vec3) -> Self {
        let sheen = SheenLayer::new(model, color, roughness, n, self.base.geometric_normal(), wo);
        let below = 1.0 - sheen.albedo();
        self.base.attenuate(below);
        let mut rest = self.base.albedo_estimate();
        if let Some((coat, _)) = &mut self.coat {
            coat.attenuate(below);
            rest += coat.albedo();
        }
        let a = sheen.albedo();
        let p = if a + rest > 0.0 { a / (a + rest) } else { 1.0 };
        // As under a coat, what lies below is always sampled a little.
        self.sheen = Some((sheen, p.clamp(0.0, 0.9)));
        self
    }

    /// True when the BSDF reflects nothing (e.g. a black emitter): the path can stop here.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.coat.is_none() && self.sheen.is_none() && self.base.is_black()
    }

    /// True when the BSDF is the Lambert lobe alone (no specular lobe).
    #[inline]
    pub fn is_diffuse(&self) -> bool {
        self.coat.is_none() && self.sheen.is_none() && self.base.is_diffuse()
    }

    /// True when sampling must choose between lobes (and so needs a number for it).
    #[inline]
    pub fn has_lobe_choice(&self) -> bool {
        self.coat.is_some() || self.sheen.is_some() || self.base.has_lobe_choice()
    }

    /// The shading normal (facing wo).
    #[inline]
    pub fn shading_normal(&self) -> Vec3 {
        self.base.shading_normal()
    }

    /// The geometric normal facing wo: the BSDF is zero for light arriving from behind it.
    #[inline]
    pub fn geometric_normal(&self) -> Vec3 {
        self.base.geometric_normal()
    }

    /// f(wo, wi) and the density of sampling `wi` (world, unit) for this wo.
    #[inline(always)]
    pub fn eval(&self, wi: Vec3) -> (Vec3, f32) {
        let (f, pdf) = self.eval_below_sheen(wi);
        match &self.sheen {
            None => (f, pdf),
            Some((sheen, p)) => self.add_sheen(sheen, *p, wi, f, pdf),
        }
    }

    /// The value and density of the base and the coat.
    #[inline(always)]
    fn eval_below_sheen(&self, wi: Vec3) -> (Vec3, f32) {
        let (f, pdf) = self.base.eval(wi);
        match &self.coat {
            None => (f, pdf),
            Some((coat, p)) => self.add_coat(coat, *p, wi, f, pdf),
        }
    }

    /// The stack's value and density at `wi` from those below the sheen (`f`, `pdf`) and the
    /// sheen's.
    #[inline(never)]
    fn add_sheen(&self, sheen: &SheenLayer, p: f32, wi: Vec3, f: Vec3, pdf: f32) -> (Vec3, f32) {
        self.add_layer(p, wi, f, pdf, |wi, cos_s| sheen.eval(wi, cos_s))
    }

    /// The stack's value and density at `wi` from the base's (`f`, `pdf`) and the coat's.
    #[inline(never)]
    fn add_coat(&self, coat: &Coat, p: f32, wi: Vec3, f: Vec3, pdf: f32) -> (Vec3, f32) {
        self.add_layer(p, wi, f, pdf, |wi, cos_s| coat.eval(wi, cos_s))
    }

    /// The value and density at `wi` of a layer (`eval`: its value and density given `wi` and
    /// the shading cosine) sampled with probability `p` over what lies below it (`f`, `pdf`):
    /// nothing below the shading or the geometric surface.
    #[inline(always)]
    fn add_layer(
        &self,
        p: f32,
        wi: Vec3,
        f: Vec3,
        pdf: f32,
        eval: impl FnOnce(Vec3, f32) -> (Vec3, f32),
    ) -> (Vec3, f32) {
        let cos_s = wi.dot(self.base.shading_normal());
        if cos_s <= 0.0 || wi.dot(self.base.geometric_normal()) <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let (fl, pl) = eval(wi, cos_s);
        (f + fl, (1.0 - p) * pdf + p * pl)
    }

    /// Samples wi from `u` (2-D, stratified) and `u_lobe` (1-D lobe choice).
    #[inline(always)]
    pub fn sample(&self, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        let Some((sheen, p)) = &self.sheen else { return self.sample_below_sheen(u, u_lobe) };
        let wi = if u_lobe < *p {
            sheen.sample(u)?
        } else {
            self.sample_below_sheen(u, ((u_lobe - p) / (1.0 - p)).min(1.0 - f32::EPSILON / 2.0))?.wi
        };
        let (f, pdf) = self.eval(wi);
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample { wi, f, pdf, cos: wi.dot(self.base.shading_normal()) })
    }

    /// Samples the base and the coat (the stack below the sheen), as [`Bsdf::sample`].
    #[inline(always)]
    fn sample_below_sheen(&self, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        let Some((coat, p)) = &self.coat else { return self.base.sample(u, u_lobe) };
        let wi = if u_lobe < *p {
            coat.sample(u)?
        } else {
            self.base.sample(u, ((u_lobe - p) / (1.0 - p)).min(1.0 - f32::EPSILON / 2.0))?.wi
        };
        let (f, pdf) = self.eval_below_sheen(wi);
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample { wi, f, pdf, cos: wi.dot(self.base.shading_normal()) })
    }
}

#[cfg(test)]
mod tests {
    use super::base::tests::{albedo, halton, material};
    use super::*;

    fn coated(base: f32, metallic: f32, roughness: f32, coat: f32, coat_roughness: f32) -> Material {
        Material { coat, coat_roughness, ..material(base, metallic, roughness, 1.0) }
    }

    fn at(cos_o: f32) -> Vec3 {
        Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o)
    }

    /// Furnace: a coat over a black base reflects at most what falls on it, and never NaN, at
    /// coat roughness 0 and 1 and between, head-on and at grazing angles; over a white Lambert
    /// base the stack loses nothing (the base gets exactly what the compensated coat leaves:
    /// 1 within the tables' interpolation error), and importance sampling agrees with uniform
    /// sampling where the coat is broad enough for the latter to see it.
    #[test]
    fn coat_furnace() {
        for coat_roughness in [0.0, 0.1, 0.5, 1.0] {
            for cos_o in [1.0f32, 0.5, 0.1, 1e-3] {
                let black =
                    Bsdf::new(&coated(0.0, 0.0, 0.5, 1.0, coat_roughness), Vec3::Z, Vec3::Z, at(cos_o));
                let (is, _) = albedo(&black, 1 << 15);
                assert!(is.is_finite() && is.max_element() <= 1.0, "{coat_roughness} {cos_o}: {is}");
                assert!(is.min_element() > 0.02, "{coat_roughness} {cos_o}: the coat reflects {is}");
                let mut white_m = coated(1.0, 0.0, 1.0, 1.0, coat_roughness);
                white_m.specular = 0.0;
                let white = Bsdf::new(&white_m, Vec3::Z, Vec3::Z, at(cos_o));
                let (is, uni) = albedo(&white, 1 << 16);
                assert!((is - Vec3::ONE).abs().max_element() < 0.02, "{coat_roughness} {cos_o}: {is}");
                if coat_roughness >= 0.5 && cos_o > 0.05 {
                    assert!((is - uni).abs().max_element() < 0.03, "{coat_roughness} {cos_o}: {is} vs {uni}");
                }
            }
        }
    }

    /// The coat darkens the base beneath it by its albedo: head-on a coat of weight 1 takes
    /// about F0(1.5) = 4 % of a white diffuse base's light and reflects it itself; at grazing it
    /// takes far more. Half the weight takes half as much.
    #[test]
    fn the_coat_attenuates_the_base_by_its_albedo() {
        for (cos_o, lo, hi) in [(1.0f32, 0.03, 0.06), (0.1, 0.2, 0.6)] {
            let full = Bsdf::new(&coated(1.0, 0.0, 1.0, 1.0, 0.2), Vec3::Z, Vec3::Z, at(cos_o));
            let (_, coat_albedo) = full.coat.expect("coated");
            let taken = full.coat.unwrap().0.albedo();
            assert!(taken > lo && taken < hi, "{cos_o}: {taken} ({coat_albedo})");
            let half = Bsdf::new(&coated(1.0, 0.0, 1.0, 0.5, 0.2), Vec3::Z, Vec3::Z, at(cos_o));
            assert!((half.coat.unwrap().0.albedo() - 0.5 * taken).abs() < 1e-6);
        }
        // No coat, no layer: the stack is the base alone.
        assert!(Bsdf::new(&coated(1.0, 0.0, 1.0, 0.0, 0.2), Vec3::Z, Vec3::Z, at(0.5)).coat.is_none());
    }

    /// Furnace with the sheen on top: a white sheen over a white Lambert base (and over a
    /// coat on it) loses and gains nothing (the base keeps exactly what the sheen leaves: 1
    /// within the tables' interpolation error), at sheen roughness 0 and 1 and between,
    /// head-on and grazing, never NaN; over a black base it reflects its albedo, at most 1;
    /// importance sampling agrees with uniform sampling where the lobes are broad.
    #[test]
    fn sheen_furnace() {
        for sheen_roughness in [0.0, 0.3, 0.6, 1.0] {
            for cos_o in [1.0f32, 0.5, 0.1, 1e-3] {
                for coat in [0.0, 1.0] {
                    let mut white = coated(1.0, 0.0, 1.0, coat, 0.5);
                    white.specular = 0.0;
                    white.sheen = Vec3::ONE;
                    white.sheen_roughness = sheen_roughness;
                    let bsdf = Bsdf::new(&white, Vec3::Z, Vec3::Z, at(cos_o));
                    assert!(bsdf.sheen.is_some());
                    let (is, uni) = albedo(&bsdf, 1 << 16);
                    assert!(
                        (is - Vec3::ONE).abs().max_element() < 0.02,
                        "{sheen_roughness} {cos_o} {coat}: {is}"
                    );
                    if cos_o > 0.05 {
                        assert!(
                            (is - uni).abs().max_element() < 0.03,
                            "{sheen_roughness} {cos_o}: {is} vs {uni}"
                        );
                    }
                }
                let mut black = material(0.0, 0.0, 1.0, 0.0);
                black.sheen = Vec3::ONE;
                black.sheen_roughness = sheen_roughness;
                let bsdf = Bsdf::new(&black, Vec3::Z, Vec3::Z, at(cos_o));
                let (is, _) = albedo(&bsdf, 1 << 15);
                let r = bsdf.sheen.unwrap().0.albedo();
                assert!(is.is_finite() && is.max_element() <= 1.0, "{sheen_roughness} {cos_o}: {is}");
                assert!((is.x - r).abs() < 0.01 + 0.02 * r, "{sheen_roughness} {cos_o}: {is} vs {r}");
            }
        }
        // No sheen, no layer.
        assert!(Bsdf::new(&material(1.0, 0.0, 1.0, 1.0), Vec3::Z, Vec3::Z, at(0.5)).sheen.is_none());
    }

    fn anisotropic(
        base: f32,
        metallic: f32,
        roughness: f32,
        strength: f32,
        mapping: AnisotropyMapping,
    ) -> Material {
        let anisotropy = Some(crate::material::Anisotropy { strength, rotation: 0.0, mapping });
        Material { anisotropy, ..material(base, metallic, roughness, 1.0) }
    }

    /// Furnace for the anisotropic base, never NaN at roughness 0 and 1 and between, strengths
    /// up to 1, head-on and grazing, seen along and across the grain, in both readings. The
    /// multiple-scattering compensation and the diffuse layer's share are read from the
    /// isotropic tables at the mean α √(α_x·α_y), as Cycles reads them, which is exact head-on
    /// and approximate at grazing views: a white metal never gains more than 3 % and keeps
    /// 90 % in Blender's reading (it loses more where Cycles' bound α ≤ 1 cuts the stretched
    /// α, and at the specification's longer stretches); a white
    /// plastic keeps ≤ 1 within 2 % down to cos θo = 0.5, and gains seen grazing across the
    /// grain (its smooth direction), where the diffuse layer gets what the mean-α table says
    /// the dielectric leaves: 16 % at cos θo = 10⁻³ in Blender's reading (as in Cycles), 29 % in
    /// the specification's longer stretches (a known limit, docs/cycles.md). Importance sampling agrees
    /// with uniform sampling where the lobe is broad.
    #[test]
    fn anisotropic_furnace() {
        for mapping in [AnisotropyMapping::Blender, AnisotropyMapping::Spec] {
            for (roughness, strength) in [(0.0, 1.0), (0.3, 0.8), (0.5, 0.5), (1.0, 1.0), (0.6, 0.3)] {
                let (ax, ay) = mapping.alphas(roughness, strength);
                for cos_o in [1.0f32, 0.5, 0.1, 1e-3] {
                    for phi in [0.0f32, 1.0, std::f32::consts::FRAC_PI_2] {
                        let s = (1.0 - cos_o * cos_o).sqrt();
                        let wo = Vec3::new(s * phi.cos(), s * phi.sin(), cos_o);
                        let metal = anisotropic(1.0, 1.0, roughness, strength, mapping);
                        let bsdf = Bsdf::new(&metal, Vec3::Z, Vec3::Z, wo);
                        let (is, _) = albedo(&bsdf, 1 << 15);
                        let what = format!("{mapping:?} r {roughness} s {strength} cos {cos_o} φ {phi}");
                        assert!(is.is_finite() && is.max_element() <= 1.03, "{what}: {is}");
                        // In Blender's reading (α_x / α_y ≤ 10, both ≤ 1) the compensation
                        // restores nearly all; the specification's longer stretches (α_t 0.67
                        // over α_b 0.09 loses 23 % head-on) are beyond what isotropic tables
                        // restore: energy is lost there, never made.
                        if mapping == AnisotropyMapping::Blender && ax.max(ay) <= 1.0 {
                            assert!(is.min_element() >= 0.9, "{what}: {is}");
                        }
                        if ax.min(ay) >= 0.2 && cos_o > 0.05 {
                            let (_, uni) = albedo(&bsdf, 1 << 18);
                            assert!((is - uni).abs().max_element() < 0.03, "{what}: {is} vs {uni}");
                        }
                        let plastic = anisotropic(1.0, 0.0, roughness, strength, mapping);
                        let (is, _) = albedo(&Bsdf::new(&plastic, Vec3::Z, Vec3::Z, wo), 1 << 14);
                        assert!(is.is_finite(), "{what}: plastic {is}");
                        if cos_o >= 0.5 {
                            assert!(is.max_element() <= 1.02, "{what}: plastic {is}");
                        }
                    }
                }
            }
        }
    }

    /// A material without anisotropy (or with strength 0) builds the isotropic base, bit for
    /// bit; with it, the highlight of a light along the grain differs from one across it.
    #[test]
    fn anisotropy_zero_is_the_isotropic_base() {
        let bits = |(f, p): (Vec3, f32)| (f.to_array().map(f32::to_bits), p.to_bits());
        let wo = Vec3::new(0.5, 0.2, 0.8).normalize();
        let plain = Bsdf::new(&material(0.7, 0.6, 0.4, 1.0), Vec3::Z, Vec3::Z, wo);
        let zero = Bsdf::new(&anisotropic(0.7, 0.6, 0.4, 0.0, AnisotropyMapping::Spec), Vec3::Z, Vec3::Z, wo);
        let strong =
            Bsdf::new(&anisotropic(0.7, 0.6, 0.4, 0.9, AnisotropyMapping::Spec), Vec3::Z, Vec3::Z, wo);
        let mut differ = 0;
        for i in 0..256 {
            let wi = crate::sampling::sample_uniform_sphere(Vec2::new(halton(i, 2), halton(i, 3)));
            assert_eq!(bits(plain.eval(wi)), bits(zero.eval(wi)), "{wi}");
            differ += usize::from(bits(plain.eval(wi)) != bits(strong.eval(wi)));
        }
        assert!(differ > 50, "{differ}");
    }

    /// Grazing views under a coat whose normal map tilts away from wo give finite values.
    #[test]
    fn a_tilted_coat_stays_finite() {
        let wo = Vec3::new(-0.999, 0.0, 0.04).normalize();
        let ns = Vec3::new(0.3, 0.0, 0.95).normalize();
        let bsdf = Bsdf::new(&coated(0.8, 0.5, 0.3, 1.0, 0.0), ns, Vec3::Z, wo);
        for i in 0..1024 {
            if let Some(s) = bsdf.sample(Vec2::new(halton(i, 2), halton(i, 3)), halton(i, 5)) {
                assert!(s.f.is_finite() && s.pdf.is_finite() && s.cos > 0.0);
            }
        }
    }
}
