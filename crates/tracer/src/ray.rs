//! A ray in world (render) space: the unit the camera, the lens shaders and the integrator pass
//! around (docs/design/tracer.md §3.8).

use glam::Vec3;

/// A world-space ray with a unit direction and a time (in frames) for motion blur.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts, in world space.
    pub origin: Vec3,
    /// Unit direction, in world space.
    pub direction: Vec3,
    /// Scene time of the ray, in frames (the frame number plus the shutter offset).
    pub time: f32,
}

impl Ray {
    /// A ray from `origin` along `direction` (must be unit length) at `time`.
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3, time: f32) -> Self {
        debug_assert!(direction.is_normalized(), "ray direction {direction} not unit");
        Self { origin, direction, time }
    }

    /// The point at parameter `t` along the ray.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.direction
    }

    /// True when origin and direction are finite and the direction is unit length to 1e-4.
    pub fn is_valid(&self) -> bool {
        self.origin.is_finite()
            && self.direction.is_finite()
            && (self.direction.length_squared() - 1.0).abs() < 2e-4
            && self.time.is_finite()
    }
}
