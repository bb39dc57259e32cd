//! Light sampling for next-event estimation (docs/design/tracer.md §3.3): one light is chosen for the
//! receiving point, then a point (or direction) on it. Emissive triangles and punctual lights
//! (point, spot) are chosen through a light tree (`tree.rs`) by their importance to the
//! receiver's position and normal (`bounds.rs`); directional lights and the environment image,
//! which no box holds, are chosen beside the tree, each as likely as the whole tree (pbrt-v4
//! `BVHLightSampler`). The probability of choosing an emissive triangle or an environment
//! direction is also what MIS needs when a BSDF-sampled ray reaches them. An emissive triangle
//! that moves within the shutter is sampled, and its density evaluated, where it is at the
//! ray's time (`motion.rs`).

mod bounds;
mod distribution;
mod environment;
mod motion;
mod point;
mod spot;
mod tree;
mod triangle;

pub use bounds::LightBounds;
pub use distribution::Distribution;
pub use environment::{EnvironmentLight, EnvironmentSample};
pub use point::PointLight;
pub use spot::SpotLight;
pub use tree::LightTree;
use tree::ONE_MINUS_EPSILON;
pub use triangle::{EmissiveTriangle, luminance};

use crate::material::Material;
use crate::scene::{PunctualLight, Scene};
use glam::{Vec2, Vec3};

/// One light of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    /// An emissive triangle of the mesh.
    Triangle(EmissiveTriangle),
    /// A point light.
    Point(PointLight),
    /// A spot light.
    Spot(SpotLight),
    /// A directional light: unit direction the light travels in, and irradiance.
    Directional {
        /// Direction of travel.
        direction: Vec3,
        /// Irradiance, W/m².
        irradiance: Vec3,
    },
    /// The environment image (index into `LightSampler`'s single environment).
    Environment,
}

/// Where a shadow ray for a light sample must reach.
#[derive(Clone, Copy, Debug)]
pub enum ShadowTarget {
    /// A point on a surface (or a punctual light, with a zero normal and error).
    Point {
        /// The point.
        p: Vec3,
        /// Its floating-point error bound.
        p_error: Vec3,
        /// The surface normal there (zero: nothing to offset from).
        n: Vec3,
    },
    /// Infinitely far along the sample's direction (directional lights, the environment).
    Infinite,
}

/// A light sample for a receiver.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the receiver towards the light.
    pub wi: Vec3,
    /// Radiance (area and environment lights) or irradiance-equivalent (punctual lights:
    /// intensity / d², or a directional light's irradiance) arriving at the receiver.
    pub li: Vec3,
    /// Density: solid angle at the receiver × selection probability; for delta lights the
    /// selection probability alone.
    pub pdf: f32,
    /// True for punctual lights (no MIS: a BSDF sample can never hit them).
    pub is_delta: bool,
    /// What the shadow ray must reach.
    pub target: ShadowTarget,
    /// For emissive triangles: the mesh triangle and the barycentrics of the point, so an
    /// emissive texture can be looked up there (`li` holds the factor only).
    pub emitter: Option<(u32, [f32; 3])>,
}

/// How a light is chosen for next-event estimation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightChoice {
    /// By the light tree, for the receiving point and normal.
    Tree,
    /// In proportion to power alone, wherever the receiver is.
    Power,
}

/// All the scene's lights and how one is chosen for a receiver.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    /// The tree's lights first (emissive triangles, point and spot lights: light i is the
    /// tree's light i), then the infinite ones (directional lights, the environment).
    lights: Vec<Light>,
    tree: Option<LightTree>,
    /// Number of lights in the tree.
    finite: u32,
    /// Number of infinite lights.
    infinite: u32,
    /// Probability of choosing an infinite light: each is as likely as the whole tree.
    p_infinite: f32,
    /// When set, lights are chosen by this distribution of their power instead, wherever the
    /// receiver is (see [`LightSampler::by_power`]).
    by_power: Option<Distribution>,
    /// Mesh triangle → index in `lights` (u32::MAX for non-emissive triangles); empty when no
    /// triangle emits.
    light_of_triangle: Vec<u32>,
    environment: Option<EnvironmentLight>,
    /// The emissive triangles that move within the shutter, if any.
    motion: Option<motion::LightMotion>,
}

