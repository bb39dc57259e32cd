//! Unidirectional path tracing (docs/design.md §3.3; pbrt-v4 §13.4 `PathIntegrator`): at each
//! scattering vertex, next-event estimation towards one light chosen by its importance there
//! (a light tree), plus a BSDF sample that continues the path; both estimators of direct light (emissive triangles, the
//! environment image) are combined by multiple importance sampling with the power heuristic.
//! Delta events (smooth glass, punctual lights) take no MIS. Transmissive materials are a
//! mixture: with probability transmission × (1 − metallic) the hit is a dielectric interface
//! (smooth, or rough GGX glass, which samples lights through both its halves, `glass.rs`),
//! otherwise the opaque metallic-roughness BSDF. A path that refracts into a closed mesh with an absorbing volume carries that medium
//! and its Beer–Lambert attenuation until it refracts out. Russian roulette from a chosen depth; a
//! maximum depth counted in scattering vertices (the Cornell reference's 4 = Mitsuba's
//! `max_depth` 5: the light may be reached by the ray leaving the 4th vertex).
//!
//! Random numbers come in 4-D sets assigned by position in the path (`crate::sampler::sets`):
//! a path that stops early never shifts another decision's numbers, and each vertex's BSDF
//! direction shares a set with the next vertex's light sample, so one-bounce light is
//! stratified in 4-D. One-dimensional decisions (lobe choice, roulette) are drawn only where a
//! material has two lobes or roulette is active.
//!
//! The path of one camera ray, in the order the code runs it:
//! 1. [`PathTracer::radiance`] starts a `PathState` (`path_state.rs`) at the camera ray and
//!    finds its first vertex (`PathState::find`: the closest hit, the surface and material there
//!    and the emission seen, or the environment if the ray escapes). A path asks the scene
//!    through a [`SceneQuery`](scene_query::SceneQuery) (`scene_query.rs`: the hit queries, the
//!    surface and material at a hit, lights, the environment, the settings it reads), the one
//!    view of the scene it is handed.
//! 2. Each of the `split` branches continues from that vertex as a path of its own with its own
//!    numbers (one branch without splitting); only branch 0 samples the first vertex's light.
//! 3. `PathState::advance` takes a path one vertex further. `scatter` picks the vertex's lobe,
//!    glass ([`Dielectric`](crate::bsdf::dielectric::Dielectric), or rough glass in `glass.rs`)
//!    or the opaque [`Bsdf`](crate::bsdf::Bsdf), samples the direction that continues the
//!    path, adds next-event estimation (`sample_light`: one light sample and its shadow ray;
//!    not at smooth glass) and plays Russian roulette; `find` then traces the new ray to the
//!    next vertex.
//! 4. A path ends when its ray escapes, at the maximum depth, by roulette, or where its lobe
//!    gives no direction.

mod attributes;
mod glass;
mod path_state;
mod scene_query;

use crate::bvh::Bvh;
#[cfg(any(test, feature = "test-support"))]
use crate::bvh::Hit;
use crate::error::{Result, TracerError};
#[cfg(any(test, feature = "test-support"))]
use crate::interaction::SurfaceInteraction;
#[cfg(any(test, feature = "test-support"))]
use crate::light::LightChoice;
use crate::ray::Ray;
use crate::sampler::{MAX_SAMPLES_PER_PIXEL, Sampler};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use path_state::PathState;
use scene_query::SceneQuery;

/// Path-tracing parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IntegratorConfig {
    /// Maximum number of scattering vertices on a path.
    pub max_depth: u32,
    /// Russian roulette starts after this many scattering vertices (`u32::MAX`: never).
    pub rr_depth: u32,
    /// Paths continued from each camera ray's first hit (first-vertex splitting; 1: none). The
    /// first hit's emission and light sample are taken once; `split` BSDF samples each carry on
    /// a path of their own with weight 1/`split` (Russian roulette judges each against its own
    /// first throughput, so the 1/`split` cancels).
    /// Where indirect light makes the noise (nearly all of the Cornell box's), it then gets
    /// `split` paths per camera ray, traced and shaded once; where the camera's own
    /// dimensions do (textures, depth of field), splitting only adds cost.
    /// `spp × split` must stay within [`MAX_SAMPLES_PER_PIXEL`] (`render` checks it).
    pub split: u32,
}

