//! Sample generation (docs/design/tracer.md §3.5): every random number is a pure
//! function of (pixel, sample index, dimension, seed), so an image is the same bit for bit
//! whatever the thread count or tile order.
//!
//! The sequence is Owen-scrambled Sobol (Burley, "Practical Hash-based Owen Scrambling", JCGT
//! 9(4), 2020) from the `sobol_burley` crate, *padded* in 4-D sets: each set of four dimensions
//! is an independently shuffled and scrambled copy of Sobol dimensions 0–3 (Burley §4), seeded
//! by a hash of the pixel, the user seed and the set's index. Each pixel therefore gets its own
//! randomised low-discrepancy sequence (error falls faster than with independent samples) while
//! neighbouring pixels stay decorrelated (noise, not structured artefacts).

use glam::UVec2;
use sobol_burley::parts::{self, Int4};
use std::sync::LazyLock;

/// The largest sample count per pixel the sequence supports (sobol_burley's 2^16).
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 16;

/// Which 4-D set each decision of a camera sample draws from. Sets are assigned by position in
/// the path, never by consumption order, and the pairing inside a set is chosen so that
/// integrands that depend on two decisions together are stratified jointly:
/// - the film position and the first vertex's light sample (direct light seen by a pixel);
/// - vertex k's BSDF direction and vertex k + 1's light sample (one-bounce light).
pub mod sets {
    /// Film x, film y, light sample u, v at the first vertex.
    pub const CAMERA: u32 = 0;
    /// Lens u, v and shutter time (drawn only by cameras with a lens, renders with a shutter).
    pub const LENS_TIME: u32 = 1;
    /// Vertex k: BSDF direction u, v, then the light sample u, v of vertex k + 1.
    pub const fn vertex(k: u32) -> u32 {
        2 + k
    }
    /// Vertex k's one-dimensional decisions: lobe choice, Russian roulette.
    pub const fn decisions(k: u32) -> u32 {
        0x4000_0000 + k
    }
}

/// Sobol dimensions 0–3 (bit-reversed, as `sobol_burley` computes them) of the two bytes of a
/// bit-reversed sample index that matter (indices are below 2^16). The sequence is linear over
/// GF(2), sobol(a ⊕ b) = sobol(a) ⊕ sobol(b), so two lookups give what `sobol_burley` builds
/// with a loop over the index's set bits (eight steps on average, each a mispredicted branch
/// for a scrambled index; docs/performance.md, ledger: "Sobol step from a byte table").
static SOBOL_BYTES: LazyLock<[[Int4; 256]; 2]> = LazyLock::new(|| {
    std::array::from_fn(|k| std::array::from_fn(|b| parts::sobol_int4_rev((b as u32) << (24 - 8 * k), 0)))
});

/// The random numbers of one sample of one pixel, in padded 4-D sets.
#[derive(Clone, Copy, Debug)]
pub struct Sampler {
    pixel_seed: u32,
    index: u32,
    /// [`SOBOL_BYTES`], dereferenced once per sample rather than once per set (each `LazyLock`
    /// access is an atomic load and a branch).
    sobol_bytes: &'static [[Int4; 256]; 2],
}

impl Sampler {
    /// The sampler for sample `index` of `pixel` under `seed`.
    #[inline]
    pub fn new(pixel: UVec2, index: u32, seed: u32) -> Self {
        debug_assert!(index < MAX_SAMPLES_PER_PIXEL);
        let pixel_seed = hash(pixel.x ^ hash(pixel.y ^ hash(seed)));
        Self { pixel_seed, index, sobol_bytes: &SOBOL_BYTES }
    }

    /// The sampler of branch `branch` of `branches` split from this sample (first-vertex
    /// splitting, `crate::integrator`): index `index · branches + branch` of the same pixel's
    /// sequence, so a camera sample's branches are consecutive points of one Sobol sequence (an
    /// aligned, stratified run when `branches` is a power of two) and one branch of one
    /// (`branch(1, 0)`) is this sampler itself. The caller keeps the index below
    /// [`MAX_SAMPLES_PER_PIXEL`] (checked in debug builds only: this is per ray).
    #[inline]
    pub fn branch(&self, branches: u32, branch: u32) -> Self {
        debug_assert!(branch < branches);
        debug_assert!((self.index as u64 + 1) * branches as u64 <= MAX_SAMPLES_PER_PIXEL as u64);
        Self { index: self.index * branches + branch, ..*self }
    }

