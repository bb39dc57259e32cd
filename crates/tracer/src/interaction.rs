//! A ray's hit on a surface, and spawning rays from it without self-intersection at any scene
//! scale (docs/design/tracer.md §3.4): origins are pushed off the surface along the geometric normal
//! by the hit point's floating-point error bound and rounded away from it (pbrt-v4 §6.8.6),
//! never by a fixed epsilon.

use crate::ray::Ray;
use crate::sampling::Frame;
use glam::Vec3;

/// Geometry at a ray–surface hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    /// The hit point.
    pub p: Vec3,
    /// Absolute error bound of `p` per axis.
    pub p_error: Vec3,
    /// Unit geometric normal of the triangle's front face (counter-clockwise winding).
    pub n_geom: Vec3,
    /// The shading frame: its z is the unit shading normal (interpolated vertex normals, or
    /// `n_geom` with the triangle's precomputed tangents).
    pub shading: Frame,
    /// The mesh triangle hit (a shared mesh's, in its own space, for a copy of one).
    pub triangle: u32,
    /// Its slot in the BVH (which copy, for a copy of a shared mesh).
    pub slot: u32,
    /// Its material.
    pub material: u32,
}

impl SurfaceInteraction {
    /// A ray leaving the surface in direction `w` (unit).
    #[inline(always)]
    pub fn spawn_ray(&self, w: Vec3, time: f32) -> Ray {
        Ray::new(offset_ray_origin(self.p, self.p_error, self.n_geom, w), w, time)
    }

    /// A shadow ray towards `target` (on a surface with normal `target_n` and error
    /// `target_error`; a zero normal for a point), and the t up to which blockers count.
    #[inline(always)]
    pub fn spawn_ray_to(
        &self,
        target: Vec3,
        target_error: Vec3,
        target_n: Vec3,
        time: f32,
    ) -> Option<(Ray, f32)> {
        let origin = offset_ray_origin(self.p, self.p_error, self.n_geom, target - self.p);
        let end = if target_n == Vec3::ZERO {
            target
        } else {
            offset_ray_origin(target, target_error, target_n, origin - target)
        };
        let d = end - origin;
        let dist = d.length();
        if !(dist > 0.0) || !dist.is_finite() {
            return None;
        }
        // Stop just short of the (already offset) end point: rounding in `dist` and in the
        // blocker's t is a few ulps, far below this margin.
        Some((Ray::new(origin, d / dist, time), dist * (1.0 - 1.0 / 65536.0)))
    }
}

/// `p` pushed off its surface (normal `n`) to the side `w` points to, far enough that the
/// rounding error in `p` cannot put it back on the other side.
#[inline(always)]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let offset = if w.dot(n) < 0.0 { -d * n } else { d * n };
    let po = p + offset;
    // Round away from p so the offset is never lost to rounding.
    let away = |x: f32, o: f32| {
        if o > 0.0 {
            x.next_up()
        } else if o < 0.0 {
            x.next_down()
        } else {
            x
        }
    };
    Vec3::new(away(po.x, offset.x), away(po.y, offset.y), away(po.z, offset.z))
}
