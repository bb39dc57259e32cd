//! Rough glass at a path vertex (docs/design/tracer.md §3.3): the GGX dielectric lobe
//! (`bsdf/rough_dielectric.rs`) set in the hit's world frame, sampled to continue the path and
//! evaluated towards light samples, both halves (reflection and transmission) alike.
//!
//! The lobe lives in the frame of the shading normal turned to wo's side of the geometry; a
//! direction counts only on the side of the geometry its half says (a reflection stays on wo's
//! side, a transmission crosses), in sampling and in evaluation, so light never leaks through
//! the surface where the shading normal disagrees with the geometric one.

use crate::bsdf::rough_dielectric::RoughDielectric;
use crate::material::{AnisotropyMapping, Material};
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
        let thin = material.thin_walled;
        // The specification's reading stretches the glass's roughness as it does the opaque
        // lobes' (α_t along the anisotropy direction, the frame's x: the specular BTDF shares
        // the BRDF's distribution). Blender's keeps it isotropic at α = roughness², as Cycles'
        // Principled BSDF builds its glass closure (no tangent, `alpha_x = alpha_y`).
        let mapping = material.anisotropy.map(|a| a.mapping);
        if sp.anisotropy > 0.0 && mapping == Some(AnisotropyMapping::Spec) {
            let (ax, ay) = AnisotropyMapping::Spec.alphas(sp.roughness, sp.anisotropy);
            let t = sp.anisotropy_direction;
            let frame = Frame { x: t, y: n.cross(t), z: n };
            let wo_local = local_wo(&frame, wo);
            let lobe = RoughDielectric::anisotropic(ax, ay, eta, wo_local, sp.base_color, thin);
            let evaluable = ax * ay > SINGULAR_ALPHA_PRODUCT;
            return Self { frame, wo: wo_local, lobe, n_geom, entering, evaluable };
        }
        let frame = Frame::from_z(n);
        let wo_local = local_wo(&frame, wo);
        let lobe = RoughDielectric::new(sp.roughness, eta, wo_local, sp.base_color, thin);
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

