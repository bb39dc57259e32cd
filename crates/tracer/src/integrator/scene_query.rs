//! The scene as a path vertex sees it ([`SceneQuery`]): the queries a path makes and nothing
//! else. Closest hit and occlusion (alpha-tested where the scene needs), the surface geometry at
//! a hit (a shading frame from vertex normals or the triangle's own), the material evaluated
//! there (textures, normal map, vertex colour), the triangles a leaving ray skips, light
//! sampling and its densities, the environment's radiance, and the path settings it reads.

use super::IntegratorConfig;
use super::attributes::{Attributes, lerp3};
use crate::bsdf::BsdfParams;
use crate::bvh::{Bvh, Hit, Leaving};
use crate::interaction::SurfaceInteraction;
#[cfg(any(test, feature = "test-support"))]
use crate::light::LightChoice;
use crate::light::{LightSample, LightSampler};
use crate::material::{AlphaMode, Material};
use crate::ray::Ray;
use crate::sampling::Frame;
use crate::scene::{Placement, Scene};
use crate::shading::{self, ShadingPoint, TangentFrame};
use crate::texture::Texture;
use glam::{Vec2, Vec3};

/// Tangent data for materials without a normal map (never read).
const NO_FRAME: TangentFrame = TangentFrame { tangent: None, dpdu: Vec3::X, dpdv: Vec3::Y };

/// A scene prepared for the path's queries: BVH, lights, materials and shading attributes, and
/// the settings a path reads at each vertex.
pub(super) struct SceneQuery {
    bvh: Bvh,
    lights: LightSampler,
    materials: Vec<Material>,
    material_ids: Vec<u32>,
    textures: Vec<Texture>,
    attributes: Attributes,
    /// Per triangle (mesh order): the frame around the unit geometric normal (its z), computed
    /// once here rather than at every hit, where the normal's cross product, square root and
    /// division and the frame's own division sat between the hit and everything shading does
    /// with it. Flat-shaded hits use it as their shading frame (36 bytes per triangle;
    /// docs/performance.md, ledger: "precomputed shading frame").
    geometric_frames: Vec<Frame>,
    /// Per triangle: does its material have an alpha test? `None` when no material does, in
    /// which case traversal runs without any test callback.
    alpha_tested: Option<Vec<bool>>,
    environment: Vec3,
    /// Every emitter a BSDF-sampled ray could reach is also reached by light sampling (no
    /// constant environment outside the light sampler), so the last vertex may estimate its
    /// direct light by light sampling alone (see `PathState::scatter`).
    lights_cover_emission: bool,
    /// `IntegratorConfig::max_depth`.
    max_depth: u32,
    /// `IntegratorConfig::rr_depth`.
    rr_depth: u32,
    /// 1 / `IntegratorConfig::split`: the weight of each branch continued from a first hit
    /// (exactly 1 without splitting, so a multiply by it changes no bit).
    branch_weight: f32,
    /// Rough glass takes light samples, weighted by MIS against its BSDF samples; always, but
    /// for the test hook that compares the BSDF-only estimator (`PathTracer::without_glass_nee`).
    glass_light_sampling: bool,
}

