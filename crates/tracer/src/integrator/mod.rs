//! Unidirectional path tracing (docs/design.md §3.3; pbrt-v4 §13.4 `PathIntegrator`): at each
//! scattering vertex, next-event estimation towards one light chosen by power, plus a BSDF
//! sample that continues the path; both estimators of direct light (emissive triangles, the
//! environment image) are combined by multiple importance sampling with the power heuristic.
//! Delta events (glass, punctual lights) take no MIS. Transmissive materials are a mixture:
//! with probability transmission × (1 − metallic) the hit is a smooth dielectric interface,
//! otherwise the opaque metallic-roughness BSDF. Russian roulette from a chosen depth; a
//! maximum depth counted in scattering vertices (the Cornell reference's 4 = Mitsuba's
//! `max_depth` 5: the light may be reached by the ray leaving the 4th vertex).
//!
//! Random numbers come in 4-D sets assigned by position in the path (`crate::sampler::sets`):
//! a path that stops early never shifts another decision's numbers, and each vertex's BSDF
//! direction shares a set with the next vertex's light sample, so one-bounce light is
//! stratified in 4-D. One-dimensional decisions (lobe choice, roulette) are drawn only where a
//! material has two lobes or roulette is active.

mod surface;

use crate::bsdf::dielectric::Dielectric;
use crate::bsdf::{Bsdf, BsdfParams};
use crate::bvh::{Bvh, Hit, Leaving};
use crate::error::{Result, TracerError};
use crate::interaction::SurfaceInteraction;
use crate::light::{LightSampler, ShadowTarget};
use crate::material::Material;
use crate::ray::Ray;
use crate::sampler::{MAX_SAMPLES_PER_PIXEL, Sampler, sets};
use crate::sampling::{Frame, power_heuristic};
use crate::scene::Scene;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use surface::Attributes;

/// Path-tracing parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorConfig {
    /// Maximum number of scattering vertices on a path.
    pub max_depth: u32,
    /// Russian roulette starts after this many scattering vertices (`u32::MAX`: never).
    pub rr_depth: u32,
    /// Paths continued from each camera ray's first hit (first-vertex splitting; 1: none). The
    /// first hit's emission and light sample are taken once; `split` BSDF samples each carry on
    /// a path of their own with weight 1/`split` (Russian roulette judges each at full weight).
    /// Where indirect light makes the noise (nearly all of the Cornell box's), it then gets
    /// `split` paths per camera ray, traced and shaded once; where the camera's own
    /// dimensions do (textures, depth of field), splitting only adds cost.
    /// `spp × split` must stay within [`MAX_SAMPLES_PER_PIXEL`] (`render` checks it).
    pub split: u32,
}

impl IntegratorConfig {
    /// A general-purpose default: 8 scattering vertices, roulette after 5. (Throughput-based
    /// roulette only pays on long paths: from depth 3 it cost the Cornell box more noise than
    /// it saved time; docs/performance.md, ledger.)
    pub const DEFAULT: Self = Self { max_depth: 8, rr_depth: 5, split: 1 };

    /// The same configuration with another maximum depth.
    pub const fn with_max_depth(self, max_depth: u32) -> Self {
        Self { max_depth, ..self }
    }

    /// The same configuration with roulette from another depth.
    pub const fn with_rr_depth(self, rr_depth: u32) -> Self {
        Self { rr_depth, ..self }
    }

    /// The same configuration with `split` paths continued from each first hit.
    pub const fn with_split(self, split: u32) -> Self {
        Self { split, ..self }
    }
}

