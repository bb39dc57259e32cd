//! Image statistics for tests and benchmarks: error metrics (MSE, relMSE) and the statistical
//! golden test that tells "noisy but right" from "wrong" without flaky thresholds.
//!
//! The statistical test is Mitsuba 3's (docs/testing.md §2): each pixel-channel's difference from
//! the reference, divided by the standard error the render's own per-sample variance predicts, is a
//! z-score; its two-sided p-value is compared with a Šidák-corrected significance so that the
//! chance of *any* false failure in a correct image is 1 %, and the test passes when ≥ 99.75 % of
//! pixel-channels pass. Because a small global bias (a 2 % darker image) hides under per-pixel
//! noise, an image-level check adds the z-score of each channel's mean difference. All functions
//! panic if the images' sizes differ (a programming error, not a measurement).

use crate::image::RgbImage;
use std::fmt;

/// Mean squared error over all pixels and channels. Any non-finite pixel makes it non-finite.
pub fn mse(image: &RgbImage, reference: &RgbImage) -> f64 {
    mean_over_channels(image, reference, |x, r| (x - r) * (x - r))
}

// relMSE's regulariser lives with adaptive sampling, which renders use (this module is built for
// tests and benchmarks only, the `test-support` feature).
pub use crate::adaptive::REL_MSE_EPSILON;

/// Relative MSE, the Cornell README's convention: mean over pixels *and* channels of
/// (x − r)² / (r² + 0.01). (pbrt's variant divides by (r + 0.01)²; the numbers differ.)
/// Any non-finite pixel in either image makes it non-finite, never silently skipped.
pub fn rel_mse(image: &RgbImage, reference: &RgbImage) -> f64 {
    mean_over_channels(image, reference, |x, r| (x - r) * (x - r) / (r * r + REL_MSE_EPSILON))
}

/// The variance part of relMSE, from two renders that differ only in their seed: mean over pixels
/// and channels of (a − b)² / 2 / (r² + 0.01). Each render's own noise has expectation σ²/(r² +
/// 0.01) per channel, and (a − b)² estimates 2σ², so this needs no converged reference — `r`
/// only sets the denominators (any good estimate of the image will do; bias is left out).
pub fn two_seed_rel_mse(a: &RgbImage, b: &RgbImage, r: &RgbImage) -> f64 {
    assert_same_size(&[(a, "first seed"), (b, "second seed"), (r, "reference")]);
    let sum: f64 = (a.pixels.iter().zip(&b.pixels).zip(&r.pixels))
        .flat_map(|((a, b), r)| (0..3).map(move |c| (a[c] as f64, b[c] as f64, r[c] as f64)))
        .map(|(a, b, r)| 0.5 * (a - b) * (a - b) / (r * r + REL_MSE_EPSILON))
        .sum();
    sum / (3 * a.pixels.len().max(1)) as f64
}

fn mean_over_channels(image: &RgbImage, reference: &RgbImage, f: impl Fn(f64, f64) -> f64) -> f64 {
    assert_same_size(&[(image, "image"), (reference, "reference")]);
    let sum: f64 = (image.pixels.iter().zip(&reference.pixels))
        .flat_map(|(x, r)| (0..3).map(move |c| (x[c] as f64, r[c] as f64)))
        // A non-finite input must not turn into a finite term (∞ − ∞ is NaN, which propagates).
        .map(|(x, r)| if x.is_finite() && r.is_finite() { f(x, r) } else { f64::NAN })
        .sum();
    sum / (3 * image.pixels.len().max(1)) as f64
}

fn assert_same_size(images: &[(&RgbImage, &str)]) {
    let (first, first_name) = images[0];
    for (image, name) in images {
        assert!(
            (image.width, image.height) == (first.width, first.height)
                && image.pixels.len() == first.width as usize * first.height as usize,
            "{name} is {} × {} ({} pixels) but {first_name} is {} × {}",
            image.width,
            image.height,
            image.pixels.len(),
            first.width,
            first.height
        );
    }
}

