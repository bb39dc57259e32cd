//! Tests of the in-betweener (docs/design/workflow.md §7).

use super::*;
use crate::test_util::{Rng, scratch_dir};
use glam::{DVec3, Vec3};
use std::cell::RefCell;

fn bits(r: &StoredRay) -> [u32; 6] {
    bytemuck::cast(*r)
}

fn same_bits(a: &[StoredRay], b: &[StoredRay]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| bits(x) == bits(y))
}

/// A key of random rays: origins in [−5, 5]³, unit directions anywhere.
fn random_key(w: u32, h: u32, rng: &mut Rng) -> RayFile {
    let rays = (0..w * h)
        .map(|_| {
            StoredRay::new((Vec3::new(rng.unit(), rng.unit(), rng.unit()) - 0.5) * 10.0, rng.direction())
        })
        .collect();
    RayFile::new(w, h, 0, 7, rays).unwrap()
}

/// `frames.len()` random keys of one size.
fn random_keys(w: u32, h: u32, frames: &[u32], seed: u64) -> Vec<(u32, RayFile)> {
    let mut rng = Rng::new(seed);
    frames.iter().map(|&f| (f, random_key(w, h, &mut rng))).collect()
}

const BOTH: [InbetweenMode; 2] = [InbetweenMode::Smooth, InbetweenMode::Linear];

#[test]
fn keys_are_reproduced_bit_for_bit_and_held_outside() {
    let keys = random_keys(5, 4, &[10, 3, 30], 1);
    let want: Vec<Vec<StoredRay>> = [1, 0, 2].iter().map(|&k| keys[k].1.rays.clone()).collect();
    let k = Keys::new(keys, None).unwrap();
    assert_eq!(k.frames(), [3, 10, 30]);
    for mode in BOTH {
        for (frame, key) in [(3, 0), (10, 1), (30, 2), (0, 0), (2, 0), (31, 2), (1000, 2), (u32::MAX, 2)] {
            let f = k.frame(frame, mode);
            assert!(same_bits(&f.rays, &want[key]), "{mode:?} frame {frame}");
            assert_eq!((f.width, f.height, f.frame, f.camera_id, f.computed), (5, 4, frame, 0, true));
        }
        for time in [-1.5, 2.999, 30.0001, f64::NAN] {
            let key = if time > 20.0 { 2 } else { 0 };
            assert_eq!(bits(&k.ray(7, time, mode)), bits(&want[key][7]), "{mode:?} t = {time}");
        }
        // Between keys the rays differ from both neighbours.
        let f = k.frame(5, mode);
        assert!(!same_bits(&f.rays, &want[0]) && !same_bits(&f.rays, &want[1]));
    }
    // One key: every frame holds it.
    let one = Keys::new(random_keys(3, 2, &[8], 2), None).unwrap();
    let key = one.key_rays(0).to_vec();
    for frame in [0, 8, 9, 500] {
        assert!(same_bits(&one.frame(frame, InbetweenMode::Smooth).rays, &key));
    }
}

#[test]
fn keys_of_other_sizes_are_resampled_by_the_lens_reader_rule() {
    let mut rng = Rng::new(3);
    let (small, large, odd) =
        (random_key(6, 4, &mut rng), random_key(12, 8, &mut rng), random_key(3, 5, &mut rng));
    // The earliest key (frame 0, given last) sets the default resolution.
    let k = Keys::new(vec![(9, small.clone()), (20, odd.clone()), (0, large.clone())], None).unwrap();
    assert_eq!(k.resolution(), UVec2::new(12, 8));
    assert!(same_bits(k.key_rays(0), &large.rays), "a key at the output size is kept as it is");
    for (index, file) in [(1, small), (2, odd)] {
        let sampler = RaySampler::new(Arc::new(file), UVec2::new(12, 8)).unwrap();
        let want: Vec<StoredRay> =
            (0..96).map(|p| sampler.at(Vec2::new((p % 12) as f32 + 0.5, (p / 12) as f32 + 0.5))).collect();
        assert!(same_bits(k.key_rays(index), &want), "key {index}");
        for mode in BOTH {
            assert!(same_bits(&k.frame(k.frames()[index], mode).rays, &want));
        }
    }
    // An explicit resolution resamples every key, including the earliest.
    let k2 = Keys::new(vec![(0, large)], Some(UVec2::new(7, 3))).unwrap();
    assert_eq!(k2.frame(0, InbetweenMode::Smooth).rays.len(), 21);
}