impl SceneQuery {
    /// Prepares `scene` (already validated) for paths traced with `config`; with the `previous`
    /// pose's BVH, refits it when it can (see `PathTracer::reposed`), and says whether it did.
    pub(super) fn new(scene: &Scene, config: IntegratorConfig, previous: Option<Bvh>) -> (Self, bool) {
        let mesh = &scene.mesh;
        // The BVH first: its build's transient arrays (the largest of a big scene's) then
        // never coexist with the shading arrays below (docs/performance.md, ledger: "BVH
        // before the shading arrays").
        // Triangles that move within the shutter go in the BVH's motion tree, emitters too: light
        // sampling places them where the ray's time has them (`light::motion`).
        let moving = scene.motion.as_deref().and_then(|motion| {
            let moving = motion.moving_triangles(mesh);
            moving.contains(&true).then_some((motion, moving))
        });
        let mut refitted = false;
        let instances = scene.instances.as_deref();
        let bvh = match (&moving, previous) {
            (Some((motion, moving)), _) => Bvh::build_scene(mesh, Some((motion, moving)), instances),
            (None, _) if instances.is_some() => Bvh::build_scene(mesh, None, instances),
            (None, Some(mut bvh)) => {
                refitted = bvh.refit(mesh);
                if refitted { bvh } else { Bvh::build(mesh) }
            }
            (None, None) => Bvh::build(mesh),
        };
        let mut attributes = Attributes::gather(mesh);
        if let Some((motion, _)) = &moving {
            attributes.gather_motion(mesh, &motion.normals);
        }
        let alpha_tested =
            scene.materials.iter().any(Material::has_alpha).then(|| {
                mesh.material_ids.iter().map(|&m| scene.materials[m as usize].has_alpha()).collect()
            });
        let lights = LightSampler::new(scene);
        let lights_cover_emission = lights.environment().is_some() || scene.environment.color == Vec3::ZERO;
        let geometric_frames = (0..mesh.triangle_count())
            .map(|t| {
                let [v0, v1, v2] = mesh.corners(t);
                Frame::from_z((v1 - v0).cross(v2 - v0).normalize_or(Vec3::Z))
            })
            .collect();
        let query = Self {
            bvh,
            geometric_frames,
            lights,
            lights_cover_emission,
            materials: scene.materials.clone(),
            material_ids: mesh.material_ids.clone(),
            textures: scene.textures.clone(),
            attributes,
            alpha_tested,
            environment: scene.environment.color,
            max_depth: config.max_depth,
            rr_depth: config.rr_depth,
            branch_weight: 1.0 / config.split as f32,
            glass_light_sampling: true,
        };
        (query, refitted)
    }

    /// The BVH, handed on to the next pose's query (`PathTracer::reposed`).
    pub(super) fn into_bvh(self) -> Bvh {
        self.bvh
    }

    /// True when every material is an untextured, opaque Lambertian (no metallic, specular or
    /// transmission weight), no triangle has vertex normals or colours and every light is an
    /// emissive triangle: the Lambert-only path applies (see `PathTracer::lambert_only`).
    pub(super) fn lambert_only(&self) -> bool {
        self.attributes.normals.is_none()
            && self.attributes.colors.is_none()
            && self.lights.triangles_only()
            && self.materials.iter().all(|m| {
                m.textures.is_empty()
                    && !m.has_alpha()
                    && m.transmission == 0.0
                    && m.coat == 0.0
                    && !m.has_sheen()
                    && BsdfParams::of(m).is_lambert()
            })
    }

    /// True when some material is alpha-tested.
    pub(super) fn has_alpha(&self) -> bool {
        self.alpha_tested.is_some()
    }

    /// Bytes the per-triangle shading arrays take.
    pub(super) fn shading_bytes(&self) -> usize {
        use std::mem::size_of_val;
        self.attributes.bytes()
            + size_of_val(&self.geometric_frames[..])
            + size_of_val(&self.material_ids[..])
            + self.alpha_tested.as_ref().map_or(0, |a| size_of_val(&a[..]))
    }

    /// The acceleration structure (for tests).
    #[cfg(any(test, feature = "test-support"))]
    pub(super) fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// The same scene with lights chosen by `choice` (test and benchmark hook).
    #[cfg(any(test, feature = "test-support"))]
    pub(super) fn with_light_choice(mut self, choice: LightChoice, scene: &Scene) -> Self {
        self.lights = self.lights.choosing(choice, scene);
        self
    }

    /// The same scene with rough glass estimating its direct light by BSDF samples alone, as
    /// smooth glass does (test hook: the two estimators must agree).
    #[cfg(any(test, feature = "test-support"))]
    pub(super) fn without_glass_light_sampling(self) -> Self {
        Self { glass_light_sampling: false, ..self }
    }

