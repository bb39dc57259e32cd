//! Sample generation (SPEC §3, "Sampling and determinism"): every random number is a pure
//! function of (pixel, sample index, dimension, seed), so an image is the same bit for bit
//! whatever the thread count or tile order.
//!
//! The sequence is Owen-scrambled Sobol (Burley, "Practical Hash-based Owen Scrambling", JCGT
//! 9(4), 2020) from the `sobol_burley` crate, *padded* in 4-D sets: each set of four dimensions
//! is an independently shuffled and scrambled copy of Sobol dimensions 0–3 (Burley §4), seeded
//! by a hash of the pixel, the user seed and the set's index. Each pixel therefore gets its own
//! randomised low-discrepancy sequence (error falls faster than with independent samples) while
//! neighbouring pixels stay decorrelated (noise, not structured artefacts).

use glam::{UVec2, Vec2};

/// The largest sample count per pixel the sequence supports (sobol_burley's 2^16).
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 16;

/// The random numbers of one sample of one pixel, handed out in 4-D sets.
#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    pixel_seed: u32,
    index: u32,
    set: u32,
}

impl Sampler {
    /// The sampler for sample `index` of `pixel` under `seed`.
    #[inline]
    pub fn new(pixel: UVec2, index: u32, seed: u32) -> Self {
        debug_assert!(index < MAX_SAMPLES_PER_PIXEL);
        let pixel_seed = hash(pixel.x ^ hash(pixel.y ^ hash(seed)));
        Self { pixel_seed, index, set: 0 }
    }

    /// Skips to dimension set `set` (sets are how the integrator assigns dimensions to uses).
    #[inline]
    pub fn start_set(&mut self, set: u32) {
        self.set = set;
    }

    /// The next four dimensions (one padded 4-D set): the first two form a well-stratified 2-D
    /// pattern and are the ones to use for 2-D decisions.
    #[inline]
    pub fn next_4d(&mut self) -> [f32; 4] {
        let seed = hash(self.pixel_seed ^ self.set.wrapping_mul(0x9e37_79b9));
        self.set += 1;
        sobol_burley::sample_4d(self.index, 0, seed)
    }

    /// The next set's first two dimensions.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let [a, b, _, _] = self.next_4d();
        Vec2::new(a, b)
    }
}

/// A 32-bit integer hash with good avalanche (Chris Wellons' "lowbias32").
#[inline]
pub(crate) const fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x21f0_aaad);
    x ^= x >> 15;
    x = x.wrapping_mul(0xd35a_2d97);
    x ^= x >> 15;
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_inputs_same_numbers_different_pixels_differ() {
        let a = Sampler::new(UVec2::new(3, 4), 17, 5).next_4d();
        assert_eq!(a, Sampler::new(UVec2::new(3, 4), 17, 5).next_4d());
        assert_ne!(a, Sampler::new(UVec2::new(4, 3), 17, 5).next_4d());
        assert_ne!(a, Sampler::new(UVec2::new(3, 4), 17, 6).next_4d());
        let mut s = Sampler::new(UVec2::new(3, 4), 17, 5);
        let first = s.next_4d();
        assert_ne!(first, s.next_4d(), "sets are decorrelated");
    }

    /// Each 4-D set's first two dimensions are stratified: 64 samples put exactly one point in
    /// each cell of an 8 × 8 grid (a (0, 2)-sequence property that Owen scrambling keeps).
    #[test]
    fn two_dimensional_stratification() {
        for set in 0..4 {
            let mut grid = [0u32; 64];
            for i in 0..64 {
                let mut s = Sampler::new(UVec2::new(11, 2), i, 99);
                s.start_set(set);
                let u = s.next_2d();
                grid[(u.y * 8.0) as usize * 8 + (u.x * 8.0) as usize] += 1;
            }
            assert!(grid.iter().all(|&c| c == 1), "set {set}: {grid:?}");
        }
    }
}
