//! Numerical stress tests of the MCC remapper's arithmetic (docs/design/mcc.md §5.3, §5.5,
//! §5.7): every result is checked against an independent f64
//! computation, never against the code's own output.
//!
//! * slerp over 10^5 random pairs, a third nearly parallel and a third nearly opposite, plus
//!   exactly opposite ones: finite, unit length ± 1e-6, and at angle t·θ from a and (1 − t)·θ
//!   from b (± 1e-5, θ in f64); away from opposite, within 2e-6 + 4ε/(π − θ) of an f64 slerp
//!   (the second term is the conditioning of the great circle near π).
//! * burp over 10^5 random direction sets (1 … 63 directions): finite, unit, and within 1e-4 rad
//!   of burp computed in f64 when no step of the chain is within 0.1 rad of opposite; with such
//!   steps (where the great circle is ill-conditioned) finite and unit.
//! * step 3's weights for 63 cameras: against the product formula of docs/design/mcc.md §5.3 in f64,
//!   finite, non-negative, summing to 1; and in a whole 63-camera remap every background pixel's
//!   smoothed weights sum to 1.
//! * degenerate collage shapes: 1×1, 1×N and N×1, and a collage whose only camera pixels are
//!   its border, remap to finite unit rays (camera pixels bit for bit).

use glam::{DVec3, Vec3};
use mcc::remap::burp::burp;
use mcc::remap::weights::interpolation_weights;
use mcc::slerp::slerp;
use mcc::test_util::{view, weights_by_product};
use mcc::{Collage, RayFile, Regions, RemapConfig, StoredRay, remap};
use std::collections::BTreeMap;
use tracer::test_support::Rng;

/// The angle between two vectors, accurate over [0, π] (f64).
fn angle(a: DVec3, b: DVec3) -> f64 {
    let (a, b) = (a.normalize(), b.normalize());
    2.0 * (a - b).length().atan2((a + b).length())
}

/// A unit f32 vector exactly (to f32) at angle `theta` from unit `a` in a random plane.
fn at_angle(rng: &mut Rng, a: DVec3, theta: f64) -> DVec3 {
    let p = rng.direction_f64();
    let u = (p - a * a.dot(p)).normalize();
    a * theta.cos() + u * theta.sin()
}

/// Slerp in f64 on the same (f32) inputs: None for (numerically) opposite inputs.
fn slerp64(a: DVec3, b: DVec3, t: f64) -> Option<DVec3> {
    let theta = angle(a, b);
    let u = (b - a * a.dot(b)).try_normalize()?;
    if std::f64::consts::PI - theta < 1e-9 {
        return None;
    }
    Some(a * (t * theta).cos() + u * (t * theta).sin())
}

#[test]
fn slerp_of_random_pairs_near_parallel_and_near_opposite() {
    use std::f64::consts::PI;
    let mut rng = Rng::new(1);
    let (mut worst_angle, mut worst_ref, mut worst_len) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..100_000 {
        let a = rng.direction_f64().as_vec3().normalize();
        let a64 = a.as_dvec3();
        let b = match i % 4 {
            0 => rng.direction_f64(),
            1 => {
                let th = rng.log_uniform(1e-8, 1e-1);
                at_angle(&mut rng, a64, th)
            }
            2 => {
                let th = PI - rng.log_uniform(1e-8, 1e-1);
                at_angle(&mut rng, a64, th)
            }
            _ => -a64, // exactly opposite (after rounding: -a is exact)
        }
        .as_vec3()
        .normalize();
        let b64 = b.as_dvec3();
        let theta = angle(a64, b64);
        for t in [rng.unit_f64() as f32, 0.5, 1e-3, 1.0 - 1e-3] {
            let r = slerp(a, b, t);
            let r64 = r.as_dvec3();
            assert!(r.is_finite(), "slerp({a}, {b}, {t}) = {r}");
            let len = (r64.length() - 1.0).abs();
            worst_len = worst_len.max(len);
            let from_a = (angle(a64, r64) - t as f64 * theta).abs();
            let to_b = (angle(r64, b64) - (1.0 - t as f64) * theta).abs();
            worst_angle = worst_angle.max(from_a).max(to_b);
            assert!(
                len <= 1e-6 && from_a <= 1e-5 && to_b <= 1e-5,
                "slerp({a}, {b}, {t}) = {r} (θ = {theta}): length off by {len:e}, angle from a off by \
                 {from_a:e}, to b by {to_b:e}"
            );
            // Away from opposite, compare the vectors. The great circle's plane comes from
            // a + b (|a + b| ≈ π − θ), whose rounding and the inputs' own length errors (a few
            // ε = 2^-23 per component) tilt it by ~4ε / (π − θ): conditioning any f32 slerp
            // has, allowed for in the tolerance (the angle checks above are unaffected by it).
            if theta < PI - 1e-3 {
                let want = slerp64(a64, b64, t as f64).expect("not opposite");
                let off = (r64 - want).length();
                let tolerance = 2e-6 + 4.0 * f32::EPSILON as f64 / (PI - theta);
                worst_ref = worst_ref.max(off / tolerance);
                assert!(
                    off <= tolerance,
                    "slerp({a}, {b}, {t}) = {r}, f64 slerp {want}: {off:e} apart (tolerance {tolerance:e})"
                );
            }
        }
        assert_eq!((slerp(a, b, 0.0), slerp(a, b, 1.0)), (a, b), "t = 0 and 1 return the inputs");
    }
    println!(
        "4 × 10^5 slerps: worst length error {worst_len:.2e}, worst angle error {worst_angle:.2e} rad, \
         worst distance to the f64 slerp {worst_ref:.2} of its tolerance"
    );
}