impl IntegratorConfig {
    /// A general-purpose default: 8 scattering vertices, roulette after 3 (judged against the
    /// first vertex's throughput: docs/performance.md, ledger "roulette against the first
    /// vertex").
    pub const DEFAULT: Self = Self { max_depth: 8, rr_depth: 3, split: 1 };

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

/// What a camera ray that hits nothing records.
const MISSED: FirstHit = FirstHit { albedo: Vec3::ZERO, normal: Vec3::ZERO, depth: f32::INFINITY };

/// The radiance estimate of one camera ray.
#[derive(Clone, Copy, Debug)]
pub struct PathSample {
    /// Radiance along the ray.
    pub radiance: Vec3,
    /// Rays traced (closest-hit and shadow).
    pub rays: u32,
}

/// A scene prepared for path tracing: the paths' view of it ([`SceneQuery`]) and the
/// settings the camera ray's driver reads.
pub struct PathTracer {
    scene: SceneQuery,
    /// Every material is an untextured, opaque Lambertian (no metallic, specular or
    /// transmission weight), no triangle has vertex normals or colours and every light is an emissive
    /// triangle, so renders may take the Lambert-only path (see [`PathTracer::lambert_only`]).
    lambert_only: bool,
    config: IntegratorConfig,
    /// The BVH was refitted from another pose's ([`PathTracer::reposed`]).
    refitted: bool,
}

impl PathTracer {
    /// Prepares `scene` (validated again here: NaN geometry never reaches the BVH).
    pub fn new(scene: &Scene, config: IntegratorConfig) -> Result<Self> {
        Self::prepare(scene, config, None)
    }

    /// Prepares `scene`, another pose of the scene this tracer was prepared for (the next
    /// frame of a shot), with the same configuration: this tracer's BVH is refitted to it
    /// ([`Bvh::refit`]) instead of built afresh when both have the same triangles and nothing
    /// moves within a shutter; else it is built. The renders are the same bits either way
    /// (closest hits break ties by triangle index, not by the tree's shape).
    pub fn reposed(self, scene: &Scene) -> Result<Self> {
        let config = self.config;
        Self::prepare(scene, config, Some(self.scene.into_bvh()))
    }

    /// Whether the BVH was refitted rather than built (by [`PathTracer::reposed`]).
    pub fn refitted(&self) -> bool {
        self.refitted
    }

    fn prepare(scene: &Scene, config: IntegratorConfig, previous: Option<Bvh>) -> Result<Self> {
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
        let (scene, refitted) = SceneQuery::new(scene, config, previous);
        Ok(Self { lambert_only: scene.lambert_only(), scene, config, refitted })
    }

    /// The configuration in use.
    pub fn config(&self) -> IntegratorConfig {
        self.config
    }

    /// Test hook: the acceleration structure (tests trace rays against it directly).
    #[doc(hidden)]
    #[cfg(any(test, feature = "test-support"))]
    pub fn bvh(&self) -> &Bvh {
        self.scene.bvh()
    }

    /// Bytes the per-triangle shading arrays take (vertex attributes gathered per triangle,
    /// geometric frames, material ids, alpha-test flags): a shared mesh's once.
    pub fn shading_bytes(&self) -> usize {
        self.scene.shading_bytes()
    }

    /// True when some material is alpha-tested (renders then use the alpha-aware traversal).
    pub fn has_alpha(&self) -> bool {
        self.scene.has_alpha()
    }

    /// True when every surface is an untextured, opaque, flat-shaded Lambertian lit by
    /// emissive triangles alone (the Cornell box's class of scene). Renders then take
    /// [`PathTracer::radiance`] with `LAMBERT`, which leaves out what such scenes lack (vertex
    /// normals, textures, glass, the specular lobe's set-up, other kinds of light) and gives
    /// the same bits as the general path, sooner (docs/performance.md, ledger: "Lambert-only
    /// path", "triangle lights without dispatch").
    pub fn lambert_only(&self) -> bool {
        self.lambert_only
    }

