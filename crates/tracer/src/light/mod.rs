//! Light sampling for next-event estimation (docs/design.md §3.3): one light is chosen in
//! proportion to its emitted power, then a point (or direction) on it. Emissive triangles,
//! punctual lights (point, spot, directional) and an environment image share one distribution;
//! the density of choosing an emissive triangle or an environment direction is also what MIS
//! needs when a BSDF-sampled ray reaches them.

mod distribution;
mod environment;
mod point;
mod spot;
mod triangle;

pub use distribution::Distribution;
pub use environment::{EnvironmentLight, EnvironmentSample};
pub use point::PointLight;
pub use spot::SpotLight;
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

/// All the scene's lights and the power distribution over them.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    lights: Vec<Light>,
    distribution: Option<Distribution>,
    /// Mesh triangle → index in `lights` (u32::MAX for non-emissive triangles); empty when no
    /// triangle emits.
    light_of_triangle: Vec<u32>,
    environment: Option<(EnvironmentLight, u32)>,
}

impl LightSampler {
    /// Gathers the lights of `scene`: emissive triangles, punctual lights, environment image.
    pub fn new(scene: &Scene) -> Self {
        let materials = &scene.materials;
        let mut lights = Vec::new();
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
                    lights.push(Light::Triangle(tri));
                }
            }
        }
        for light in &scene.lights {
            lights.push(match *light {
                PunctualLight::Point { position, intensity } => {
                    Light::Point(PointLight { position, intensity })
                }
                PunctualLight::Spot { position, direction, intensity, inner_cone, outer_cone, falloff } => {
                    Light::Spot(SpotLight::new(
                        position, direction, intensity, inner_cone, outer_cone, falloff,
                    ))
                }
                PunctualLight::Directional { direction, irradiance } => {
                    Light::Directional { direction, irradiance }
                }
            });
        }
        let environment = scene.environment_map.as_ref().and_then(EnvironmentLight::new).map(|env| {
            lights.push(Light::Environment);
            (env, lights.len() as u32 - 1)
        });
        let radius = scene.bounds().map_or(1.0, |(lo, hi)| 0.5 * (hi - lo).length()).max(1e-6);
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| match l {
                Light::Triangle(t) => t.power(),
                Light::Point(p) => p.power(),
                Light::Spot(s) => s.power(),
                Light::Directional { irradiance, .. } => {
                    std::f64::consts::PI * (radius as f64).powi(2) * luminance(*irradiance) as f64
                }
                Light::Environment => environment.as_ref().map_or(0.0, |(e, _)| e.power(radius)),
            })
            .collect();
        let distribution = Distribution::new(&powers);
        Self { lights, distribution, light_of_triangle, environment }
    }

    /// True when there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.distribution.is_none()
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// The environment image light, if the scene has one.
    #[inline]
    pub fn environment(&self) -> Option<&EnvironmentLight> {
        self.environment.as_ref().map(|(e, _)| e)
    }

    /// Chooses a light and a point on it for a receiver at `p_ref`; `u` is a stratified 2-D
    /// number (u.x also chooses the light).
    #[inline(always)]
    pub fn sample(&self, p_ref: Vec3, u: Vec2) -> Option<LightSample> {
        let dist = self.distribution.as_ref()?;
        let (i, p_select, ux) = dist.sample(u.x);
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
            Light::Triangle(tri) => triangle_sample(tri, p_select, p_ref, u),
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
                let (env, _) = self.environment.as_ref()?;
                let s = env.sample(u)?;
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
    pub fn sample_triangles(&self, p_ref: Vec3, u: Vec2) -> Option<LightSample> {
        let dist = self.distribution.as_ref()?;
        let (i, p_select, ux) = dist.sample(u.x);
        match &self.lights[i] {
            Light::Triangle(tri) => triangle_sample(tri, p_select, p_ref, Vec2::new(ux, u.y)),
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

    /// For MIS: the density with which [`LightSampler::sample`] would have produced the point
    /// of mesh triangle `triangle` seen `dist` away along `wi` (0 if it is not a light).
    #[inline]
    pub fn pdf_triangle(&self, triangle: u32, dist: f32, wi: Vec3) -> f32 {
        let Some(dist_table) = &self.distribution else { return 0.0 };
        let Some(&i) = self.light_of_triangle.get(triangle as usize) else { return 0.0 };
        if i == u32::MAX {
            return 0.0;
        }
        match &self.lights[i as usize] {
            Light::Triangle(tri) => tri.pdf_solid_angle(dist, wi) * dist_table.pmf(i as usize),
            _ => 0.0,
        }
    }

    /// For MIS: the density with which [`LightSampler::sample`] would have chosen direction
    /// `w` towards the environment (0 without an environment image).
    #[inline]
    pub fn pdf_environment(&self, w: Vec3) -> f32 {
        match (&self.environment, &self.distribution) {
            (Some((env, i)), Some(d)) => env.pdf(w) * d.pmf(*i as usize),
            _ => 0.0,
        }
    }
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
