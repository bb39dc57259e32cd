//! The one generator of random test inputs (renders draw their numbers from `sampler.rs`).

use glam::{DVec3, Vec3};

/// SplitMix64 (Steele, Lea and Flood 2014): tiny, deterministic, good enough to draw random test
/// cases. The state is the seed itself, so a seed names one fixed stream.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// The stream of `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n > 0).
    pub fn below(&mut self, n: u32) -> u32 {
        (self.next_u64() % n as u64) as u32
    }

    /// Uniform in [0, 1), with 24 random bits (every value exact in f32).
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [0, 1), with 53 random bits.
    pub fn unit_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Log-uniform in [lo, hi) (0 < lo < hi), in f64: every scale between equally likely.
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit_f64()).exp()
    }

    /// Uniform in the cube [−h, h)³.
    pub fn in_cube(&mut self, h: f32) -> Vec3 {
        Vec3::new(self.range(-h, h), self.range(-h, h), self.range(-h, h))
    }

    /// A unit vector, uniform over the sphere (by rejection from the cube, away from its
    /// centre).
    pub fn direction(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.unit(), self.unit(), self.unit()) * 2.0 - 1.0;
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }

    /// A unit vector, uniform over the sphere, in f64 (for oracles computed in f64).
    pub fn direction_f64(&mut self) -> DVec3 {
        let z = 1.0 - 2.0 * self.unit_f64();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f64::consts::TAU * self.unit_f64();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// Uniform barycentric coordinates on a triangle.
    pub fn barycentrics(&mut self) -> [f32; 3] {
        let (mut u, mut v) = (self.unit(), self.unit());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        [1.0 - u - v, u, v]
    }
}