/// World direction `wo` in `frame`, kept just above its horizon (the shading normal may put it
/// below where the geometric one does not).
#[inline(always)]
fn local_wo(frame: &Frame, wo: Vec3) -> Vec3 {
    let mut w = frame.to_local(wo);
    w.z = w.z.max(1e-6);
    w.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Anisotropy;
    use crate::sampling::sample_uniform_sphere;
    use crate::test_support::Rng;

    /// Three uniform numbers from the tests' one generator (`test_support::rng`).
    fn numbers(rng: &mut Rng) -> (Vec2, f32) {
        (Vec2::new(rng.unit(), rng.unit()), rng.unit())
    }

    /// Frosted glass (roughness 0.4, index 1.5) with anisotropy `strength` along world
    /// direction `t`, at a hit whose shading and geometric normal is `n`.
    fn glass(strength: f32, mapping: AnisotropyMapping, n: Vec3, t: Vec3) -> (ShadingPoint, Material) {
        let material = Material {
            transmission: 1.0,
            roughness: 0.4,
            ior: 1.5,
            anisotropy: Some(Anisotropy { strength, rotation: 0.0, mapping }),
            ..Material::diffuse("glass", Vec3::ONE)
        };
        let sp =
            ShadingPoint { anisotropy: strength, anisotropy_direction: t, ..ShadingPoint::of(&material, n) };
        (sp, material)
    }

    /// In the world, a sampled direction's density and weight are what evaluation gives it
    /// (both halves, from outside and inside, anisotropic in both readings or not): light
    /// samples and BSDF samples weigh the same lobe.
    #[test]
    fn sampling_matches_evaluation_in_the_world() {
        let n = Vec3::new(0.3, -0.2, 0.9).normalize();
        let t = n.cross(Vec3::X).normalize();
        for (strength, mapping) in [
            (0.0, AnisotropyMapping::Blender),
            (0.8, AnisotropyMapping::Blender),
            (0.6, AnisotropyMapping::Spec),
        ] {
            let (sp, material) = glass(strength, mapping, n, t);
            for wo in [Vec3::new(0.2, 0.5, 0.8).normalize(), Vec3::new(-0.4, 0.1, -0.9).normalize()] {
                let lobe = RoughGlass::new(&sp, &material, n, wo);
                assert!(lobe.takes_light_samples());
                let (mut found, mut rng) = (0, Rng::new(1));
                for _ in 0..2048 {
                    let (u, u_fresnel) = numbers(&mut rng);
                    let Some(s) = lobe.sample(u, u_fresnel) else {
                        continue;
                    };
                    found += 1;
                    let (f, pdf) = lobe.eval(s.wi);
                    assert!((pdf - s.pdf).abs() <= 1e-4 * pdf, "{pdf} vs {}", s.pdf);
                    let w = f * lobe.cos(s.wi) / pdf;
                    assert!(
                        (w - s.weight).abs().max_element() <= 2e-3 * s.weight.max_element(),
                        "{w} vs {s:?}"
                    );
                }
                assert!(found > 1500, "{found} of 2048 samples kept");
            }
        }
    }

    /// The specification's anisotropy stretches the lobe along its direction: transmitted
    /// directions spread wider along `t` than across it (and as wide both ways without
    /// anisotropy). Without anisotropy, and in Blender's reading whatever the strength (Cycles'
    /// Principled glass is isotropic), the lobe is the isotropic one in the normal's own frame,
    /// bit for bit.
    #[test]
    fn anisotropy_stretches_along_its_direction() {
        let (n, t) = (Vec3::Z, Vec3::new(1.0, 1.0, 0.0).normalize());
        let b = n.cross(t);
        // Seen head-on, so that the refracted lobe is centred on −n.
        let spread = |strength: f32| {
            let wo = n;
            let (sp, material) = glass(strength, AnisotropyMapping::Spec, n, t);
            let lobe = RoughGlass::new(&sp, &material, n, wo);
            let (mut along, mut across, mut rng) = (0.0f64, 0.0f64, Rng::new(2));
            for _ in 0..4096 {
                // u_fresnel near 1: refraction.
                if let Some(s) = lobe.sample(numbers(&mut rng).0, 0.999) {
                    along += (s.wi.dot(t) as f64).powi(2);
                    across += (s.wi.dot(b) as f64).powi(2);
                }
            }
            along / across
        };
        let (isotropic, stretched) = (spread(0.0), spread(0.9));
        assert!((isotropic - 1.0).abs() < 0.2, "isotropic {isotropic}");
        assert!(stretched > 3.0, "stretched {stretched}");

        let wo = Vec3::new(0.1, -0.2, 1.0).normalize();
        let frame = Frame::from_z(n);
        let wo_local = frame.to_local(wo).normalize();
        let plain = RoughDielectric::new(0.4, 1.5, wo_local, Vec3::ONE, false);
        for (strength, mapping) in [(0.0, AnisotropyMapping::Spec), (0.9, AnisotropyMapping::Blender)] {
            let (sp, material) = glass(strength, mapping, n, t);
            let (lobe, mut rng) = (RoughGlass::new(&sp, &material, n, wo), Rng::new(3));
            for _ in 0..256 {
                let (u, u_fresnel) = numbers(&mut rng);
                let a = lobe.sample(u, u_fresnel).map(|s| (s.wi, s.weight, s.pdf));
                let b =
                    plain.sample(wo_local, u, u_fresnel).map(|s| (frame.from_local(s.wi), s.weight, s.pdf));
                assert_eq!(a, b, "{mapping:?} {strength}");
                let wi = sample_uniform_sphere(u);
                assert_eq!(lobe.eval(wi), plain.eval(wo_local, frame.to_local(wi)));
            }
        }
    }
}
