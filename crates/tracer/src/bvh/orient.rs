//! The exact orientation of a point against a triangle's plane, for f32 corners: Shewchuk's
//! `orient3d` (the `robust` crate), with a cheaper exact path for the case it is slowest at.
//!
//! `robust::orient3d` decides most points with one f64 determinant and an error bound; points on
//! or within rounding of the plane fall to its adaptive path of floating-point expansions, which
//! is slow (about ten times the filter). Those are the common case for leaf-mates: neighbouring
//! triangles of a surface, coplanar or nearly so (a flat floor, a wall, a skinned sheet). A refit
//! decides them every frame (`leaving::slot_sides`), where the adaptive path was most of its
//! time (docs/performance.md, ledger: "refit: exact sides in integers"). Four f32 points whose
//! nonzero coordinates span at most [`SPREAD`] binades are integers times one power of two, and
//! their determinant is then exact in i128; only wider spans take `robust`'s adaptive path.

use robust::Coord3D;

/// The widest span of binades (largest exponent less smallest, over the nonzero coordinates of
/// the four points) for which the i128 determinant cannot overflow: coordinates below 2^(24 +
/// SPREAD) ulps of the smallest, differences below 2^41, 2×2 minors below 2^83, the
/// determinant below 2^126.
const SPREAD: i32 = 16;

/// Shewchuk's first error bound for orient3d, (7 + 56ε)ε with ε = 2^−53.
const BOUND_A: f64 = (7.0 + 56.0 * f64::EPSILON / 2.0) * f64::EPSILON / 2.0;

/// A value whose sign is the sign of the exact orient3d(a, b, c, d) (as `robust::orient3d`:
/// positive when `d` lies below the plane of `a`, `b`, `c` seen counter-clockwise from above,
/// zero when on it).
///
/// Written out without closures or array maps: the workspace's incremental release builds did
/// not inline those, and the calls cost more than the arithmetic.
#[inline]
pub(super) fn orient3d(a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3]) -> f64 {
    let (dx, dy, dz) = (f64::from(d[0]), f64::from(d[1]), f64::from(d[2]));
    let (adx, ady, adz) = (f64::from(a[0]) - dx, f64::from(a[1]) - dy, f64::from(a[2]) - dz);
    let (bdx, bdy, bdz) = (f64::from(b[0]) - dx, f64::from(b[1]) - dy, f64::from(b[2]) - dz);
    let (cdx, cdy, cdz) = (f64::from(c[0]) - dx, f64::from(c[1]) - dy, f64::from(c[2]) - dz);
    let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
    let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
    let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    if det.abs() > BOUND_A * permanent {
        return det;
    }
    if let Some(exact) = in_integers(&[a, b, c, d]) {
        return exact as f64;
    }
    robust::orient3d(coord(a), coord(b), coord(c), coord(d))
}

fn coord(p: [f32; 3]) -> Coord3D<f32> {
    Coord3D { x: p[0], y: p[1], z: p[2] }
}

/// The exponent of `x`'s ulp: a finite f32 is m · 2^e with |m| < 2^24 (denormals share the
/// lowest e).
#[inline(always)]
fn ulp_exponent(x: f32) -> i32 {
    ((x.to_bits() >> 23) & 0xff).max(1) as i32 - 150
}

/// `x` as an integer count of 2^`lo` (exact when `lo` ≤ its ulp's exponent and the count fits).
#[inline(always)]
fn count_of(x: f32, lo: i32) -> i64 {
    if x == 0.0 {
        return 0;
    }
    let bits = x.to_bits();
    let implicit = if (bits >> 23) & 0xff == 0 { 0 } else { 1 << 23 };
    let v = ((bits & 0x7f_ffff) as i64 | implicit) << (ulp_exponent(x) - lo);
    if bits >> 31 == 1 { -v } else { v }
}