/// Complementary error function, Numerical Recipes' Chebyshev fit `erfcc`: fractional error
/// below 1.2 × 10⁻⁷ everywhere, tails included (erfc(5) ≈ 1.5 × 10⁻¹²), so p-values down to the
/// Šidák levels used here (~10⁻⁸) are trustworthy.
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277))))))));
    let r = t * poly.exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// One Monte Carlo estimate of an image: per-pixel means and per-sample variances of `samples`
/// samples per pixel.
///
/// When the variance is estimated from the same samples, z follows Student's t with N − 1
/// degrees of freedom rather than a normal law, and its heavier tails fail pixels by chance: for
/// Gaussian samples on a 256² image, 1.2 % of pixel-channels at N = 4 (the test fails),
/// 0.1 % at N = 8, 0.007 % at N = 16. Render samples are skewed (fireflies), so use N ≥ 64.
#[derive(Clone, Copy, Debug)]
pub struct Estimate<'a> {
    /// Per-pixel mean of the samples (the rendered image).
    pub mean: &'a RgbImage,
    /// Per-pixel *per-sample* variance: the unbiased sample variance of that pixel's samples
    /// (not the variance of the mean, which is this divided by `samples`).
    pub variance: &'a RgbImage,
    /// Samples per pixel.
    pub samples: u32,
}

/// Settings of the statistical golden test; [`Default`] gives Mitsuba 3's values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StatTest {
    /// Family-wise significance (Šidák): the chance that a correct image has even one failing
    /// pixel-channel. Default 0.01.
    pub significance: f64,
    /// Fraction of pixel-channels that must pass. Default 0.9975.
    pub min_pass_fraction: f64,
    /// Per-sample variances are floored at this, so a pixel whose samples all agreed (a black
    /// corner, a light seen directly) does not turn a rounding difference into a huge z.
    /// Default 1e-4.
    pub variance_floor: f64,
    /// Largest accepted z-score of a channel's mean difference (image-level bias). Default 5.
    pub max_bias_z: f64,
}

impl Default for StatTest {
    fn default() -> Self {
        Self { significance: 0.01, min_pass_fraction: 0.9975, variance_floor: 1e-4, max_bias_z: 5.0 }
    }
}

/// The outcome of a statistical golden test; `Display` explains it to a human.
#[derive(Clone, Debug, PartialEq)]
pub struct StatReport {
    /// The settings used.
    pub settings: StatTest,
    /// Pixel-channels tested (3 × pixels).
    pub tested: usize,
    /// Pixel-channels whose p-value fell below `alpha` (non-finite ones included).
    pub failed: usize,
    /// Pixel-channels with a non-finite mean, variance or reference; any one fails the test.
    pub non_finite: usize,
    /// The Šidák-corrected per-pixel-channel significance 1 − (1 − significance)^(1/tested).
    pub alpha: f64,
    /// The finite pixel-channel with the largest z: (x, y, channel 0–2, z).
    pub worst: Option<(u32, u32, usize, f64)>,
    /// Per channel, the z-score of the mean difference over the image (NaN if non-finite input).
    pub bias_z: [f64; 3],
    /// Per channel, the mean difference (test − reference) itself, for the message.
    pub mean_difference: [f64; 3],
}

impl StatReport {
    /// Fraction of pixel-channels that passed.
    pub fn pass_fraction(&self) -> f64 {
        1.0 - self.failed as f64 / self.tested.max(1) as f64
    }

    /// Whether enough pixel-channels passed (and none was non-finite).
    pub fn pixels_passed(&self) -> bool {
        self.non_finite == 0 && self.pass_fraction() >= self.settings.min_pass_fraction
    }

    /// Whether every channel's mean difference is within `max_bias_z` standard errors.
    pub fn bias_passed(&self) -> bool {
        self.bias_z.iter().all(|&z| z < self.settings.max_bias_z) // NaN fails.
    }

    /// Whether the image is statistically consistent with the reference.
    pub fn passed(&self) -> bool {
        self.pixels_passed() && self.bias_passed()
    }
}

