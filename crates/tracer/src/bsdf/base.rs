//! The Principled base: the glTF 2.0 metallic-roughness model (glTF spec Appendix B) with
//! `KHR_materials_specular`'s dielectric F0 and weight:
//!
//! ```text
//! f = (1 − m)·[(1 − s·max(A_d(wo)))·ρ/π + s·F_d·S] + m·F_m·S,     S = D·G2 / (4 |n·wo| |n·wi|)
//! ```
//! with F_m Schlick's Fresnel at the half vector (F0 the base colour), F_d the dielectric layer's
//! as Blender has it (`fresnel.rs`: the exact Fresnel of the material's η remapped to start at
//! F0 = min(0.04·specular colour, 1)), and A_d(wo) the compensated dielectric lobe's
//! directional albedo: the diffuse base loses what the layer above it reflects, as in Blender's
//! Principled BSDF, rather than glTF's per-direction `fresnel_mix` (docs/design/tracer.md §3.10).
//! Sampling picks the diffuse lobe (cosine) or
//! the specular lobe (GGX visible normals) in proportion to an estimate of their albedo for wo,
//! and reports the mixture density, so both lobes' values count at every sampled direction.
//!
//! Where a shading normal would mirror wo below the surface, the specular lobes use a raised
//! normal of their own (`raised_normal.rs`, Blender's bump-map correction).
//!
//! The GGX lobe carries Turquin's multiple-scattering compensation (`compensation.rs`), so a
//! white metal reflects all light at every roughness, as Blender's energy-compensated GGX does.
//!
//! Surfaces are two-sided: the frame faces wo's side of the geometric normal, and only
//! reflection on that side is non-zero (no light through an opaque surface via shading normals).

use super::fresnel::LayerFresnel;
use super::ggx::Ggx;
use super::{BsdfParams, BsdfSample, compensation, lambert, raised_normal};
use crate::sampling::Frame;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// The Principled base of one shading point, with wo fixed: metal beside the dielectric
/// specular layer over the diffuse lobe.
#[derive(Clone, Copy, Debug)]
pub struct Base {
    frame: Frame,
    /// The specular lobes' own frame and wo in it, where Blender's bump-map correction raises
    /// their normal (`raised_normal.rs`); `None` when they share the shading frame.
    raised: Option<(Frame, Vec3)>,
    /// With a normal map, the smoothed normal without it (on ng's side) and the GGX α² of the
    /// map's tilt, for Blender's bump shadowing of the diffuse lobe ([`Base::with_bump`]).
    bump: Option<(Vec3, f32)>,
    /// Geometric normal on wo's side.
    ng: Vec3,
    /// wo in the shading frame.
    wo: Vec3,
    /// (1 − m) · base colour / π, times what the dielectric layer leaves the base for this wo.
    diffuse: Vec3,
    /// (1 − m) · specular weight.
    dielectric_weight: f32,
    layer: LayerFresnel,
    metal_weight: f32,
    f0_metal: Vec3,
    /// Multiple-scattering compensation factors of the dielectric and metal lobes for this wo.
    ms_dielectric: Vec3,
    ms_metal: Vec3,
    ggx: Ggx,
    /// Probability of sampling the specular lobe (0 for a purely diffuse material).
    p_specular: f32,
}

/// The shading frame and geometric normal turned to face `wo`, and `wo` in that frame (kept
/// just above the horizon, where a shading normal can put it below).
#[inline(always)]
pub(super) fn facing(shading: Frame, ng: Vec3, wo: Vec3) -> (Frame, Vec3, Vec3) {
    let ng = if ng.dot(wo) < 0.0 { -ng } else { ng };
    let frame = if shading.z.dot(ng) < 0.0 { shading.flipped() } else { shading };
    let mut wo_local = frame.to_local(wo);
    wo_local.z = wo_local.z.max(1e-6);
    (frame, ng, wo_local)
}

