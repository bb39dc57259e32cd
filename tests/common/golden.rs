//! The statistical golden-image machinery (issue 6 item 1; docs/testing.md §2): a golden is a
//! converged render stored as a ZIP-compressed EXR with its per-sample variance as a second layer
//! and its samples per pixel in the metadata; a test renders the same view at modest spp with
//! another seed (independent samples) and compares with `StatTest::between`: per pixel-channel z =
//! |x − g| / sqrt(var_x/N_x + var_g/N_g), Šidák threshold for a 1 % family-wise false-failure rate,
//! ≥ 99.75 % passing, plus the image-level bias check on each channel's mean difference.
//!
//! `UPDATE_GOLDEN=1` re-renders every golden the run reaches (narrow it with cargo's test-name
//! filter) and prints how it changed against the old file; without it a missing golden fails the
//! test with the command that blesses it. A golden with NaN/Inf samples is never written.

use std::path::{Path, PathBuf};
use tracer::image::RgbImage;
use tracer::image_io::{Aov, read_exr, write_exr};
use tracer::render::Rendered;
use tracer::test_support::compare::{Estimate, StatReport, StatTest};

/// Seed of every golden render; tests use [`TEST_SEED`], so their samples are independent of the
/// golden's (random numbers are a function of pixel, sample index, dimension and seed).
pub const GOLDEN_SEED: u32 = 0x601d_e75e;
/// Seed of every test render.
pub const TEST_SEED: u32 = 20261121;

/// A golden has this many times the test's samples per pixel: its noise then adds 1/16 to the
/// variance of the difference (the test's power drops by 3 %), and the variance image it stores
/// is estimated from thousands of samples.
pub const GOLDEN_SPP_FACTOR: u32 = 16;

/// Metadata keys of a golden EXR (shared with the EXRs the CLI writes).
const SPP_KEY: &str = "mcctrace/spp";
const WHAT_KEY: &str = "mcctrace/what";

/// A Monte Carlo estimate of an image, owned: per-pixel mean, per-sample variance, spp, and how
/// many samples came out NaN/Inf.
#[derive(Clone, Debug)]
pub struct Sampled {
    /// Per-pixel mean (the image).
    pub mean: RgbImage,
    /// Per-pixel per-sample variance (not divided by `spp`).
    pub variance: RgbImage,
    /// Samples per pixel.
    pub spp: u32,
    /// Samples that came out NaN/Inf (the film records them as black).
    pub nonfinite_samples: u64,
}

impl Sampled {
    /// Takes a render's image and variance (the spp as the render was asked for).
    pub fn from_rendered(r: Rendered, spp: u32) -> Self {
        Self {
            mean: r.images.image,
            variance: r.images.variance,
            spp,
            nonfinite_samples: r.stats.nonfinite_samples,
        }
    }

    /// The borrowed estimate `tracer::test_support::compare` takes.
    pub fn estimate(&self) -> Estimate<'_> {
        Estimate { mean: &self.mean, variance: &self.variance, samples: self.spp }
    }

    /// The same estimate of an image `k` times as bright (mean × k, per-sample variance × k²):
    /// what a renderer with a global gain error would produce.
    pub fn scaled(&self, k: f32) -> Self {
        Self {
            mean: super::scaled(&self.mean, k),
            variance: super::scaled(&self.variance, k * k),
            ..self.clone()
        }
    }
}

/// Where golden `name` lives.
pub fn golden_path(name: &str) -> PathBuf {
    super::repo_root().join("tests/data/golden").join(format!("{name}.exr"))
}

/// Whether this run re-blesses goldens (`UPDATE_GOLDEN` set to anything but "" or "0").
pub fn updating() -> bool {
    std::env::var("UPDATE_GOLDEN").is_ok_and(|v| !v.is_empty() && v != "0")
}

/// Reads a golden: RGB mean, `variance` layer and `mcctrace/spp` metadata.
pub fn read_golden(path: &Path) -> Result<Sampled, String> {
    let exr = read_exr(path).map_err(|e| format!("{e}"))?;
    let variance =
        exr.rgb_layer("variance").ok_or_else(|| format!("{}: no 'variance' layer", path.display()))?.clone();
    let spp = exr
        .metadata
        .get(SPP_KEY)
        .and_then(|v| v.parse::<u32>().ok())
        .ok_or_else(|| format!("{}: no '{SPP_KEY}' metadata", path.display()))?;
    Ok(Sampled { mean: exr.rgb, variance, spp, nonfinite_samples: 0 })
}

/// Writes a golden (ZIP-compressed EXR, two RGB layers, spp and a description as metadata).
pub fn write_golden(path: &Path, golden: &Sampled, what: &str) {
    std::fs::create_dir_all(path.parent().expect("golden directory")).expect("create the golden directory");
    let meta = [(SPP_KEY, golden.spp.to_string()), (WHAT_KEY, what.to_string())];
    write_exr(path, &golden.mean, &[Aov::Rgb { name: "variance", image: &golden.variance }], &meta)
        .expect("write the golden");
}

