//! Overscan: a camera's film enlarged by a border of N pixels on every side, continuing the
//! same projection (docs/design/tracer.md §3.8, `render --overscan N`). Pixel (i + N, j + N) of the
//! enlarged film is exactly pixel (i, j) of the original, so cropping N pixels gives the original
//! view back. Works for every model, since it only shifts film positions; for models with an edge
//! (the fisheye's circle, the panorama's poles) the border shows what the model gives there.

use super::{Camera, CameraSample};
use crate::ray::Ray;
use glam::{UVec2, Vec2};

/// A camera whose film has an extra border of `border` pixels.
pub struct Overscan {
    inner: Box<dyn Camera>,
    border: u32,
}

impl Overscan {
    /// Wraps `inner` (built at the original resolution) with a border of `border` pixels.
    pub fn new(inner: Box<dyn Camera>, border: u32) -> Self {
        Self { inner, border }
    }
}

impl Camera for Overscan {
    #[inline]
    fn generate_ray(&self, sample: &CameraSample) -> Option<Ray> {
        let shifted = CameraSample { p_film: sample.p_film - Vec2::splat(self.border as f32), ..*sample };
        self.inner.generate_ray(&shifted)
    }

    fn resolution(&self) -> UVec2 {
        self.inner.resolution() + UVec2::splat(2 * self.border)
    }

    fn uses_lens(&self) -> bool {
        self.inner.uses_lens()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{CameraDesc, Projection};
    use glam::Vec3;

    #[test]
    fn interior_pixels_are_the_original_view() {
        let desc = CameraDesc::look_at(
            "c",
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::ZERO,
            Vec3::Y,
            Projection::Perspective { fov_y: 0.7 },
        )
        .unwrap();
        let plain = desc.build(UVec2::new(40, 30)).unwrap();
        let over = Overscan::new(desc.build(UVec2::new(40, 30)).unwrap(), 5);
        assert_eq!(over.resolution(), UVec2::new(50, 40));
        for (i, j) in [(0, 0), (39, 29), (17, 3)] {
            let a = plain.generate_ray(&CameraSample::pixel_centre(i, j, 0.0)).unwrap();
            let b = over.generate_ray(&CameraSample::pixel_centre(i + 5, j + 5, 0.0)).unwrap();
            assert_eq!(a, b);
        }
        // The border continues the projection outwards.
        let corner = over.generate_ray(&CameraSample::pixel_centre(0, 0, 0.0)).unwrap();
        let first = plain.generate_ray(&CameraSample::pixel_centre(0, 0, 0.0)).unwrap();
        assert!(corner.direction.angle_between(first.direction) > 0.0);
    }
}
