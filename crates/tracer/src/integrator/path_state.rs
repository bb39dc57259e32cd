//! One path between its vertices: the state a path carries from one scattering vertex to the
//! next ([`PathState`]), the vertex it stands on ([`Vertex`]), and the step that takes it one
//! vertex further ([`PathState::advance`]: scatter, then find the next vertex).

use super::glass::RoughGlass;
use super::scene_query::SceneQuery;
use super::{FirstHit, PathSample};
use crate::bsdf::dielectric::Dielectric;
use crate::bsdf::{Bsdf, BsdfParams};
use crate::bvh::{Hit, Leaving};
use crate::interaction::SurfaceInteraction;
use crate::light::ShadowTarget;
use crate::material::Material;
use crate::ray::Ray;
use crate::sampler::{Sampler, sets};
use crate::sampling::{Frame, power_heuristic};
use crate::shading::ShadingPoint;
use glam::{Vec2, Vec3};

/// What next-event estimation asks of the lobe at a vertex: the opaque [`Bsdf`] or rough glass.
trait LightReceiver {
    /// The normal around whose hemisphere light arrives (for the light choice); zero for a lobe
    /// that takes light from every direction (glass).
    fn receiver_normal(&self) -> Vec3;
    /// f(wo, wi) without the cosine, and the density with which the lobe samples `wi`.
    fn eval(&self, wi: Vec3) -> (Vec3, f32);
    /// |cos θi| against the shading normal.
    fn cos(&self, wi: Vec3) -> f32;
    /// The absorbing medium a shadow ray along `wi` crosses, for a path now in `current`.
    fn shadow_medium(&self, wi: Vec3, current: Option<Vec3>) -> Option<Vec3>;
}

impl LightReceiver for Bsdf {
    #[inline(always)]
    fn receiver_normal(&self) -> Vec3 {
        self.geometric_normal()
    }

    #[inline(always)]
    fn eval(&self, wi: Vec3) -> (Vec3, f32) {
        Bsdf::eval(self, wi)
    }

    #[inline(always)]
    fn cos(&self, wi: Vec3) -> f32 {
        wi.dot(self.shading_normal()).abs()
    }

    /// None: an opaque surface inside an absorbing solid is not modelled (the path's medium is
    /// entered and left through glass alone).
    #[inline(always)]
    fn shadow_medium(&self, _: Vec3, _: Option<Vec3>) -> Option<Vec3> {
        None
    }
}

/// Rough glass at vertex `v` (with the vertex for the medium its directions lead into).
struct GlassAt<'v, 't> {
    lobe: RoughGlass,
    v: &'v Vertex<'t>,
}

impl LightReceiver for GlassAt<'_, '_> {
    #[inline(always)]
    fn receiver_normal(&self) -> Vec3 {
        Vec3::ZERO
    }

    #[inline(always)]
    fn eval(&self, wi: Vec3) -> (Vec3, f32) {
        self.lobe.eval(wi)
    }

    #[inline(always)]
    fn cos(&self, wi: Vec3) -> f32 {
        self.lobe.cos(wi)
    }

    #[inline(always)]
    fn shadow_medium(&self, wi: Vec3, current: Option<Vec3>) -> Option<Vec3> {
        medium_along(self.v, wi, current)
    }
}

/// The absorbing medium a ray leaving glass vertex `v` along `wi` travels through, for a path
/// now in `current`: across a solid interface, the closed mesh's volume when it enters (none
/// when it leaves, or when the mesh has no volume); on wo's side, or through a thin wall,
/// `current`.
#[inline(always)]
fn medium_along(v: &Vertex, wi: Vec3, current: Option<Vec3>) -> Option<Vec3> {
    let entering = v.si.n_geom.dot(v.wo) > 0.0;
    if !v.material.thin_walled && (wi.dot(v.si.n_geom) > 0.0) != entering {
        (entering && v.material.has_volume()).then_some(v.material.attenuation)
    } else {
        current
    }
}