/// The frame of unit normal `n` whose x axis is `t` made perpendicular to it (an anisotropic
/// lobe's direction kept on a raised normal); `Frame::from_z(n)` where `t` lies along `n`.
fn around(n: Vec3, t: Vec3) -> Frame {
    match (t - n * n.dot(t)).normalize_or_zero() {
        x if x == Vec3::ZERO => Frame::from_z(n),
        x => Frame { x, y: n.cross(x), z: n },
    }
}

#[inline]
fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (Vec3::ONE - f0) * (m2 * m2 * m)
}

impl Base {
    /// The base with parameters `p` (e.g. textured) in the shading frame `shading` (z: the unit
    /// shading normal, facing either way; `Frame::from_z`, or a triangle's precomputed frame),
    /// with geometric normal `ng`, seen from world direction `wo`.
    #[inline(always)]
    pub fn with_frame(p: &BsdfParams, shading: Frame, ng: Vec3, wo: Vec3) -> Self {
        let (frame, ng, wo_local) = facing(shading, ng, wo);
        let m = p.metallic;
        let base = p.base_color;
        let specular = p.specular;
        let layer = LayerFresnel::new(0.04 * p.specular_color, p.ior);
        // Anisotropic: α_x along the frame's x (the anisotropy direction); the compensation
        // tables are read at the roughness of the mean α, √(α_x·α_y), as Cycles reads them.
        let (ggx, ms_roughness) = if p.anisotropy > 0.0 {
            let (ax, ay) = p.anisotropy_mapping.alphas(p.roughness, p.anisotropy);
            let ggx = Ggx::anisotropic(ax, ay);
            let (ax, ay) = ggx.alphas();
            (ggx, (ax * ay).sqrt().sqrt())
        } else {
            (Ggx::from_roughness(p.roughness), p.roughness)
        };

        let diffuse = (1.0 - m) * base * FRAC_1_PI;
        let dielectric_weight = (1.0 - m) * specular;
        let metal_weight = m;
        let raised = if dielectric_weight == 0.0 && metal_weight == 0.0 {
            None
        } else {
            raised_normal::raised(ng, wo, frame.z).map(|n| {
                let f = if ggx.is_anisotropic() { around(n, frame.x) } else { Frame::from_z(n) };
                let mut wo_s = f.to_local(wo);
                wo_s.z = wo_s.z.max(1e-6);
                (f, wo_s)
            })
        };
        // cos θo of the specular lobes, against their own normal.
        let mu = raised.map_or(wo_local.z, |(_, w)| w.z);
        let p_specular = if dielectric_weight == 0.0 && metal_weight == 0.0 {
            0.0
        } else {
            let fd = layer.eval(mu).max_element();
            let fm = schlick(base, mu).element_sum() / 3.0;
            let w_spec = dielectric_weight * fd + metal_weight * fm;
            let w_diff = (1.0 - m) * (1.0 - specular * fd) * base.element_sum() / 3.0;
            if w_spec + w_diff > 0.0 { (w_spec / (w_spec + w_diff)).clamp(0.0, 1.0) } else { 0.0 }
        };
        let (ms_dielectric, ms_metal, diffuse) = if p_specular > 0.0 {
            let (ms_dielectric, layer_albedo) = compensation::dielectric(&layer, mu, ms_roughness);
            // The base beneath the dielectric layer gets what the layer does not reflect for this
            // wo, as in Blender's Principled BSDF (docs/design/tracer.md §3.10).
            let beneath = (1.0 - specular * layer_albedo.max_element()).max(0.0);
            (ms_dielectric, compensation::factor(base, mu, ms_roughness), diffuse * beneath)
        } else {
            (Vec3::ONE, Vec3::ONE, diffuse)
        };
        Self {
            frame,
            raised,
            bump: None,
            ng,
            wo: wo_local,
            diffuse,
            dielectric_weight,
            layer,
            metal_weight,
            f0_metal: base,
            ms_dielectric,
            ms_metal,
            ggx,
            p_specular,
        }
    }

