//! Orthographic camera (pbrt-v4 §5.1; glTF `orthographic` with `ymag` as the half height):
//! parallel rays along −Z from points on the view window.

use super::{Camera, CameraFrame, CameraSample};
use crate::ray::Ray;
use glam::{UVec2, Vec2};

/// Parallel projection through a window `2 · half_height` tall.
#[derive(Clone, Debug)]
pub struct Orthographic {
    frame: CameraFrame,
    /// Half extents of the view window (x from the film's aspect ratio).
    half_extent: Vec2,
}

impl Orthographic {
    pub(crate) fn new(frame: CameraFrame, half_height: f32) -> Self {
        Self { half_extent: Vec2::new(half_height * frame.aspect(), half_height), frame }
    }
}

impl Camera for Orthographic {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<Ray> {
        let p = self.frame.screen(sample.p_film) * self.half_extent;
        let origin = self.frame.origin + p.x * self.frame.right + p.y * self.frame.up;
        Some(Ray::new(origin, -self.frame.back, sample.time))
    }

    fn resolution(&self) -> UVec2 {
        self.frame.resolution
    }
}