/// Slerp in f64 by the textbook formula (accurate away from θ = 0 and π).
fn slerp_f64(a: DVec3, b: DVec3, s: f64) -> DVec3 {
    let (a, b) = (a.normalize(), b.normalize());
    let theta = a.dot(b).clamp(-1.0, 1.0).acos();
    ((a * ((1.0 - s) * theta).sin() + b * (s * theta).sin()) / theta.sin()).normalize()
}

#[test]
fn linear_mode_is_per_pixel_lerp_and_slerp() {
    let frames = [0u32, 7, 20];
    let keys = random_keys(6, 5, &frames, 4);
    let k = Keys::new(keys.clone(), None).unwrap();
    let mut checked = 0;
    for f in 0..=20u32 {
        let out = k.frame(f, InbetweenMode::Linear);
        let seg = if f < 7 { 0 } else { 1 };
        let (t0, t1) = (frames[seg] as f64, frames[seg + 1] as f64);
        let s = (f as f64 - t0) / (t1 - t0);
        for (p, got) in out.rays.iter().enumerate() {
            let (a, b) = (&keys[seg].1.rays[p], &keys[seg + 1].1.rays[p]);
            // Independent recomputation in f64.
            let o = a.origin.as_dvec3() + (b.origin.as_dvec3() - a.origin.as_dvec3()) * s;
            assert!((got.origin.as_dvec3() - o).length() < 2e-6, "frame {f} pixel {p}: origin");
            let (da, db) = (a.direction.as_dvec3(), b.direction.as_dvec3());
            let theta = da.normalize().dot(db.normalize()).clamp(-1.0, 1.0).acos();
            if theta > 1e-2 && theta < std::f64::consts::PI - 1e-2 {
                let d = slerp_f64(da, db, s);
                let err = (got.direction.as_dvec3() - d).length();
                assert!(err < 2e-6, "frame {f} pixel {p}: direction off by {err}");
                checked += 1;
            }
            // And exactly the crate's per-ray interpolation.
            assert_eq!(bits(got), bits(&lerp_rays(a, b, s as f32)));
        }
    }
    assert!(checked > 500, "{checked}");
}

/// Keys at the column's non-uniform frames, with some nearly opposite neighbouring directions.
const COLUMN: [u32; 4] = [0, 150, 400, 500];

fn column_keys(seed: u64) -> Vec<(u32, RayFile)> {
    let mut keys = random_keys(5, 4, &COLUMN, seed);
    // Pixel 0: nearly opposite directions at keys 0 and 150; pixel 1: at keys 150 and 400;
    // pixel 2: exactly opposite at 400 and 500; pixel 3: one direction at every key.
    let opposite = |d: Vec3, eps: f32| (-d + d.any_orthonormal_vector() * eps).normalize();
    keys[1].1.rays[0].direction = opposite(keys[0].1.rays[0].direction, 1e-3);
    keys[2].1.rays[1].direction = opposite(keys[1].1.rays[1].direction, 1e-5);
    keys[3].1.rays[2].direction = -keys[2].1.rays[2].direction;
    for k in 1..4 {
        keys[k].1.rays[3].direction = keys[0].1.rays[3].direction;
    }
    keys
}

/// The one-frame finite-difference check of C1 at a key, on samples r(t−2), …, r(t+2).
///
/// A curve that is C1 at t, cubic on each side, has one-frame differences
/// D+ = r(t+1) − r(t) = v + a₊/2 + j₊/6 and D− = r(t) − r(t−1) = v − a₋/2 + j₋/6 (a, j its
/// second and third derivatives on each side), so |D+ − D−| ≤ (|a₊| + |a₋|)/2 + |j₊ − j₋|/6.
/// The second differences A± = r(t±2) − 2r(t±1) + r(t) measure a± + j± (a Hermite segment h
/// frames long has |j| ~ |a|/h, under 1 % of |a| here), so the tolerance 0.75·(|A+| + |A−|)
/// leaves a 50 % margin, plus the f32 rounding of the five samples (`noise`: 8 ulps of the
/// values). A velocity jump J (any C0-only scheme, or tangents not scaled by the real key
/// spacing) adds J to D+ − D− and fails as soon as J exceeds the curvature term.
fn c1_violation(r: [Vec3; 5], noise: f32) -> Option<String> {
    let (d_minus, d_plus) = (r[2] - r[1], r[3] - r[2]);
    let a_minus = r[0] - 2.0 * r[1] + r[2];
    let a_plus = r[4] - 2.0 * r[3] + r[2];
    let gap = (d_plus - d_minus).length();
    let tol = 0.75 * (a_minus.length() + a_plus.length()) + noise;
    (gap > tol).then(|| format!("velocity jump {gap:.3e} > tolerance {tol:.3e} (D− {d_minus}, D+ {d_plus})"))
}

