//! Watertight ray–triangle intersection (Woop, Benthin & Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013) with pbrt-v4's conservative bound on t (pbrt-v4 §6.8.4) and
//! the floating-point error bound of the barycentric hit point (pbrt-v4 §6.8.5).
//!
//! Watertight: a ray through a shared edge or vertex of a closed mesh hits at least one of the
//! triangles. That holds because the edge functions of a shared edge are computed from the same
//! transformed vertices with the same operations, in f64 from exact f32 products, so the two
//! triangles see exactly opposite values. (obvhs's own Möller–Trumbore test is not watertight.)

use glam::{Vec3, Vec3A};

/// γ(n) = nε / (1 − nε) with ε = 2⁻²⁴ (pbrt-v4 §6.8.1): the bound on the relative error of n
/// rounded f32 operations.
#[inline]
pub(crate) const fn gamma(n: i32) -> f32 {
    let e = n as f32 * (f32::EPSILON * 0.5);
    e / (1.0 - e)
}

/// A ray prepared for the watertight test: the axis permutation that makes z the dominant
/// direction component, the origin in that order, and the shear that maps the direction to +z.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WatertightRay {
    /// Axis indices (x, y, z) of the permuted frame.
    k: [usize; 3],
    /// The origin, permuted.
    origin: [f32; 3],
    sx: f32,
    sy: f32,
    sz: f32,
    /// 2·|sx|/|sz| and 2·|sy|/|sz|: turn the scaled z extent into the bound on the shear
    /// terms |sx·(z − o_z)|, |sy·(z − o_z)| in the t error bound.
    shear_x: f32,
    shear_y: f32,
}

/// Where a ray hits a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TriangleHit {
    /// Ray parameter of the hit (distance, for a unit direction).
    pub t: f32,
    /// Barycentric weights of the three corners.
    pub b: [f32; 3],
}

