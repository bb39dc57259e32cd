//! Emissive triangles that move within the shutter (docs/design/tracer.md §3.12): their corners
//! at every motion step, so that next-event estimation samples each at the shadow ray's time
//! (its area, normal and points there) and MIS evaluates the same density when a BSDF-sampled
//! ray of that time reaches it. Between two steps a corner is interpolated exactly as the
//! tracer's motion tree interpolates it for the ray (`bvh::motion`), so a sampled point lies on
//! the triangle the shadow ray meets. A scene whose emitters do not move has none of this.

use super::bounds::LightBounds;
use super::triangle::{EmissiveTriangle, luminance};
use crate::scene::{Mesh, SceneMotion};
use glam::Vec3;

/// The moving emissive triangles' corners at the motion steps.
#[derive(Clone, Debug)]
pub(super) struct LightMotion {
    /// Light index → slot in `corners` (`u32::MAX`: the light does not move).
    slot_of_light: Vec<u32>,
    /// Corners at every step, slot-major: slot s's step k at `s * steps + k`.
    corners: Vec<[Vec3; 3]>,
    /// Steps (≥ 2).
    steps: usize,
    /// Ray time of the first step.
    open: f32,
    /// Steps per unit of ray time after the first: (steps − 1) / (close − open).
    rate: f32,
}

impl LightMotion {
    /// The motion of the triangle lights `lights` (light index → mesh triangle; `None` for the
    /// other lights) of `mesh` under `motion`; `None` when none of them moves.
    pub fn new(mesh: &Mesh, motion: &SceneMotion, lights: &[Option<u32>]) -> Option<Self> {
        let moving = motion.moving_triangles(mesh);
        let steps = motion.steps();
        let mut slot_of_light = vec![u32::MAX; lights.len()];
        let mut corners = Vec::new();
        for (i, t) in lights.iter().enumerate() {
            let Some(t) = *t else { continue };
            if !moving[t as usize] {
                continue;
            }
            slot_of_light[i] = (corners.len() / steps) as u32;
            let vertices = mesh.triangles[t as usize];
            corners.extend((0..steps).map(|k| vertices.map(|v| motion.positions[k][v as usize])));
        }
        if corners.is_empty() {
            return None;
        }
        let rate = (steps - 1) as f32 / (motion.close - motion.open);
        Some(Self { slot_of_light, corners, steps, open: motion.open, rate })
    }

    /// Whether light `i` moves.
    #[inline(always)]
    pub fn moves(&self, i: usize) -> bool {
        self.slot_of_light.get(i).is_some_and(|&s| s != u32::MAX)
    }

    /// Light `i` (a moving triangle, `tri` at the frame's pose) at ray time `time`: `None` when
    /// it is degenerate then. The step and fraction, and each corner's interpolation
    /// ((1 − f)·p + f·q clamped to the two steps' range), are the motion tree's, bit for bit.
    #[inline]
    pub fn at(&self, i: usize, tri: &EmissiveTriangle, time: f32) -> Option<EmissiveTriangle> {
        let slot = self.slot_of_light[i] as usize;
        let x = ((time - self.open) * self.rate).clamp(0.0, (self.steps - 1) as f32);
        let step = (x as usize).min(self.steps - 2);
        let f = x - step as f32;
        let f = if f.is_nan() { 0.0 } else { f };
        let g = 1.0 - f;
        let (a, b) = (&self.corners[slot * self.steps + step], &self.corners[slot * self.steps + step + 1]);
        let p: [Vec3; 3] = std::array::from_fn(|c| {
            let lerp = |p: f32, q: f32| (p * g + q * f).clamp(p.min(q), p.max(q));
            Vec3::new(lerp(a[c].x, b[c].x), lerp(a[c].y, b[c].y), lerp(a[c].z, b[c].z))
        });
        EmissiveTriangle::new(tri.triangle, p, tri.radiance, tri.two_sided)
    }

    /// The light tree's bounds of light `i` over the whole shutter: the union of its boxes at
    /// the steps (a corner between two steps stays in their box), the largest intensity any
    /// step has, and normals in every direction: a triangle whose corners are interpolated
    /// between steps can face outside the steps' cones, and a cone that left it out would
    /// give it no chance where it lights.
    pub fn bounds(&self, i: usize, tri: &EmissiveTriangle) -> LightBounds {
        let slot = self.slot_of_light[i] as usize;
        let at_step = |k: usize| {
            EmissiveTriangle::new(
                tri.triangle,
                self.corners[slot * self.steps + k],
                tri.radiance,
                tri.two_sided,
            )
        };
        let mut bounds = tri.bounds();
        let mut intensity = bounds.intensity;
        for k in 0..self.steps {
            if let Some(step) = at_step(k) {
                bounds = bounds.union(&step.bounds());
                intensity = intensity.max(luminance(step.radiance) * step.area);
            }
        }
        LightBounds { intensity, cos_theta_o: -1.0, ..bounds }
    }
}