const ORIGIN_NOISE: f32 = 8.0 * 1e-6; // 8 ulps at |origin| ≤ 16
const DIRECTION_NOISE: f32 = 8.0 * 2.5e-7; // 8 × the kernel's ≈ 2 ulp direction error

/// Per pixel, (origin, direction) violations of the C1 check at the interior keys, frames from
/// `frame(n)` at integer frames.
fn c1_report(k: &Keys, mode: InbetweenMode) -> Vec<String> {
    let mut bad = Vec::new();
    for &t in &COLUMN[1..3] {
        let samples: Vec<RayFile> = (t - 2..=t + 2).map(|f| k.frame(f, mode)).collect();
        for p in 0..samples[0].rays.len() {
            let at = |pick: fn(&StoredRay) -> Vec3| {
                std::array::from_fn::<Vec3, 5, _>(|n| pick(&samples[n].rays[p]))
            };
            if let Some(e) = c1_violation(at(|r| r.origin), ORIGIN_NOISE) {
                bad.push(format!("key {t}, pixel {p}, origin: {e}"));
            }
            if let Some(e) = c1_violation(at(|r| r.direction), DIRECTION_NOISE) {
                bad.push(format!("key {t}, pixel {p}, direction: {e}"));
            }
        }
    }
    bad
}

#[test]
fn smooth_mode_is_c1_at_interior_keys_and_linear_is_not() {
    for seed in [5, 6, 7] {
        let k = Keys::new(column_keys(seed), None).unwrap();
        let bad = c1_report(&k, InbetweenMode::Smooth);
        assert!(bad.is_empty(), "smooth, seed {seed}:\n{}", bad.join("\n"));
        // The same check catches a C0-only scheme: linear fails it at (nearly) every pixel
        // that moves (pixel 3's direction never moves, so its direction passes).
        let linear = c1_report(&k, InbetweenMode::Linear);
        assert!(linear.len() >= 2 * 2 * 20 - 2 - 2, "linear, seed {seed}: only {} failures", linear.len());
    }
}

#[test]
fn the_c1_check_catches_tangents_not_scaled_by_the_key_spacing() {
    // Uniform Catmull–Rom evaluated segment by segment (tangent (p_{k+1} − p_{k−1})/2 per unit
    // of the segment parameter) is C1 in the parameter but not in frames when keys are unevenly
    // spaced: at key 150 its per-frame velocity jumps from m/150 to m/250.
    let keys = column_keys(8);
    let p = |k: usize, px: usize| keys[k].1.rays[px].origin;
    let naive = |px: usize, t: f64| {
        let k = COLUMN.partition_point(|&f| f as f64 <= t).clamp(1, 3) - 1;
        let s = ((t - COLUMN[k] as f64) / (COLUMN[k + 1] - COLUMN[k]) as f64) as f32;
        let m = |j: usize| if j == 0 || j == 3 { Vec3::ZERO } else { (p(j + 1, px) - p(j - 1, px)) * 0.5 };
        let (s2, s3) = (s * s, s * s * s);
        p(k, px) * (2.0 * s3 - 3.0 * s2 + 1.0)
            + m(k) * (s3 - 2.0 * s2 + s)
            + p(k + 1, px) * (3.0 * s2 - 2.0 * s3)
            + m(k + 1) * (s3 - s2)
    };
    let mut failures = 0;
    for px in 0..20 {
        let r = std::array::from_fn(|n| naive(px, 150.0 + n as f64 - 2.0));
        failures += c1_violation(r, ORIGIN_NOISE).is_some() as usize;
    }
    assert!(failures >= 19, "{failures}");
}

