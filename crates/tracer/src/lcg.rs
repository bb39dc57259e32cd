//! A deterministic little generator of test inputs (tests only: renders draw their numbers from
//! `sampler.rs`).

use glam::Vec3;

/// A 64-bit linear congruential generator (Knuth's MMIX constants).
pub(crate) struct Lcg(pub(crate) u64);

impl Lcg {
    /// A number in [0, 1) with 24 random bits.
    pub(crate) fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }

    /// A point of the cube [−1, 1)³.
    pub(crate) fn vec(&mut self) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * 2.0 - Vec3::ONE
    }

    /// A unit vector, uniform over the sphere (by rejection from the cube).
    pub(crate) fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec();
            if (0.01..1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }
}