impl LightSampler {
    /// Gathers the lights of `scene`: emissive triangles, punctual lights, environment image.
    pub fn new(scene: &Scene) -> Self {
        let materials = &scene.materials;
        let mut lights = Vec::new();
        let mut bounds = Vec::new();
        let mut light_of_triangle = Vec::new();
        if materials.iter().any(Material::is_emissive) {
            light_of_triangle = vec![u32::MAX; scene.mesh.triangle_count()];
            for (t, &m) in scene.mesh.material_ids.iter().enumerate() {
                let material = &materials[m as usize];
                if !material.is_emissive() {
                    continue;
                }
                // An emissive texture scales the factor; the factor bounds the power.
                if let Some(tri) = EmissiveTriangle::new(
                    t as u32,
                    scene.mesh.corners(t),
                    material.emission,
                    material.emission_two_sided,
                ) {
                    light_of_triangle[t] = lights.len() as u32;
                    bounds.push(tri.bounds());
                    lights.push(Light::Triangle(tri));
                }
            }
        }
        // Moving emitters are bounded over the whole shutter, so that the tree's choice (a
        // function of the receiver alone) never rules one out where it lights at some time.
        let motion = scene.motion.as_deref().and_then(|m| {
            let triangles: Vec<Option<u32>> = lights
                .iter()
                .map(|l| match l {
                    Light::Triangle(t) => Some(t.triangle),
                    _ => None,
                })
                .collect();
            motion::LightMotion::new(&scene.mesh, m, &triangles)
        });
        if let Some(m) = &motion {
            for (i, light) in lights.iter().enumerate() {
                if let (true, Light::Triangle(t)) = (m.moves(i), light) {
                    bounds[i] = m.bounds(i, t);
                }
            }
        }
        let mut infinite = Vec::new();
        for light in &scene.lights {
            match *light {
                PunctualLight::Point { position, intensity } => {
                    let point = PointLight { position, intensity };
                    bounds.push(point.bounds());
                    lights.push(Light::Point(point));
                }
                PunctualLight::Spot { position, direction, intensity, inner_cone, outer_cone, falloff } => {
                    let spot =
                        SpotLight::new(position, direction, intensity, inner_cone, outer_cone, falloff);
                    bounds.push(spot.bounds());
                    lights.push(Light::Spot(spot));
                }
                PunctualLight::Directional { direction, irradiance } => {
                    infinite.push(Light::Directional { direction, irradiance })
                }
            }
        }
        let tree = LightTree::build(&bounds);
        let environment = scene.environment_map.as_ref().and_then(EnvironmentLight::new);
        if environment.is_some() {
            infinite.push(Light::Environment);
        }
        let finite = lights.len() as u32;
        lights.extend(infinite);
        let infinite = lights.len() as u32 - finite;
        let p_infinite = infinite as f32 / (infinite + u32::from(tree.is_some())).max(1) as f32;
        let flat = infinite == 0 && one_flat_emitter(&lights);
        let sampler = Self {
            lights,
            tree,
            finite,
            infinite,
            p_infinite,
            by_power: None,
            light_of_triangle,
            environment,
            motion,
        };
        // One flat emitter (the Cornell box's light): every receiver sees all of it from the
        // same side, so the tree's bounds tell its triangles apart by distance alone, which
        // does not pay for the walk (docs/performance.md, ledger: "light tree").
        if flat { sampler.by_power(scene) } else { sampler }
    }

    /// The same lights chosen in proportion to their power alone, wherever the receiver is
    /// (directional lights and the environment by the power they send through the scene's
    /// bounding disc): the choice before the light tree, kept to measure the tree against.
    pub fn by_power(self, scene: &Scene) -> Self {
        self.choosing(LightChoice::Power, scene)
    }

    /// The same lights chosen as `choice` says.
    pub fn choosing(mut self, choice: LightChoice, scene: &Scene) -> Self {
        if choice == LightChoice::Tree {
            self.by_power = None;
            return self;
        }
        let radius = scene.bounds().map_or(1.0, |(lo, hi)| 0.5 * (hi - lo).length()).max(1e-6) as f64;
        let powers: Vec<f64> = self
            .lights
            .iter()
            .map(|l| match l {
                Light::Triangle(t) => t.power(),
                Light::Point(p) => p.power(),
                Light::Spot(s) => s.power(),
                Light::Directional { irradiance, .. } => {
                    std::f64::consts::PI * radius * radius * luminance(*irradiance) as f64
                }
                Light::Environment => self.environment.as_ref().map_or(0.0, |e| e.power(radius as f32)),
            })
            .collect();
        self.by_power = Distribution::new(&powers);
        self
    }