/// Burp in f64 (docs/design/mcc.md §5.5): r_{n−1} = p_{n−1}; r_k = slerp(r_{k+1}, p_k, α_k / β_k). Also
/// says whether any step met a nearly opposite pair (within 0.1 of π): there the great circle is
/// ill-conditioned (an input error δ tilts it by δ/(π − θ)), the chain compounds it, and f32
/// and f64 may legitimately part.
fn burp64(directions: &[DVec3], weights: &[f64]) -> (DVec3, bool) {
    let mut r: Option<DVec3> = None;
    let mut beta = 0.0;
    let mut ill = false;
    for (&p, &a) in directions.iter().zip(weights).rev() {
        if a <= 0.0 {
            continue;
        }
        beta += a;
        r = Some(match r {
            None => p,
            Some(r) => {
                ill |= angle(r, p) > std::f64::consts::PI - 0.1;
                slerp64(r, p, (a / beta).min(1.0)).unwrap_or(r)
            }
        });
    }
    (r.expect("a positive weight"), ill)
}

#[test]
fn burp_of_random_direction_sets() {
    let mut rng = Rng::new(2);
    let (mut checked, mut ill_conditioned, mut worst) = (0u32, 0u32, 0.0f64);
    for i in 0..100_000 {
        let n = if i % 100 == 0 { 63 } else { 1 + (rng.next_u64() % 8) as usize };
        let base = rng.direction_f64();
        let directions: Vec<Vec3> = (0..n)
            .map(|k| {
                let d = match (i % 3, k % 3) {
                    // A third of the sets mix a direction, its near-opposites and near-copies.
                    (0, 0) => {
                        let th = rng.log_uniform(1e-8, 1e-2);
                        -at_angle(&mut rng, base, th)
                    }
                    (0, 1) => {
                        let th = rng.log_uniform(1e-8, 1e-2);
                        at_angle(&mut rng, base, th)
                    }
                    // Another third are a cone of nearby directions (neighbouring eye rays).
                    (1, _) => {
                        let th = rng.unit_f64() * 0.5;
                        at_angle(&mut rng, base, th)
                    }
                    _ => rng.direction_f64(),
                };
                d.as_vec3().normalize()
            })
            .collect();
        let raw: Vec<f64> = (0..n).map(|_| rng.log_uniform(1e-6, 1.0)).collect();
        let sum: f64 = raw.iter().sum();
        let weights: Vec<f32> = raw.iter().map(|w| (w / sum) as f32).collect();
        let got = burp(&directions, &weights).expect("positive weights");
        assert!(
            got.is_finite() && (got.as_dvec3().length() - 1.0).abs() <= 1e-6,
            "burp of {n} directions gave {got}"
        );
        let d64: Vec<DVec3> = directions.iter().map(|d| d.as_dvec3()).collect();
        let w64: Vec<f64> = weights.iter().map(|&w| w as f64).collect();
        let (want, ill) = burp64(&d64, &w64);
        if ill {
            ill_conditioned += 1;
            continue;
        }
        checked += 1;
        let off = angle(got.as_dvec3(), want);
        worst = worst.max(off);
        assert!(off <= 1e-4, "burp of {n} directions: {got} vs f64 {want}, {off:e} rad apart");
    }
    println!(
        "10^5 burps: {checked} compared with f64 burp (worst {worst:.2e} rad), {ill_conditioned} with a \
         nearly opposite step checked for unit length only"
    );
    assert!(checked > 60_000, "only {checked} sets were compared");
    // A single positive weight is that direction exactly; no positive weight is None.
    assert_eq!(burp(&[Vec3::X, Vec3::Y, Vec3::Z], &[0.0, 1.0, 0.0]), Some(Vec3::Y));
    assert_eq!(burp(&[Vec3::X, Vec3::Y], &[0.0, f32::NAN]), None);
}