impl WatertightRay {
    /// Prepares a ray from `origin` along `direction` (any length, not zero), given the
    /// reciprocal of each direction component (shared with the BVH's node tests).
    #[inline]
    pub fn new(origin: Vec3, direction: Vec3, inv_dir: [f32; 3]) -> Self {
        let a = direction.abs();
        let kz = if a.x > a.y {
            if a.x > a.z { 0 } else { 2 }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let kx = if kz == 2 { 0 } else { kz + 1 };
        let ky = if kx == 2 { 0 } else { kx + 1 };
        let d = direction.to_array();
        let o = origin.to_array();
        // d[kz] is the largest component (≥ 1/√3 of the length), so its reciprocal is exact
        // enough; any consistent shear keeps the test watertight.
        let sz = inv_dir[kz];
        let (sx, sy) = (-d[kx] * sz, -d[ky] * sz);
        Self {
            k: [kx, ky, kz],
            origin: [o[kx], o[ky], o[kz]],
            sx,
            sy,
            sz,
            shear_x: 2.0 * (sx / sz).abs(),
            shear_y: 2.0 * (sy / sz).abs(),
        }
    }

    /// Intersects the triangle (p0, p1, p2) within (0, t_max); both faces count.
    #[inline(always)]
    pub fn intersect(&self, tri: &[[f32; 3]; 3], t_max: f32) -> Option<TriangleHit> {
        let [kx, ky, kz] = self.k;
        let [ox, oy, oz] = self.origin;
        // Translate to the ray origin, permute so z is the dominant axis, then shear.
        let (p0z, p1z, p2z) = (tri[0][kz] - oz, tri[1][kz] - oz, tri[2][kz] - oz);
        let p0x = (tri[0][kx] - ox) + self.sx * p0z;
        let p0y = (tri[0][ky] - oy) + self.sy * p0z;
        let p1x = (tri[1][kx] - ox) + self.sx * p1z;
        let p1y = (tri[1][ky] - oy) + self.sy * p1z;
        let p2x = (tri[2][kx] - ox) + self.sx * p2z;
        let p2y = (tri[2][ky] - oy) + self.sy * p2z;

        // Edge functions from exact products (f32 × f32 is exact in f64).
        let e64 = [
            p1x as f64 * p2y as f64 - p1y as f64 * p2x as f64,
            p2x as f64 * p0y as f64 - p2y as f64 * p0x as f64,
            p0x as f64 * p1y as f64 - p0y as f64 * p1x as f64,
        ];
        let [e0, e1, e2] = e64.map(|e| e as f32);
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        // Scaled hit distance, tested against the range before the division.
        let (z0, z1, z2) = (p0z * self.sz, p1z * self.sz, p2z * self.sz);
        let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
        let sheared = Sheared { x: [p0x, p1x, p2x], y: [p0y, p1y, p2y], z: [z0, z1, z2], e: e64 };
        if det == 0.0 {
            // Zero area, or edge functions below f32's range (a triangle on the denormal grid).
            return if e64 == [0.0; 3] { None } else { self.intersect_f64(&sheared, t_max) };
        }
        // Coordinates past ~1e19 from the ray origin overflow f32 here (t came out NaN); below
        // ~1e-15 the products fall under f32's normal range and lose the hit.
        let normal = |x: f32| x.is_finite() && x.abs() >= f32::MIN_POSITIVE;
        if !(normal(det) && normal(t_scaled)) {
            if z0 == 0.0 && z1 == 0.0 && z2 == 0.0 {
                // The triangle lies in the plane across the ray's dominant axis through its
                // origin, which the ray meets only at t = 0: a miss, exactly. This is every
                // ray leaving an axis-aligned wall, tested against the wall's own triangles
                // (the hit point, and so the origin, has no rounding error there), which would
                // go to the f64 path for nothing
                // (docs/performance.md, ledger: "in-plane triangle is a miss").
                return None;
            }
            return self.intersect_f64(&sheared, t_max);
        }
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;

        // Reject hits whose t is not conservatively positive (pbrt-v4 §6.8.4): the error bound
        // of t from the errors of the sheared coordinates and edge functions. The sheared
        // x' = (x − o_x) + sx·(z − o_z) is off by at most γ5·(|x − o_x| + |sx·(z − o_z)|)
        // ≤ γ5·(|x'| + 2|sx|·|z − o_z|). pbrt-v4 bounds the shear term by the scaled z extent
        // alone, which for rays grazing a large triangle (|sx| or |sy| tiny, the hit far along
        // a wide, thin projected triangle) inflates δt past the hit and throws it away.
        let max_zt = z0.abs().max(z1.abs()).max(z2.abs());
        let delta_z = gamma(3) * max_zt;
        let max_xt = p0x.abs().max(p1x.abs()).max(p2x.abs());
        let max_yt = p0y.abs().max(p1y.abs()).max(p2y.abs());
        let delta_x = gamma(5) * (max_xt + self.shear_x * max_zt);
        let delta_y = gamma(5) * (max_yt + self.shear_y * max_zt);
        let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t = 3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
        if !(t.is_finite() && delta_t.is_finite()) {
            // The bound's products overflowed (huge coordinates) or 1/det did (a det on the
            // denormal grid): redo it with f64's range.
            return self.intersect_f64(&sheared, t_max);
        }
        if t <= delta_t {
            return None;
        }
        Some(TriangleHit { t, b: [e0 * inv_det, e1 * inv_det, e2 * inv_det] })
    }

    /// The end of [`WatertightRay::intersect`] in f64, for triangles whose f32 arithmetic
    /// overflows or underflows (coordinates past ~1e19, or on the denormal grid): the same
    /// formulas and the same error bound (the f32 rounding it bounds happened before, in the
    /// sheared coordinates; f64 adds far less). The edge-function signs were already tested on
    /// the f32 values, as for every triangle; they are tested again here for those that
    /// rounded to 0, from the same f64 values a neighbour sharing the edge computes.
    #[cold]
    #[inline(never)]
    fn intersect_f64(&self, s: &Sheared, t_max: f32) -> Option<TriangleHit> {
        let g = |n: i32| gamma(n) as f64;
        let [e0, e1, e2] = s.e;
        // Edge functions that rounded to 0 in f32 passed the sign test there; f64 has them.
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        let t_max = t_max as f64;
        let z = s.z.map(f64::from);
        let t_scaled = e0 * z[0] + e1 * z[1] + e2 * z[2];
        if det == 0.0
            || (det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det))
            || (det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det))
        {
            return None;
        }
        let t = t_scaled / det;
        let max = |v: [f32; 3]| v.iter().fold(0.0f64, |m, x| m.max(x.abs() as f64));
        let (max_xt, max_yt, max_zt) = (max(s.x), max(s.y), max(s.z));
        let delta_z = g(3) * max_zt;
        let delta_x = g(5) * (max_xt + self.shear_x as f64 * max_zt);
        let delta_y = g(5) * (max_yt + self.shear_y as f64 * max_zt);
        let delta_e = 2.0 * (g(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t = 3.0 * (g(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) / det.abs();
        // t is within (0, t_max], so it fits f32; it must stay positive once rounded.
        let t32 = t as f32;
        if !(t > delta_t && t.is_finite() && delta_t.is_finite()) || t32 <= 0.0 {
            return None;
        }
        Some(TriangleHit { t: t32, b: [(e0 / det) as f32, (e1 / det) as f32, (e2 / det) as f32] })
    }
}

/// A triangle in the watertight test's sheared frame: x, y and scaled z of its corners, and
/// its edge functions before rounding to f32 (for [`WatertightRay::intersect_f64`]).
struct Sheared {
    x: [f32; 3],
    y: [f32; 3],
    z: [f32; 3],
    e: [f64; 3],
}

/// The hit point from barycentrics and its absolute error bound per axis (pbrt-v4 §6.8.5):
/// interpolating the corners is far more accurate than `origin + t · direction`.
#[inline]
pub(crate) fn hit_point(tri: &[[f32; 3]; 3], b: [f32; 3]) -> (Vec3, Vec3) {
    let [v0, v1, v2] = tri.map(Vec3A::from_array);
    let (q0, q1, q2) = (v0 * b[0], v1 * b[1], v2 * b[2]);
    let p = q0 + q1 + q2;
    let err = gamma(7) * (q0.abs() + q1.abs() + q2.abs());
    (p.into(), err.into())
}

/// Reciprocals of a direction's components, with zeros (and denormal-small values) mapped to
/// ±1e30 rather than infinity so slab arithmetic never meets 0 × ∞.
#[inline]
pub(crate) fn safe_reciprocal(d: Vec3) -> [f32; 3] {
    d.to_array().map(|x| if x.abs() < 1e-30 { 1e30f32.copysign(x) } else { 1.0 / x })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: Vec3, b: Vec3, c: Vec3) -> [[f32; 3]; 3] {
        [a.to_array(), b.to_array(), c.to_array()]
    }

    fn ray(o: Vec3, d: Vec3) -> WatertightRay {
        WatertightRay::new(o, d, safe_reciprocal(d))
    }

    /// The same hit, scaled by 10^k: t scales with it and stays finite, from the denormal grid
    /// to near f32's limit (from 1e20 on the f32 edge-function products overflowed and t came
    /// out NaN; below ~1e-20 1/det did).
    #[test]
    fn huge_and_tiny_triangles_give_finite_t() {
        for s in [1e-39f32, 1e-30, 1e-20, 1e-10, 1.0, 1e10, 1e19, 1e20, 1e30, 1e36] {
            let t = tri(
                Vec3::new(-1.0, -1.0, 0.0) * s,
                Vec3::new(1.0, -1.0, 0.0) * s,
                Vec3::new(0.0, 1.0, 0.0) * s,
            );
            // Meets z = 0 at (0.25, 0.25)·s, inside.
            let d = Vec3::new(0.05, 0.05, -1.0).normalize();
            let o = Vec3::new(0.0, 0.0, 5.0) * s;
            let h = ray(o, d).intersect(&t, f32::INFINITY).unwrap_or_else(|| panic!("scale {s:e}: miss"));
            let want = 5.0 * s / -d.z;
            assert!(h.t.is_finite() && (h.t / want - 1.0).abs() < 1e-4, "scale {s:e}: t = {} vs {want}", h.t);
            assert!((h.b.iter().sum::<f32>() - 1.0).abs() < 1e-5, "scale {s:e}: {:?}", h.b);
            assert!(ray(o, -d).intersect(&t, f32::INFINITY).is_none(), "scale {s:e}: behind");
            assert!(ray(o, d).intersect(&t, 0.5 * want).is_none(), "scale {s:e}: beyond t_max");
        }
    }

    /// A ray leaving a point of an axis-aligned triangle (no rounding error there, so the
    /// origin is in its plane) never hits that triangle, whichever way it leaves; a triangle
    /// in a parallel plane a hair away still is hit.
    #[test]
    fn rays_from_a_triangles_plane_miss_it() {
        let floor = tri(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 1.0));
        let o = Vec3::new(0.125, 0.0, 0.25);
        for d in [Vec3::Y, -Vec3::Y, Vec3::new(0.3, 0.9, -0.2), Vec3::new(0.6, -0.5, 0.4)] {
            assert!(ray(o, d.normalize()).intersect(&floor, f32::INFINITY).is_none(), "{d}");
        }
        let above = tri(Vec3::new(-1.0, 1e-6, -1.0), Vec3::new(1.0, 1e-6, -1.0), Vec3::new(0.0, 1e-6, 1.0));
        let h = ray(o, Vec3::Y).intersect(&above, f32::INFINITY).expect("the plane just above");
        assert!((h.t - 1e-6).abs() < 1e-12, "{}", h.t);
    }