impl Default for IntegratorConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the first hit of a camera path saw (for albedo / normal / depth AOVs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FirstHit {
    /// Base colour at the first hit (zero on a miss).
    pub albedo: Vec3,
    /// Shading normal at the first hit, facing the camera (zero on a miss).
    pub normal: Vec3,
    /// Distance to the first hit (infinite on a miss).
    pub depth: f32,
}

/// The radiance estimate of one camera ray.
#[derive(Clone, Copy, Debug)]
pub struct PathSample {
    /// Radiance along the ray.
    pub radiance: Vec3,
    /// Rays traced (closest-hit and shadow).
    pub rays: u32,
}

/// A scene prepared for path tracing: BVH, lights, materials and shading attributes.
pub struct PathTracer {
    bvh: Bvh,
    lights: LightSampler,
    materials: Vec<Material>,
    material_ids: Vec<u32>,
    textures: Vec<Texture>,
    attributes: Attributes,
    /// Per triangle (mesh order): the frame around the unit geometric normal (its z), computed
    /// once here rather than at every hit, where the normal's cross product, square root and
    /// division and the frame's own division sat between the hit and everything shading does
    /// with it. Flat-shaded hits use it as their shading frame (36 bytes per triangle).
    geometric_frames: Vec<Frame>,
    /// Per triangle: does its material have an alpha test? `None` when no material does, in
    /// which case traversal runs without any test callback.
    alpha_tested: Option<Vec<bool>>,
    /// Every material is an untextured, opaque Lambertian (no metallic, specular or
    /// transmission weight), no triangle has vertex normals and every light is an emissive
    /// triangle, so renders may take the Lambert-only path (see [`PathTracer::lambert_only`]).
    lambert_only: bool,
    environment: Vec3,
    /// Every emitter a BSDF-sampled ray could reach is also reached by light sampling (no
    /// constant environment outside the light sampler), so the last vertex may estimate its
    /// direct light by light sampling alone (see [`PathTracer::radiance`]).
    lights_cover_emission: bool,
    config: IntegratorConfig,
    /// 1 / `config.split`: the weight of each branch continued from a first hit (exactly 1
    /// without splitting, so a multiply by it changes no bit).
    branch_weight: f32,
}

impl PathTracer {
    /// Prepares `scene` (validated again here: NaN geometry never reaches the BVH).
    pub fn new(scene: &Scene, config: IntegratorConfig) -> Result<Self> {
        scene.validate()?;
        if config.max_depth == 0 {
            return Err(TracerError::Settings("max depth must be at least 1".into()));
        }
        if config.split == 0 || config.split > MAX_SAMPLES_PER_PIXEL {
            return Err(TracerError::Settings(format!(
                "{} paths split from each first hit: must be 1 ..= {MAX_SAMPLES_PER_PIXEL}",
                config.split
            )));
        }
        let mesh = &scene.mesh;
        let attributes = Attributes::gather(mesh);
        let alpha_tested =
            scene.materials.iter().any(Material::has_alpha).then(|| {
                mesh.material_ids.iter().map(|&m| scene.materials[m as usize].has_alpha()).collect()
            });
        let lights = LightSampler::new(scene);
        let lambert_only = attributes.normals.is_none()
            && lights.triangles_only()
            && scene.materials.iter().all(|m| {
                m.textures.is_empty()
                    && !m.has_alpha()
                    && m.transmission == 0.0
                    && BsdfParams::of(m).is_lambert()
            });
        let lights_cover_emission = lights.environment().is_some() || scene.environment.color == Vec3::ZERO;
        let geometric_frames = (0..mesh.triangle_count())
            .map(|t| {
                let [v0, v1, v2] = mesh.corners(t);
                Frame::from_z((v1 - v0).cross(v2 - v0).normalize_or(Vec3::Z))
            })
            .collect();
        Ok(Self {
            bvh: Bvh::build(mesh),
            geometric_frames,
            lights,
            lights_cover_emission,
            materials: scene.materials.clone(),
            material_ids: mesh.material_ids.clone(),
            textures: scene.textures.clone(),
            attributes,
            alpha_tested,
            lambert_only,
            environment: scene.environment.color,
            config,
            branch_weight: 1.0 / config.split as f32,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> IntegratorConfig {
        self.config
    }

    /// The acceleration structure (for tests and tools).
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// True when some material is alpha-tested (renders then use the alpha-aware traversal).
    pub fn has_alpha(&self) -> bool {
        self.alpha_tested.is_some()
    }

    /// True when every surface is an untextured, opaque, flat-shaded Lambertian lit by
    /// emissive triangles alone (the Cornell box's class of scene). Renders then take
    /// [`PathTracer::radiance`] with `LAMBERT`, which leaves out what such scenes lack (vertex
    /// normals, textures, glass, the specular lobe's set-up, other kinds of light) and gives
    /// the same bits as the general path, sooner (docs/performance.md, ledger).
    pub fn lambert_only(&self) -> bool {
        self.lambert_only
    }

    /// Test hook: makes renders take the general path even where the Lambert-only one applies
    /// (tests compare the two, bit for bit).
    #[doc(hidden)]
    pub fn without_lambert_path(mut self) -> Self {
        self.lambert_only = false;
        self
    }

    /// The surface geometry at `hit`.
    #[inline]
    pub fn interaction(&self, hit: &Hit) -> SurfaceInteraction {
        self.surface::<false>(hit)
    }

    /// Estimates the radiance arriving along `ray`; with `AOV`, records the first hit; with
    /// `ALPHA`, runs alpha tests during traversal (only scenes with alpha-tested materials
    /// need it: see [`PathTracer::has_alpha`]); with `LAMBERT`, takes the Lambert-only path
    /// (only for scenes where [`PathTracer::lambert_only`] holds: it reads no texture, vertex
    /// normal, transmission or specular parameter, and samples triangle lights alone).
    /// `u_light` is the first vertex's light sample (it shares the camera's set, see
    /// `crate::sampler::sets`).
    ///
    /// With first-vertex splitting (`IntegratorConfig::split` = N > 1), branch b of camera
    /// sample i draws every number past the camera's from sample i·N + b of the pixel's sequence
    /// ([`Sampler::branch`]; the caller keeps i·N + b below [`MAX_SAMPLES_PER_PIXEL`], as
    /// `render` does). Branch 0 runs the whole path; each later one resumes at the first
    /// hit, kept from branch 0, and takes neither its emission nor its light sample again. Any
    /// MIS weights that sum to one keep the estimate unbiased, so the first hit's light sample
    /// and its N BSDF samples share the power heuristic of one sample each.
    #[inline(always)]
    pub fn radiance<const AOV: bool, const ALPHA: bool, const LAMBERT: bool>(
        &self,
        ray: Ray,
        sampler: &Sampler,
        u_light: Vec2,
        first: &mut FirstHit,
    ) -> PathSample {
        let camera_ray = ray;
        let mut ray = ray;
        let mut u_light = u_light;
        let mut l = Vec3::ZERO;
        let mut beta = Vec3::ONE;
        let mut rays = 0u32;
        let mut prev_bsdf_pdf = 0.0f32;
        // The previous bounce was a delta event: emission it finds takes no MIS weight.
        let mut specular_bounce = false;
        let max_depth = self.config.max_depth;
        let mut depth = 0u32;
        // The triangles the current ray cannot hit: the one it was spawned from, and its
        // leaf-mates behind it (none for the eye ray).
        let mut leaving = Leaving::NOTHING;
        // First-vertex splitting: the branch being traced, its numbers, the camera ray's hit
        // (kept for the branches after the first) and whether this vertex resumes at it.
        let split = self.config.split;
        let mut branch = 0u32;
        let base = *sampler;
        let mut sampler = base.branch(split, 0);
        let mut camera_hit: Option<Hit> = None;
        let mut resumed = false;
        let branch_scale = split as f32;
        'branches: loop {
            loop {
                let hit = if resumed {
                    let Some(hit) = camera_hit else { break 'branches };
                    hit
                } else {
                    rays += 1;
                    let Some(hit) = self.closest_hit::<ALPHA>(&ray, leaving) else {
                        let env = self.lights.environment();
                        let le = env.map_or(self.environment, |e| e.radiance(ray.direction));
                        if le != Vec3::ZERO {
                            let w = if depth == 0 || specular_bounce || env.is_none() {
                                1.0
                            } else {
                                power_heuristic(prev_bsdf_pdf, self.lights.pdf_environment(ray.direction))
                            };
                            l += beta * le * w;
                        }
                        if AOV && depth == 0 {
                            *first =
                                FirstHit { albedo: Vec3::ZERO, normal: Vec3::ZERO, depth: f32::INFINITY };
                        }
                        break;
                    };
                    if depth == 0 {
                        camera_hit = Some(hit);
                    }
                    hit
                };
                debug_assert!(!LAMBERT || self.lambert_only);
                let si = self.surface::<LAMBERT>(&hit);
                let material = &self.materials[si.material as usize];
                let sp = self.shade::<LAMBERT>(material, &si, hit.barycentrics);
                let wo = -ray.direction;

                if !resumed
                    && sp.emission != Vec3::ZERO
                    && (material.emission_two_sided || si.n_geom.dot(wo) > 0.0)
                {
                    if depth == 0 || specular_bounce {
                        l += beta * sp.emission;
                    } else {
                        let light_pdf = self.lights.pdf_triangle(hit.triangle, hit.t, ray.direction);
                        l += beta * sp.emission * power_heuristic(prev_bsdf_pdf, light_pdf);
                    }
                }
                if AOV && depth == 0 {
                    let n = if sp.normal.dot(wo) < 0.0 { -sp.normal } else { sp.normal };
                    *first = FirstHit { albedo: sp.base_color, normal: n, depth: hit.t };
                }
                if depth == max_depth {
                    break;
                }

                // Numbers for this vertex (BSDF direction + next light sample) are drawn when the
                // path goes on; the one-dimensional decisions only when needed.
                let roulette = depth + 1 >= self.config.rr_depth;
                let glass_weight = material.transmission * (1.0 - sp.metallic);
                let mut decisions = None;
                let vertex = depth;
                let mut decide =
                    |k: usize| decisions.get_or_insert_with(|| sampler.get(sets::decisions(vertex)))[k];

                let glass =
                    !LAMBERT && glass_weight > 0.0 && (glass_weight >= 1.0 || decide(2) < glass_weight);
                if glass {
                    // A smooth dielectric interface: reflect or refract by Fresnel.
                    let lobe = Dielectric::new(sp.normal, si.n_geom, wo, material.ior, sp.base_color);
                    let Some(s) = lobe.sample(decide(3)) else { break };
                    beta *= s.weight;
                    specular_bounce = true;
                    let [_, _, l0, l1] = sampler.get(sets::vertex(depth));
                    u_light = Vec2::new(l0, l1);
                    ray = si.spawn_ray(s.wi, ray.time);
                } else {
                    let bsdf = if LAMBERT {
                        Bsdf::lambert(sp.base_color, si.shading, si.n_geom, wo)
                    } else {
                        let params = BsdfParams {
                            base_color: sp.base_color,
                            metallic: sp.metallic,
                            roughness: sp.roughness,
                            ..BsdfParams::of(material)
                        };
                        // The hit's shading frame, unless a normal map moved the normal.
                        let frame = if material.textures.normal.is_some() {
                            Frame::from_z(sp.normal)
                        } else {
                            si.shading
                        };
                        Bsdf::with_frame(&params, frame, si.n_geom, wo)
                    };
                    if bsdf.is_black() {
                        break;
                    }
                    // At the last vertex the BSDF ray could only find emission, which light
                    // sampling already covers: estimate it by light sampling alone (weight 1) and
                    // skip that ray and its hit. Unbiased either way; done only on diffuse BSDFs
                    // (where a light sample is never the worse strategy by much) past the first
                    // vertex (direct light seen by the camera keeps MIS). On the Cornell box this
                    // saves one closest-hit query in every path that reaches the last vertex.
                    let light_only = depth + 1 == max_depth
                        && depth > 0
                        && self.lights_cover_emission
                        && bsdf.is_diffuse();

                    // The BSDF sample that continues the path, its ray and the next vertex's light
                    // numbers come before next-event estimation. They do not depend on it, and
                    // placed ahead of its shadow query they are computed while the query runs
                    // instead of after it. An `if`, not `bool::then` with a closure, which LLVM
                    // once left out of line (docs/performance.md, ledger).
                    let next = if light_only {
                        None
                    } else {
                        let [u0, u1, l0, l1] = sampler.get(sets::vertex(depth));
                        let u_lobe = if bsdf.has_lobe_choice() { decide(0) } else { 0.5 };
                        let bs = bsdf.sample(Vec2::new(u0, u1), u_lobe);
                        Some((bs.map(|bs| (bs, si.spawn_ray(bs.wi, ray.time))), Vec2::new(l0, l1)))
                    };

                    // Next-event estimation (once per first hit, not per branch).
                    let ls = if resumed {
                        None
                    } else if LAMBERT {
                        self.lights.sample_triangles(si.p, u_light)
                    } else {
                        self.lights.sample(si.p, u_light)
                    };
                    if let Some(ls) = ls {
                        let (f, bsdf_pdf) = bsdf.eval(ls.wi);
                        let mut li = ls.li;
                        if let (false, Some((tri, b))) = (LAMBERT, ls.emitter) {
                            let m = &self.materials[self.material_ids[tri as usize] as usize];
                            if let Some(r) = &m.textures.emissive {
                                li *= r.eval(&self.textures, self.uvs(tri, b)).truncate();
                            }
                        }
                        if f != Vec3::ZERO && li != Vec3::ZERO {
                            let shadow = match ls.target {
                                ShadowTarget::Point { p, p_error, n } => {
                                    si.spawn_ray_to(p, p_error, n, ray.time)
                                }
                                ShadowTarget::Infinite => {
                                    Some((si.spawn_ray(ls.wi, ray.time), f32::INFINITY))
                                }
                            };
                            if let Some((shadow, t_max)) = shadow {
                                rays += 1;
                                if !self.occluded::<ALPHA>(
                                    &shadow,
                                    t_max,
                                    self.bvh.leaving(hit.slot, shadow.direction),
                                ) {
                                    let cos = ls.wi.dot(bsdf.shading_normal()).abs();
                                    let w = if ls.is_delta || light_only {
                                        1.0
                                    } else {
                                        power_heuristic(ls.pdf, bsdf_pdf)
                                    };
                                    l += beta * f * li * (cos * w / ls.pdf);
                                }
                            }
                        }
                    }

                    // Continue the path along the BSDF sample drawn above. (`next` nests its two
                    // Options on purpose: flattened, LLVM emitted more instructions;
                    // docs/performance.md, ledger.)
                    let Some((Some((bs, next_ray)), u_next)) = next else { break };
                    u_light = u_next;
                    beta *= bs.f * (bs.cos / bs.pdf);
                    prev_bsdf_pdf = bs.pdf;
                    specular_bounce = false;
                    ray = next_ray;
                }
                // Either branch spawned the next ray here.
                leaving = self.bvh.leaving(hit.slot, ray.direction);
                if depth == 0 {
                    beta *= self.branch_weight;
                    resumed = false;
                }
                depth += 1;

                if roulette {
                    // A branch's throughput at full weight (its 1/N left out, ×1 exactly when
                    // unsplit): with the 1/N in, roulette would end N − 1 of N branches on
                    // average at its first vertex and undo the split.
                    let q = (1.0 - beta.max_element() * branch_scale).max(0.0);
                    if decide(1) < q {
                        break;
                    }
                    beta /= 1.0 - q;
                }
            }
            // The path has ended; the next branch resumes at the camera ray's hit.
            branch += 1;
            if branch == split {
                break;
            }
            sampler = base.branch(split, branch);
            ray = camera_ray;
            beta = Vec3::ONE;
            prev_bsdf_pdf = 0.0;
            specular_bounce = false;
            depth = 0;
            leaving = Leaving::NOTHING;
            resumed = true;
        }
        PathSample { radiance: l, rays }
    }
}