    /// The four numbers of dimension set `set` (see [`sets`]): a randomised 4-D Sobol point,
    /// independently shuffled and scrambled per pixel and set. Bit for bit
    /// `sobol_burley::sample_4d(index, 0, seed)` (a test checks it), with its Sobol step
    /// taken from the module's two-byte table (`SOBOL_BYTES`).
    #[inline]
    pub fn get(&self, set: u32) -> [f32; 4] {
        let seed = hash(self.pixel_seed ^ set.wrapping_mul(0x9e37_79b9));
        // sobol_burley::sample_4d's steps, in its order and with its constants.
        let shuffled = parts::owen_scramble_rev(self.index.reverse_bits(), parts::hash(seed ^ 0x79c6_8e4a));
        let [high, low] = self.sobol_bytes;
        let sobol = high[(shuffled >> 24) as usize] ^ low[((shuffled >> 16) & 0xff) as usize];
        let seed = seed.wrapping_mul(0x9c8f_2d3b);
        // `parts::owen_scramble_int4_rev(sobol, parts::hash_int4(..))`, lane by lane through the
        // scalar versions of the same functions: `Int4` picks its multiply when sobol_burley is
        // compiled, so even the x86-64-v3 build of the tile loop got SSE2's five-step emulation
        // of a 32-bit lane multiply; plain lanes let each build use its own (one `vpmulld` on
        // x86-64-v3). Integer arithmetic, so the bits are the same either way.
        let mut lanes: [u32; 4] = sobol.into();
        for (x, c) in lanes.iter_mut().zip([0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8]) {
            *x = parts::owen_scramble_rev(*x, parts::hash(seed ^ c));
        }
        Int4::from(lanes).reverse_bits().to_f32_norm()
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

    /// The table-driven Sobol step gives sobol_burley's own numbers, bit for bit, over the
    /// whole index range and many seeds and sets.
    #[test]
    fn matches_sobol_burley_bit_for_bit() {
        for index in (0..MAX_SAMPLES_PER_PIXEL).step_by(7).chain([0, 1, 255, 256, MAX_SAMPLES_PER_PIXEL - 1])
        {
            for (pixel, set) in
                [(UVec2::new(0, 0), 0u32), (UVec2::new(17, 3), 5), (UVec2::new(1919, 1079), 0x4000_0003)]
            {
                let sampler = Sampler::new(pixel, index, index ^ 0x5bd1_e995);
                let seed = hash(sampler.pixel_seed ^ set.wrapping_mul(0x9e37_79b9));
                let want = sobol_burley::sample_4d(index, 0, seed);
                assert_eq!(
                    sampler.get(set).map(f32::to_bits),
                    want.map(f32::to_bits),
                    "index {index}, set {set}"
                );
            }
        }
    }

    /// A branch is the sample of index `index · branches + branch` of the same pixel and seed;
    /// one branch of one is the sample itself.
    #[test]
    fn branches_are_later_indices_of_the_same_sequence() {
        let (pixel, seed) = (UVec2::new(5, 9), 77);
        let base = Sampler::new(pixel, 13, seed);
        for set in [0, 3, sets::decisions(1)] {
            assert_eq!(base.branch(1, 0).get(set), base.get(set));
            for b in 0..4 {
                assert_eq!(base.branch(4, b).get(set), Sampler::new(pixel, 13 * 4 + b, seed).get(set));
            }
        }
    }

    #[test]
    fn same_inputs_same_numbers_different_pixels_differ() {
        let a = Sampler::new(UVec2::new(3, 4), 17, 5).get(0);
        assert_eq!(a, Sampler::new(UVec2::new(3, 4), 17, 5).get(0));
        assert_ne!(a, Sampler::new(UVec2::new(4, 3), 17, 5).get(0));
        assert_ne!(a, Sampler::new(UVec2::new(3, 4), 17, 6).get(0));
        assert_ne!(a, Sampler::new(UVec2::new(3, 4), 17, 5).get(1), "sets are decorrelated");
    }

    /// Each 4-D set's first two dimensions are stratified: 64 samples put exactly one point in
    /// each cell of an 8 × 8 grid (a (0, 2)-sequence property that Owen scrambling keeps); and
    /// so are 16 samples over the 2 × 2 × 2 × 2 cells of all four dimensions.
    #[test]
    fn stratification() {
        for set in [0, 1, 7, sets::decisions(3)] {
            let mut grid = [0u32; 64];
            let mut cells = [0u32; 16];
            for i in 0..64 {
                let u = Sampler::new(UVec2::new(11, 2), i, 99).get(set);
                grid[(u[1] * 8.0) as usize * 8 + (u[0] * 8.0) as usize] += 1;
                if i < 16 {
                    cells[u.iter().enumerate().map(|(d, x)| ((*x * 2.0) as usize) << d).sum::<usize>()] += 1;
                }
            }
            assert!(grid.iter().all(|&c| c == 1), "set {set}: {grid:?}");
            assert!(cells.iter().all(|&c| c == 1), "set {set}: {cells:?}");
        }
    }
}