    /// Whether rough glass takes light samples (see `PathState::scatter`).
    #[inline(always)]
    pub(super) fn glass_light_sampling(&self) -> bool {
        self.glass_light_sampling
    }

    /// The maximum number of scattering vertices on a path.
    #[inline(always)]
    pub(super) fn max_depth(&self) -> u32 {
        self.max_depth
    }

    /// The depth from which Russian roulette plays.
    #[inline(always)]
    pub(super) fn rr_depth(&self) -> u32 {
        self.rr_depth
    }

    /// The weight of each branch continued from a first hit (1 / split).
    #[inline(always)]
    pub(super) fn branch_weight(&self) -> f32 {
        self.branch_weight
    }

    /// Whether light sampling reaches every emitter a BSDF-sampled ray could (then the last
    /// vertex may take its direct light from light sampling alone).
    #[inline(always)]
    pub(super) fn lights_cover_emission(&self) -> bool {
        self.lights_cover_emission
    }

    /// The material with index `id`.
    #[inline(always)]
    pub(super) fn material(&self, id: u32) -> &Material {
        &self.materials[id as usize]
    }

    /// What a ray leaving the hit at `slot` along `direction` skips.
    #[inline(always)]
    pub(super) fn leaving(&self, slot: u32, direction: Vec3) -> Leaving {
        self.bvh.leaving(slot, direction)
    }

    /// One light sample for a receiver at `p` facing `n` (every way for `n` zero: glass) at the
    /// ray's `time` (emissive triangles alone with `TRIANGLES`, for scenes lit by nothing
    /// else), with numbers `u`.
    #[inline(always)]
    pub(super) fn light_sample<const TRIANGLES: bool>(
        &self,
        p: Vec3,
        n: Vec3,
        u: Vec2,
        time: f32,
    ) -> Option<LightSample> {
        if TRIANGLES {
            self.lights.sample_triangles(p, n, u, time)
        } else {
            self.lights.sample(p, n, u, time)
        }
    }

    /// The emissive texture's value at barycentrics `b` of emitter `triangle`, when its
    /// material has one (it scales the light sample's radiance).
    #[inline(always)]
    pub(super) fn emissive_texture(&self, triangle: u32, b: [f32; 3]) -> Option<Vec3> {
        let m = &self.materials[self.material_ids[triangle as usize] as usize];
        let r = m.textures.emissive.as_ref()?;
        Some(r.eval(&self.textures, self.attributes.uvs(triangle, b)).truncate())
    }

    /// The density with which light sampling at `p_ref` (facing `n`) picks the point at
    /// distance `dist` along `wi` on `triangle` (where it is at `time`, if it moves).
    #[inline(always)]
    pub(super) fn pdf_triangle(
        &self,
        p_ref: Vec3,
        n: Vec3,
        triangle: u32,
        dist: f32,
        wi: Vec3,
        time: f32,
    ) -> f32 {
        self.lights.pdf_triangle(p_ref, n, triangle, dist, wi, time)
    }

    /// Whether light sampling picks the environment (an image), rather than the environment
    /// being a constant colour no light sample reaches.
    #[inline(always)]
    pub(super) fn samples_environment(&self) -> bool {
        self.lights.environment().is_some()
    }

    /// The environment's radiance along `w` (a ray that escapes).
    #[inline(always)]
    pub(super) fn environment(&self, w: Vec3) -> Vec3 {
        self.lights.environment().map_or(self.environment, |e| e.radiance(w))
    }

    /// The density with which light sampling picks the environment along `w`.
    #[inline(always)]
    pub(super) fn pdf_environment(&self, w: Vec3) -> f32 {
        self.lights.pdf_environment(w)
    }

