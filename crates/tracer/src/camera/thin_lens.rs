//! Thin-lens camera (pbrt-v4 §5.2.3): depth of field. A ray leaves a point on the aperture disk
//! towards the point on the plane of focus that the pinhole ray through the same film position
//! reaches.

use super::{Camera, CameraFrame, CameraSample};
use crate::ray::Ray;
use crate::sampling::sample_uniform_disk_concentric;
use glam::{UVec2, Vec2, Vec3};

/// A perspective camera with a circular aperture focused at a distance.
#[derive(Clone, Debug)]
pub struct ThinLens {
    frame: CameraFrame,
    film_scale: Vec2,
    lens_radius: f32,
    focus_distance: f32,
}

impl ThinLens {
    pub(crate) fn new(frame: CameraFrame, fov_y: f32, lens_radius: f32, focus_distance: f32) -> Self {
        let tan = (0.5 * fov_y).tan();
        Self { film_scale: Vec2::new(tan * frame.aspect(), tan), frame, lens_radius, focus_distance }
    }
}

impl Camera for ThinLens {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<Ray> {
        let p = self.frame.screen(sample.p_film) * self.film_scale;
        // Point in focus, camera space: the pinhole ray scaled to reach z = −focus_distance.
        let p_focus = Vec3::new(p.x, p.y, -1.0) * self.focus_distance;
        let p_lens = self.lens_radius * sample_uniform_disk_concentric(sample.p_lens);
        let p_lens = Vec3::new(p_lens.x, p_lens.y, 0.0);
        let direction = self.frame.to_world(p_focus - p_lens).normalize();
        let origin = self.frame.origin + self.frame.to_world(p_lens);
        Some(Ray::new(origin, direction, sample.time))
    }

    fn resolution(&self) -> UVec2 {
        self.frame.resolution
    }

    fn uses_lens(&self) -> bool {
        self.lens_radius > 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{CameraDesc, Projection};

    /// Every lens sample of one film position meets the plane of focus at the same point.
    #[test]
    fn rays_converge_on_the_focus_plane() {
        let desc = CameraDesc::look_at(
            "dof",
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(1.0, 2.0, -10.0),
            Vec3::Y,
            Projection::ThinLens { fov_y: 0.8, lens_radius: 0.3, focus_distance: 4.0 },
        )
        .unwrap();
        let cam = desc.build(UVec2::new(32, 16)).unwrap();
        let p_film = Vec2::new(7.3, 11.9);
        let meet = |u: Vec2| {
            let r = cam.generate_ray(&CameraSample { p_film, p_lens: u, time: 0.0 }).unwrap();
            // Plane of focus: z = 3 − 4 = −1 in world space.
            let t = (-1.0 - r.origin.z) / r.direction.z;
            r.at(t)
        };
        let centre = meet(Vec2::splat(0.5));
        for u in [Vec2::new(0.0, 0.0), Vec2::new(0.9, 0.1), Vec2::new(0.3, 0.99)] {
            assert!((meet(u) - centre).length() < 1e-5);
        }
    }
}
