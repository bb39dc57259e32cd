use super::*;
use crate::test_util::Rng;

/// The membrane by plain Gauss–Seidel in f64 until it stops moving (the definition, slowly).
fn brute(w: usize, h: usize, fixed: &[bool], values: &[f64]) -> Vec<f64> {
    let mut u = values.to_vec();
    for _ in 0..400_000 {
        let mut change = 0.0f64;
        for y in 0..h {
            for x in 0..w {
                let p = y * w + x;
                if fixed[p] {
                    continue;
                }
                let (mut s, mut n) = (0.0, 0.0);
                for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                    if xx >= 0 && yy >= 0 && (xx as usize) < w && (yy as usize) < h {
                        s += u[yy as usize * w + xx as usize];
                        n += 1.0;
                    }
                }
                let v = s / n;
                change = change.max((v - u[p]).abs());
                u[p] = v;
            }
        }
        if change < 1e-14 {
            break;
        }
    }
    u
}

/// Discs and rings of fixed pixels (at least one fixed pixel).
fn random_mask(rng: &mut Rng, w: usize, h: usize) -> Vec<bool> {
    let mut fixed = vec![false; w * h];
    for _ in 0..1 + rng.below(4) {
        let (cx, cy) = (rng.below(w as u32) as i64, rng.below(h as u32) as i64);
        let r = 1 + rng.below((w.max(h) / 3) as u32 + 1) as i64;
        let ring = rng.below(2) == 0;
        for (p, f) in fixed.iter_mut().enumerate() {
            let (x, y) = ((p % w) as i64, (p / w) as i64);
            let d2 = (x - cx).pow(2) + (y - cy).pow(2);
            if d2 <= r * r && (!ring || d2 * 4 >= r * r) {
                *f = true;
            }
        }
    }
    if !fixed.iter().any(|&f| f) {
        fixed[rng.below((w * h) as u32) as usize] = true;
    }
    fixed
}

#[test]
fn matches_gauss_seidel_to_convergence() {
    let mut rng = Rng::new(31);
    for case in 0..60 {
        let (w, h) = (1 + rng.below(48) as usize, 1 + rng.below(36) as usize);
        let fixed = random_mask(&mut rng, w, h);
        let values: Vec<f64> =
            (0..w * h).map(|p| if fixed[p] { rng.unit() as f64 * 4.0 - 2.0 } else { 0.0 }).collect();
        let want = brute(w, h, &fixed, &values);
        let mut membrane = Membrane::<1>::new(Grid::new(w, h));
        let mut got: Vec<[f32; 1]> = values.iter().map(|&v| [v as f32]).collect();
        let solved = membrane.solve(|p| fixed[p], &mut got, 1e-5, 100);
        assert!(solved.relative_residual <= 1e-5, "case {case}: {solved:?}");
        for p in 0..w * h {
            if fixed[p] {
                assert_eq!(got[p][0], values[p] as f32, "fixed pixels keep their values");
            }
            // f32 and a residual of 1e-5 of the start's: within 1e-4 of values spanning 4.
            assert!(
                (got[p][0] as f64 - want[p]).abs() < 1e-4,
                "case {case} {w}x{h} pixel {p}: {} vs {}",
                got[p][0],
                want[p]
            );
        }
    }
}

#[test]
fn reproduces_a_linear_ramp_between_two_fixed_columns() {
    // Fixed first and last columns holding a ramp in x: the membrane (Neumann above and below)
    // is the ramp itself, in every channel.
    let (w, h) = (301, 173);
    let fixed: Vec<bool> = (0..w * h).map(|p| p % w == 0 || p % w == w - 1).collect();
    let ramp = |p: usize| [(p % w) as f32 / (w - 1) as f32, 3.0 - 2.0 * (p % w) as f32 / (w - 1) as f32];
    let mut values: Vec<[f32; 2]> =
        (0..w * h).map(|p| if fixed[p] { ramp(p) } else { [0.5, -1.0] }).collect();
    let solved = Membrane::<2>::new(Grid::new(w, h)).solve(|p| fixed[p], &mut values, 1e-5, 50);
    assert!(solved.relative_residual <= 1e-5, "{solved:?}");
    // The residual left (1e-5 of the start's) sits in the smoothest mode, whose eigenvalue
    // ~(π/300)² ≈ 1e-4 magnifies it: the error stays within a tenth of one pixel's step (1/300).
    for (p, v) in values.iter().enumerate() {
        let want = ramp(p);
        assert!(
            (v[0] - want[0]).abs() < 3.3e-4 && (v[1] - want[1]).abs() < 6.6e-4,
            "pixel {p}: {v:?} vs {want:?}"
        );
    }
}

#[test]
fn few_iterations_on_a_large_grid_and_a_symmetric_preconditioner() {
    // Rings and discs on 640 × 360: the iteration count is the solver's cost, and it must stay
    // small (it grows with the levels only slowly).
    let (w, h) = (640, 360);
    let mut rng = Rng::new(3);
    let fixed = random_mask(&mut rng, w, h);
    let values: Vec<[f32; 2]> = (0..w * h)
        .map(|p| if fixed[p] { [(p % w) as f32 * 0.01, ((p / w) as f32 * 0.1).sin()] } else { [0.0; 2] })
        .collect();
    let mut membrane = Membrane::<2>::new(Grid::new(w, h));
    let mut u = values.clone();
    let solved = membrane.solve(|p| fixed[p], &mut u, 1e-5, 40);
    assert!(solved.relative_residual <= 1e-5 && solved.iterations <= 8, "{solved:?}");
    // Conjugate gradients needs <M⁻¹a, b> = <a, M⁻¹b> (the hierarchy is the last mask's).
    let random = |rng: &mut Rng| -> Vec<[f32; 2]> {
        (0..w * h).map(|p| if fixed[p] { [0.0; 2] } else { [rng.unit() - 0.5, rng.unit() - 0.5] }).collect()
    };
    let (a, b) = (random(&mut rng), random(&mut rng));
    let mut apply = |v: &[[f32; 2]]| {
        membrane.r.copy_from_slice(v);
        membrane.precondition();
        membrane.z.clone()
    };
    let (ma, mb) = (apply(&a), apply(&b));
    let (x, y) = (dots(&ma, &b, w), dots(&a, &mb, w));
    for k in 0..2 {
        assert!((x[k] - y[k]).abs() <= 1e-5 * x[k].abs().max(y[k].abs()), "{x:?} vs {y:?}");
    }
    assert!(dots(&ma, &a, w).iter().all(|&v| v > 0.0));
}

#[test]
fn same_bits_for_any_thread_count() {
    let (w, h) = (300, 200);
    let mut rng = Rng::new(8);
    let fixed = random_mask(&mut rng, w, h);
    let values: Vec<[f32; 3]> =
        (0..w * h).map(|p| if fixed[p] { [rng.unit(), rng.unit(), rng.unit()] } else { [0.0; 3] }).collect();
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut u = values.clone();
        pool.install(|| Membrane::<3>::new(Grid::new(w, h)).solve(|p| fixed[p], &mut u, 1e-6, 30));
        u.iter().flat_map(|v| v.map(f32::to_bits)).collect::<Vec<u32>>()
    };
    assert_eq!(run(1), run(3));
}
