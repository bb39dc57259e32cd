//! Spatial and directional bounds of one light or a cluster of lights, and the importance of
//! such a cluster for a receiving point (docs/design/tracer.md §3.3; Conty & Kulla 2018, "Importance
//! Sampling of Many Lights with Adaptive Tree Splitting"; pbrt-v4 `LightBounds`): a box, a
//! bound on the radiant intensity, and a cone of emission normals — axis `w`, spread θo of the
//! normals, θe beyond the normals over which light still leaves (π/2 for a surface).

use glam::{DVec3, Vec3};

/// What a light (or a cluster of lights) can send where.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Box corner with the smallest coordinates.
    pub lo: Vec3,
    /// Box corner with the largest coordinates.
    pub hi: Vec3,
    /// Unit axis of the cone of emission normals.
    pub w: Vec3,
    /// Bound on the radiant intensity by luminance (W/sr), summed over a cluster.
    pub intensity: f32,
    /// cos θo: the normals lie within θo of `w`.
    pub cos_theta_o: f32,
    /// cos θe: light leaves within θe of some normal.
    pub cos_theta_e: f32,
    /// Light also leaves against the normals (a two-sided emitter).
    pub two_sided: bool,
}

/// Angles added to a merged cone so that rounding never shrinks it below its members (radians).
const CONE_SLACK: f64 = 1e-6;

impl LightBounds {
    /// The centre of the box.
    #[inline]
    pub fn centre(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// The smallest bounds holding both `self` and `other` (the cone slightly widened so that
    /// rounding cannot leave a member's normal outside it).
    pub fn union(&self, other: &Self) -> Self {
        let (w, cos_theta_o) = cone_union(self, other);
        Self {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
            w,
            intensity: self.intensity + other.intensity,
            cos_theta_o,
            cos_theta_e: self.cos_theta_e.min(other.cos_theta_e),
            two_sided: self.two_sided || other.two_sided,
        }
    }

    /// Surface area of the box.
    pub fn area(&self) -> f64 {
        let d = (self.hi - self.lo).as_dvec3();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// The solid-angle measure of the cone (θo plus the spread θe around it) that the build's
    /// cost weighs (Conty & Kulla 2018, eq. 1; pbrt-v4 `EvaluateCost`).
    pub fn orientation_measure(&self) -> f64 {
        use std::f64::consts::PI;
        let cos_o = self.cos_theta_o as f64;
        let theta_o = cos_o.clamp(-1.0, 1.0).acos();
        let theta_e = (self.cos_theta_e as f64).clamp(-1.0, 1.0).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let sin_o = (1.0 - cos_o * cos_o).max(0.0).sqrt();
        2.0 * PI * (1.0 - cos_o)
            + PI / 2.0
                * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o + cos_o)
    }

    /// How much light the bounds can send to a receiver at `p` whose incident directions lie
    /// in the hemisphere around unit `n` (or anywhere, for `n` zero: a receiver that transmits,
    /// rough glass): intensity × the best emission cosine × the best receiver cosine / the
    /// squared distance, each best over the box's directions seen from `p`. Never zero where
    /// some member can light the receiver (conservative), zero where the cones show none can.
    #[inline(always)]
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let centre = self.centre();
        let r2 = 0.25 * (self.hi - self.lo).length_squared();
        let to_p = p - centre;
        let d2 = to_p.length_squared();
        if d2 <= r2 {
            // Inside the bounding sphere every direction is possible; the radius stands in for
            // the distance, which says nothing here.
            return (self.intensity / r2.max(f32::MIN_POSITIVE)).min(MAX_IMPORTANCE);
        }
        let wi = to_p / d2.sqrt();
        // The box seen from p lies within θb of the direction to its centre.
        let sin2_b = r2 / d2;
        let (sin_b, cos_b) = (sin2_b.sqrt(), (1.0 - sin2_b).sqrt());
        let mut cos_w = self.w.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
        let sin_o = (1.0 - self.cos_theta_o * self.cos_theta_o).max(0.0).sqrt();
        // θx = max(0, θw − θo), then θ' = max(0, θx − θb): the angle between p and the nearest
        // direction any member's normal may emit along.
        let (cos_x, sin_x) = cos_sin_sub_clamped(cos_w, sin_w, self.cos_theta_o, sin_o);
        let (cos_p, _) = cos_sin_sub_clamped(cos_x, sin_x, cos_b, sin_b);
        if cos_p < self.cos_theta_e {
            return 0.0;
        }
        // A receiver without a side (rough glass takes light through its surface too) has no
        // receiver cosine to bound, as pbrt-v4's points in media; opaque receivers never take
        // this branch (`n` is loop-invariant in a tree walk, so it costs them a predicted jump).
        if n == Vec3::ZERO {
            return (self.intensity * cos_p.max(MIN_EMISSION_COS) / d2).min(MAX_IMPORTANCE);
        }
        // The receiver's side: the box within θb of the direction towards its centre, −wi.
        let cos_i = -wi.dot(n);
        let sin_i = (1.0 - cos_i * cos_i).max(0.0).sqrt();
        let (cos_ip, _) = cos_sin_sub_clamped(cos_i, sin_i, cos_b, sin_b);
        if cos_ip <= 0.0 {
            return 0.0;
        }
        // A spot's spread may reach past a right angle: its cosine there still counts a little.
        (self.intensity * cos_p.max(MIN_EMISSION_COS) * cos_ip / d2).min(MAX_IMPORTANCE)
    }
}

/// Importances stay finite when added (a receiver on top of a point light).
const MAX_IMPORTANCE: f32 = 1e30;

/// The least emission cosine an importance counts inside the cone (so that it never vanishes
/// where light can leave).
const MIN_EMISSION_COS: f32 = 1e-3;