/// The exact determinant's sign as an i128 (−1, 0 or 1), when every coordinate is finite and
/// the nonzero ones span at most [`SPREAD`] binades.
fn in_integers(p: &[[f32; 3]; 4]) -> Option<i128> {
    let (mut lo, mut hi) = (i32::MAX, i32::MIN);
    for point in p {
        for &x in point {
            if !x.is_finite() {
                return None;
            }
            if x != 0.0 {
                let e = ulp_exponent(x);
                lo = lo.min(e);
                hi = hi.max(e);
            }
        }
    }
    if lo > hi {
        return Some(0); // All four points are the origin.
    }
    if hi - lo > SPREAD {
        return None;
    }
    let mut q = [[0i128; 3]; 3];
    for i in 0..3 {
        for k in 0..3 {
            q[i][k] = i128::from(count_of(p[i][k], lo) - count_of(p[3][k], lo));
        }
    }
    let [[adx, ady, adz], [bdx, bdy, bdz], [cdx, cdy, cdz]] = q;
    let det = adz * (bdx * cdy - cdx * bdy) + bdz * (cdx * ady - adx * cdy) + cdz * (adx * bdy - bdx * ady);
    Some(det.signum())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reference(a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3]) -> f64 {
        robust::orient3d(coord(a), coord(b), coord(c), coord(d))
    }

    /// The sign agrees with `robust::orient3d` on points on the plane (exactly, by construction
    /// on an axis-aligned and on a tilted plane through integer-friendly coordinates), within
    /// rounding of it, far from it, at mixed scales (past [`SPREAD`]: the fallback) and with
    /// zeros among the coordinates.
    #[test]
    fn the_sign_is_robusts() {
        let mut rng = crate::test_support::Rng::new(0x0e1e_47a3);
        let mut next = move || rng.unit() * 2.0 - 1.0;
        let (mut zero, mut integer_paths) = (0, 0);
        for round in 0..20_000 {
            let scale = [1.0f32, 1e-3, 1e3, 1e-12, 1e12][round % 5];
            let mut pt = || [next() * scale, next() * scale, next() * scale];
            let (a, b, c) = (pt(), pt(), pt());
            let d = match round % 4 {
                // On a plane z = k: exactly coplanar.
                0 => {
                    let k = a[2];
                    let flat = |p: [f32; 3]| [p[0], p[1], k];
                    check(flat(a), flat(b), flat(c), flat(pt()), &mut zero, &mut integer_paths);
                    continue;
                }
                // On the tilted plane z = x + 2y with small-integer-times-power-of-two points.
                1 => {
                    let g = |v: f32| (v * 64.0).round() / 16.0;
                    let on = |x: f32, y: f32| [g(x), g(y), g(x) + 2.0 * g(y)];
                    let (p, q, r, s) = (on(a[0], a[1]), on(b[0], b[1]), on(c[0], c[1]), on(next(), next()));
                    check(p, q, r, s, &mut zero, &mut integer_paths);
                    continue;
                }
                // Within a rounding of the plane: an affine mix of the corners, rounded.
                2 => {
                    let (u, v) = (next(), next());
                    [0, 1, 2].map(|i| a[i] + u * (b[i] - a[i]) + v * (c[i] - a[i]))
                }
                // Mixed scales: a coordinate far below the others.
                _ => [next() * scale * 1e-9, 0.0, next() * scale],
            };
            check(a, b, c, d, &mut zero, &mut integer_paths);
        }
        assert!(zero > 5_000, "exactly coplanar cases were exercised ({zero})");
        assert!(integer_paths > 5_000, "the integer path was exercised ({integer_paths})");
    }

    fn check(a: [f32; 3], b: [f32; 3], c: [f32; 3], d: [f32; 3], zero: &mut u32, ints: &mut u32) {
        let (ours, theirs) = (orient3d(a, b, c, d), reference(a, b, c, d));
        assert_eq!(ours.partial_cmp(&0.0), theirs.partial_cmp(&0.0), "{a:?} {b:?} {c:?} {d:?}");
        *zero += u32::from(theirs == 0.0);
        *ints += u32::from(in_integers(&[a, b, c, d]).is_some());
    }
}
