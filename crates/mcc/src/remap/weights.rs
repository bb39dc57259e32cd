//! Step 3 of the remapper (docs/design.md §5.3): initial weights. A camera pixel of camera c gets
//! α_c = 1 and every other α = 0. A background pixel P with participants S (the cameras with an
//! edge pixel in P's region; all cameras if none has, with a warning naming the region) gets
//!
//! * |S| = 1: α = 1 for that camera;
//! * otherwise, with d_i = |P − e_i(P)| and g_i = d_i / Σ_j d_j:
//!   v_i = (1 − g_i)·Π_{j≠i} g_j and α_i = v_i / Σ_j v_j.
//!
//! The product underflows long before 63 cameras (g ~ 1/63 each: 63^-62 ≈ 1e-112 in f64 is fine,
//! but the same collage in f32, or a few hundred cameras in f64, is not). Dividing every v_i by the
//! common factor Π_j g_j > 0 leaves α unchanged and gives v_i ∝ (1 − g_i)/g_i = (D − d_i)/d_i with
//! D = Σ_j d_j: no product, no underflow. A zero distance (never the case for a background pixel,
//! whose nearest edge pixels are other pixels, but the function is public) is handled exactly:
//! one camera at distance 0 takes α = 1, the limit of the formula; several share equally.

use super::RemapWarning;
use super::nearest::NearestEdges;
use crate::regions::Regions;
use rayon::prelude::*;

/// Step 3's weights from the distances `d` (≥ 0) of a pixel's participants, into `alpha`
/// (same length and order). They are ≥ 0, sum to 1, and α_k → 1 as d_k → 0.
pub fn interpolation_weights(d: &[f64], alpha: &mut [f64]) {
    match d.len() {
        0 => return,
        1 => {
            alpha[0] = 1.0;
            return;
        }
        _ => {}
    }
    let zeros = d.iter().filter(|&&x| x == 0.0).count();
    if zeros > 0 {
        let share = 1.0 / zeros as f64;
        for (a, &x) in alpha.iter_mut().zip(d) {
            *a = if x == 0.0 { share } else { 0.0 };
        }
        return;
    }
    let total: f64 = d.iter().sum();
    let mut sum = 0.0;
    for (a, &x) in alpha.iter_mut().zip(d) {
        // (D − d_i)/d_i, with D − d_i summed from the others' distances is the same to rounding.
        *a = (total - x).max(0.0) / x;
        sum += *a;
    }
    if sum > 0.0 && sum.is_finite() {
        alpha.iter_mut().for_each(|a| *a /= sum);
    } else {
        alpha.iter_mut().for_each(|a| *a = 1.0 / d.len() as f64);
    }
}

/// The cameras participating in each region (`participates[k][r]`: camera k has an edge pixel in
/// region r; all cameras where none has), and a warning for every region with background pixels
/// that no camera touches.
pub(crate) fn participants(
    participates: &[Vec<bool>],
    regions: &Regions,
    background: &[usize],
    cameras: usize,
) -> (Vec<Vec<usize>>, Vec<RemapWarning>) {
    let mut warnings = Vec::new();
    let lists = (0..regions.count())
        .map(|r| {
            let s: Vec<usize> = (0..cameras).filter(|&k| participates[k][r]).collect();
            if !s.is_empty() {
                return s;
            }
            if background[r] > 0 {
                warnings.push(RemapWarning::RegionWithoutCameras {
                    region: r as u32,
                    info: regions.info[r].clone(),
                    background_pixels: background[r],
                });
            }
            (0..cameras).collect()
        })
        .collect();
    (lists, warnings)
}