#[test]
fn weights_of_63_cameras() {
    let mut rng = Rng::new(3);
    let mut alpha = vec![0.0; 63];
    for case in 0..2000 {
        let d: Vec<f64> = (0..63)
            .map(|k| match case % 3 {
                0 => rng.log_uniform(1.0, 300.0),  // pixel distances
                1 => 10.0 + (k % 2) as f64 * 1e-9, // nearly all equal
                _ => rng.log_uniform(1e-3, 1e4),   // wide spread
            })
            .collect();
        interpolation_weights(&d, &mut alpha);
        let want = weights_by_product(&d);
        let sum: f64 = alpha.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "case {case}: weights sum to {sum}");
        for (i, (&a, &w)) in alpha.iter().zip(&want).enumerate() {
            assert!(a.is_finite() && a >= 0.0, "case {case}: α_{i} = {a}");
            assert!((a - w).abs() <= 1e-12 + 1e-9 * w, "case {case}: α_{i} = {a}, product formula {w}");
        }
    }
    // Distances of zero: the cameras at distance 0 share the weight equally (the limit).
    let mut d = vec![5.0; 63];
    d[7] = 0.0;
    d[40] = 0.0;
    interpolation_weights(&d, &mut alpha);
    assert!(alpha.iter().enumerate().all(|(i, &a)| a == if i == 7 || i == 40 { 0.5 } else { 0.0 }));
}

/// The views of `ids` ([`view`]: odd and even cameras look opposite ways, the nearly opposite
/// eye rays slerp must survive).
fn views(ids: impl IntoIterator<Item = u32>, w: u32, h: u32) -> BTreeMap<u32, RayFile> {
    ids.into_iter().map(|id| (id, view(id, w, h))).collect()
}

/// Remaps `ids` (w × h) and checks every ray: camera pixels bit for bit, background pixels
/// finite with unit directions. Returns the rays.
fn remap_checked(what: &str, w: u32, h: u32, ids: Vec<u32>, config: &RemapConfig) -> mcc::RemapOutput {
    let files = views(ids.iter().copied().filter(|&id| id != 0), w, h);
    let collage = Collage::new(w, h, ids).unwrap();
    let out =
        remap(&collage, &Regions::single(w, h), &files, 0, config).unwrap_or_else(|e| panic!("{what}: {e}"));
    for (p, ray) in out.rays.rays.iter().enumerate() {
        let id = collage.ids[p];
        if id != 0 {
            let want = files[&id].rays[p];
            let same = bytemuck_bits(ray) == bytemuck_bits(&want);
            assert!(same, "{what}: camera pixel {p} changed: {ray:?} vs {want:?}");
        } else {
            assert!(
                ray.origin.is_finite()
                    && ray.direction.is_finite()
                    && (ray.direction.length() - 1.0).abs() <= 1e-6,
                "{what}: background pixel {p} got {ray:?}"
            );
        }
    }
    out
}

fn bytemuck_bits(r: &StoredRay) -> [u32; 6] {
    [r.origin.x, r.origin.y, r.origin.z, r.direction.x, r.direction.y, r.direction.z].map(f32::to_bits)
}