    /// The surface geometry at `hit`; with `FLAT` (a mesh without vertex normals), the
    /// triangle's own frame without looking for vertex normals.
    #[inline(always)]
    pub(super) fn surface<const FLAT: bool>(&self, hit: &Hit) -> SurfaceInteraction {
        if hit.slot as usize >= self.bvh.static_slots() {
            return self.copy_or_moving_surface::<FLAT>(hit);
        }
        self.still_surface::<FLAT>(hit)
    }

    /// [`SceneQuery::surface`] of a moving triangle or an instance's: one branch on the slot
    /// keeps them out of the way of a scene without either.
    #[inline(never)]
    fn copy_or_moving_surface<const FLAT: bool>(&self, hit: &Hit) -> SurfaceInteraction {
        if let Some((tri, place)) = self.bvh.shared_hit(hit.slot) {
            return self.copy_surface::<FLAT>(hit, tri, place);
        }
        if self.bvh.is_moving(hit.slot) {
            return self.moving_surface::<FLAT>(hit);
        }
        self.still_surface::<FLAT>(hit)
    }

    /// [`SceneQuery::surface`] of a triangle that stands still in the mesh's world space.
    #[inline(always)]
    fn still_surface<const FLAT: bool>(&self, hit: &Hit) -> SurfaceInteraction {
        let tri = &self.bvh.triangle_at(hit.slot, hit.time);
        let (p, p_error) = crate::triangle::hit_point(tri, hit.barycentrics);
        let t = hit.triangle as usize;
        let geometric = self.geometric_frames[t];
        let n_geom = geometric.z;
        // A smooth hit's frame is built here even when no BSDF will need it (the path's last
        // hit, a normal-mapped material): building it only at the BSDF was slower on the café
        // (docs/performance.md, ledger: "shading frame only where a BSDF needs it").
        let shading = match &self.attributes.normals {
            _ if FLAT => geometric,
            Some(normals) => {
                let [n0, n1, n2] = normals[t];
                // A zero vertex normal marks a part without normals: shade it flat.
                if n0 == Vec3::ZERO || n1 == Vec3::ZERO || n2 == Vec3::ZERO {
                    geometric
                } else {
                    Frame::from_z(lerp3(normals[t], hit.barycentrics).normalize_or(n_geom))
                }
            }
            None => geometric,
        };
        self.interaction(hit, (p, p_error), n_geom, shading)
    }

    /// The interaction at `hit` on its point (and error bound), geometric normal and shading
    /// frame.
    #[inline(always)]
    fn interaction(
        &self,
        hit: &Hit,
        (p, p_error): (Vec3, Vec3),
        n_geom: Vec3,
        shading: Frame,
    ) -> SurfaceInteraction {
        let (triangle, slot) = (hit.triangle, hit.slot);
        SurfaceInteraction {
            p,
            p_error,
            n_geom,
            shading,
            triangle,
            slot,
            material: self.material_ids[triangle as usize],
        }
    }

    /// [`SceneQuery::surface`] of a copy of a shared mesh: its world corners from the copy
    /// (the bits flattening gives), its frame from them, and its vertex normals moved by the
    /// copy's placement vertex by vertex, as flattening moves them, then interpolated.
    #[inline(always)]
    fn copy_surface<const FLAT: bool>(
        &self,
        hit: &Hit,
        tri: [[f32; 3]; 3],
        place: &Placement,
    ) -> SurfaceInteraction {
        let (p, p_error) = crate::triangle::hit_point(&tri, hit.barycentrics);
        let t = hit.triangle as usize;
        let geometric = frame_of(&tri);
        let n_geom = geometric.z;
        let shading = match &self.attributes.normals {
            _ if FLAT => geometric,
            Some(normals) => {
                let world = normals[t].map(|n| place.normal(n));
                if world.contains(&Vec3::ZERO) {
                    geometric
                } else {
                    Frame::from_z(lerp3(world, hit.barycentrics).normalize_or(n_geom))
                }
            }
            None => geometric,
        };
        self.interaction(hit, (p, p_error), n_geom, shading)
    }