    /// The Lambert lobe alone, of albedo `base_color`: the same BSDF, bit for bit, as
    /// [`Base::with_frame`] for parameters with no metallic and no specular weight
    /// ([`BsdfParams::is_lambert`]), without setting up the lobes that then weigh nothing.
    #[inline(always)]
    pub fn lambert(base_color: Vec3, shading: Frame, ng: Vec3, wo: Vec3) -> Self {
        let (frame, ng, wo_local) = facing(shading, ng, wo);
        Self {
            frame,
            raised: None,
            bump: None,
            ng,
            wo: wo_local,
            // (1 − 0)·base·(1/π), as `with_frame` has it: 1·base is base exactly.
            diffuse: base_color * FRAC_1_PI,
            dielectric_weight: 0.0,
            layer: LayerFresnel::new(Vec3::ZERO, 1.5),
            metal_weight: 0.0,
            f0_metal: base_color,
            ms_dielectric: Vec3::ONE,
            ms_metal: Vec3::ONE,
            ggx: Ggx::from_roughness(1.0),
            p_specular: 0.0,
        }
    }

    /// This BSDF of a normal-mapped surface whose smoothed normal without the map is `smooth`
    /// (unit, either side): the diffuse lobe is shadowed as Blender does it (Cycles'
    /// `bump_shadowing_term`, on by default: a GGX masking G1(α², |n_s·wi|) with α² = ⅛·tan²
    /// of the map's tilt), and no light arrives from below the smoothed surface.
    #[inline]
    pub fn with_bump(mut self, smooth: Vec3) -> Self {
        let ns = if smooth.dot(self.ng) < 0.0 { -smooth } else { smooth };
        let cos_d = ns.dot(self.frame.z).abs();
        if cos_d < 1.0 {
            let tan2 = 1.0 / (cos_d * cos_d).max(1e-12) - 1.0;
            self.bump = Some((ns, (0.125 * tan2).clamp(0.0, 1.0)));
        }
        self
    }

    /// f for `wi` (world) with the bump shadowing of [`Base::with_bump`] applied.
    #[inline(always)]
    fn bump_shadowed(&self, wi: Vec3, f: Vec3) -> Vec3 {
        let Some((ns, alpha2)) = self.bump else { return f };
        let cos_i = ns.dot(wi);
        if cos_i < 1e-6 {
            return Vec3::ZERO;
        }
        if cos_i >= 1.0 {
            return f;
        }
        let tan2 = 1.0 / (cos_i * cos_i) - 1.0;
        let g1 = 2.0 / (1.0 + (1.0 + alpha2 * tan2).sqrt());
        f - self.diffuse * (1.0 - g1)
    }

    /// Scales every lobe by `t` (what a layer above leaves the base, in [0, 1]).
    #[inline]
    pub fn attenuate(&mut self, t: f32) {
        self.diffuse *= t;
        self.dielectric_weight *= t;
        self.metal_weight *= t;
    }

    /// An estimate of the base's albedo for wo (for choosing between it and a layer above).
    #[inline]
    pub fn albedo_estimate(&self) -> f32 {
        let mu = self.raised.map_or(self.wo.z, |(_, w)| w.z);
        let diffuse = self.diffuse.element_sum() * (std::f32::consts::PI / 3.0);
        let dielectric = self.dielectric_weight * self.layer.eval(mu).max_element();
        let metal = self.metal_weight * schlick(self.f0_metal, mu).element_sum() / 3.0;
        diffuse + dielectric + metal
    }

