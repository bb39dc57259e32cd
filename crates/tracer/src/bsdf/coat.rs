//! The coat: a clear dielectric GGX reflection over the rest of the material
//! (`KHR_materials_clearcoat`), as Blender's Principled BSDF renders the coat its glTF importer
//! sets up (Cycles' `svm_node_closure_bsdf`, "Coat"): index 1.5, untinted, the exact dielectric
//! Fresnel, energy-compensated as Cycles' `bsdf_microfacet_setup_fresnel_dielectric` does
//! (`compensation::dielectric` with F0 = F0(1.5), which is then the plain dielectric Fresnel),
//! on a normal of its own (the coat's normal map, else the surface's without the base's map),
//! raised where it would mirror wo below the surface (`raised_normal.rs`).
//!
//! The coat weighs `weight`·f; what lies below it keeps 1 − weight·A(wo), A the compensated
//! lobe's directional albedo ([`Coat::albedo`]): Cycles' `closure_layering_weight`.

use super::fresnel::{LayerFresnel, f0_of_ior};
use super::ggx::Ggx;
use super::{compensation, raised_normal};
use crate::sampling::Frame;
use glam::{Vec2, Vec3};

/// The coat's index of refraction: Blender's importer leaves the Principled default.
pub const COAT_IOR: f32 = 1.5;

/// The coat lobe at one shading point, with wo fixed.
#[derive(Clone, Copy, Debug)]
pub struct Coat {
    /// The coat's frame (its normal as z, on wo's side, raised if needed) and wo in it.
    frame: Frame,
    wo: Vec3,
    /// weight × the multiple-scattering compensation factor.
    scale: f32,
    layer: LayerFresnel,
    ggx: Ggx,
    /// weight × the compensated lobe's albedo for wo.
    albedo: f32,
}

impl Coat {
    /// The coat of weight `weight` (in (0, 1]) and perceptual roughness `roughness` on unit
    /// normal `n` (either side), geometric normal `ng` facing wo, seen from world direction `wo`.
    #[inline]
    pub fn new(weight: f32, roughness: f32, n: Vec3, ng: Vec3, wo: Vec3) -> Self {
        let n = if n.dot(ng) < 0.0 { -n } else { n };
        let n = raised_normal::raised(ng, wo, n).unwrap_or(n);
        let frame = Frame::from_z(n);
        let mut wo_local = frame.to_local(wo);
        wo_local.z = wo_local.z.max(1e-6);
        let layer = LayerFresnel::new(Vec3::splat(f0_of_ior(COAT_IOR)), COAT_IOR);
        let (factor, albedo) = compensation::dielectric(&layer, wo_local.z, roughness);
        Self {
            frame,
            wo: wo_local,
            scale: weight * factor.x,
            layer,
            ggx: Ggx::from_roughness(roughness),
            albedo: (weight * albedo.x).clamp(0.0, 1.0),
        }
    }

    /// weight × the coat's directional albedo for wo: the share of light it takes from the
    /// layers below.
    #[inline]
    pub fn albedo(&self) -> f32 {
        self.albedo
    }

    /// Scales the coat by `k` (in [0, 1]): a layer above takes the rest of the light.
    #[inline]
    pub fn attenuate(&mut self, k: f32) {
        self.scale *= k;
        self.albedo *= k;
    }

    /// f(wo, wi) times cos(coat normal, wi) / `cos_s` (the integrator weighs f by the cosine of
    /// the shading normal, `cos_s` > 0), and the density of sampling `wi` (world, unit) from
    /// this lobe.
    #[inline]
    pub fn eval(&self, wi: Vec3, cos_s: f32) -> (Vec3, f32) {
        let wi = self.frame.to_local(wi);
        if wi.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let wo = self.wo;
        let h = (wo + wi).normalize_or(Vec3::Z);
        let f = self.layer.eval(wo.dot(h).max(0.0)).x;
        let s = self.ggx.d(h) * self.ggx.g2(wo, wi) / (4.0 * wo.z * cos_s);
        (Vec3::splat(self.scale * f * s), self.ggx.pdf_reflection(wo, h))
    }

    /// A direction sampled from the lobe's visible normals (world, unit), or `None` below the
    /// coat.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<Vec3> {
        let h = self.ggx.sample_visible_normal(self.wo, u);
        let wi = 2.0 * self.wo.dot(h) * h - self.wo;
        (wi.z > 0.0).then(|| self.frame.from_local(wi).normalize())
    }
}
