//! Equirectangular (latitude–longitude) panorama: x spans longitude −180° … 180° with the view
//! direction at the centre, y spans latitude 90° (top) … −90° (bottom).

use super::{Camera, CameraFrame, CameraSample};
use crate::ray::Ray;
use glam::{UVec2, Vec3};
use std::f32::consts::{PI, TAU};

/// A full-sphere panorama camera (a non-linear camera model).
#[derive(Clone, Debug)]
pub struct Equirectangular {
    frame: CameraFrame,
}

impl Equirectangular {
    pub(crate) fn new(frame: CameraFrame) -> Self {
        Self { frame }
    }
}

impl Camera for Equirectangular {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<Ray> {
        let phi = (sample.p_film.x / self.frame.resolution.x as f32 - 0.5) * TAU;
        let lat = (0.5 - sample.p_film.y / self.frame.resolution.y as f32) * PI;
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (sin_lat, cos_lat) = lat.sin_cos();
        let dir_camera = Vec3::new(sin_phi * cos_lat, sin_lat, -cos_phi * cos_lat);
        let direction = self.frame.to_world(dir_camera).normalize();
        Some(Ray::new(self.frame.origin, direction, sample.time))
    }

    fn resolution(&self) -> UVec2 {
        self.frame.resolution
    }
}