#[test]
fn velocity_at_a_key_is_the_frame_scaled_catmull_rom_tangent() {
    // Independently: m_k = (p_{k+1} − p_{k−1}) / (t_{k+1} − t_{k−1}) per frame for origins, and
    // the same difference of arc vectors (acos-based here) for directions. One-sided differences
    // over δ frames are off by |a|·δ/2 ≈ |A|/(2δ) (A the second difference at step δ).
    let keys = column_keys(9);
    let k = Keys::new(keys.clone(), None).unwrap();
    let log = |a: DVec3, b: DVec3| {
        let (a, b) = (a.normalize(), b.normalize());
        let perp = b - a * a.dot(b);
        perp.normalize_or_zero() * a.dot(b).clamp(-1.0, 1.0).acos()
    };
    for (ki, &t) in COLUMN.iter().enumerate().skip(1).take(2) {
        let span = (COLUMN[ki + 1] - COLUMN[ki - 1]) as f64;
        for px in 4..20 {
            let (prev, key, next) =
                (&keys[ki - 1].1.rays[px], &keys[ki].1.rays[px], &keys[ki + 1].1.rays[px]);
            let mo = (next.origin.as_dvec3() - prev.origin.as_dvec3()) / span;
            let d = key.direction.as_dvec3();
            let md = (log(d, next.direction.as_dvec3()) - log(d, prev.direction.as_dvec3())) / span;
            for delta in [1.0, 0.25] {
                let r = |n: f64| k.ray(px, t as f64 + n * delta, InbetweenMode::Smooth);
                for sign in [-1.0, 1.0] {
                    let (r0, r1, r2) = (r(0.0), r(sign), r(2.0 * sign));
                    for (what, v0, v1, v2, m, noise) in [
                        ("origin", r0.origin, r1.origin, r2.origin, mo, ORIGIN_NOISE),
                        ("direction", r0.direction, r1.direction, r2.direction, md, DIRECTION_NOISE),
                    ] {
                        let v = ((v1 - v0) * sign as f32 / delta as f32).as_dvec3();
                        let a = (v2 - 2.0 * v1 + v0).length() as f64;
                        let tol = 0.75 * a / delta + (noise as f64) / delta;
                        let err = (v - m).length();
                        assert!(
                            err <= tol,
                            "key {t} pixel {px} {what} δ={delta} side {sign}: {v} vs {m} ({err:.2e} > {tol:.2e})"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn smooth_mode_is_continuous_and_joins_the_holds_smoothly() {
    let k = Keys::new(column_keys(10), None).unwrap();
    let eps = 1e-3;
    for &t in &COLUMN {
        for px in 0..20 {
            let at = k.ray(px, t as f64, InbetweenMode::Smooth);
            for side in [-eps, eps] {
                let r = k.ray(px, t as f64 + side, InbetweenMode::Smooth);
                // Velocities here are at most ~0.1 unit and ~0.05 rad per frame (2π/250 for
                // the nearly opposite pixels), so a 1e-3-frame step moves under 1e-4.
                assert!((r.origin - at.origin).length() < 1e-4, "key {t} pixel {px}");
                assert!((r.direction - at.direction).length() < 1e-4, "key {t} pixel {px}");
            }
        }
    }
    // Two keys: an eased lerp / slerp (zero velocity at both keys, so the holds join C1).
    let keys = random_keys(4, 4, &[10, 30], 11);
    let k = Keys::new(keys.clone(), None).unwrap();
    for f in 10..=30 {
        let s = (f - 10) as f64 / 20.0;
        let e = s * s * (3.0 - 2.0 * s);
        for (p, got) in k.frame(f, InbetweenMode::Smooth).rays.iter().enumerate() {
            let (a, b) = (&keys[0].1.rays[p], &keys[1].1.rays[p]);
            let o = a.origin.as_dvec3().lerp(b.origin.as_dvec3(), e);
            assert!((got.origin.as_dvec3() - o).length() < 2e-6, "frame {f} pixel {p}");
            let d = slerp_f64(a.direction.as_dvec3(), b.direction.as_dvec3(), e);
            assert!((got.direction.as_dvec3() - d).length() < 2e-6, "frame {f} pixel {p}");
        }
    }
    let near_end = k.ray(3, 10.01, InbetweenMode::Smooth).origin - keys[0].1.rays[3].origin;
    assert!(near_end.length() < 1e-4, "zero velocity at the first key: moved {near_end}");
}

#[test]
fn never_nan_or_non_unit_over_random_keys() {
    let mut rng = Rng::new(12);
    let mut rays_checked = 0usize;
    for trial in 0..60 {
        let n = 1 + rng.below(5) as usize;
        let mut frames: Vec<u32> = Vec::new();
        while frames.len() < n {
            let f = rng.below(40);
            if !frames.contains(&f) {
                frames.push(f);
            }
        }
        frames.sort();
        // Keys of random sizes; the first key's pixels set the pattern for nearly opposite,
        // exactly opposite, equal and nearly equal directions at neighbouring keys.
        let mut keys: Vec<(u32, RayFile)> = Vec::new();
        for (ki, &f) in frames.iter().enumerate() {
            let (w, h) = if trial % 3 == 0 { (4, 3) } else { (1 + rng.below(6), 1 + rng.below(5)) };
            let mut key = random_key(w, h, &mut rng);
            if ki > 0 && (keys[ki - 1].1.width, keys[ki - 1].1.height) == (w, h) {
                for (p, r) in key.rays.iter_mut().enumerate() {
                    let d = keys[ki - 1].1.rays[p].direction;
                    let q = d.any_orthonormal_vector();
                    r.direction = match (p + ki) % 6 {
                        0 => -d,
                        1 => (-d + q * 1e-6).normalize(),
                        2 => (-d + q * 3e-3).normalize(),
                        3 => d,
                        4 => (d + q * 1e-7).normalize(),
                        _ => r.direction,
                    };
                }
            }
            // Stored directions need only be unit to 1e-4 (ray_file::UNIT_TOLERANCE).
            for r in key.rays.iter_mut().step_by(4) {
                r.direction *= 1.0 + 9e-5 * if ki % 2 == 0 { 1.0 } else { -1.0 };
            }
            keys.push((f, key));
        }
        let resolution = (trial % 2 == 0).then(|| UVec2::new(1 + rng.below(7), 1 + rng.below(6)));
        let k = Keys::new(keys, resolution).unwrap();
        let (first, last) = (frames[0], frames[n - 1]);
        for mode in BOTH {
            for f in first.saturating_sub(2)..=last + 2 {
                let out = k.frame(f, mode);
                // Key frames and holds are the (resampled) keys' rays; in-betweens are unit to f32
                // precision even when the keys are not.
                let between = f > first && f < last && !frames.contains(&f);
                let tolerance = if between { 1e-6 } else { 1e-4 };
                for (p, r) in out.rays.iter().enumerate() {
                    let len = r.direction.as_dvec3().length();
                    assert!(
                        r.origin.is_finite() && (len - 1.0).abs() <= tolerance,
                        "trial {trial} {mode:?} frame {f} pixel {p}: {r:?} (|d| = {len})"
                    );
                }
                rays_checked += out.rays.len();
                assert!(out.first_defect().is_none());
            }
            for _ in 0..20 {
                let t = first as f64 + rng.unit() as f64 * (last - first) as f64;
                if frames.contains(&(t as u32)) && t.fract() == 0.0 {
                    continue;
                }
                let r = k.ray(0, t, mode);
                assert!(r.origin.is_finite() && (r.direction.length() - 1.0).abs() <= 1e-6, "t = {t}: {r:?}");
            }
        }
    }
    assert!(rays_checked > 10_000, "{rays_checked}");
}

#[test]
fn frames_do_not_depend_on_the_thread_count() {
    let k = Keys::new(random_keys(37, 23, &[0, 5, 17, 30], 13), None).unwrap();
    let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
    for mode in BOTH {
        for f in [2, 5, 11, 29] {
            let one = pool(1).install(|| k.frame(f, mode));
            let three = pool(3).install(|| k.frame(f, mode));
            assert!(same_bits(&one.rays, &three.rays), "{mode:?} frame {f}");
            // `ray` at an integer time is what `frame` computes.
            for p in [0, 100, 850] {
                assert_eq!(bits(&k.ray(p, f as f64, mode)), bits(&one.rays[p]));
            }
        }
    }
}

#[test]
fn bad_inputs_are_refused_with_names() {
    let err = |r: Result<Keys>| r.unwrap_err().to_string();
    assert!(err(Keys::new(Vec::new(), None)).contains("no keys"));
    assert!(err(Keys::load(&[], None)).contains("no keys"));
    // Duplicate frames in memory: both keys are named.
    let mut keys = random_keys(3, 2, &[5, 9, 5], 14);
    let e = err(Keys::new(keys.clone(), None));
    assert!(e.contains("frame 5") && e.contains("keys 1 and 3"), "{e}");
    // A malformed key in memory.
    keys[2].0 = 6;
    keys[1].1.rays[4].direction = Vec3::new(0.0, 2.0, 0.0);
    let e = err(Keys::new(keys.clone(), None));
    assert!(e.contains("key at frame 9") && e.contains("pixel (1, 1)") && e.contains("not unit"), "{e}");
    keys[1].1.rays.pop();
    let e = err(Keys::new(keys, None));
    assert!(e.contains("key at frame 9") && e.contains("5 rays for a 3x2"), "{e}");
    assert!(err(Keys::new(random_keys(3, 2, &[0], 15), Some(UVec2::new(0, 4)))).contains("0x4"));
    // From files: duplicates name both files (before reading either), unreadable files name
    // themselves.
    let dir = scratch_dir("inbetween-bad");
    let (a, b, garbage, missing) =
        (dir.join("a.mcr"), dir.join("b.mcr"), dir.join("garbage.mcr"), dir.join("missing.mcr"));
    for (path, (_, key)) in [&a, &b].into_iter().zip(random_keys(3, 2, &[0, 1], 16)) {
        key.write(path, RayFormat::Binary).unwrap();
    }
    std::fs::write(&garbage, b"3 2\n0 0 1 2 3 0 0 1\n").unwrap();
    let e = err(Keys::load(&[(0, a.clone()), (4, b.clone()), (4, a.clone())], None));
    assert!(e.contains("a.mcr") && e.contains("b.mcr") && e.contains("frame 4"), "{e}");
    let e = err(Keys::load(&[(0, a.clone()), (9, missing.clone())], None));
    assert!(e.contains("missing.mcr"), "{e}");
    let e = err(Keys::load(&[(0, a.clone()), (9, garbage.clone())], None));
    assert!(e.contains("garbage.mcr"), "{e}");
    let ok = Keys::load(&[(7, b.clone()), (2, a.clone())], Some(UVec2::new(6, 4))).unwrap();
    assert_eq!((ok.frames(), ok.resolution()), (vec![2, 7], UVec2::new(6, 4)));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_frames_writes_computed_rerender_files() {
    let dir = scratch_dir("inbetween-write");
    let out = dir.join("lens");
    let k = Keys::new(random_keys(6, 3, &[2, 5], 17), None).unwrap();
    for format in [RayFormat::Binary, RayFormat::Text] {
        let seen = RefCell::new(Vec::new());
        let paths =
            write_frames(&k, 0..=6, InbetweenMode::Smooth, &out, format, &|f| seen.borrow_mut().push(f))
                .unwrap();
        assert_eq!(*seen.borrow(), (0..=6).collect::<Vec<_>>());
        assert_eq!(paths.len(), 7);
        for (f, path) in (0..=6).zip(&paths) {
            assert_eq!(path, &out.join(rerender_name(f, format)));
            let read = RayFile::read(path).unwrap();
            let want = k.frame(f, InbetweenMode::Smooth);
            assert!(same_bits(&read.rays, &want.rays), "{format:?} frame {f}");
            if format == RayFormat::Binary {
                assert_eq!((read.frame, read.camera_id, read.computed), (f, 0, true));
            }
        }
    }
    // Nothing else (no temporary files) is left behind.
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 14, "{names:?}");
    // A failure is reported with the file's name: a directory where a frame's file must go.
    std::fs::create_dir_all(out.join(rerender_name(9, RayFormat::Binary))).unwrap();
    let e = write_frames(&k, 8..=10, InbetweenMode::Linear, &out, RayFormat::Binary, &|_| {}).unwrap_err();
    assert!(e.to_string().contains("rerender-frame0009.mcr"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Keys loaded with a crop lose the border of their own pixels before resampling: a key's
/// inner rays come back bit for bit; a crop that leaves nothing names the file.
#[test]
fn keys_load_cropped() {
    let dir = scratch_dir("inbetween-crop");
    let (a, b) = (dir.join("a.mcr"), dir.join("b.mcr"));
    let keys = random_keys(8, 6, &[0, 4], 18);
    for (path, (_, key)) in [&a, &b].into_iter().zip(&keys) {
        key.write(path, RayFormat::Binary).unwrap();
    }
    let cropped = Keys::load_cropped(&[(0, a.clone()), (4, b.clone())], 2, None).unwrap();
    assert_eq!(cropped.resolution(), UVec2::new(4, 2));
    assert!(same_bits(cropped.key_rays(0), &keys[0].1.without_border(2).unwrap().rays));
    let frame = cropped.frame(4, InbetweenMode::Smooth);
    assert!(same_bits(&frame.rays, &keys[1].1.without_border(2).unwrap().rays));
    let e = Keys::load_cropped(&[(0, a)], 3, None).unwrap_err().to_string();
    assert!(e.contains("a.mcr") && e.contains("crop 3 leaves nothing of a 8x6 key"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
