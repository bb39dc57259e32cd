//! Branch-free arithmetic for loops that run many pixels at once in SIMD lanes (docs/design.md
//! §5.7, §7): selects, glam's normalisation without its `Option`, the half angle (atan) and
//! sin/cos as Cephes' polynomials, and the fixed perpendicular of slerp's opposite-vector rule.
//! The in-betweener's smooth kernel uses them all; the crate's slerp (and so the remapper's burp
//! in lanes) the selects and the normalisation, so that its scalar and lane forms are the same
//! operations and give the same bits.
//!
//! Every function is `#[inline(always)]` so that it is compiled inside the loop that calls it,
//! with that loop's CPU features ([`has_avx2`]); the operations are IEEE's lane by lane — no FMA
//! is enabled and Rust never contracts `a * b + c` — so the bits do not depend on the features.

use glam::Vec3;

/// Whether this CPU runs AVX2 (8 f32 lanes), for the loops compiled twice: baseline x86-64 (SSE2,
/// 4 lanes) and AVX2 (std caches the answer).
#[inline]
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// One loop compiled twice from its `#[inline(always)]` body, and the one way to pick between
/// them: `$dispatch` runs `$avx2` (the body compiled with AVX2: eight f32 lanes a vector) when the
/// CPU has it ([`has_avx2`]), else `$baseline` (baseline x86-64: four lanes). The bodies use the
/// same IEEE operations either way (no FMA), so the choice changes no bit; tests call both twins
/// to check that.
macro_rules! avx2_twins {
    (
        $(#[$doc:meta])*
        $vis:vis fn $dispatch:ident | $baseline:ident | $avx2:ident ($($arg:ident: $ty:ty),* $(,)?) => $body:ident
    ) => {
        $(#[$doc])*
        $vis fn $dispatch($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            if $crate::lanes::has_avx2() {
                // SAFETY: the CPU has AVX2 (checked just above), the one feature `$avx2` enables.
                unsafe { $avx2($($arg),*) };
                return;
            }
            $baseline($($arg),*);
        }

        #[doc = concat!("[`", stringify!($body), "`] compiled for baseline x86-64.")]
        fn $baseline($($arg: $ty),*) {
            $body($($arg),*);
        }

        #[doc = concat!("[`", stringify!($body), "`] compiled with AVX2: the same IEEE operations (no FMA), the same bits.")]
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) {
            $body($($arg),*);
        }
    };
}
pub(crate) use avx2_twins;

/// `if c { x } else { y }` on values already computed: LLVM makes it a SIMD blend. (A select
/// between two *loads* would become a load through a selected pointer, which does not
/// vectorise; every select in these loops picks between computed values.)
#[inline(always)]
pub(crate) fn select(c: bool, x: f32, y: f32) -> f32 {
    if c { x } else { y }
}

/// [`select`] of each component.
#[inline(always)]
pub(crate) fn select3(c: bool, x: Vec3, y: Vec3) -> Vec3 {
    Vec3::new(select(c, x.x, y.x), select(c, x.y, y.y), select(c, x.z, y.z))
}

/// `v` scaled to unit length as glam's `try_normalize` does it (v · (1 / |v|)), or `fallback`
/// where glam returns `None` (a zero, tiny or non-finite length). Branch-free.
#[inline(always)]
pub(crate) fn normalize_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let rcp = 1.0 / v.dot(v).sqrt();
    let ok = rcp.is_finite() && rcp > 0.0;
    select3(ok, v * select(ok, rcp, 1.0), fallback)
}

/// The deterministic unit vector ⟂ `a` used when `a` and `b` span no plane (equal or exactly
/// opposite): `a.any_orthonormal_vector()` (Duff et al. 2017, written with `copysign`, which
/// equals glam's `signum` for every non-NaN input), re-orthogonalised for an `a` that is unit only
/// to f32 precision. Branch-free.
#[inline(always)]
pub(crate) fn perpendicular(a: Vec3) -> Vec3 {
    let sign = 1.0f32.copysign(a.z);
    let k = -1.0 / (sign + a.z);
    let q = Vec3::new(a.x * a.y * k, sign + a.y * a.y * k, -a.y);
    let q = q - a * a.dot(q);
    q * (1.0 / q.dot(q).sqrt())
}