/// A shaded path vertex: the hit, its surface, and its material evaluated there.
#[derive(Clone, Copy)]
pub(super) struct Vertex<'t> {
    hit: Hit,
    si: SurfaceInteraction,
    material: &'t Material,
    sp: ShadingPoint,
    /// The direction back along the ray that found the vertex.
    wo: Vec3,
}

impl Vertex<'_> {
    /// What the camera sees at this vertex (for the AOVs).
    #[inline(always)]
    pub(super) fn first_hit(&self) -> FirstHit {
        let n = if self.sp.normal.dot(self.wo) < 0.0 { -self.sp.normal } else { self.sp.normal };
        FirstHit { albedo: self.sp.base_color, normal: n, depth: self.hit.t }
    }

    /// What the camera sees of an unlit surface (its base colour, as emitted radiance), or
    /// `None` for a lit one.
    #[inline(always)]
    pub(super) fn unlit(&self) -> Option<Vec3> {
        self.material.unlit.then_some(self.sp.base_color)
    }

    /// The opaque BSDF here (the Lambert lobe alone with `LAMBERT`).
    #[inline(always)]
    fn bsdf<const LAMBERT: bool>(&self) -> Bsdf {
        let (sp, si) = (&self.sp, &self.si);
        if LAMBERT {
            return Bsdf::lambert(sp.base_color, si.shading, si.n_geom, self.wo);
        }
        let params = BsdfParams {
            base_color: sp.base_color,
            // What is not glass: the metal and the dielectric over diffuse in Cycles' proportions.
            metallic: BsdfParams::opaque_metallic(sp.metallic, sp.transmission),
            roughness: sp.roughness,
            specular: sp.specular,
            specular_color: sp.specular_color,
            ior: self.material.ior,
            anisotropy: sp.anisotropy,
            anisotropy_mapping: self.material.anisotropy.map_or_else(Default::default, |a| a.mapping),
        };
        // The hit's shading frame, unless a normal map moved the normal (then shadowed as Blender
        // does, docs/design/tracer.md §3.10).
        let bsdf = if sp.anisotropy > 0.0 {
            // The frame's x along the anisotropy direction, which the GGX lobe stretches.
            let frame = Frame {
                x: sp.anisotropy_direction,
                y: sp.normal.cross(sp.anisotropy_direction),
                z: sp.normal,
            };
            let bsdf = Bsdf::with_frame(&params, frame, si.n_geom, self.wo);
            if self.material.textures.normal.is_some() { bsdf.with_bump(si.shading.z) } else { bsdf }
        } else if self.material.textures.normal.is_some() {
            Bsdf::with_frame(&params, Frame::from_z(sp.normal), si.n_geom, self.wo).with_bump(si.shading.z)
        } else {
            Bsdf::with_frame(&params, si.shading, si.n_geom, self.wo)
        };
        // The layers over the base, top last (bsdf/mod.rs: the stack's order).
        let bsdf = if sp.coat > 0.0 {
            bsdf.with_coat(sp.coat, sp.coat_roughness, sp.coat_normal, self.wo)
        } else {
            bsdf
        };
        if sp.sheen != Vec3::ZERO {
            bsdf.with_sheen(
                self.material.sheen_model,
                sp.sheen,
                sp.sheen_roughness,
                self.sheen_normal(),
                self.wo,
            )
        } else {
            bsdf
        }
    }

    /// The normal Cycles lays the sheen on: the one the coat and the surface share (with a
    /// coat of weight w, their mix by w).
    #[inline]
    fn sheen_normal(&self) -> Vec3 {
        let sp = &self.sp;
        if sp.coat > 0.0 {
            sp.normal.lerp(sp.coat_normal, sp.coat).normalize_or(sp.normal)
        } else {
            sp.normal
        }
    }

    /// At a glass vertex of a material with a sheen: the sheen alone when `u` says so (taken
    /// with probability its albedo, `Bsdf::sheen_over_glass`), else `None` (the glass).
    #[inline(never)]
    fn sheen_over_glass(&self, u: f32) -> Option<Bsdf> {
        let sp = &self.sp;
        let shading = (Frame::from_z(sp.normal), self.si.n_geom);
        let model = self.material.sheen_model;
        Bsdf::sheen_over_glass(model, sp.sheen, sp.sheen_roughness, self.sheen_normal(), shading, self.wo, u)
    }
}

