//! Adaptive sampling: where a render's samples go when they need not be spread evenly.
//!
//! A pilot pass gives every pixel a quarter of the average budget; the rest goes where the
//! pilot saw the most *relative* noise (variance / (mean² + `REL_MSE_EPSILON`), relMSE's own
//! weighting), so the finished image's relative error (what the eye and relMSE measure) is
//! spread evenly instead of piling up in dark, noisy corners. With an
//! error ∝ v_i / n_i per pixel of relative variance v_i, the mean error is least for
//! n_i ∝ √v_i (a Lagrange multiplier on Σ n_i); that is the share used here. The pilot's
//! variance is itself noisy, so it is averaged over each pixel's 3×3 neighbourhood first.
//!
//! Everything is a pure function of the pilot film, computed in a fixed order, so the counts
//! (and the image) do not depend on the thread count.

use crate::film::PixelAccumulator;
use crate::sampler::MAX_SAMPLES_PER_PIXEL;

/// relMSE's regulariser: a squared error is divided by r² + this, so black pixels count their
/// error against 0.1 rather than divide by zero (`compare::rel_mse`; the pilot's relative noise
/// is weighed the same way).
pub const REL_MSE_EPSILON: f64 = 0.01;

/// The pilot pass takes this fraction (1 / `PILOT_SHARE`) of the average samples per pixel.
pub const PILOT_SHARE: u32 = 4;

/// No pixel takes more than this many times the average samples per pixel.
pub const MAX_SHARE: u32 = 16;

/// The pilot pass's samples per pixel for an average of `spp`, or `None` when `spp` is too
/// small to split (under [`PILOT_SHARE`] samples: every pixel takes all of them).
pub fn pilot_spp(spp: u32) -> Option<u32> {
    (spp >= PILOT_SHARE).then_some(spp / PILOT_SHARE)
}