    /// True when there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// The environment image light, if the scene has one.
    #[inline]
    pub fn environment(&self) -> Option<&EnvironmentLight> {
        self.environment.as_ref()
    }

    /// Chooses a light for a receiver at `p` whose light arrives in the hemisphere around unit
    /// `n` (from anywhere for `n` zero: glass), with `u` ∈ [0, 1): (index in `lights`, its probability, `u` rescaled to [0, 1)).
    #[inline(always)]
    fn choose(&self, p: Vec3, n: Vec3, u: f32) -> Option<(usize, f32, f32)> {
        if let Some(power) = &self.by_power {
            return Some(power.sample(u));
        }
        if u < self.p_infinite {
            let x = u / self.p_infinite * self.infinite as f32;
            let k = (x as u32).min(self.infinite - 1);
            let rest = (x - k as f32).clamp(0.0, ONE_MINUS_EPSILON);
            return Some(((self.finite + k) as usize, self.p_infinite / self.infinite as f32, rest));
        }
        // Without infinite lights p_infinite is 0 and these change no bit.
        let u = ((u - self.p_infinite) / (1.0 - self.p_infinite)).min(ONE_MINUS_EPSILON);
        let (i, pmf, rest) = self.tree.as_ref()?.sample(p, n, u)?;
        Some((i as usize, pmf * (1.0 - self.p_infinite), rest))
    }

    /// Chooses a light and a point on it for a receiver at `p_ref` whose light arrives in the
    /// hemisphere around unit `n` (from anywhere for `n` zero: glass), for a shadow ray at ray time `time` (a moving emitter is
    /// sampled where it is then); `u` is a stratified 2-D number (u.x also chooses the light).
    #[inline(always)]
    pub fn sample(&self, p_ref: Vec3, n: Vec3, u: Vec2, time: f32) -> Option<LightSample> {
        let (i, p_select, ux) = self.choose(p_ref, n, u.x)?;
        let u = Vec2::new(ux, u.y);
        let point = |position: Vec3, intensity: Vec3| {
            let to_light = position - p_ref;
            let d2 = to_light.length_squared();
            (d2 > 0.0).then(|| {
                let wi = to_light / d2.sqrt();
                let target = ShadowTarget::Point { p: position, p_error: Vec3::ZERO, n: Vec3::ZERO };
                (wi, intensity / d2, target)
            })
        };
        match &self.lights[i] {
            Light::Triangle(tri) => self.triangle_sample(i, tri, p_select, p_ref, u, time),
            Light::Point(pl) => {
                let (wi, li, target) = point(pl.position, pl.intensity)?;
                Some(LightSample { wi, li, pdf: p_select, is_delta: true, target, emitter: None })
            }
            Light::Spot(spot) => {
                let (wi, li, target) = point(spot.position, spot.intensity)?;
                let li = li * spot.falloff(-wi);
                (li != Vec3::ZERO).then_some(LightSample {
                    wi,
                    li,
                    pdf: p_select,
                    is_delta: true,
                    target,
                    emitter: None,
                })
            }
            Light::Directional { direction, irradiance } => Some(LightSample {
                wi: -*direction,
                li: *irradiance,
                pdf: p_select,
                is_delta: true,
                target: ShadowTarget::Infinite,
                emitter: None,
            }),
            Light::Environment => {
                let s = self.environment.as_ref()?.sample(u)?;
                Some(LightSample {
                    wi: s.wi,
                    li: s.radiance,
                    pdf: s.pdf * p_select,
                    is_delta: false,
                    target: ShadowTarget::Infinite,
                    emitter: None,
                })
            }
        }
    }

    /// [`LightSampler::sample`] for a sampler whose every light is an emissive triangle
    /// ([`LightSampler::triangles_only`]): the same sample, bit for bit, without the dispatch
    /// on the kind of light.
    #[inline(always)]
    pub fn sample_triangles(&self, p_ref: Vec3, n: Vec3, u: Vec2, time: f32) -> Option<LightSample> {
        let (i, p_select, ux) = self.choose(p_ref, n, u.x)?;
        match &self.lights[i] {
            Light::Triangle(tri) => self.triangle_sample(i, tri, p_select, p_ref, Vec2::new(ux, u.y), time),
            _ => {
                debug_assert!(false, "sample_triangles on a sampler with other lights");
                None
            }
        }
    }