/// One golden test: `render(spp, seed)` renders the view (mean, variance, spp).
///
/// With `UPDATE_GOLDEN` set, first renders the golden at `test_spp × GOLDEN_SPP_FACTOR` with
/// [`GOLDEN_SEED`], refuses it if any sample was NaN/Inf, prints how it differs from the old
/// golden (the statistical test of new against old: mean difference per channel, fraction of
/// pixel-channels that would fail, worst z) and writes it. Then renders the test at `test_spp`
/// with [`TEST_SEED`], compares it with the golden and asserts that it passes. Returns the test
/// render, the golden and the report, for extra checks (e.g. that a biased copy fails).
pub fn check_golden(
    name: &str,
    what: &str,
    test_spp: u32,
    render: impl Fn(u32, u32) -> Sampled,
) -> (Sampled, Sampled, StatReport) {
    let path = golden_path(name);
    if updating() {
        bless(name, what, &path, test_spp * GOLDEN_SPP_FACTOR, &render);
    }
    let golden = read_golden(&path).unwrap_or_else(|e| {
        panic!(
            "golden '{name}' unreadable ({e}); bless it with \
             UPDATE_GOLDEN=1 cargo test --release -p mcctrace-suite --test suite {name}"
        )
    });
    let test = super::timed(&format!("{name}: test render, {test_spp} spp"), || render(test_spp, TEST_SEED));
    assert_eq!(test.nonfinite_samples, 0, "{name}: the test render has NaN/Inf samples");
    assert_eq!(
        (test.mean.width, test.mean.height),
        (golden.mean.width, golden.mean.height),
        "{name}: test render and golden differ in size (re-bless if the size changed on purpose)"
    );
    let report = StatTest::default().between(test.estimate(), golden.estimate());
    println!("{name} ({what}) against its {}-spp golden:\n{report}", golden.spp);
    println!(
        "{name}: smallest detectable global gain error ≈ {:.2} %",
        100.0 * detectable_bias(&test, &golden)
    );
    if std::env::var_os("MCCTRACE_TEST_OUTPUT").is_some() {
        // EXRs and sRGB previews of both, for a person to look at.
        for (which, image) in [("test", &test.mean), ("golden", &golden.mean)] {
            let stem = format!("golden-{name}-{which}");
            super::maybe_save(&stem, image);
            let png = super::repo_root().join("target/test-output").join(format!("{stem}.png"));
            tracer::image_io::write_png_srgb(&png, image).expect("write the preview");
        }
    }
    assert!(report.passed(), "{name} ({what}) no longer matches its golden {}:\n{report}", path.display());
    (test, golden, report)
}

/// Renders, checks and writes golden `name`, printing what changed.
fn bless(name: &str, what: &str, path: &Path, spp: u32, render: &impl Fn(u32, u32) -> Sampled) {
    let new = super::timed(&format!("{name}: golden render, {spp} spp"), || render(spp, GOLDEN_SEED));
    // Never bless a broken render: NaN/Inf samples are a bug, not a look.
    assert_eq!(new.nonfinite_samples, 0, "{name}: refusing to bless a golden with NaN/Inf samples");
    assert!(
        new.mean.pixels.iter().chain(&new.variance.pixels).all(|p| p.is_finite()),
        "{name}: refusing to bless a golden with non-finite pixels"
    );
    match read_golden(path) {
        Ok(old) if (old.mean.width, old.mean.height) == (new.mean.width, new.mean.height) => {
            let change = StatTest::default().between(new.estimate(), old.estimate());
            let worst = change.worst.map_or(0.0, |w| w.3);
            println!(
                "re-blessing {name}: mean difference new − old per channel {:+.3e} {:+.3e} {:+.3e} \
                 (z {:.2} {:.2} {:.2}); {:.3} % of pixel-channels would fail; max z {worst:.2}; \
                 old {} spp, new {spp} spp",
                change.mean_difference[0],
                change.mean_difference[1],
                change.mean_difference[2],
                change.bias_z[0],
                change.bias_z[1],
                change.bias_z[2],
                100.0 * (1.0 - change.pass_fraction()),
                old.spp,
            );
            println!("{name}: the old golden against the new one:\n{change}");
        }
        Ok(old) => println!(
            "re-blessing {name}: size {}x{} -> {}x{}",
            old.mean.width, old.mean.height, new.mean.width, new.mean.height
        ),
        Err(e) => println!("blessing {name} (no usable old golden: {e})"),
    }
    write_golden(path, &new, what);
    let bytes = std::fs::metadata(path).map_or(0, |m| m.len());
    println!("wrote {} ({bytes} bytes)", path.display());
}

/// The smallest global gain error |k − 1| that the bias check would flag (z = max_bias_z) in the
/// least sensitive channel: max_bias_z · sqrt(Σ var_x/N_x + var_g/N_g) / |Σ g|, with the floored
/// variances the test uses. A figure of merit printed by every golden test.
pub fn detectable_bias(test: &Sampled, golden: &Sampled) -> f64 {
    let settings = StatTest::default();
    let floor = settings.variance_floor;
    let mut worst = 0.0f64;
    for c in 0..3 {
        let (mut sum, mut var) = (0.0f64, 0.0f64);
        for i in 0..golden.mean.pixels.len() {
            sum += golden.mean.pixels[i][c] as f64;
            var += (test.variance.pixels[i][c] as f64).max(floor) / test.spp as f64
                + (golden.variance.pixels[i][c] as f64).max(floor) / golden.spp as f64;
        }
        if sum > 0.0 {
            worst = worst.max(settings.max_bias_z * var.sqrt() / sum);
        }
    }
    worst
}

/// Asserts that the same test render made 2 % darker fails against the golden: the test has the
/// power to see a small global bias, not only broken images.
pub fn assert_darker_fails(name: &str, test: &Sampled, golden: &Sampled) {
    let darker = test.scaled(0.98);
    let report = StatTest::default().between(darker.estimate(), golden.estimate());
    println!("{name} × 0.98 against its golden:\n{report}");
    assert!(!report.passed(), "{name}: a 2 % darker render passed against the golden:\n{report}");
}