/// The initial weight planes (one per camera index, f32): rows in parallel, every plane's row
/// written by the task that owns the row.
pub(crate) fn initial_weights(
    cam: &[u32],
    region: &[u32],
    nearest: &NearestEdges,
    participants: &[Vec<usize>],
    cameras: usize,
    width: usize,
) -> Vec<Vec<f32>> {
    let mut planes = vec![vec![0f32; cam.len()]; cameras];
    let rows = super::rows_mut(&mut planes, width);
    rows.into_par_iter().enumerate().for_each_init(
        || (Vec::with_capacity(cameras), vec![0f64; cameras]),
        |(d, alpha), (y, mut row)| {
            // `row[k][x]` reaches across planes: an index loop is the clear form here.
            #[allow(clippy::needless_range_loop)]
            for x in 0..width {
                let p = y * width + x;
                let c = cam[p];
                if c != 0 {
                    row[c as usize - 1][x] = 1.0;
                    continue;
                }
                let s = &participants[region[p] as usize];
                d.clear();
                for &k in s {
                    // u32 division: several times cheaper than usize division on x86-64.
                    let (e, w) = (nearest.planes[k][p], width as u32);
                    let (dx, dy) = ((e % w) as f64 - x as f64, (e / w) as f64 - y as f64);
                    d.push((dx * dx + dy * dy).sqrt());
                }
                interpolation_weights(d, &mut alpha[..s.len()]);
                for (&k, &a) in s.iter().zip(alpha.iter()) {
                    row[k][x] = a as f32;
                }
            }
        },
    );
    planes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The formula as written, in f64 (fine for few cameras).
    fn literal(d: &[f64]) -> Vec<f64> {
        let total: f64 = d.iter().sum();
        let g: Vec<f64> = d.iter().map(|x| x / total).collect();
        let v: Vec<f64> = (0..d.len())
            .map(|i| (1.0 - g[i]) * (0..d.len()).filter(|&j| j != i).map(|j| g[j]).product::<f64>())
            .collect();
        let sum: f64 = v.iter().sum();
        v.iter().map(|x| x / sum).collect()
    }

    #[test]
    fn equals_the_literal_formula() {
        let mut rng = crate::test_util::Rng::new(8);
        for _ in 0..1000 {
            let n = 2 + rng.below(7) as usize;
            let d: Vec<f64> = (0..n).map(|_| 1.0 + rng.unit() as f64 * 100.0).collect();
            let mut a = vec![0.0; n];
            interpolation_weights(&d, &mut a);
            for (x, y) in a.iter().zip(literal(&d)) {
                assert!((x - y).abs() < 1e-12, "{a:?}");
            }
        }
    }

    #[test]
    fn interpolates_sums_to_one_and_never_nan() {
        // α_k → 1 as d_k → 0.
        let mut a = [0.0; 3];
        let mut last = 0.0;
        for dk in [10.0, 1.0, 0.1, 1e-3, 1e-6, 1e-9] {
            interpolation_weights(&[dk, 5.0, 7.0], &mut a);
            assert!(a[0] > last);
            last = a[0];
        }
        assert!(last > 1.0 - 1e-8);
        interpolation_weights(&[0.0, 5.0, 7.0], &mut a);
        assert_eq!(a, [1.0, 0.0, 0.0]);
        interpolation_weights(&[0.0, 0.0, 7.0], &mut a);
        assert_eq!(a, [0.5, 0.5, 0.0]);
        let mut one = [0.0];
        interpolation_weights(&[3.0], &mut one);
        assert_eq!(one, [1.0]);
        // 63 cameras (the literal product underflows to 0/0 for many more): finite, sums to 1.
        for n in [63usize, 511, 5000] {
            let d: Vec<f64> = (0..n).map(|i| 1.0 + (i * 7919 % 1000) as f64).collect();
            let mut a = vec![0.0; n];
            interpolation_weights(&d, &mut a);
            assert!(a.iter().all(|x| x.is_finite() && *x >= 0.0));
            assert!((a.iter().sum::<f64>() - 1.0).abs() < 1e-9);
            // Nearer cameras weigh more.
            let nearest = (0..n).min_by(|&i, &j| d[i].total_cmp(&d[j])).unwrap();
            assert!(a.iter().all(|&x| x <= a[nearest]));
        }
        assert!(literal(&(0..5000).map(|i| 1.0 + i as f64).collect::<Vec<_>>()).iter().any(|x| x.is_nan()));
    }
}