    #[test]
    fn hits_inside_misses_outside() {
        let t = tri(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
        let r = ray(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let h = r.intersect(&t, f32::INFINITY).unwrap();
        assert!((h.t - 5.0).abs() < 1e-6);
        assert!((h.b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert!(r.intersect(&t, 4.9).is_none(), "beyond t_max");
        assert!(ray(Vec3::new(2.0, 0.0, 5.0), -Vec3::Z).intersect(&t, f32::INFINITY).is_none());
        assert!(ray(Vec3::new(0.0, 0.0, 5.0), Vec3::Z).intersect(&t, f32::INFINITY).is_none(), "behind");
        // Degenerate (zero-area) triangles are never hit.
        let flat = tri(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        assert!(r.intersect(&flat, f32::INFINITY).is_none());
    }

    /// Rays at cos 1e-7 to a 2048-wide plane hit it far away (the t error bound used to throw
    /// these hits away: found by tests/robustness.rs's grazing-ray test).
    #[test]
    fn grazing_rays_hit_large_triangles() {
        let t = tri(
            Vec3::new(-1024.0, 1.5, -1024.0),
            Vec3::new(1024.0, 1.5, -1024.0),
            Vec3::new(0.0, 1.5, 1024.0),
        );
        for (slope, dist) in [(1e-5f32, 5.0f32), (1e-7, 2.0), (1e-7, 250.0), (1e-3, 300.0)] {
            let d = Vec3::new(0.0, -slope, 1.0).normalize();
            let o = Vec3::new(3.0, 1.5 + slope * dist, -100.0);
            let h = ray(o, d).intersect(&t, f32::INFINITY).expect("grazing hit kept");
            // Where this (rounded) ray meets the plane, in f64.
            let want = (o.y as f64 - 1.5) / -(d.y as f64);
            assert!((h.t as f64 - want).abs() < 1e-3 * want, "slope {slope}: t {} vs {want}", h.t);
        }
    }

    /// Rays aimed exactly at the shared (interior) edges and the centre vertex of a fan hit at
    /// least one triangle. (The rim is the mesh's open boundary: a ray there may miss.)
    #[test]
    fn watertight_on_shared_edges() {
        let c = Vec3::new(0.1, 0.2, 0.0);
        let ring: Vec<Vec3> = (0..7)
            .map(|k| {
                let a = k as f32 * std::f32::consts::TAU / 7.0;
                Vec3::new(a.cos() * 1.3, a.sin() * 0.7, 0.05 * k as f32)
            })
            .collect();
        let fan: Vec<[[f32; 3]; 3]> = (0..7).map(|k| tri(c, ring[k], ring[(k + 1) % 7])).collect();
        let origin = Vec3::new(0.3, -0.2, 4.0);
        for (k, &corner) in ring.iter().enumerate() {
            for s in 0..64 {
                let target = c.lerp(corner, s as f32 / 64.0);
                let r = ray(origin, target - origin);
                assert!(
                    fan.iter().any(|t| r.intersect(t, f32::INFINITY).is_some()),
                    "leak at edge {k} step {s}"
                );
            }
        }
    }
}