    /// [`SceneQuery::surface`] of a triangle that moves within the shutter: its corners, frame
    /// and vertex normals at the ray's time.
    #[cold]
    fn moving_surface<const FLAT: bool>(&self, hit: &Hit) -> SurfaceInteraction {
        let tri = self.bvh.triangle_at(hit.slot, hit.time);
        let (p, p_error) = crate::triangle::hit_point(&tri, hit.barycentrics);
        let t = hit.triangle as usize;
        let geometric = frame_of(&tri);
        let n_geom = geometric.z;
        let shading = match (&self.attributes.normals, &self.attributes.motion_normals) {
            _ if FLAT => geometric,
            // A rigidly moving copy's normals turn with it: those at the shutter's opening,
            // by the (inverse transpose of the) motion from there.
            (Some(normals), Some(steps))
                if !normals[t].contains(&Vec3::ZERO)
                    && let Some(m) = self.bvh.rigid_motion(hit.slot, hit.time) =>
            {
                let cofactor = crate::scene::normal_matrix(glam::Mat3::from(m.matrix3));
                let n = cofactor * lerp3(steps[0][t], hit.barycentrics);
                Frame::from_z(n.normalize_or(n_geom))
            }
            (Some(normals), Some(steps)) if !normals[t].contains(&Vec3::ZERO) => {
                let (k, f) = self.bvh.motion_step(hit.time);
                let (a, b) = (steps[k][t], steps[k + 1][t]);
                let at: [Vec3; 3] = std::array::from_fn(|i| a[i] * (1.0 - f) + b[i] * f);
                Frame::from_z(lerp3(at, hit.barycentrics).normalize_or(n_geom))
            }
            _ => geometric,
        };
        self.interaction(hit, (p, p_error), n_geom, shading)
    }

    /// The material evaluated at `si` (textures, normal map, vertex colour). `UNTEXTURED`: the
    /// scene has none of these (the Lambert-only path).
    #[inline(always)]
    pub(super) fn shade<const UNTEXTURED: bool>(
        &self,
        material: &Material,
        si: &SurfaceInteraction,
        b: [f32; 3],
    ) -> ShadingPoint {
        // An anisotropic material needs its tangent frame even without textures.
        let mut sp = if UNTEXTURED || (material.textures.is_empty() && material.anisotropy.is_none()) {
            ShadingPoint::of(material, si.shading.z)
        } else {
            let uv = self.attributes.uvs(si.triangle, b);
            let t = &material.textures;
            let frame = if t.normal.is_some() || t.coat_normal.is_some() || material.anisotropy.is_some() {
                self.tangent_frame(si, b)
            } else {
                NO_FRAME
            };
            shading::evaluate(material, &self.textures, uv, si.shading.z, &frame)
        };
        if !UNTEXTURED && let Some(c) = self.attributes.vertex_color(si.triangle, b) {
            sp.base_color *= c.truncate();
            sp.alpha = (sp.alpha * c.w).clamp(0.0, 1.0);
        }
        sp
    }

    /// Tangent data for normal mapping and anisotropy: vertex tangents if the mesh has them, and the
    /// triangle's ∂p/∂u, ∂p/∂v from its texture coordinates.
    fn tangent_frame(&self, si: &SurfaceInteraction, b: [f32; 3]) -> TangentFrame {
        let t = si.triangle as usize;
        let tangent = self.attributes.tangents.as_ref().and_then(|ts| {
            let v = match self.shared_copy(si.slot) {
                Some(place) => ts[t].map(|x| place.tangent(x)),
                None => ts[t],
            };
            (v.iter().all(|x| x.truncate() != Vec3::ZERO)).then(|| lerp3(v, b))
        });
        // At the shutter's opening, for a moving triangle.
        let [p0, p1, p2] = self.bvh.triangle_at(si.slot, f32::NEG_INFINITY).map(Vec3::from_array);
        let [uv0, uv1, uv2] = self.attributes.uvs.as_ref().map_or([Vec2::ZERO, Vec2::X, Vec2::Y], |u| u[t]);
        let (d1, d2) = (uv1 - uv0, uv2 - uv0);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let det = d1.x * d2.y - d1.y * d2.x;
        let (dpdu, dpdv) = if det.abs() > 1e-12 {
            let inv = 1.0 / det;
            ((d2.y * e1 - d1.y * e2) * inv, (d1.x * e2 - d2.x * e1) * inv)
        } else {
            (e1, e2)
        };
        TangentFrame { tangent, dpdu, dpdv }
    }