/// One path between vertices: where it goes next and what it carries.
#[derive(Clone, Copy)]
pub(super) struct PathState {
    /// The ray to the next vertex (the camera ray before the first).
    ray: Ray,
    /// Throughput: the product of f·cos/pdf (and roulette's and splitting's weights) so far.
    beta: Vec3,
    /// The BSDF density of `ray`'s direction, to weigh the emission it finds by MIS.
    prev_pdf: f32,
    /// Where `ray` left and the geometric normal there facing it: the receiver for which light
    /// sampling would have chosen the emitter `ray` finds (its MIS weight).
    prev_p: Vec3,
    prev_n: Vec3,
    /// `ray` left a delta event (glass): the emission it finds takes no MIS weight.
    specular: bool,
    /// Scattering vertices behind the path (0: `ray` is the camera ray).
    depth: u32,
    /// The largest component of the throughput the first vertex passed on (the branch's,
    /// weight 1/N included): Russian roulette's yardstick.
    first_beta: f32,
    /// The triangles `ray` cannot hit: the one it leaves and its leaf-mates behind it.
    leaving: Leaving,
    /// The light-sample numbers of the next vertex.
    u_light: Vec2,
    /// The path's numbers (branch b of camera sample i: sample i·N + b).
    sampler: Sampler,
    /// The absorption σa of the medium `ray` travels through (entered by refracting into a
    /// closed transmissive mesh with `KHR_materials_volume`), `None` outside any: Beer–Lambert
    /// attenuation exp(−σa·t) along the segment. Scenes without a volume never set it.
    medium: Option<Vec3>,
}

/// The one-dimensional decisions at a vertex, drawn from its set only when one is needed.
struct Decisions<'s> {
    sampler: &'s Sampler,
    vertex: u32,
    drawn: Option<[f32; 4]>,
}

impl Decisions<'_> {
    /// The opaque BSDF's lobe choice.
    const LOBE: usize = 0;
    /// Russian roulette.
    const ROULETTE: usize = 1;
    /// Glass or the opaque BSDF, for a partly transmissive material.
    const GLASS: usize = 2;
    /// Reflection or refraction at glass.
    const FRESNEL: usize = 3;

    #[inline(always)]
    fn get(&mut self, k: usize) -> f32 {
        self.drawn.get_or_insert_with(|| self.sampler.get(sets::decisions(self.vertex)))[k]
    }
}

impl PathState {
    /// A path about to trace the camera ray `ray`, with numbers `sampler` and the first vertex's
    /// light sample `u_light`.
    #[inline(always)]
    pub(super) fn camera(ray: Ray, sampler: Sampler, u_light: Vec2) -> Self {
        Self {
            ray,
            beta: Vec3::ONE,
            prev_pdf: 0.0,
            prev_p: Vec3::ZERO,
            prev_n: Vec3::ZERO,
            specular: false,
            depth: 0,
            first_beta: 1.0,
            leaving: Leaving::NOTHING,
            u_light,
            sampler,
            medium: None,
        }
    }

    /// The same path drawing its numbers from `sampler` (a split branch at the camera ray).
    #[inline(always)]
    pub(super) fn with_sampler(self, sampler: Sampler) -> Self {
        Self { sampler, ..self }
    }

