//! Rough glass at a path vertex (docs/design/tracer.md §3.3): the GGX dielectric lobe
//! (`bsdf/rough_dielectric.rs`) set in the hit's world frame, sampled to continue the path and
//! evaluated towards light samples, both halves (reflection and transmission) alike.
//!
//! The lobe lives in the frame of the shading normal turned to wo's side of the geometry; a
//! direction counts only on the side of the geometry its half says (a reflection stays on wo's
//! side, a transmission crosses), in sampling and in evaluation, so light never leaks through
//! the surface where the shading normal disagrees with the geometric one.

use crate::bsdf::rough_dielectric::RoughDielectric;
use crate::material::Material;
use crate::sampling::Frame;
use crate::shading::ShadingPoint;
use glam::{Vec2, Vec3};

/// α_x·α_y at or below which Cycles takes a microfacet lobe for a delta one: it neither
/// evaluates it towards light samples nor weighs what its rays find by MIS
/// (`BSDF_ROUGHNESS_SQ_THRESH` in Blender 4.0–5.1's `kernel/svm/types.h`, used by
/// `bsdf_microfacet_eval_flag`: roughness ≤ 0.0038).
const SINGULAR_ALPHA_PRODUCT: f32 = 2e-10;

/// The rough glass lobe at one vertex, wo fixed.
#[derive(Clone, Copy, Debug)]
pub(super) struct RoughGlass {
    /// The shading frame turned to wo's side of the interface (z: the shading normal).
    frame: Frame,
    /// wo in `frame` (z > 0).
    wo: Vec3,
    lobe: RoughDielectric,
    /// The geometric normal (the front face's).
    n_geom: Vec3,
    /// wo is on the geometric normal's side: the ray enters the medium.
    entering: bool,
    /// Rough enough that Cycles evaluates it (not a delta lobe): it takes light samples.
    evaluable: bool,
}

/// A direction sampled from [`RoughGlass`].
#[derive(Clone, Copy, Debug)]
pub(super) struct GlassSample {
    /// World direction, unit length.
    pub(super) wi: Vec3,
    /// f·|cos θi| / pdf.
    pub(super) weight: Vec3,
    /// Solid-angle density of `wi`.
    pub(super) pdf: f32,
}

impl RoughGlass {
    /// The lobe at a hit shaded `sp` with `material`, geometric normal `n_geom` (the front
    /// face's), seen from world direction `wo`.
    #[inline(always)]
    pub(super) fn new(sp: &ShadingPoint, material: &Material, n_geom: Vec3, wo: Vec3) -> Self {
        let entering = n_geom.dot(wo) > 0.0;
        // The shading normal on wo's side of the geometry, and η the far side's over wo's.
        let n = if sp.normal.dot(n_geom) < 0.0 { -sp.normal } else { sp.normal };
        let (n, eta) = if entering { (n, material.ior) } else { (-n, 1.0 / material.ior) };
        let frame = Frame::from_z(n);
        let mut wo_local = frame.to_local(wo);
        wo_local.z = wo_local.z.max(1e-6);
        let wo_local = wo_local.normalize();
        let lobe = RoughDielectric::new(sp.roughness, eta, wo_local, sp.base_color, material.thin_walled);
        let alpha = sp.roughness * sp.roughness;
        let evaluable = alpha * alpha > SINGULAR_ALPHA_PRODUCT;
        Self { frame, wo: wo_local, lobe, n_geom, entering, evaluable }
    }

    /// Whether the lobe takes light samples (weighted by MIS against its own): where Cycles
    /// evaluates it, i.e. unless it is so smooth that Cycles takes it for a delta lobe.
    #[inline(always)]
    pub(super) fn takes_light_samples(&self) -> bool {
        self.evaluable
    }

    /// Samples the lobe with numbers `u` (the microfacet) and `u_fresnel` (reflection or
    /// transmission); `None` where the direction would leave on the wrong side of the geometry
    /// (the path ends, as in Cycles).
    #[inline(always)]
    pub(super) fn sample(&self, u: Vec2, u_fresnel: f32) -> Option<GlassSample> {
        let s = self.lobe.sample(self.wo, u, u_fresnel)?;
        let wi = self.frame.from_local(s.wi);
        self.on_its_side(wi, s.wi.z).then_some(GlassSample { wi, weight: s.weight, pdf: s.pdf })
    }

    /// f(wo, wi) (without the cosine) and the density [`RoughGlass::sample`] gives world
    /// direction `wi`; zero where `wi` is on the wrong side of the geometry for its half.
    #[inline(always)]
    pub(super) fn eval(&self, wi: Vec3) -> (Vec3, f32) {
        let local = self.frame.to_local(wi);
        if !self.on_its_side(wi, local.z) {
            return (Vec3::ZERO, 0.0);
        }
        self.lobe.eval(self.wo, local)
    }

    /// |cos θi| of world direction `wi` against the shading normal.
    #[inline(always)]
    pub(super) fn cos(&self, wi: Vec3) -> f32 {
        wi.dot(self.frame.z).abs()
    }

    /// True when world direction `wi` (whose local z is `z`) crosses the geometry exactly when
    /// it is a transmission: a reflection stays on wo's side.
    #[inline(always)]
    fn on_its_side(&self, wi: Vec3, z: f32) -> bool {
        (wi.dot(self.n_geom) > 0.0) == (self.entering == (z > 0.0))
    }
}