/// atan2(y, x) for y, x ≥ 0, not both 0: the half angle between unit vectors whose difference
/// and sum have lengths y and x. Cephes' `atanf` reduction and polynomial (error under 2e-7),
/// branch-free: atan(lo/hi), reduced by atan(z) = π/4 + atan((z − 1)/(z + 1)) above tan(π/8),
/// and π/2 − atan when y > x.
#[inline(always)]
pub(crate) fn half_angle(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};
    let swap = y > x;
    let (lo, hi) = (select(swap, x, y), select(swap, y, x));
    let big = lo > 0.414_213_57 * hi;
    let z = select(big, lo - hi, lo) / select(big, lo + hi, hi);
    let z2 = z * z;
    let poly = ((0.080_537_446 * z2 - 0.138_776_85) * z2 + 0.199_777_11) * z2 - 0.333_329_5;
    let atan = select(big, FRAC_PI_4, 0.0) + (poly * z2 * z + z);
    select(swap, FRAC_PI_2 - atan, atan)
}

/// sin and cos of `x` (|x| ≲ 10⁴), Cephes' `sinf`/`cosf`: x is reduced by the nearest multiple of
/// π/2 (a three-part Cody–Waite π/2), then minimax polynomials on [−π/4, π/4]; absolute error
/// under 2.5e-7 on |x| < 2π. Branch-free, no libm call (std's `sin_cos` is two libm calls and
/// does not vectorise).
#[inline(always)]
pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
    const FRAC_2_PI: f32 = std::f32::consts::FRAC_2_PI;
    const DP1: f32 = 1.570_312_5;
    const DP2: f32 = 4.837_513e-4;
    const DP3: f32 = 7.549_79e-8;
    // Nearest quadrant by truncating x·2/π ± ½, clamped first so that the conversion is in
    // range (`max`/`min` return the non-NaN operand: a NaN clamps too, and stays NaN in `y`;
    // `clamp` would pass the NaN on to the conversion).
    #[allow(clippy::manual_clamp)]
    let v = (x * FRAC_2_PI + 0.5f32.copysign(x)).max(-1e6).min(1e6);
    // SAFETY: v is finite and within ±1e6.
    let q = unsafe { v.to_int_unchecked::<i32>() };
    let j = q as f32;
    let y = ((x - j * DP1) - j * DP2) - j * DP3;
    let z = y * y;
    let s = ((-1.951_529_6e-4 * z + 8.332_161e-3) * z - 1.666_665_5e-1) * z * y + y;
    let c = ((2.443_315_7e-5 * z - 1.388_731_6e-3) * z + 4.166_664_6e-2) * z * z - 0.5 * z + 1.0;
    // Quadrant q: (s, c), (c, −s), (−s, −c), (−c, s): swap on odd q, then negate both if q & 2.
    let odd = q & 1 != 0;
    let flip = ((q & 2) as u32) << 30;
    (f32::from_bits(select(odd, c, s).to_bits() ^ flip), f32::from_bits(select(odd, -s, c).to_bits() ^ flip))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_trigonometry_is_accurate() {
        let mut worst = (0.0f64, 0.0f64);
        let mut x = -12.0f64;
        while x <= 12.0 {
            let (s, c) = sin_cos(x as f32);
            let xf = x as f32 as f64;
            worst.0 = worst.0.max((s as f64 - xf.sin()).abs());
            worst.0 = worst.0.max((c as f64 - xf.cos()).abs());
            x += 1e-4;
        }
        assert!(worst.0 < 2.5e-7, "sin_cos error {}", worst.0);
        for k in 0..=20000 {
            let theta = std::f64::consts::PI * k as f64 / 20000.0;
            let (y, x) = ((theta / 2.0).sin() as f32, (theta / 2.0).cos() as f32);
            let want = (y as f64).atan2(x as f64);
            worst.1 = worst.1.max((half_angle(y, x) as f64 - want).abs());
        }
        assert!(worst.1 < 2e-7, "half_angle error {}", worst.1);
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert!(sin_cos(f32::NAN).0.is_nan());
    }
}
