//! Light sampling for next-event estimation (SPEC §3, "Integrator"): one light is chosen in
//! proportion to its emitted power, then a point on it. Emissive triangles (area lights) and
//! point lights share one distribution; the density of choosing an emissive triangle by light
//! sampling is also what MIS needs when a BSDF-sampled ray hits it.

mod distribution;
mod point;
mod triangle;

pub use distribution::Distribution;
pub use point::PointLight;
pub use triangle::{EmissiveTriangle, luminance};

use crate::material::Material;
use crate::scene::{PunctualLight, Scene};
use glam::{Vec2, Vec3};

/// One light of the scene.
#[derive(Clone, Copy, Debug)]
pub enum Light {
    /// An emissive triangle of the mesh.
    Triangle(EmissiveTriangle),
    /// A point light.
    Point(PointLight),
}

/// A point on a light chosen for a receiver, with what is needed to trace the shadow ray.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the receiver towards the point.
    pub wi: Vec3,
    /// The point on the light.
    pub p: Vec3,
    /// Its floating-point error bound (zero for point lights).
    pub p_error: Vec3,
    /// The light's normal there (zero for point lights: nothing to offset from).
    pub n: Vec3,
    /// Radiance (area lights) or intensity / d² (point lights) arriving at the receiver.
    pub li: Vec3,
    /// Density: solid angle at the receiver × selection probability; for delta lights the
    /// selection probability alone.
    pub pdf: f32,
    /// True for point lights (no MIS: a BSDF sample can never hit them).
    pub is_delta: bool,
}

/// All the scene's lights and the power distribution over them.
#[derive(Clone, Debug, Default)]
pub struct LightSampler {
    lights: Vec<Light>,
    distribution: Option<Distribution>,
    /// Mesh triangle → index in `lights` (u32::MAX for non-emissive triangles); empty when no
    /// triangle emits.
    light_of_triangle: Vec<u32>,
}

impl LightSampler {
    /// Gathers the lights of `scene`: its emissive triangles and punctual lights.
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
                if let Some(tri) = EmissiveTriangle::new(
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
            match *light {
                PunctualLight::Point { position, intensity } => {
                    lights.push(Light::Point(PointLight { position, intensity }))
                }
            }
        }
        let powers: Vec<f64> = lights
            .iter()
            .map(|l| match l {
                Light::Triangle(t) => t.power(),
                Light::Point(p) => p.power(),
            })
            .collect();
        let distribution = Distribution::new(&powers);
        Self { lights, distribution, light_of_triangle }
    }

    /// True when there is nothing to sample.
    pub fn is_empty(&self) -> bool {
        self.distribution.is_none()
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Chooses a light and a point on it for a receiver at `p_ref`; `u` is a stratified 2-D
    /// number (u.x also chooses the light).
    #[inline]
    pub fn sample(&self, p_ref: Vec3, u: Vec2) -> Option<LightSample> {
        let dist = self.distribution.as_ref()?;
        let (i, p_select, ux) = dist.sample(u.x);
        match &self.lights[i] {
            Light::Triangle(tri) => {
                let s = tri.sample(Vec2::new(ux, u.y));
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
                Some(LightSample { wi, p: s.p, p_error: s.p_error, n: s.n, li, pdf, is_delta: false })
            }
            Light::Point(pl) => {
                let to_light = pl.position - p_ref;
                let d2 = to_light.length_squared();
                if d2 == 0.0 {
                    return None;
                }
                Some(LightSample {
                    wi: to_light / d2.sqrt(),
                    p: pl.position,
                    p_error: Vec3::ZERO,
                    n: Vec3::ZERO,
                    li: pl.intensity / d2,
                    pdf: p_select,
                    is_delta: true,
                })
            }
        }
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
            Light::Point(_) => 0.0,
        }
    }
}