    /// True when the BSDF reflects nothing (e.g. a black emitter): the path can stop here.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.diffuse.max_element() == 0.0 && self.p_specular == 0.0
    }

    /// True when the BSDF is the Lambert lobe alone (no specular lobe).
    #[inline]
    pub fn is_diffuse(&self) -> bool {
        self.p_specular == 0.0
    }

    /// True when sampling must choose between two lobes (and so needs a number for it).
    #[inline]
    pub fn has_lobe_choice(&self) -> bool {
        self.p_specular > 0.0 && self.p_specular < 1.0
    }

    /// The shading normal (facing wo).
    #[inline]
    pub fn shading_normal(&self) -> Vec3 {
        self.frame.z
    }

    /// The geometric normal facing wo: the BSDF is zero for light arriving from behind it.
    #[inline]
    pub fn geometric_normal(&self) -> Vec3 {
        self.ng
    }

    /// f(wo, wi) and the density of sampling `wi` (world, unit) for this wo.
    // Always inlined, as `eval_local`: out of line, the BSDF went through memory for the call
    // (docs/performance.md, ledger: "`Bsdf::eval` always inlined": measured as `Bsdf`'s).
    #[inline(always)]
    pub fn eval(&self, wi: Vec3) -> (Vec3, f32) {
        if wi.dot(self.ng) <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let wl = self.frame.to_local(wi);
        if wl.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let (f, pdf) = match self.raised {
            None => self.eval_local(wl),
            Some((f, wo)) => self.eval_raised(wl, f.to_local(wi), wo),
        };
        (self.bump_shadowed(wi, f), pdf)
    }

    // Always inlined: on the Lambert-only path LLVM then sees p_specular = 0 from
    // `Base::lambert` and drops the specular code and the BSDF's trip through memory
    // (docs/performance.md, ledger: "`Bsdf::eval_local` always inlined": measured as `Bsdf`'s).
    #[inline(always)]
    fn eval_local(&self, wi: Vec3) -> (Vec3, f32) {
        if self.p_specular == 0.0 {
            return (self.diffuse, lambert::pdf(wi));
        }
        let (spec, spec_pdf) = self.specular(self.wo, wi);
        let f = self.diffuse + spec;
        let pdf = (1.0 - self.p_specular) * lambert::pdf(wi) + self.p_specular * spec_pdf;
        (f, pdf)
    }

    /// The specular lobes' value and sampling density for `wo`, `wi` in their frame (wi.z > 0).
    #[inline(always)]
    fn specular(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let h = (wo + wi).normalize_or(Vec3::Z);
        let wo_h = wo.dot(h).max(0.0);
        let fd = self.layer.eval(wo_h);
        let fm = schlick(self.f0_metal, wo_h);
        let s = self.ggx.d(h) * self.ggx.g2(wo, wi) / (4.0 * wo.z * wi.z);
        let f =
            (self.dielectric_weight * fd * self.ms_dielectric + self.metal_weight * fm * self.ms_metal) * s;
        (f, self.ggx.pdf_reflection(wo, h))
    }

    /// [`Base::eval_local`] with raised specular lobes: `wi` in the shading frame (z > 0), `wi_s`
    /// and `wo_s` in theirs. The integrator weighs f by the shading normal's cosine, so the
    /// specular value carries the ratio of their cosines; where wi is below the shading horizon
    /// both lobes count nothing (Cycles' specular lobe still reflects a little there).
    #[inline(never)]
    fn eval_raised(&self, wi: Vec3, wi_s: Vec3, wo_s: Vec3) -> (Vec3, f32) {
        let diffuse_pdf = (1.0 - self.p_specular) * lambert::pdf(wi);
        if wi_s.z <= 0.0 {
            return (self.diffuse, diffuse_pdf);
        }
        let (spec, spec_pdf) = self.specular(wo_s, wi_s);
        (self.diffuse + spec * (wi_s.z / wi.z), diffuse_pdf + self.p_specular * spec_pdf)
    }

    /// Samples wi from `u` (2-D, stratified) and `u_lobe` (1-D lobe choice).
    #[inline(always)]
    pub fn sample(&self, u: Vec2, u_lobe: f32) -> Option<BsdfSample> {
        let wi = if u_lobe < self.p_specular {
            let wo = self.raised.map_or(self.wo, |(_, w)| w);
            let h = self.ggx.sample_visible_normal(wo, u);
            let wi = 2.0 * wo.dot(h) * h - wo;
            if wi.z <= 0.0 {
                return None;
            }
            match self.raised {
                None => wi,
                Some((f, _)) => self.frame.to_local(f.from_local(wi)),
            }
        } else {
            lambert::sample(u)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let wi_world = self.frame.from_local(wi);
        if wi_world.dot(self.ng) <= 0.0 {
            return None;
        }
        let (f, pdf) = match self.raised {
            None => self.eval_local(wi),
            Some((fr, wo)) => self.eval_raised(wi, fr.to_local(wi_world), wo),
        };
        if pdf <= 0.0 || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample { wi: wi_world.normalize(), f: self.bump_shadowed(wi_world, f), pdf, cos: wi.z })
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::bsdf::Bsdf;
    use crate::material::Material;
    use crate::sampling::sample_uniform_sphere;

    pub(in crate::bsdf) fn material(base: f32, metallic: f32, roughness: f32, specular: f32) -> Material {
        Material { base_color: Vec3::splat(base), metallic, roughness, specular, ..Material::default() }
    }

    pub(in crate::bsdf) fn halton(i: u32, b: u32) -> f32 {
        let (mut f, mut r, mut i) = (1.0f64, 0.0f64, i as u64);
        while i > 0 {
            f /= b as f64;
            r += f * (i % b as u64) as f64;
            i /= b as u64;
        }
        r as f32
    }

    /// ∫ f cos dwi by importance sampling and by uniform sphere sampling.
    pub(in crate::bsdf) fn albedo(bsdf: &Bsdf, n: u32) -> (Vec3, Vec3) {
        let mut by_sampling = Vec3::ZERO;
        let mut uniform = Vec3::ZERO;
        for i in 0..n {
            let u = Vec2::new(halton(i, 2), halton(i, 3));
            if let Some(s) = bsdf.sample(u, halton(i, 5)) {
                assert!(s.f.is_finite() && s.pdf.is_finite() && s.pdf > 0.0);
                by_sampling += s.f * s.cos / s.pdf;
            }
            let wi = sample_uniform_sphere(u);
            let (f, pdf) = bsdf.eval(wi);
            assert!(f.is_finite() && pdf.is_finite());
            uniform += f * wi.dot(bsdf.shading_normal()).abs() * (4.0 * std::f32::consts::PI);
        }
        (by_sampling / n as f32, uniform / n as f32)
    }

    /// White furnace: a white metal reflects all the light at every roughness and angle (the
    /// multiple-scattering compensation at work), never NaN; importance sampling agrees with
    /// uniform sampling.
    #[test]
    fn white_furnace_ggx() {
        let n = Vec3::Z;
        for roughness in [0.05, 0.2, 0.5, 0.8, 1.0] {
            for cos_o in [1.0f32, 0.7, 0.3, 0.05] {
                let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
                let bsdf = Bsdf::new(&material(1.0, 1.0, roughness, 1.0), n, n, wo);
                let (is, _) = albedo(&bsdf, 1 << 16);
                // Energy-compensated: a white metal reflects all light (to the table's
                // interpolation error), never more.
                assert!(
                    (is - Vec3::ONE).abs().max_element() < 0.015,
                    "roughness {roughness} cos {cos_o}: {is}"
                );
                // Uniform sampling only resolves broad lobes (a narrow one covers ~1e-3 of the
                // sphere: a few hundred of the samples, ~6 % noise).
                if roughness >= 0.5 {
                    let (_, uni) = albedo(&bsdf, 1 << 18);
                    assert!(
                        (is - uni).abs().max_element() < 0.03,
                        "roughness {roughness} cos {cos_o}: {is} vs {uni}"
                    );
                }
            }
        }
    }

    /// At α = 1 and normal incidence D = 1/π and G2 = 2μ/(1 + μ), so the single-scattering
    /// albedo of a white metal is ∫₀¹ μ/(1 + μ) dμ · 2π/(2π) = 1 − ln 2 (closed form); the
    /// uncompensated lobe (compensation factor divided out) must give exactly that.
    #[test]
    fn ggx_albedo_closed_form() {
        let bsdf = Bsdf::new(&material(1.0, 1.0, 1.0, 1.0), Vec3::Z, Vec3::Z, Vec3::Z);
        let (is, _) = albedo(&bsdf, 1 << 16);
        let single = is.x / bsdf.base.ms_metal.x;
        let want = 1.0 - std::f32::consts::LN_2;
        assert!((single - want).abs() < 1e-3, "{single} vs {want}");
    }

    /// A Lambertian surface reflects exactly its albedo; the dielectric layer never adds energy.
    #[test]
    fn diffuse_and_dielectric_albedo() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let lambert = Bsdf::new(&material(0.5, 0.0, 1.0, 0.0), Vec3::Z, Vec3::Z, wo);
        let (a, _) = albedo(&lambert, 1 << 12);
        assert!((a - Vec3::splat(0.5)).abs().max_element() < 1e-3, "{a}");
        for roughness in [0.1, 0.5, 1.0] {
            let plastic = Bsdf::new(&material(1.0, 0.0, roughness, 1.0), Vec3::Z, Vec3::Z, wo);
            let (is, uni) = albedo(&plastic, 1 << 17);
            assert!(is.max_element() <= 1.0 + 1e-2, "{is}");
            if roughness >= 0.5 {
                assert!((is - uni).abs().max_element() < 0.03, "{is} vs {uni}");
            }
        }
    }

    /// `KHR_materials_specular` scales F0 by the colour, not F90: a black `specularColorFactor`
    /// over a black base reflects nothing head-on but keeps the grazing rim (F90 = the factor).
    #[test]
    fn black_specular_colour_keeps_the_grazing_rim() {
        let m = Material { specular_color: Vec3::ZERO, ..material(0.0, 0.0, 0.3, 1.0) };
        let at = |cos_o: f32| {
            let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
            albedo(&Bsdf::new(&m, Vec3::Z, Vec3::Z, wo), 1 << 14).0.x
        };
        let (head_on, grazing) = (at(1.0), at(0.05));
        assert!(head_on < 1e-3, "head-on {head_on}");
        assert!(grazing > 0.2 && grazing <= 1.0, "grazing {grazing}");
    }

    /// What is not glass keeps Cycles' proportions: metal m, dielectric over diffuse
    /// (1 − m)(1 − T), once the glass's (1 − m)·T is taken out; a half-metal glass has no
    /// diffuse part at all.
    #[test]
    fn the_opaque_rest_of_a_glass_keeps_cycles_proportions() {
        assert_eq!(BsdfParams::opaque_metallic(0.5, 1.0), 1.0);
        for (m, t) in [(0.3, 0.0), (0.0, 0.4), (0.0, 1.0), (1.0, 0.7)] {
            assert_eq!(BsdfParams::opaque_metallic(m, t), m, "{m} {t}");
        }
        for (m, t) in [(0.2f32, 0.5f32), (0.7, 0.9), (0.5, 0.25)] {
            let (glass, m_rest) = ((1.0 - m) * t, BsdfParams::opaque_metallic(m, t));
            assert!(((1.0 - glass) * m_rest - m).abs() < 1e-6, "{m} {t}");
            assert!(((1.0 - glass) * (1.0 - m_rest) - (1.0 - m) * (1.0 - t)).abs() < 1e-6, "{m} {t}");
        }
    }

    #[test]
    fn no_light_through_the_surface() {
        let bsdf = Bsdf::new(&material(0.8, 0.0, 1.0, 0.0), Vec3::Z, Vec3::Z, Vec3::new(0.0, 0.6, 0.8));
        assert_eq!(bsdf.eval(Vec3::new(0.0, 0.0, -1.0)).0, Vec3::ZERO);
        // Seen from below, the surface reflects downwards (two-sided).
        let below = Bsdf::new(&material(0.8, 0.0, 1.0, 0.0), Vec3::Z, Vec3::Z, Vec3::new(0.0, 0.6, -0.8));
        assert!(below.eval(Vec3::new(0.0, 0.0, -1.0)).0.x > 0.0);
        // A grazing wo below a tilted shading normal gives finite values.
        let tilted = Bsdf::new(
            &material(0.8, 0.5, 0.3, 1.0),
            Vec3::new(0.3, 0.0, 0.95).normalize(),
            Vec3::Z,
            Vec3::new(-0.999, 0.0, 0.04).normalize(),
        );
        for i in 0..256 {
            if let Some(s) = tilted.sample(Vec2::new(halton(i, 2), halton(i, 3)), halton(i, 5)) {
                assert!(s.f.is_finite() && s.pdf.is_finite());
            }
        }
    }
    /// `Bsdf::lambert` is `Bsdf::with_frame` for Lambert parameters, bit for bit: the same
    /// values, densities and samples for directions all round, with shading normals tilted
    /// against the geometric one and seen from either side. Parameters with a metallic or
    /// specular weight are not Lambert.
    #[test]
    fn lambert_is_with_frame_bit_for_bit() {
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        let mut checked = 0;
        for (k, base) in [0.0f32, 0.05, 0.725, 1.0].into_iter().enumerate() {
            let mut m = material(base, 0.0, 0.4 + 0.1 * k as f32, 0.0);
            m.base_color.y *= 0.5;
            let params = BsdfParams::of(&m);
            assert!(params.is_lambert());
            for i in 0..64 {
                let ng = sample_uniform_sphere(Vec2::new(halton(i, 2), halton(i, 3)));
                let ns =
                    (ng + 0.4 * sample_uniform_sphere(Vec2::new(halton(i, 5), halton(i, 7)))).normalize();
                let wo = sample_uniform_sphere(Vec2::new(halton(i, 11), halton(i, 13)));
                let frame = Frame::from_z(ns);
                let general = Bsdf::with_frame(&params, frame, ng, wo);
                let lambert = Bsdf::lambert(params.base_color, frame, ng, wo);
                assert_eq!(general.is_black(), lambert.is_black());
                assert!(lambert.is_diffuse() && !lambert.has_lobe_choice());
                for j in 0..32 {
                    let u = Vec2::new(halton(64 * i + j, 2), halton(64 * i + j, 3));
                    let wi = sample_uniform_sphere(u);
                    let ((fa, pa), (fb, pb)) = (general.eval(wi), lambert.eval(wi));
                    assert!(bits(fa) == bits(fb) && pa.to_bits() == pb.to_bits(), "eval {wi}");
                    match (general.sample(u, 0.5), lambert.sample(u, 0.5)) {
                        (Some(a), Some(b)) => {
                            assert!(bits(a.wi) == bits(b.wi) && bits(a.f) == bits(b.f));
                            assert!(a.pdf.to_bits() == b.pdf.to_bits() && a.cos.to_bits() == b.cos.to_bits());
                            checked += 1;
                        }
                        (None, None) => {}
                        _ => panic!("one samples, the other does not"),
                    }
                }
            }
        }
        assert!(checked > 4000, "{checked} samples compared");
        assert!(!BsdfParams::of(&material(0.5, 0.2, 0.5, 0.0)).is_lambert(), "metallic");
        let mut specular = material(0.5, 0.0, 0.5, 1.0);
        specular.specular_color = Vec3::ONE;
        assert!(!BsdfParams::of(&specular).is_lambert(), "specular");
    }
}
