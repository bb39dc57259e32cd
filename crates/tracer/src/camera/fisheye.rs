//! Equidistant fisheye: the angle from the view axis grows linearly with the distance from the
//! film centre; the image circle is inscribed in the film and spans `fov`. Film positions outside
//! the circle give no ray (the film stays black there).

use super::{Camera, CameraFrame, CameraSample};
use crate::ray::Ray;
use glam::{UVec2, Vec2, Vec3};

/// An equidistant fisheye lens (a non-linear camera model).
#[derive(Clone, Debug)]
pub struct Fisheye {
    frame: CameraFrame,
    /// Screen coordinates scaled so the inscribed image circle has radius 1.
    circle_scale: Vec2,
    half_fov: f32,
}

impl Fisheye {
    pub(crate) fn new(frame: CameraFrame, fov: f32) -> Self {
        let aspect = frame.aspect();
        let circle_scale = if aspect >= 1.0 { Vec2::new(aspect, 1.0) } else { Vec2::new(1.0, 1.0 / aspect) };
        Self { frame, circle_scale, half_fov: 0.5 * fov }
    }
}

impl Camera for Fisheye {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<Ray> {
        let p = self.frame.screen(sample.p_film) * self.circle_scale;
        let r = p.length();
        if r > 1.0 {
            return None;
        }
        let theta = r * self.half_fov;
        let (sin_t, cos_t) = theta.sin_cos();
        let (cos_phi, sin_phi) = if r > 0.0 { (p.x / r, p.y / r) } else { (1.0, 0.0) };
        let dir_camera = Vec3::new(sin_t * cos_phi, sin_t * sin_phi, -cos_t);
        let direction = self.frame.to_world(dir_camera).normalize();
        Some(Ray::new(self.frame.origin, direction, sample.time))
    }

    fn resolution(&self) -> UVec2 {
        self.frame.resolution
    }
}
