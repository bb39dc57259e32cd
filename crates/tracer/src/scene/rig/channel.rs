//! Keyframe animation channels: one animated property of one node, sampled at any time (glTF 2.0
//! §3.11 and Appendix C).
//!
//! Sampling (glTF Appendix C): a time before the first key or after the last is clamped to that
//! key; STEP holds the previous key; LINEAR lerps translation and scale and slerps rotations
//! (shortest path, normalised); CUBICSPLINE evaluates the cubic Hermite spline through the keys
//! with the in- and out-tangents scaled by the key interval, and normalises rotations.

use glam::{DVec4, Vec4};

/// Which part of a node's transform, or which of its morph weights, a channel animates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(in crate::scene) enum Property {
    /// The translation (xyz).
    Translation,
    /// The rotation quaternion (xyzw).
    Rotation,
    /// The scale (xyz).
    Scale,
    /// Morph-target weights 4g … 4g + 3 (a glTF `weights` channel is split into groups of four,
    /// each interpolated component by component like a translation).
    Weights(u16),
}

impl Property {
    /// Where an animated node keeps this property's channel (see `Animated` in the parent
    /// module): the transform's three slots, then one per group of weights.
    pub(super) fn slot(self) -> usize {
        match self {
            Self::Translation => 0,
            Self::Rotation => 1,
            Self::Scale => 2,
            Self::Weights(g) => 3 + usize::from(g),
        }
    }
}

impl std::fmt::Display for Property {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Translation => f.write_str("translation"),
            Self::Rotation => f.write_str("rotation"),
            Self::Scale => f.write_str("scale"),
            Self::Weights(g) => write!(f, "morph weights {}..={}", 4 * g, 4 * g + 3),
        }
    }
}

/// How a channel's value varies between keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(in crate::scene) enum Interpolation {
    /// The previous key's value, held.
    Step,
    /// Lerp (translation, scale) or slerp (rotation) between the two keys.
    Linear,
    /// Cubic Hermite spline; each key has an in-tangent, a value and an out-tangent.
    CubicSpline,
}

/// One animated property of one node: key times and values.
#[derive(Clone, Debug)]
pub(in crate::scene) struct Channel {
    /// The node of the [`Rig`](super::Rig) it animates.
    pub node: usize,
    /// What it animates.
    pub property: Property,
    interpolation: Interpolation,
    /// Key times in seconds, finite and strictly increasing, at least one.
    times: Vec<f32>,
    /// One value per key (translation and scale in xyz, w = 0; rotations as xyzw), or for
    /// CUBICSPLINE three: in-tangent, value, out-tangent.
    values: Vec<Vec4>,
}

impl Channel {
    /// Checks the keys (the message names the key at fault); STEP and LINEAR rotations are
    /// normalised, since exporters write unit quaternions only to float precision.
    pub(in crate::scene) fn new(
        node: usize,
        property: Property,
        interpolation: Interpolation,
        times: Vec<f32>,
        mut values: Vec<Vec4>,
    ) -> Result<Self, String> {
        if times.is_empty() {
            return Err("the sampler has no keys".to_owned());
        }
        for (k, &t) in times.iter().enumerate() {
            if !t.is_finite() {
                return Err(format!("key {k}: time {t} is not finite"));
            }
            if k > 0 && t <= times[k - 1] {
                return Err(format!(
                    "key {k}: time {t} s is not after key {}'s {} s (key times must increase strictly)",
                    k - 1,
                    times[k - 1]
                ));
            }
        }
        let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
        if values.len() != times.len() * per_key {
            let how = if per_key == 3 { "three (in-tangent, value, out-tangent)" } else { "one" };
            return Err(format!(
                "{} output values for {} keys; {interpolation:?} needs {how} per key",
                values.len(),
                times.len()
            ));
        }
        for (i, v) in values.iter().enumerate() {
            let (k, role) = (
                i / per_key,
                if per_key == 3 { ["in-tangent", "value", "out-tangent"][i % 3] } else { "value" },
            );
            if !v.is_finite() {
                return Err(format!("key {k}: {property} {role} {v} is not finite"));
            }
            if property == Property::Rotation && role == "value" && v.length_squared() < 1e-12 {
                return Err(format!("key {k}: rotation quaternion {v} is zero; it is no rotation"));
            }
        }
        if property == Property::Rotation && per_key == 1 {
            values.iter_mut().for_each(|q| *q = q.normalize());
        }
        Ok(Self { node, property, interpolation, times, values })
    }

