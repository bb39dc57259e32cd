//! An emissive triangle as a light: uniform area sampling (Heitz's low-distortion warp keeps
//! the 2-D stratification), converted to solid angle at the receiver (pbrt-v4 §12.3).

use super::bounds::LightBounds;
use crate::sampling::sample_uniform_triangle;
use crate::triangle::gamma;
use glam::{Vec2, Vec3};

/// A triangle that emits constant radiance from its front face (or both).
#[derive(Clone, Copy, Debug)]
pub struct EmissiveTriangle {
    /// Corners, counter-clockwise seen from the front.
    pub p: [Vec3; 3],
    /// Unit front-face normal.
    pub n: Vec3,
    /// Area.
    pub area: f32,
    /// Emitted radiance.
    pub radiance: Vec3,
    /// Whether the back face emits too.
    pub two_sided: bool,
    /// The mesh triangle (for emissive textures, looked up at the sampled point).
    pub triangle: u32,
}

/// A point sampled on an emissive triangle.
#[derive(Clone, Copy, Debug)]
pub struct AreaSample {
    /// The point.
    pub p: Vec3,
    /// Its floating-point error bound.
    pub p_error: Vec3,
    /// Front normal there.
    pub n: Vec3,
    /// Barycentric weights of the corners there.
    pub b: [f32; 3],
}

impl EmissiveTriangle {
    /// The light for mesh triangle `triangle` with corners `p` (None if degenerate).
    pub fn new(triangle: u32, p: [Vec3; 3], radiance: Vec3, two_sided: bool) -> Option<Self> {
        let c = (p[1] - p[0]).cross(p[2] - p[0]);
        let area = 0.5 * c.length();
        (area > 0.0 && area.is_finite()).then(|| Self {
            p,
            n: c.normalize(),
            area,
            radiance,
            two_sided,
            triangle,
        })
    }

    /// Emitted power, by luminance (the weight for choosing among lights).
    pub fn power(&self) -> f64 {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        luminance(self.radiance) as f64 * self.area as f64 * std::f64::consts::PI * sides
    }

    /// Its bounds for the light tree: the corners' box, the normal (both ways if two-sided), and
    /// the largest intensity, L·A, straight along the normal.
    pub fn bounds(&self) -> LightBounds {
        let [a, b, c] = self.p;
        LightBounds {
            lo: a.min(b).min(c),
            hi: a.max(b).max(c),
            w: self.n,
            intensity: luminance(self.radiance) * self.area,
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided: self.two_sided,
        }
    }

    /// A uniformly distributed point on the triangle.
    #[inline]
    pub fn sample(&self, u: Vec2) -> AreaSample {
        let b = sample_uniform_triangle(u);
        let (q0, q1, q2) = (self.p[0] * b[0], self.p[1] * b[1], self.p[2] * b[2]);
        let p = q0 + q1 + q2;
        let p_error = gamma(6) * (q0.abs() + q1.abs() + q2.abs());
        AreaSample { p, p_error, n: self.n, b }
    }

    /// Radiance leaving the light towards `w` (a direction *from* the light).
    #[inline]
    pub fn emitted(&self, w: Vec3) -> Vec3 {
        if self.two_sided || self.n.dot(w) > 0.0 { self.radiance } else { Vec3::ZERO }
    }

    /// Solid-angle density at a receiver `dist` away seeing the light along `wi` (towards it),
    /// given the point was chosen uniformly by area.
    #[inline]
    pub fn pdf_solid_angle(&self, dist: f32, wi: Vec3) -> f32 {
        let cos = self.n.dot(wi).abs();
        if cos == 0.0 { 0.0 } else { dist * dist / (self.area * cos) }
    }
}

/// Rec. 709 luminance of linear RGB.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}