impl StatTest {
    /// Tests a noisy render against a converged reference whose own noise is negligible (per
    /// docs/testing.md §2, the render's own variance stands in when the reference has no variance
    /// image): z = |x − ref| · sqrt(N / max(var, floor)).
    pub fn against_reference(&self, test: Estimate<'_>, reference: &RgbImage) -> StatReport {
        assert_same_size(&[(test.mean, "mean"), (test.variance, "variance"), (reference, "reference")]);
        let floor = self.variance_floor;
        let n = test.samples.max(1) as f64;
        self.run(
            test.mean,
            reference,
            |i, c| (test.variance.pixels[i][c] as f64).max(floor) / n,
            &[test.variance],
        )
    }

    /// Tests two independent noisy renders of the same scene against each other (e.g. a scene
    /// rendered at two scales): the difference's variance is var_a / N_a + var_b / N_b, each
    /// variance floored first.
    pub fn between(&self, a: Estimate<'_>, b: Estimate<'_>) -> StatReport {
        assert_same_size(&[
            (a.mean, "a.mean"),
            (a.variance, "a.variance"),
            (b.mean, "b.mean"),
            (b.variance, "b.variance"),
        ]);
        let floor = self.variance_floor;
        let (na, nb) = (a.samples.max(1) as f64, b.samples.max(1) as f64);
        self.run(
            a.mean,
            b.mean,
            |i, c| {
                (a.variance.pixels[i][c] as f64).max(floor) / na
                    + (b.variance.pixels[i][c] as f64).max(floor) / nb
            },
            &[a.variance, b.variance],
        )
    }

    /// The shared test: `variance_of_difference(i, c)` is the variance of x − r at pixel i.
    fn run(
        &self,
        x: &RgbImage,
        r: &RgbImage,
        variance_of_difference: impl Fn(usize, usize) -> f64,
        variances: &[&RgbImage],
    ) -> StatReport {
        let tested = 3 * x.pixels.len();
        // Šidák: per-test alpha such that P(no false failure among `tested`) = 1 − significance.
        // ln_1p/exp_m1 keep it accurate where the naive formula would cancel (alpha ~ 1e-8).
        let alpha = -((-self.significance).ln_1p() / tested.max(1) as f64).exp_m1();
        let mut report = StatReport {
            settings: *self,
            tested,
            failed: 0,
            non_finite: 0,
            alpha,
            worst: None,
            bias_z: [0.0; 3],
            mean_difference: [0.0; 3],
        };
        let mut sum_difference = [0.0f64; 3];
        let mut sum_variance = [0.0f64; 3];
        for i in 0..x.pixels.len() {
            for c in 0..3 {
                let (xi, ri) = (x.pixels[i][c], r.pixels[i][c]);
                let finite =
                    xi.is_finite() && ri.is_finite() && variances.iter().all(|v| v.pixels[i][c].is_finite());
                if !finite {
                    // f64::max would quietly replace a NaN variance by the floor: count it instead.
                    report.non_finite += 1;
                    report.failed += 1;
                    sum_difference[c] = f64::NAN;
                    continue;
                }
                let difference = xi as f64 - ri as f64;
                let variance = variance_of_difference(i, c);
                let z = difference.abs() / variance.sqrt();
                // p = P(|Z| ≥ z) for a standard normal Z.
                if erfc(z / std::f64::consts::SQRT_2) < alpha {
                    report.failed += 1;
                }
                if report.worst.is_none_or(|w| z > w.3) {
                    let width = x.width as usize;
                    report.worst = Some(((i % width) as u32, (i / width) as u32, c, z));
                }
                sum_difference[c] += difference;
                sum_variance[c] += variance;
            }
        }
        // The mean of P independent differences has variance Σ var_i / P², so the z of the mean
        // difference is |Σ d_i| / sqrt(Σ var_i): the P cancels.
        for c in 0..3 {
            report.bias_z[c] = sum_difference[c].abs() / sum_variance[c].sqrt();
            report.mean_difference[c] = sum_difference[c] / x.pixels.len().max(1) as f64;
        }
        report
    }
}