    /// The last key's time.
    pub(in crate::scene) fn end(&self) -> f32 {
        self.times.last().copied().unwrap_or(0.0)
    }

    /// The value of key `k`.
    fn value(&self, k: usize) -> Vec4 {
        match self.interpolation {
            Interpolation::CubicSpline => self.values[3 * k + 1],
            _ => self.values[k],
        }
    }

    /// The animated value at `t` seconds, clamped to the key range (rotations normalised).
    pub(in crate::scene) fn sample(&self, t: f32) -> Vec4 {
        let last = self.times.len() - 1;
        if t.is_nan() || t <= self.times[0] {
            return self.finish(self.value(0), self.value(0));
        }
        if t >= self.times[last] {
            return self.finish(self.value(last), self.value(last));
        }
        // times[k] ≤ t < times[k + 1]
        let k = self.times.partition_point(|&s| s <= t) - 1;
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let dt = t1 - t0;
        let u = ((t - t0) / dt).clamp(0.0, 1.0);
        let (a, b) = (self.value(k), self.value(k + 1));
        let v = match (self.interpolation, self.property) {
            (Interpolation::Step, _) => a,
            (Interpolation::Linear, Property::Rotation) => slerp(a, b, u),
            (Interpolation::Linear, _) => a.lerp(b, u),
            (Interpolation::CubicSpline, _) => {
                // p(u) = (2u³ − 3u² + 1) p0 + (u³ − 2u² + u) m0 + (−2u³ + 3u²) p1 + (u³ − u²) m1,
                // m0 = dt · out-tangent of key k, m1 = dt · in-tangent of key k + 1.
                let m0 = self.values[3 * k + 2] * dt;
                let m1 = self.values[3 * (k + 1)] * dt;
                let (u2, u3) = (u * u, u * u * u);
                a * (2.0 * u3 - 3.0 * u2 + 1.0)
                    + m0 * (u3 - 2.0 * u2 + u)
                    + b * (-2.0 * u3 + 3.0 * u2)
                    + m1 * (u3 - u2)
            }
        };
        self.finish(v, if u < 0.5 { a } else { b })
    }

    /// Normalises a rotation (falling back on `nearest`, a key's value, if a spline passes
    /// through zero); translation and scale pass through.
    fn finish(&self, v: Vec4, nearest: Vec4) -> Vec4 {
        if self.property != Property::Rotation {
            return v;
        }
        let n = v.normalize_or_zero();
        if n == Vec4::ZERO || !n.is_finite() { nearest.normalize() } else { n }
    }
}