    /// How the copy at `slot` moves its shared mesh's attributes; `None` (after one compare)
    /// for a triangle of the static tree.
    #[inline(always)]
    fn shared_copy(&self, slot: u32) -> Option<&Placement> {
        if (slot as usize) < self.bvh.static_slots() { None } else { self.bvh.shared_copy(slot) }
    }

    /// Whether the alpha test lets a ray through (false) or stops it (true) at barycentrics
    /// `b` of `triangle`. Masked surfaces compare alpha with the cut-off; blended ones are
    /// hit with probability alpha, decided by a hash of the ray and the point (deterministic).
    /// Unlit surfaces stop camera rays alone (`camera`), as Blender's import makes them.
    #[inline]
    fn alpha_accepts(&self, tested: &[bool], triangle: u32, b: [f32; 3], ray: &Ray, camera: bool) -> bool {
        if !tested[triangle as usize] {
            return true;
        }
        let material = &self.materials[self.material_ids[triangle as usize] as usize];
        if material.unlit && !camera {
            return false;
        }
        let mut alpha = shading::alpha(material, &self.textures, self.attributes.uvs(triangle, b));
        if let Some(c) = self.attributes.vertex_color(triangle, b) {
            alpha *= c.w;
        }
        match material.alpha_mode {
            AlphaMode::Opaque => true,
            AlphaMode::Mask { cutoff } => alpha >= cutoff,
            AlphaMode::Blend => {
                let bits = [ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x, b[0], b[1]];
                let h =
                    bits.iter().fold(triangle ^ 0x68bc_21eb, |h, x| crate::sampler::hash(h ^ x.to_bits()));
                ((h >> 8) as f32 / (1u32 << 24) as f32) < alpha
            }
        }
    }

    /// The closest hit along `ray` (skipping `leaving`), alpha-tested with `ALPHA`; `camera`:
    /// the ray comes from the camera (unlit surfaces stop it).
    #[inline]
    pub(super) fn closest_hit<const ALPHA: bool>(
        &self,
        ray: &Ray,
        leaving: Leaving,
        camera: bool,
    ) -> Option<Hit> {
        match (ALPHA, &self.alpha_tested) {
            (true, Some(tested)) => self.bvh.intersect_from(ray, f32::INFINITY, leaving, |t, b| {
                self.alpha_accepts(tested, t, b, ray, camera)
            }),
            _ => self.bvh.intersect_from(ray, f32::INFINITY, leaving, |_, _| true),
        }
    }

    /// Whether anything blocks `ray` before `t_max` (skipping `leaving`), alpha-tested with `ALPHA`.
    #[inline]
    pub(super) fn occluded<const ALPHA: bool>(&self, ray: &Ray, t_max: f32, leaving: Leaving) -> bool {
        match (ALPHA, &self.alpha_tested) {
            (true, Some(tested)) => self
                .bvh
                .occluded_from(ray, t_max, leaving, |t, b| self.alpha_accepts(tested, t, b, ray, false)),
            _ => self.bvh.occluded_from(ray, t_max, leaving, |_, _| true),
        }
    }
}

/// The frame around the unit geometric normal of the triangle with world corners `tri`.
#[inline(always)]
fn frame_of(tri: &[[f32; 3]; 3]) -> Frame {
    let [v0, v1, v2] = tri.map(Vec3::from_array);
    Frame::from_z((v1 - v0).cross(v2 - v0).normalize_or(Vec3::Z))
}