/// Each pixel's total samples (pilot included) for an average of `spp` per pixel, from the
/// `pilot` film (`width` × `height`, row-major) that took `pilot_spp(spp)` samples per pixel.
/// Every pixel keeps at least its pilot samples and takes at most [`MAX_SHARE`] × `spp` and at
/// most `limit` (the sampler's range: [`MAX_SAMPLES_PER_PIXEL`] over the branches each sample
/// splits into); the total never exceeds `spp` per pixel on average.
pub fn sample_counts(pilot: &[PixelAccumulator], width: u32, height: u32, spp: u32, limit: u32) -> Vec<u32> {
    debug_assert!(limit >= spp && limit <= MAX_SAMPLES_PER_PIXEL);
    debug_assert_eq!(pilot.len(), width as usize * height as usize);
    let Some(pilot_spp) = pilot_spp(spp) else {
        return vec![spp; pilot.len()];
    };
    let relative: Vec<f64> = pilot
        .iter()
        .map(|p| {
            let (mean, var) = (p.mean(), p.variance());
            (0..3).map(|c| var[c] / (mean[c] * mean[c] + REL_MSE_EPSILON)).sum::<f64>() / 3.0
        })
        .collect();
    let (w, h) = (width as usize, height as usize);
    let weight: Vec<f64> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let (mut sum, mut n) = (0.0, 0.0);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    sum += relative[yy * w + xx];
                    n += 1.0;
                }
            }
            (sum / n).sqrt()
        })
        .collect();
    let total: f64 = weight.iter().sum();
    let extra = (spp - pilot_spp) as f64 * pilot.len() as f64;
    let most = limit.min(spp.saturating_mul(MAX_SHARE));
    // A film with no noise at all (or NaN weights, which cannot arise from finite
    // accumulators) is sampled evenly.
    let even = !(total > 0.0 && total.is_finite());
    // Shares are fractional; the fractions carry on to the next pixel (row-major), so the
    // counts add up to the budget instead of losing up to a sample per pixel to rounding.
    let mut carry = 0.0;
    weight
        .iter()
        .map(|&wt| {
            let share = if even { (spp - pilot_spp) as f64 } else { extra * wt / total };
            let whole = (share + carry).floor();
            carry = share + carry - whole;
            (pilot_spp as f64 + whole).min(most as f64) as u32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A pilot film whose pixel i took `n` samples alternating between `a[i]` and `b[i]`.
    fn film(values: &[(f32, f32)], n: u32) -> Vec<PixelAccumulator> {
        values
            .iter()
            .map(|&(a, b)| {
                let mut p = PixelAccumulator::default();
                for k in 0..n {
                    p.add(Vec3::splat(if k % 2 == 0 { a } else { b }));
                }
                p
            })
            .collect()
    }

    /// Noisier pixels (relative to their value) get more samples, in proportion to the square
    /// root of their blurred relative variance; every pixel keeps its pilot; the total stays
    /// within the budget and close to it.
    #[test]
    fn noisy_pixels_get_more_samples_within_budget() {
        // 8 × 1 film: quiet bright pixels on the left, noisy dark ones on the right.
        let values: Vec<(f32, f32)> = (0..8).map(|x| if x < 4 { (1.0, 1.02) } else { (0.0, 0.2) }).collect();
        let spp = 64;
        let pilot = film(&values, pilot_spp(spp).unwrap());
        let counts = sample_counts(&pilot, 8, 1, spp, MAX_SAMPLES_PER_PIXEL);
        assert!(counts.iter().all(|&n| n >= 16), "{counts:?}");
        assert!(counts[0] < counts[7] && counts[1] < counts[6], "{counts:?}");
        assert!(counts.windows(2).all(|w| w[0] <= w[1]), "monotone in the noise: {counts:?}");
        let total: u32 = counts.iter().sum();
        assert!(total <= 8 * spp && total + 1 >= 8 * spp, "total {total}");
        // Brute force: the share of the extra samples is √v over Σ√v, v blurred over 3 pixels.
        let rel = |p: &PixelAccumulator| {
            let (m, v) = (p.mean(), p.variance());
            (0..3).map(|c| v[c] / (m[c] * m[c] + 0.01)).sum::<f64>() / 3.0
        };
        let v: Vec<f64> = pilot.iter().map(rel).collect();
        let blurred: Vec<f64> = (0..8)
            .map(|x: usize| {
                let r = x.saturating_sub(1)..(x + 2).min(8);
                let n = r.len() as f64;
                (r.map(|i| v[i]).sum::<f64>() / n).sqrt()
            })
            .collect();
        let sum: f64 = blurred.iter().sum();
        let mut given = 0.0;
        for (x, &count) in counts.iter().enumerate() {
            // What the first x + 1 pixels have between them, less what the first x have.
            let upto = |k: usize| (48.0 * 8.0 * blurred[..k].iter().sum::<f64>() / sum + 1e-9).floor();
            assert_eq!(count as f64, 16.0 + upto(x + 1) - given, "pixel {x}");
            given = upto(x + 1);
        }
    }

    /// A noiseless film is sampled evenly; too few samples to split are not split; no pixel
    /// exceeds the cap even when all the noise is in one pixel.
    #[test]
    fn even_small_and_capped_cases() {
        let flat = film(&[(0.5, 0.5); 6], 8);
        assert_eq!(sample_counts(&flat, 3, 2, 32, MAX_SAMPLES_PER_PIXEL), vec![32; 6]);
        assert_eq!(pilot_spp(3), None);
        assert_eq!(sample_counts(&film(&[(0.0, 1.0); 4], 3), 2, 2, 3, MAX_SAMPLES_PER_PIXEL), vec![3; 4]);
        let mut one = vec![(0.3, 0.3); 400];
        one[210] = (0.0, 5.0);
        let counts = sample_counts(&film(&one, 4), 20, 20, 16, MAX_SAMPLES_PER_PIXEL);
        assert_eq!(counts.iter().max(), Some(&(16 * MAX_SHARE)));
        assert!(counts.iter().all(|&n| n >= 4));
        // A limit below the share's cap (the sampler's range split between branches) holds.
        let counts = sample_counts(&film(&one, 4), 20, 20, 16, 100);
        assert_eq!(counts.iter().max(), Some(&100));
        assert!(counts.iter().all(|&n| n >= 4));
    }
}
