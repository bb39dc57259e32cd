//! The tile loop compiled for three x86-64 levels — the baseline, x86-64-v3 (AVX2, FMA,
//! BMI1/2, LZCNT) and x86-64-v4 (AVX-512 F, BW, CD, DQ, VL) — and the best one this CPU runs,
//! chosen once per render. The image bits do not depend on the choice: Rust never contracts
//! a·b + c into an FMA by itself, LLVM reorders no floating-point arithmetic without
//! fast-math flags, and each level's operations are IEEE's (a test compares all three).
//!
//! The loop's code is the same at every level; what a level changes is the instructions LLVM
//! may pick: v3's AVX2 and BMI, v4's 32 vector registers (so fewer spills). Each level paid for
//! itself (docs/performance.md, ledger: "x86-64-v3 tile loop", "x86-64-v4 tile loop").

use super::tile::TileJob;
use crate::film::PixelAccumulator;
#[cfg(test)]
use std::sync::atomic::{AtomicU8, Ordering};

/// An instruction-set level the tile loop is compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Level {
    /// x86-64 (SSE2), or any other architecture.
    Baseline = 0,
    /// x86-64-v3.
    V3 = 1,
    /// x86-64-v4.
    V4 = 2,
}

/// The highest level renders may use; unit tests lower it to compare the levels (the crate's
/// own tests only: nothing else can reach it, so it exists only in their build).
#[cfg(test)]
pub(super) static CAP: AtomicU8 = AtomicU8::new(Level::V4 as u8);

/// The best level this CPU runs (in unit tests, at most [`CAP`]).
pub(super) fn level() -> Level {
    #[cfg(test)]
    let cap = match CAP.load(Ordering::Relaxed) {
        0 => Level::Baseline,
        1 => Level::V3,
        _ => Level::V4,
    };
    #[cfg(not(test))]
    let cap = Level::V4;
    detected().min(cap)
}

/// The best level this CPU runs.
fn detected() -> Level {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        let v3 =
            has!("avx2") && has!("fma") && has!("bmi1") && has!("bmi2") && has!("lzcnt") && has!("popcnt");
        let v4 =
            has!("avx512f") && has!("avx512bw") && has!("avx512cd") && has!("avx512dq") && has!("avx512vl");
        match (v3, v4) {
            (true, true) => Level::V4,
            (true, false) => Level::V3,
            _ => Level::Baseline,
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Level::Baseline
    }
}

/// [`TileJob::trace_tile`] at `level`, which must be at most [`level()`]'s answer.
#[inline]
pub(super) fn trace_tile<const AOV: bool, const ALPHA: bool, const LAMBERT: bool>(
    level: Level,
    job: &TileJob,
    tile: u32,
) -> (Vec<PixelAccumulator>, u64, u64) {
    debug_assert!(level <= detected());
    match level {
        Level::Baseline => job.trace_tile::<AOV, ALPHA, LAMBERT>(tile),
        // SAFETY: `level` is at most what `detected` found, so the CPU has every feature the
        // function enables.
        #[cfg(target_arch = "x86_64")]
        Level::V3 => unsafe { trace_tile_v3::<AOV, ALPHA, LAMBERT>(job, tile) },
        // SAFETY: as above.
        #[cfg(target_arch = "x86_64")]
        Level::V4 => unsafe { trace_tile_v4::<AOV, ALPHA, LAMBERT>(job, tile) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => job.trace_tile::<AOV, ALPHA, LAMBERT>(tile),
    }
}

/// [`TileJob::trace_tile`] compiled for x86-64-v3.
///
/// # Safety
/// The CPU must have AVX2, FMA, BMI1, BMI2, LZCNT and POPCNT.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,sse3,ssse3,sse4.1,sse4.2")]
unsafe fn trace_tile_v3<const AOV: bool, const ALPHA: bool, const LAMBERT: bool>(
    job: &TileJob,
    tile: u32,
) -> (Vec<PixelAccumulator>, u64, u64) {
    job.trace_tile::<AOV, ALPHA, LAMBERT>(tile)
}

/// [`TileJob::trace_tile`] compiled for x86-64-v4.
///
/// # Safety
/// The CPU must have x86-64-v3's features and AVX-512 F, BW, CD, DQ and VL.
#[cfg(target_arch = "x86_64")]
#[target_feature(
    enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,popcnt,sse3,ssse3,sse4.1,sse4.2,avx512f,avx512bw,avx512cd,avx512dq,avx512vl"
)]
unsafe fn trace_tile_v4<const AOV: bool, const ALPHA: bool, const LAMBERT: bool>(
    job: &TileJob,
    tile: u32,
) -> (Vec<PixelAccumulator>, u64, u64) {
    job.trace_tile::<AOV, ALPHA, LAMBERT>(tile)
}