    /// Test hook: makes renders take the general path even where the Lambert-only one applies
    /// (tests compare the two, bit for bit).
    #[doc(hidden)]
    #[cfg(any(test, feature = "test-support"))]
    pub fn without_lambert_path(mut self) -> Self {
        self.lambert_only = false;
        self
    }

    /// Test and benchmark hook: lights chosen by the tree or by power alone, whatever the
    /// scene would take (`benches/lights.rs` measures the two against each other).
    #[doc(hidden)]
    #[cfg(any(test, feature = "test-support"))]
    pub fn with_light_choice(self, choice: LightChoice, scene: &Scene) -> Self {
        Self { scene: self.scene.with_light_choice(choice, scene), ..self }
    }

    /// Test hook: rough glass estimates its direct light by BSDF samples alone, without light
    /// samples and MIS (tests check that both estimators agree).
    #[doc(hidden)]
    #[cfg(any(test, feature = "test-support"))]
    pub fn without_glass_nee(self) -> Self {
        Self { scene: self.scene.without_glass_light_sampling(), ..self }
    }

    /// Test hook: the surface geometry at `hit` (tests spawn rays from it).
    #[doc(hidden)]
    #[cfg(any(test, feature = "test-support"))]
    pub fn interaction(&self, hit: &Hit) -> SurfaceInteraction {
        self.scene.surface::<false>(hit)
    }

    /// Estimates the radiance arriving along `ray`; with `AOV`, records the first hit; with
    /// `ALPHA`, runs alpha tests during traversal (only scenes with alpha-tested materials
    /// need it: see [`PathTracer::has_alpha`]); with `LAMBERT`, takes the Lambert-only path
    /// (only for scenes where [`PathTracer::lambert_only`] holds: it reads no texture, vertex
    /// normal, transmission or specular parameter, and samples triangle lights alone).
    /// `u_light` is the first vertex's light sample (it shares the camera's set, see
    /// `crate::sampler::sets`).
    ///
    /// The camera ray is traced and its first vertex shaded once. With first-vertex splitting
    /// (`IntegratorConfig::split` = N > 1), N branches then continue from that vertex; branch b
    /// of camera sample i draws every number past the camera's from sample i·N + b of the
    /// pixel's sequence ([`Sampler::branch`]; the caller keeps i·N + b below
    /// [`MAX_SAMPLES_PER_PIXEL`], as `render` does). The first vertex's emission is taken once,
    /// with the camera ray, and its light sample once, by branch 0; each branch samples a BSDF
    /// direction of its own. Any MIS weights that sum to one keep the estimate unbiased, so the
    /// first hit's light sample and its N BSDF samples share the power heuristic of one sample
    /// each.
    #[inline(always)]
    pub fn radiance<const AOV: bool, const ALPHA: bool, const LAMBERT: bool>(
        &self,
        ray: Ray,
        sampler: &Sampler,
        u_light: Vec2,
        first: &mut FirstHit,
    ) -> PathSample {
        debug_assert!(!LAMBERT || self.lambert_only);
        let mut out = PathSample { radiance: Vec3::ZERO, rays: 0 };
        let split = self.config.split;
        let mut camera = PathState::camera(ray, sampler.branch(split, 0), u_light);
        let found = camera.find::<ALPHA, LAMBERT>(&self.scene, &mut out);
        if AOV {
            *first = found.as_ref().map_or(MISSED, |v| v.first_hit());
        }
        let Some(first_vertex) = found else { return out };
        // An unlit surface shows its colour and nothing more (only camera rays see it).
        if let (false, Some(colour)) = (LAMBERT, first_vertex.unlit()) {
            out.radiance += colour;
            return out;
        }
        for branch in 0..split {
            let mut path = camera.with_sampler(sampler.branch(split, branch));
            let mut vertex = first_vertex;
            // The first vertex's light is sampled once, by branch 0; every later vertex's by
            // the path that reaches it.
            let mut sample_light = branch == 0;
            while let Some(next) =
                path.advance::<ALPHA, LAMBERT>(&self.scene, &vertex, sample_light, &mut out)
            {
                vertex = next;
                sample_light = true;
            }
        }
        out
    }
}