/// Spherical linear interpolation of unit quaternions along the shorter arc (glTF Appendix C),
/// in double precision.
fn slerp(a: Vec4, b: Vec4, u: f32) -> Vec4 {
    let (a, mut b, u) = (a.as_dvec4(), b.as_dvec4(), f64::from(u));
    let mut dot = a.dot(b);
    if dot < 0.0 {
        // q and −q are the same rotation: take the short way round.
        b = -b;
        dot = -dot;
    }
    let theta0 = dot.min(1.0).acos();
    let q: DVec4 = if theta0 < 1e-6 {
        a.lerp(b, u)
    } else {
        let s = theta0.sin();
        a * (((1.0 - u) * theta0).sin() / s) + b * ((u * theta0).sin() / s)
    };
    q.normalize().as_vec4()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    fn channel(
        property: Property,
        interpolation: Interpolation,
        times: &[f32],
        values: &[[f32; 4]],
    ) -> Channel {
        let values = values.iter().map(|v| Vec4::from(*v)).collect();
        Channel::new(0, property, interpolation, times.to_vec(), values).unwrap()
    }

    fn close(a: Vec4, b: Vec4, tol: f32) -> bool {
        (a - b).abs().max_element() <= tol
    }

    #[track_caller]
    fn check(c: &Channel, t: f32, want: [f32; 4]) {
        let got = c.sample(t);
        assert!(close(got, Vec4::from(want), 1e-6), "t = {t}: {got} vs {want:?}");
    }

    #[test]
    fn step_holds_the_previous_key_and_clamps() {
        let c = channel(
            Property::Translation,
            Interpolation::Step,
            &[1.0, 2.0, 4.0],
            &[[1.0, 0.0, 0.0, 0.0], [0.0, 5.0, 0.0, 0.0], [0.0, 0.0, 9.0, 0.0]],
        );
        check(&c, -3.0, [1.0, 0.0, 0.0, 0.0]); // before the first key: the first
        check(&c, 1.0, [1.0, 0.0, 0.0, 0.0]);
        check(&c, 1.999, [1.0, 0.0, 0.0, 0.0]); // held until the next key
        check(&c, 2.0, [0.0, 5.0, 0.0, 0.0]);
        check(&c, 3.99, [0.0, 5.0, 0.0, 0.0]);
        check(&c, 4.0, [0.0, 0.0, 9.0, 0.0]);
        check(&c, 100.0, [0.0, 0.0, 9.0, 0.0]); // after the last key: the last
        check(&c, f32::NAN, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(c.end(), 4.0);
        // A rotation held by STEP is the (normalised) key, not blended.
        let r = channel(
            Property::Rotation,
            Interpolation::Step,
            &[0.0, 1.0],
            &[[0.0, 0.0, 0.0, 2.0], [0.0, 0.0, 1.0, 0.0]],
        );
        check(&r, 0.75, [0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn linear_lerps_translation_and_scale() {
        let keys = [[0.0, 0.0, 0.0, 0.0], [2.0, 4.0, -2.0, 0.0], [2.0, 0.0, 6.0, 0.0]];
        for property in [Property::Translation, Property::Scale] {
            let c = channel(property, Interpolation::Linear, &[1.0, 3.0, 4.0], &keys);
            check(&c, 0.0, [0.0, 0.0, 0.0, 0.0]);
            check(&c, 1.5, [0.5, 1.0, -0.5, 0.0]); // a quarter of the way from key 0 to key 1
            check(&c, 3.0, [2.0, 4.0, -2.0, 0.0]);
            check(&c, 3.5, [2.0, 2.0, 2.0, 0.0]); // halfway from key 1 to key 2
            check(&c, 7.0, [2.0, 0.0, 6.0, 0.0]);
        }
    }

    /// Slerp written independently of the code under test: q(u) = a · (a⁻¹ b)^u, the power
    /// taken through the axis–angle form, along the shorter arc.
    fn reference_slerp(a: DQuat, b: DQuat, u: f64) -> DQuat {
        let b = if a.dot(b) < 0.0 { -b } else { b };
        let delta = a.inverse() * b;
        let (axis, angle) = delta.to_axis_angle();
        (a * DQuat::from_axis_angle(axis, angle * u)).normalize()
    }

    fn same_rotation(a: Vec4, b: DQuat, tol: f64) -> bool {
        let a = a.as_dvec4();
        let b = DVec4::new(b.x, b.y, b.z, b.w);
        // q and −q are the same rotation.
        (a - b).abs().max_element() <= tol || (a + b).abs().max_element() <= tol
    }

    #[test]
    fn linear_slerps_rotation_along_the_shorter_arc() {
        let a = DQuat::from_axis_angle(glam::DVec3::new(1.0, 2.0, 2.0).normalize(), 0.3);
        let b = DQuat::from_axis_angle(glam::DVec3::new(-1.0, 0.5, 0.0).normalize(), 2.6);
        let q = |q: DQuat| [q.x as f32, q.y as f32, q.z as f32, q.w as f32];
        // Key 2 is key 1 negated: the same rotation, so nothing moves between them.
        let c = channel(Property::Rotation, Interpolation::Linear, &[0.0, 2.0, 3.0], &[q(a), q(b), q(-b)]);
        for t in [0.1f32, 0.5, 1.0, 1.3, 1.9] {
            let want = reference_slerp(a, b, f64::from(t) / 2.0);
            let got = c.sample(t);
            assert!(same_rotation(got, want, 2e-6), "t = {t}: {got} vs {want}");
            assert!((got.length() - 1.0).abs() < 1e-6);
            // Not a normalised lerp: at large angles the two differ measurably between the keys
            // (though not at the midpoint, where they agree by symmetry).
            let nlerp = (DVec4::from(q(a).map(f64::from)) * (1.0 - f64::from(t) / 2.0)
                + DVec4::from(q(b).map(f64::from)) * (f64::from(t) / 2.0))
                .normalize();
            if t == 0.5 || t == 1.3 {
                assert!((got.as_dvec4() - nlerp).abs().max_element() > 1e-3, "t = {t}: slerp equals nlerp");
            }
        }
        for t in [2.0f32, 2.25, 2.5, 2.99, 3.0, 9.0] {
            assert!(same_rotation(c.sample(t), b, 2e-6), "t = {t}: {}", c.sample(t));
        }
        assert!(same_rotation(c.sample(-1.0), a, 1e-7));
        // From a to −b: still the short way round (the same path as a to b).
        let short = channel(Property::Rotation, Interpolation::Linear, &[0.0, 1.0], &[q(a), q(-b)]);
        assert!(same_rotation(short.sample(0.5), reference_slerp(a, b, 0.5), 2e-6));
        // Nearly identical keys fall back on a lerp without dividing by sin θ ≈ 0.
        let tiny = DQuat::from_rotation_z(1e-8);
        let near =
            channel(Property::Rotation, Interpolation::Linear, &[0.0, 1.0], &[q(DQuat::IDENTITY), q(tiny)]);
        assert!(near.sample(0.5).is_finite() && same_rotation(near.sample(0.5), DQuat::IDENTITY, 1e-7));
    }

    #[test]
    fn cubic_spline_by_hand() {
        // Keys at t = 1 and t = 3 (dt = 2), translation x only:
        //   key 0: in-tangent 9 (unused), value 1, out-tangent 2
        //   key 1: in-tangent −1, value 4, out-tangent 7 (unused)
        // At t = 2: u = 0.5, h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = −0.125, so
        //   p = 0.5·1 + 0.125·(2·2) + 0.5·4 − 0.125·(2·−1) = 0.5 + 0.5 + 2 + 0.25 = 3.25.
        // At t = 1.5: u = 0.25, h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = −0.046875:
        //   p = 0.84375 + 0.140625·4 + 0.15625·4 − 0.046875·(−2) = 2.125.
        let c = channel(
            Property::Translation,
            Interpolation::CubicSpline,
            &[1.0, 3.0],
            &[
                [9.0, 0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0, 0.0],
                [-1.0, 0.0, 0.0, 0.0],
                [4.0, 0.0, 0.0, 0.0],
                [7.0, 0.0, 0.0, 0.0],
            ],
        );
        check(&c, 2.0, [3.25, 0.0, 0.0, 0.0]);
        check(&c, 1.5, [2.125, 0.0, 0.0, 0.0]);
        check(&c, 0.0, [1.0, 0.0, 0.0, 0.0]); // clamped to the values, never the tangents
        check(&c, 1.0, [1.0, 0.0, 0.0, 0.0]);
        check(&c, 3.0, [4.0, 0.0, 0.0, 0.0]);
        check(&c, 5.0, [4.0, 0.0, 0.0, 0.0]);

        // Rotations are normalised: from identity to 90° about z with zero tangents, the spline
        // at u = 0.5 is h00 · key 0 + h01 · key 1 = the plain average of the two keys, which is
        // then normalised.
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let zero = [0.0; 4];
        let r = channel(
            Property::Rotation,
            Interpolation::CubicSpline,
            &[0.0, 1.0],
            &[zero, [0.0, 0.0, 0.0, 1.0], zero, zero, [0.0, 0.0, h, h], zero],
        );
        let mid = Vec4::new(0.0, 0.0, h / 2.0, (1.0 + h) / 2.0);
        assert!(close(r.sample(0.5), mid.normalize(), 1e-6), "{}", r.sample(0.5));
        assert!((r.sample(0.3).length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn bad_keys_are_refused_naming_the_key() {
        let v = |n: usize| vec![Vec4::ONE; n];
        let make = |times: &[f32], values: Vec<Vec4>, i: Interpolation| {
            Channel::new(0, Property::Rotation, i, times.to_vec(), values).unwrap_err()
        };
        let e = make(&[0.0, 1.0, 1.0], v(3), Interpolation::Linear);
        assert!(e.contains("key 2") && e.contains("increase strictly"), "{e}");
        let e = make(&[0.0, f32::NAN], v(2), Interpolation::Linear);
        assert!(e.contains("key 1") && e.contains("not finite"), "{e}");
        let e = make(&[0.0, 1.0], v(3), Interpolation::Step);
        assert!(e.contains("3 output values for 2 keys"), "{e}");
        let e = make(&[0.0, 1.0], v(2), Interpolation::CubicSpline);
        assert!(e.contains("2 output values for 2 keys") && e.contains("three"), "{e}");
        let mut nan = v(2);
        nan[1].y = f32::NAN;
        let e = make(&[0.0, 1.0], nan, Interpolation::Linear);
        assert!(e.contains("key 1") && e.contains("not finite"), "{e}");
        let mut zero = v(6);
        zero[4] = Vec4::ZERO; // key 1's value; zero tangents are fine
        zero[0] = Vec4::ZERO;
        let e = make(&[0.0, 1.0], zero, Interpolation::CubicSpline);
        assert!(e.contains("key 1") && e.contains("zero"), "{e}");
        assert!(make(&[], v(0), Interpolation::Linear).contains("no keys"));
    }
}