#[test]
fn a_63_camera_collage_has_weights_summing_to_one() {
    // 63 cameras in a 9 × 7 grid of 12 × 10 cells, each a disc-ish blob with background around.
    let (w, h) = (108, 70);
    let ids: Vec<u32> = (0..w * h)
        .map(|p| {
            let (x, y) = (p % w, p / w);
            let (cx, cy) = (x / 12, y / 10);
            let (dx, dy) = (x % 12, y % 10);
            let inside = (3..9).contains(&dx) && (2..8).contains(&dy) && (dx + dy + cx) % 5 != 0;
            if inside { 1 + cy * 9 + cx } else { 0 }
        })
        .collect();
    let config = RemapConfig { debug: true, ..RemapConfig::GLASSNER };
    let out = remap_checked("63 cameras", w, h, ids.clone(), &config);
    let debug = out.debug.expect("debug data");
    assert_eq!(debug.cameras.len(), 63);
    let mut worst = 0.0f64;
    for p in 0..(w * h) as usize {
        let weights: Vec<f32> = debug.weights.iter().map(|plane| plane[p]).collect();
        assert!(weights.iter().all(|a| a.is_finite() && *a >= 0.0), "pixel {p}: {weights:?}");
        let sum: f64 = weights.iter().map(|&a| a as f64).sum();
        worst = worst.max((sum - 1.0).abs());
        assert!((sum - 1.0).abs() < 1e-5, "pixel {p}: 63 weights sum to {sum}");
    }
    println!("63-camera collage: worst |Σα − 1| = {worst:.2e}");
}

#[test]
fn one_by_one_and_one_by_n_collages() {
    // 1 × 1: one camera pixel is that ray; a background-only image is refused, not a panic.
    remap_checked("1×1", 1, 1, vec![5], &RemapConfig::GLASSNER);
    let files = views([5], 1, 1);
    let err = remap(
        &Collage::new(1, 1, vec![0]).unwrap(),
        &Regions::single(1, 1),
        &files,
        0,
        &RemapConfig::GLASSNER,
    );
    assert!(err.is_err(), "a collage with no camera pixel must be an error");
    // 1 × N and N × 1 with facing cameras, background runs between them, and at the ends.
    let mut rng = Rng::new(4);
    for n in [2u32, 3, 7, 64, 257] {
        for _ in 0..4 {
            let ids: Vec<u32> = (0..n)
                .map(|_| match rng.next_u64() % 4 {
                    0 | 1 => 0,
                    k => (k as u32) + (rng.next_u64() % 3) as u32, // ids 2 … 5
                })
                .collect();
            if ids.iter().all(|&id| id == 0) {
                continue;
            }
            for (w, h) in [(n, 1), (1, n)] {
                for config in [RemapConfig::GLASSNER, RemapConfig::UNSMOOTHED] {
                    remap_checked(&format!("{w}×{h}"), w, h, ids.clone(), &config);
                }
            }
        }
    }
}

/// Only the outermost ring of pixels belongs to cameras (every camera pixel is an edge pixel by
/// the image-border rule, docs/design/mcc.md §5.1). With one camera, every weight is 1, so each
/// interior pixel gets exactly the ray of its nearest border pixel (ties to the smallest row, then
/// column); with two, rays are finite and unit.
#[test]
fn a_collage_whose_only_camera_pixels_are_the_border() {
    for (w, h) in [(3u32, 3u32), (16, 12), (5, 40)] {
        let border = |x: u32, y: u32| x == 0 || y == 0 || x == w - 1 || y == h - 1;
        let one: Vec<u32> = (0..w * h).map(|p| if border(p % w, p / w) { 3 } else { 0 }).collect();
        let out = remap_checked(&format!("{w}×{h} border, one camera"), w, h, one, &RemapConfig::GLASSNER);
        let file = view(3, w, h);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                // Brute force: the nearest border pixel, raster order on ties.
                let (mut best, mut best_d) = ((0, 0), u32::MAX);
                for by in 0..h {
                    for bx in 0..w {
                        let d = (bx as i64 - x as i64).pow(2) + (by as i64 - y as i64).pow(2);
                        if border(bx, by) && (d as u32) < best_d {
                            (best, best_d) = ((bx, by), d as u32);
                        }
                    }
                }
                let got = out.rays.get(x, y);
                let want = file.get(best.0, best.1);
                assert_eq!(bytemuck_bits(got), bytemuck_bits(want), "{w}×{h}: pixel ({x}, {y}) vs {best:?}");
            }
        }
        // Two facing cameras share the ring (top and left one, bottom and right the other).
        let two: Vec<u32> = (0..w * h)
            .map(|p| {
                let (x, y) = (p % w, p / w);
                if !border(x, y) {
                    0
                } else if y == 0 || x == 0 {
                    1
                } else {
                    2
                }
            })
            .collect();
        for config in [RemapConfig::GLASSNER, RemapConfig::UNSMOOTHED] {
            remap_checked(&format!("{w}×{h} border, two cameras"), w, h, two.clone(), &config);
        }
    }
}