    /// Takes the path one vertex further: scatters at `vertex` (with its light sample when
    /// `sample_light`) and finds the next vertex. `None` when the path ends: no direction to
    /// go on, roulette, an escaped ray, or the maximum depth (whose emission still counts).
    #[inline(always)]
    pub(super) fn advance<'t, const ALPHA: bool, const LAMBERT: bool>(
        &mut self,
        scene: &'t SceneQuery,
        vertex: &Vertex,
        sample_light: bool,
        out: &mut PathSample,
    ) -> Option<Vertex<'t>> {
        if !self.scatter::<ALPHA, LAMBERT>(scene, vertex, sample_light, out) {
            return None;
        }
        let next = self.find::<ALPHA, LAMBERT>(scene, out)?;
        (self.depth < scene.max_depth()).then_some(next)
    }

    /// Traces `ray` to the next vertex and adds the light it finds: the environment when the
    /// ray escapes (then `None`), else the emission of the surface it hits. Both are weighted by
    /// MIS against light sampling, except on the camera ray, after a delta event, and for a
    /// constant environment (which light sampling never picks).
    #[inline(always)]
    pub(super) fn find<'t, const ALPHA: bool, const LAMBERT: bool>(
        &mut self,
        scene: &'t SceneQuery,
        out: &mut PathSample,
    ) -> Option<Vertex<'t>> {
        let ray = &self.ray;
        out.rays += 1;
        let found = scene.closest_hit::<ALPHA>(ray, self.leaving, self.depth == 0);
        if let (false, Some(sigma)) = (LAMBERT, self.medium) {
            // Beer–Lambert along the segment; a ray that escapes from inside a medium (a mesh
            // that is not closed) keeps only the channels the medium does not absorb.
            let t = found.as_ref().map_or(f32::INFINITY, |h| h.t);
            self.beta *= Vec3::select(sigma.cmpgt(Vec3::ZERO), (-sigma * t).exp(), Vec3::ONE);
        }
        let ray = &self.ray;
        let Some(hit) = found else {
            let le = scene.environment(ray.direction);
            if le != Vec3::ZERO {
                let w = if self.depth == 0 || self.specular || !scene.samples_environment() {
                    1.0
                } else {
                    power_heuristic(self.prev_pdf, scene.pdf_environment(ray.direction))
                };
                out.radiance += self.beta * le * w;
            }
            return None;
        };
        let si = scene.surface::<LAMBERT>(&hit);
        let material = scene.material(si.material);
        let sp = scene.shade::<LAMBERT>(material, &si, hit.barycentrics);
        let wo = -ray.direction;
        if sp.emission != Vec3::ZERO && (material.emission_two_sided || si.n_geom.dot(wo) > 0.0) {
            if self.depth == 0 || self.specular {
                out.radiance += self.beta * sp.emission;
            } else {
                let light_pdf = scene.pdf_triangle(
                    self.prev_p,
                    self.prev_n,
                    hit.triangle,
                    hit.t,
                    ray.direction,
                    ray.time,
                );
                out.radiance += self.beta * sp.emission * power_heuristic(self.prev_pdf, light_pdf);
            }
        }
        Some(Vertex { hit, si, material, sp, wo })
    }

    /// Scatters at vertex `v`: picks its lobe (glass or the opaque BSDF), samples the direction
    /// that continues the path into `ray`, adds next-event estimation (opaque lobe and rough
    /// glass, when `sample_light`), then plays Russian roulette. False when the path ends here.
    #[inline(always)]
    fn scatter<const ALPHA: bool, const LAMBERT: bool>(
        &mut self,
        scene: &SceneQuery,
        v: &Vertex,
        sample_light: bool,
        out: &mut PathSample,
    ) -> bool {
        let depth = self.depth;
        let time = self.ray.time;
        let mut decisions = Decisions { sampler: &self.sampler, vertex: depth, drawn: None };
        let glass_weight = v.sp.transmission * (1.0 - v.sp.metallic);
        let glass = !LAMBERT
            && glass_weight > 0.0
            && (glass_weight >= 1.0 || decisions.get(Decisions::GLASS) < glass_weight);
        // The sheen over the glass (Cycles lays it over the transmission too): taken alone, as
        // an opaque BSDF, with probability its albedo (the lobe choice's number, which the glass
        // does not use otherwise).
        let sheen_alone = if glass && v.sp.sheen != Vec3::ZERO {
            v.sheen_over_glass(decisions.get(Decisions::LOBE))
        } else {
            None
        };
        if glass && sheen_alone.is_none() {
            let [u0, u1, l0, l1] = self.sampler.get(sets::vertex(depth));
            let u_fresnel = decisions.get(Decisions::FRESNEL);
            // Index 1 bends nothing, rough or not: the smooth interface is exact there (and
            // Walter's half vector of an unbent refraction is undefined).
            let smooth = v.sp.roughness == 0.0 || v.material.ior == 1.0;
            let wi = if smooth && !v.material.thin_walled {
                let lobe = Dielectric::new(v.sp.normal, v.si.n_geom, v.wo, v.material.ior, v.sp.base_color);
                let Some(s) = lobe.sample(u_fresnel) else { return false };
                self.beta *= s.weight;
                // A delta event: what its ray finds counts in full.
                self.specular = true;
                s.wi
            } else {
                let lobe = RoughGlass::new(&v.sp, v.material, v.si.n_geom, v.wo);
                let s = lobe.sample(Vec2::new(u0, u1), u_fresnel);
                // Rough glass takes light samples, both halves (reflection and transmission),
                // weighed by MIS against its BSDF samples, unless it is so smooth that Cycles
                // takes it for a delta lobe; a light seen only through frosted glass is then
                // found by light samples, not by the rare BSDF ray that hits it (fireflies).
                let nee = lobe.takes_light_samples() && scene.glass_light_sampling();
                if nee && sample_light {
                    self.sample_light::<ALPHA, false>(scene, v, &GlassAt { lobe, v }, false, out);
                }
                let Some(s) = s else { return false };
                self.beta *= s.weight;
                self.specular = !nee;
                self.prev_pdf = s.pdf;
                self.prev_p = v.si.p;
                // The light choice at glass took light from every side (`receiver_normal`).
                self.prev_n = Vec3::ZERO;
                s.wi
            };
            self.u_light = Vec2::new(l0, l1);
            self.ray = v.si.spawn_ray(wi, time);
            // Refracted: into the medium the mesh encloses, or out of it into clear space.
            self.medium = medium_along(v, wi, self.medium);
        } else {
            let bsdf = match sheen_alone {
                Some(sheen) => sheen,
                None => v.bsdf::<LAMBERT>(),
            };
            if bsdf.is_black() {
                return false;
            }
            // At the last vertex the BSDF ray could only find emission, which light sampling
            // already covers: estimate it by light sampling alone (weight 1) and skip that ray
            // and its hit. Unbiased either way; done only on diffuse BSDFs (where a light sample
            // is never the worse strategy by much) past the first vertex (direct light seen by
            // the camera keeps MIS). It saves one closest-hit query in every path that reaches
            // the last vertex (docs/performance.md, ledger: "last vertex by light sampling
            // alone").
            let light_only = depth + 1 == scene.max_depth()
                && depth > 0
                && scene.lights_cover_emission()
                && bsdf.is_diffuse();

            // The BSDF sample that continues the path, its ray and the next vertex's light
            // numbers come before next-event estimation: they do not depend on it, and ahead of
            // its shadow query they are computed while the query runs (docs/performance.md,
            // ledger: "continuing sample before the shadow query"). An `if`, not `bool::then`
            // with a closure, which LLVM once left out of line (ledger: "Lambert-only path").
            let next = if light_only {
                None
            } else {
                let [u0, u1, l0, l1] = self.sampler.get(sets::vertex(depth));
                let u_lobe = if bsdf.has_lobe_choice() { decisions.get(Decisions::LOBE) } else { 0.5 };
                let bs = bsdf.sample(Vec2::new(u0, u1), u_lobe);
                Some((bs.map(|bs| (bs, v.si.spawn_ray(bs.wi, time))), Vec2::new(l0, l1)))
            };
            if sample_light {
                self.sample_light::<ALPHA, LAMBERT>(scene, v, &bsdf, light_only, out);
            }
            // Go on along the BSDF sample drawn above. (`next` nests its two Options on purpose:
            // docs/performance.md, ledger: "continuation sample's Options flattened".)
            let Some((Some((bs, next_ray)), u_next)) = next else { return false };
            self.u_light = u_next;
            self.beta *= bs.f * (bs.cos / bs.pdf);
            self.prev_pdf = bs.pdf;
            self.prev_p = v.si.p;
            self.prev_n = bsdf.geometric_normal();
            self.specular = false;
            self.ray = next_ray;
        }
        self.leaving = scene.leaving(v.hit.slot, self.ray.direction);
        if depth == 0 {
            self.beta *= scene.branch_weight();
            self.first_beta = self.beta.max_element().max(f32::MIN_POSITIVE);
        }
        self.depth += 1;
        if depth + 1 >= scene.rr_depth() {
            // Survival √(β / β₁), β₁ the throughput the first vertex passed on: a pixel's value
            // scales with β₁, so paths are judged by what they still carry of their own pixel's
            // light, not by what a bright pixel carries (a dark first surface does not doom its
            // paths); the root spares paths more than β / β₁ would (docs/design/tracer.md §3.3). A
            // split branch's 1/N is in both and cancels.
            let q = (1.0 - (self.beta.max_element() / self.first_beta).sqrt()).max(0.0);
            if decisions.get(Decisions::ROULETTE) < q {
                return false;
            }
            self.beta /= 1.0 - q;
        }
        true
    }

    /// Next-event estimation at `v`: one light sample (chosen for the point and the side its
    /// BSDF can receive light on), its shadow ray, and its
    /// contribution through `bsdf`, weighted by MIS against the BSDF sample unless the light is
    /// a delta light or `light_only` (the BSDF sample was skipped).
    #[inline(always)]
    fn sample_light<const ALPHA: bool, const LAMBERT: bool>(
        &self,
        scene: &SceneQuery,
        v: &Vertex,
        bsdf: &impl LightReceiver,
        light_only: bool,
        out: &mut PathSample,
    ) {
        let si = &v.si;
        let Some(ls) =
            scene.light_sample::<LAMBERT>(si.p, bsdf.receiver_normal(), self.u_light, self.ray.time)
        else {
            return;
        };
        let (f, bsdf_pdf) = bsdf.eval(ls.wi);
        let mut li = ls.li;
        if let (false, Some((tri, b))) = (LAMBERT, ls.emitter)
            && let Some(emissive) = scene.emissive_texture(tri, b)
        {
            li *= emissive;
        }
        if f == Vec3::ZERO || li == Vec3::ZERO {
            return;
        }
        let shadow = match ls.target {
            ShadowTarget::Point { p, p_error, n } => si.spawn_ray_to(p, p_error, n, self.ray.time),
            ShadowTarget::Infinite => Some((si.spawn_ray(ls.wi, self.ray.time), f32::INFINITY)),
        };
        let Some((shadow, t_max)) = shadow else { return };
        out.rays += 1;
        if scene.occluded::<ALPHA>(&shadow, t_max, scene.leaving(v.hit.slot, shadow.direction)) {
            return;
        }
        if let Some(sigma) = bsdf.shadow_medium(ls.wi, self.medium) {
            // Beer–Lambert along the shadow ray, as `find` keeps it along a path's segment.
            li *= Vec3::select(sigma.cmpgt(Vec3::ZERO), (-sigma * t_max).exp(), Vec3::ONE);
        }
        let cos = bsdf.cos(ls.wi);
        let w = if ls.is_delta || light_only { 1.0 } else { power_heuristic(ls.pdf, bsdf_pdf) };
        out.radiance += self.beta * f * li * (cos * w / ls.pdf);
    }
}