    /// True when every light is an emissive triangle (no punctual lights, no environment).
    pub fn triangles_only(&self) -> bool {
        self.lights.iter().all(|l| matches!(l, Light::Triangle(_)))
    }

    /// For MIS: the density with which [`LightSampler::sample`], for a receiver at `p_ref` with
    /// normal `n` and a ray at time `time`, would have produced the point of mesh triangle
    /// `triangle` seen `dist` away along `wi` (0 if it is not a light).
    #[inline]
    pub fn pdf_triangle(&self, p_ref: Vec3, n: Vec3, triangle: u32, dist: f32, wi: Vec3, time: f32) -> f32 {
        let Some(&i) = self.light_of_triangle.get(triangle as usize) else { return 0.0 };
        if i == u32::MAX {
            return 0.0;
        }
        let Light::Triangle(tri) = &self.lights[i as usize] else { return 0.0 };
        let pmf = match (&self.by_power, &self.tree) {
            (Some(power), _) => power.pmf(i as usize),
            (None, Some(tree)) => tree.pmf(p_ref, n, i) * (1.0 - self.p_infinite),
            (None, None) => return 0.0,
        };
        match &self.motion {
            Some(m) if m.moves(i as usize) => {
                m.at(i as usize, tri, time).map_or(0.0, |moved| moved.pdf_solid_angle(dist, wi) * pmf)
            }
            _ => tri.pdf_solid_angle(dist, wi) * pmf,
        }
    }

    /// A sample of triangle light `i` (`tri` at the frame's pose), chosen with probability
    /// `p_select`, seen from `p_ref` by a shadow ray at time `time`.
    #[inline(always)]
    fn triangle_sample(
        &self,
        i: usize,
        tri: &EmissiveTriangle,
        p_select: f32,
        p_ref: Vec3,
        u: Vec2,
        time: f32,
    ) -> Option<LightSample> {
        match &self.motion {
            Some(m) if m.moves(i) => triangle_sample(&m.at(i, tri, time)?, p_select, p_ref, u),
            _ => triangle_sample(tri, p_select, p_ref, u),
        }
    }

    /// For MIS: the density with which [`LightSampler::sample`] would have chosen direction
    /// `w` towards the environment (0 without an environment image).
    #[inline]
    pub fn pdf_environment(&self, w: Vec3) -> f32 {
        let Some(env) = &self.environment else { return 0.0 };
        // The environment is the last light.
        let pmf = match &self.by_power {
            Some(power) => power.pmf(self.lights.len() - 1),
            None => self.p_infinite / self.infinite as f32,
        };
        env.pdf(w) * pmf
    }
}

/// True when every light is a one-sided emissive triangle of one plane, all facing one way.
fn one_flat_emitter(lights: &[Light]) -> bool {
    let Some(Light::Triangle(first)) = lights.first() else { return false };
    lights.iter().all(|l| {
        let Light::Triangle(t) = l else { return false };
        let in_plane =
            |q: Vec3| (q - first.p[0]).dot(first.n).abs() <= 1e-5 * (1.0 + (q - first.p[0]).length());
        !t.two_sided && t.n.dot(first.n) >= 1.0 - 1e-6 && t.p.iter().all(|&q| in_plane(q))
    })
}

/// A sample of emissive triangle `tri`, chosen with probability `p_select`, seen from `p_ref`.
#[inline(always)]
fn triangle_sample(tri: &EmissiveTriangle, p_select: f32, p_ref: Vec3, u: Vec2) -> Option<LightSample> {
    let s = tri.sample(u);
    let to_light = s.p - p_ref;
    let d2 = to_light.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let d = d2.sqrt();
    let wi = to_light / d;
    let li = tri.emitted(-wi);
    let pdf = tri.pdf_solid_angle(d, wi) * p_select;
    if li == Vec3::ZERO || !(pdf > 0.0) || !pdf.is_finite() {
        return None;
    }
    let target = ShadowTarget::Point { p: s.p, p_error: s.p_error, n: s.n };
    Some(LightSample { wi, li, pdf, is_delta: false, target, emitter: Some((tri.triangle, s.b)) })
}