/// cos and sin of max(0, a − b) from those of a and b (angles in [0, π]).
#[inline(always)]
fn cos_sin_sub_clamped(cos_a: f32, sin_a: f32, cos_b: f32, sin_b: f32) -> (f32, f32) {
    if cos_a >= cos_b { (1.0, 0.0) } else { (cos_a * cos_b + sin_a * sin_b, sin_a * cos_b - cos_a * sin_b) }
}

/// The cone holding both members' cones (pbrt-v4 `Union` of direction cones), computed in f64,
/// widened by [`CONE_SLACK`] and its cosine rounded down to f32.
fn cone_union(a: &LightBounds, b: &LightBounds) -> (Vec3, f32) {
    use std::f64::consts::PI;
    let (wa, wb) = (a.w.as_dvec3(), b.w.as_dvec3());
    let theta_a = (a.cos_theta_o as f64).clamp(-1.0, 1.0).acos();
    let theta_b = (b.cos_theta_o as f64).clamp(-1.0, 1.0).acos();
    let theta_d = angle_between(wa, wb);
    if (theta_d + theta_b).min(PI) <= theta_a {
        return (a.w, cos_down(theta_a + CONE_SLACK));
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return (b.w, cos_down(theta_b + CONE_SLACK));
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    let axis = wa.cross(wb);
    if theta_o >= PI || axis.length_squared() == 0.0 {
        return (Vec3::Z, -1.0);
    }
    // Rotate wa towards wb by θo − θa about their common normal (Rodrigues).
    let k = axis.normalize();
    let (s, c) = (theta_o - theta_a).sin_cos();
    let w = wa * c + k.cross(wa) * s + k * k.dot(wa) * (1.0 - c);
    (w.normalize().as_vec3(), cos_down(theta_o + CONE_SLACK))
}

/// The angle between unit vectors, accurate near 0 and π.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    if a.dot(b) < 0.0 {
        std::f64::consts::PI - 2.0 * (0.5 * (a + b).length()).asin()
    } else {
        2.0 * (0.5 * (b - a).length()).asin()
    }
}

/// cos θ as an f32 no larger than the exact value (the cone never shrinks by rounding).
pub(super) fn cos_down(theta: f64) -> f32 {
    if theta >= std::f64::consts::PI {
        return -1.0;
    }
    let c = theta.cos();
    let f = c as f32;
    if f as f64 > c { f.next_down() } else { f }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface(lo: Vec3, hi: Vec3, w: Vec3) -> LightBounds {
        LightBounds { lo, hi, w, intensity: 1.0, cos_theta_o: 1.0, cos_theta_e: 0.0, two_sided: false }
    }

    #[test]
    fn union_holds_both_cones() {
        let a = surface(Vec3::ZERO, Vec3::ONE, Vec3::X);
        let b = surface(Vec3::ONE, Vec3::splat(2.0), Vec3::Y);
        let u = a.union(&b);
        assert_eq!((u.lo, u.hi), (Vec3::ZERO, Vec3::splat(2.0)));
        for w in [Vec3::X, Vec3::Y] {
            assert!(u.w.dot(w) >= u.cos_theta_o, "{w} outside the merged cone");
        }
        // A quarter turn between the normals: the merged cone spreads π/4 around their bisector.
        assert!((u.cos_theta_o - std::f32::consts::FRAC_PI_4.cos()).abs() < 1e-5);
        let opposite = a.union(&surface(Vec3::ZERO, Vec3::ONE, -Vec3::X));
        assert_eq!(opposite.cos_theta_o, -1.0);
    }

    #[test]
    fn importance_sees_facing_and_distance() {
        let light = surface(Vec3::new(-0.5, -0.5, 0.0), Vec3::new(0.5, 0.5, 0.0), Vec3::Z);
        let below = light.importance(Vec3::new(0.0, 0.0, -2.0), Vec3::Z);
        let above = light.importance(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z);
        let far_above = light.importance(Vec3::new(0.0, 0.0, 4.0), -Vec3::Z);
        assert_eq!(below, 0.0, "a one-sided light lights nothing behind it");
        assert!(above > 3.0 * far_above && far_above > 0.0);
        // A receiver that faces away from the light sees none of it.
        assert_eq!(light.importance(Vec3::new(0.0, 0.0, 2.0), Vec3::Z), 0.0);
        let two_sided = LightBounds { two_sided: true, ..light };
        assert!(two_sided.importance(Vec3::new(0.0, 0.0, -2.0), Vec3::Z) > 0.0);
    }

    /// A receiver without a side (n zero: glass) sees a light whichever way it would have
    /// faced, no less than a receiver facing it, and a point light too (a point's box has no
    /// extent, so a bound that still took a receiver cosine would give it none).
    #[test]
    fn importance_for_a_receiver_without_a_side() {
        let light = surface(Vec3::new(-0.5, -0.5, 0.0), Vec3::new(0.5, 0.5, 0.0), Vec3::Z);
        let p = Vec3::new(0.3, 0.0, 2.0);
        let facing = light.importance(p, -Vec3::Z);
        let any = light.importance(p, Vec3::ZERO);
        assert_eq!(light.importance(p, Vec3::Z), 0.0);
        assert!(any >= facing && facing > 0.0, "{any} vs {facing}");
        assert_eq!(light.importance(Vec3::new(0.0, 0.0, -2.0), Vec3::ZERO), 0.0, "still one-sided");
        let point = LightBounds { lo: Vec3::ZERO, hi: Vec3::ZERO, cos_theta_o: -1.0, ..light };
        for q in [Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, -1.0, 0.0)] {
            assert!(point.importance(q, Vec3::ZERO) > 0.0, "point light from {q}");
        }
    }
}
