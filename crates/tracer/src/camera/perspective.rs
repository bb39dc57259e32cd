//! Pinhole perspective camera (pbrt-v4 §5.2): rays from one point through a film at unit
//! distance whose half-height is tan(fov_y / 2).

use super::{Camera, CameraFrame, CameraSample};
use crate::ray::Ray;
use glam::{UVec2, Vec3};

/// A pinhole camera with a vertical field of view.
#[derive(Clone, Debug)]
pub struct Perspective {
    frame: CameraFrame,
    /// tan(fov_y / 2) · (aspect, 1): screen [−1, 1]² to the film plane at z = −1.
    film_scale: glam::Vec2,
}

impl Perspective {
    pub(crate) fn new(frame: CameraFrame, fov_y: f32) -> Self {
        let tan = (0.5 * fov_y).tan();
        Self { film_scale: glam::Vec2::new(tan * frame.aspect(), tan), frame }
    }
}

impl Camera for Perspective {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<Ray> {
        let p = self.frame.screen(sample.p_film) * self.film_scale;
        let dir_camera = Vec3::new(p.x, p.y, -1.0);
        let direction = self.frame.to_world(dir_camera).normalize();
        Some(Ray::new(self.frame.origin, direction, sample.time))
    }

    fn resolution(&self) -> UVec2 {
        self.frame.resolution
    }
}