/// [`StatTest::against_reference`] with Mitsuba 3's default settings.
pub fn statistical_test(test: Estimate<'_>, reference: &RgbImage) -> StatReport {
    StatTest::default().against_reference(test, reference)
}

impl fmt::Display for StatReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let verdict = if self.passed() { "PASSED" } else { "FAILED" };
        writeln!(f, "statistical image test {verdict}")?;
        writeln!(
            f,
            "  per pixel-channel: {} of {} failed ({:.4} % passed, {:.2} % required), Šidák alpha {:.3e}{}",
            self.failed,
            self.tested,
            100.0 * self.pass_fraction(),
            100.0 * self.settings.min_pass_fraction,
            self.alpha,
            if self.pixels_passed() { "" } else { "  <- too many outliers" }
        )?;
        if self.non_finite > 0 {
            writeln!(
                f,
                "  {} pixel-channels are NaN or infinite (mean, variance or reference)",
                self.non_finite
            )?;
        }
        if let Some((x, y, c, z)) = self.worst {
            writeln!(f, "  worst: pixel ({x}, {y}) channel {} at z = {z:.2}", ["R", "G", "B"][c])?;
        }
        for c in 0..3 {
            let flag = if self.bias_z[c] < self.settings.max_bias_z { "" } else { "  <- biased" };
            writeln!(
                f,
                "  channel {}: mean difference {:+.3e}, z = {:.2} (limit {}){flag}",
                ["R", "G", "B"][c],
                self.mean_difference[c],
                self.bias_z[c],
                self.settings.max_bias_z
            )?;
        }
        if !self.passed() {
            write!(
                f,
                "  a biased image fails the channel check; isolated outliers or a wrong region fail the count"
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn erfc_matches_known_values_to_1_2e_7() {
        let known = [
            (0.0, 1.0),
            (0.5, 0.479500122186953),
            (1.0, 0.157299207050285),
            (2.0, 4.67773498104727e-3),
            (3.0, 2.20904969985854e-5),
            (4.0, 1.54172579002800e-8),
            (5.0, 1.53745979442803e-12),
            (-1.0, 1.842700792949715),
            (-3.0, 1.999977909503001),
        ];
        for (x, want) in known {
            let got = erfc(x);
            assert!(((got - want) / want).abs() < 1.2e-7, "erfc({x}) = {got:e}, want {want:e}");
        }
        assert_eq!(erfc(40.0), 0.0);
        assert!(erfc(f64::NAN).is_nan());
    }

    #[test]
    fn mse_and_rel_mse_follow_the_readme_convention() {
        let reference = RgbImage { width: 2, height: 1, pixels: vec![Vec3::splat(0.0), Vec3::splat(1.0)] };
        let image = RgbImage { width: 2, height: 1, pixels: vec![Vec3::splat(0.1), Vec3::splat(1.0)] };
        assert!((mse(&image, &reference) - 0.005).abs() < 1e-9);
        // Pixel 0: 0.01 / 0.01 = 1 per channel; pixel 1: 0. Mean over 6 pixel-channels = 0.5.
        assert!((rel_mse(&image, &reference) - 0.5).abs() < 1e-6);
        assert_eq!(rel_mse(&reference, &reference), 0.0);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut broken = image.clone();
            broken.pixels[1].y = bad;
            assert!(!rel_mse(&broken, &reference).is_finite() && !mse(&broken, &reference).is_finite());
            assert!(!rel_mse(&reference, &broken).is_finite(), "a non-finite reference too");
        }
    }

    #[test]
    fn two_seed_rel_mse_estimates_each_renders_own_noise() {
        // Two unbiased "renders" of the same image with known noise: the estimate must find the
        // relMSE each has against the truth, which it never sees (it gets a biased `r`).
        let truth = reference(false);
        let (a, _) = render(&truth, 16, 1.0, 1);
        let (b, _) = render(&truth, 16, 1.0, 2);
        let expected = (rel_mse(&a, &truth) + rel_mse(&b, &truth)) / 2.0;
        let mut r = truth.clone();
        r.pixels.iter_mut().for_each(|p| *p *= 1.01);
        let got = two_seed_rel_mse(&a, &b, &r);
        assert!((got / expected - 1.0).abs() < 0.05, "two-seed {got:e} vs true {expected:e}");
        // The same render twice has no noise between them.
        assert_eq!(two_seed_rel_mse(&a, &a, &truth), 0.0);
    }

    /// PCG32 (O'Neill), fixed seeds: deterministic noise without a dependency.
    struct Pcg(u64);

    impl Pcg {
        /// Seeds through SplitMix64: small raw seeds would start PCG in a poorly mixed state.
        fn new(seed: u64) -> Self {
            let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            Self(z ^ (z >> 31))
        }

        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let x = (((self.0 >> 18) ^ self.0) >> 27) as u32;
            let r = x.rotate_right((self.0 >> 59) as u32);
            (r as f64 + 0.5) / 4294967296.0 // (0, 1): never 0, so ln is finite.
        }

        /// Box–Muller: a standard normal sample.
        fn normal(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    const SIZE: u32 = 64;

    /// A smooth reference with values 0.02 … 0.92 and, if `light`, a region of exactly 1 that
    /// renders without noise (like a directly seen emitter).
    fn reference(light: bool) -> RgbImage {
        let pixels = (0..SIZE * SIZE)
            .map(|i| {
                let (x, y) = ((i % SIZE) as f32 / SIZE as f32, (i / SIZE) as f32 / SIZE as f32);
                if light && y < 0.05 && (0.4..0.6).contains(&x) {
                    Vec3::ONE
                } else {
                    Vec3::new(0.02 + 0.9 * x, 0.5 * y + 0.1, 0.3)
                }
            })
            .collect();
        RgbImage { width: SIZE, height: SIZE, pixels }
    }

    /// Renders `reference` with `samples` Gaussian samples per pixel of per-sample standard
    /// deviation 0.5·sqrt(r) (0 on the "light", like a directly seen emitter), scaled by `gain`;
    /// returns the per-pixel mean and unbiased sample variance.
    fn render(reference: &RgbImage, samples: u32, gain: f32, seed: u64) -> (RgbImage, RgbImage) {
        let mut rng = Pcg::new(seed);
        let (mut mean, mut variance) = (reference.clone(), reference.clone());
        for (i, r) in reference.pixels.iter().enumerate() {
            for c in 0..3 {
                let sigma = if r[c] == 1.0 { 0.0 } else { 0.5 * (r[c] as f64).sqrt() };
                let xs: Vec<f64> =
                    (0..samples).map(|_| gain as f64 * (r[c] as f64 + sigma * rng.normal())).collect();
                let m = xs.iter().sum::<f64>() / samples as f64;
                let v = xs.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (samples - 1) as f64;
                mean.pixels[i][c] = m as f32;
                variance.pixels[i][c] = v as f32;
            }
        }
        (mean, variance)
    }

    #[test]
    fn statistical_test_passes_unbiased_noise() {
        let reference = reference(true);
        for (samples, seed) in [(16, 1), (64, 2), (256, 3)] {
            let (mean, variance) = render(&reference, samples, 1.0, seed);
            let report = statistical_test(Estimate { mean: &mean, variance: &variance, samples }, &reference);
            assert!(report.passed(), "{samples} spp:\n{report}");
            assert!(report.bias_z.iter().all(|z| *z < 3.0), "{report}");
            assert_eq!(report.tested, 3 * 64 * 64);
            assert!((report.alpha - 8.1790e-7).abs() < 1e-10, "Šidák alpha {:e}", report.alpha);
        }
    }

    #[test]
    fn statistical_test_fails_two_percent_bias_through_the_bias_check() {
        // Without noiseless pixels the bias is far below the per-pixel noise everywhere: only the
        // image-level check can see it.
        let reference = reference(false);
        let (mean, variance) = render(&reference, 64, 0.98, 4);
        let report = statistical_test(Estimate { mean: &mean, variance: &variance, samples: 64 }, &reference);
        assert!(report.pixels_passed(), "{report}");
        assert!(!report.bias_passed() && !report.passed(), "{report}");
        assert!(report.mean_difference.iter().all(|d| *d < 0.0));
        let text = report.to_string();
        assert!(text.contains("FAILED") && text.contains("<- biased"), "{text}");
        // Where some pixels have (floored) near-zero variance, those fail individually as well.
        let reference = self::reference(true);
        let (mean, variance) = render(&reference, 64, 0.98, 4);
        let report = statistical_test(Estimate { mean: &mean, variance: &variance, samples: 64 }, &reference);
        assert!(!report.pixels_passed() && !report.bias_passed(), "{report}");
    }

    /// Isolated outliers are allowed (fireflies happen): the count fails only once more than
    /// 0.25 % of pixel-channels (here 30 of 12288) fail.
    #[test]
    fn hot_pixels_fail_only_in_numbers() {
        let reference = reference(true);
        let (mut mean, variance) = render(&reference, 16, 1.0, 5);
        let hot = |mean: &mut RgbImage, i: usize, sign: f32| {
            let sigma = (variance.pixels[i].max(Vec3::splat(1e-4)) / 16.0).powf(0.5);
            mean.pixels[i] = reference.pixels[i] + sign * 50.0 * sigma;
        };
        hot(&mut mean, 1000, 1.0);
        let report = statistical_test(Estimate { mean: &mean, variance: &variance, samples: 16 }, &reference);
        assert!(report.passed(), "{report}");
        assert!(report.failed >= 3);
        let (x, y, _, z) = report.worst.unwrap();
        assert_eq!((x, y), (1000 % SIZE, 1000 / SIZE));
        assert!((z - 50.0).abs() < 1e-3, "{z}");
        // 12 hot pixels (36 pixel-channels), half up and half down so the mean is not biased.
        for k in 0..12 {
            hot(&mut mean, 97 * k + 7, if k % 2 == 0 { 1.0 } else { -1.0 });
        }
        let report = statistical_test(Estimate { mean: &mean, variance: &variance, samples: 16 }, &reference);
        assert!(!report.pixels_passed() && report.bias_passed(), "{report}");
        assert!(report.to_string().contains("too many outliers"));
    }

    #[test]
    fn non_finite_input_fails() {
        let reference = reference(true);
        let (mean, variance) = render(&reference, 16, 1.0, 6);
        let cases: [(usize, f32); 3] = [(0, f32::NAN), (1, f32::INFINITY), (2, f32::NAN)];
        for (which, bad) in cases {
            let (mut m, mut v, mut r) = (mean.clone(), variance.clone(), reference.clone());
            [&mut m, &mut v, &mut r][which].pixels[77].z = bad;
            let report = statistical_test(Estimate { mean: &m, variance: &v, samples: 16 }, &r);
            assert_eq!(report.non_finite, 1);
            assert!(!report.passed() && !report.bias_passed(), "{report}");
            assert!(report.to_string().contains("NaN or infinite"));
        }
    }

    #[test]
    fn two_noisy_renders_compare() {
        let reference = reference(true);
        let (mean_a, var_a) = render(&reference, 16, 1.0, 7);
        let (mean_b, var_b) = render(&reference, 32, 1.0, 8);
        let a = Estimate { mean: &mean_a, variance: &var_a, samples: 16 };
        let b = Estimate { mean: &mean_b, variance: &var_b, samples: 32 };
        let report = StatTest::default().between(a, b);
        assert!(report.passed(), "{report}");
        let (mean_c, var_c) = render(&reference, 32, 1.02, 9);
        let c = Estimate { mean: &mean_c, variance: &var_c, samples: 32 };
        let report = StatTest::default().between(a, c);
        assert!(!report.passed() && !report.bias_passed(), "{report}");
    }
}
