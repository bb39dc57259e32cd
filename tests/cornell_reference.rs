//! The tracer core against an independent renderer: the bundled Cornell box, loaded both as glTF
//! (`scenes/cornell/cornell.gltf`, camera `cornell`) and as the directory of OBJ parts (with the
//! README's look-at camera), rendered at 256², 4 scattering vertices, and compared with Mitsuba
//! 3's converged 16384-spp reference (`tests/data/cornell/`) by `tracer::test_support::compare`'s statistical
//! test (docs/testing.md §2: per-pixel Šidák-corrected z-test on the render's own per-sample
//! variance, plus an image-level bias check).
//!
//! What would fail: any bias in light transport (BSDF, light sampling, MIS weights, emission
//! sidedness, camera mapping, pixel filter …) large enough to show at 128 spp per pixel or as a
//! shift of the image mean. The test proves it has that power: the same render darkened by 2 %
//! must fail. No NaN/Inf sample may occur. The two formats describe the same geometry and
//! materials, so with the same seed (the same random numbers) they must agree far more closely
//! than two independent renders do.

use crate::common::*;
use tracer::image::RgbImage;
use tracer::render::Rendered;
use tracer::test_support::compare::{Estimate, rel_mse, statistical_test};

/// Samples per pixel: enough for a reliable per-pixel variance (the comparison module warns that
/// a t-distributed z has heavy tails below 64; fireflies make it worse).
const SPP: u32 = 128;
const SEED: u32 = 20240611;

fn check_against_reference(what: &str, r: &Rendered, reference: &RgbImage) {
    print_stats(what, r);
    assert_eq!(r.stats.nonfinite_samples, 0, "{what}: NaN/Inf samples");
    assert_eq!(r.stats.dropped_samples, 0, "{what}: dropped samples");
    let report = statistical_test(estimate(r), reference);
    println!(
        "{what} against the Mitsuba 3 reference (relMSE {:.3e}):\n{report}",
        rel_mse(&r.images.image, reference)
    );
    maybe_save(what, &r.images.image);
    assert!(report.passed(), "{what} differs from the Mitsuba reference:\n{report}");
}

#[test]
fn cornell_gltf_and_obj_match_mitsuba_and_each_other() {
    let reference = cornell_reference();
    let (gltf, gltf_camera) = cornell_gltf();
    let (obj, obj_camera) = cornell_obj();
    let job = Job::square(256, SPP, SEED);
    // Both are scenes of untextured, flat-shaded Lambertians, so they render on the Lambert-only
    // path (bit for bit the general one: `render::tests::lambert_path_is_the_general_path_bit_
    // for_bit`), and this test holds that path, too, to the reference.
    for (what, scene) in [("glTF", &gltf), ("OBJ", &obj)] {
        let tracer = tracer::integrator::PathTracer::new(scene, cornell_config()).unwrap();
        assert!(tracer.lambert_only(), "the {what} Cornell box is not on the Lambert-only path");
    }

    let r_gltf = timed("glTF render", || render_plain(&gltf, &gltf_camera, job));
    check_against_reference("cornell-gltf", &r_gltf, &reference);

    // Power: the same estimate made 2 % darker (mean × 0.98, per-sample variance × 0.98²) must
    // fail, or the test above could not tell a slightly wrong renderer from a right one.
    let darker = scaled(&r_gltf.images.image, 0.98);
    let darker_variance = scaled(&r_gltf.images.variance, 0.98 * 0.98);
    let biased =
        statistical_test(Estimate { mean: &darker, variance: &darker_variance, samples: SPP }, &reference);
    println!("the same render × 0.98:\n{biased}");
    assert!(!biased.passed(), "a 2 % darker image passed the reference test:\n{biased}");
    assert!(!biased.bias_passed(), "the image-level check missed a 2 % bias:\n{biased}");

    let r_obj = timed("OBJ render", || render_plain(&obj, &obj_camera, job));
    check_against_reference("cornell-obj", &r_obj, &reference);

    // Same seed, same scene in two formats: the same random numbers drive the same paths, so
    // the images can differ only where rounding in the two camera transforms (a quaternion vs a
    // look-at frame) or the loaders' vertex arithmetic sends a path elsewhere. Two *independent*
    // renders differ by about the sum of their errors against the reference (whose own relMSE,
    // 9e-6, is negligible): the same-seed twins must be far closer than that.
    let same_seed = rel_mse(&r_gltf.images.image, &r_obj.images.image);
    let independent = rel_mse(&r_gltf.images.image, &reference) + rel_mse(&r_obj.images.image, &reference);
    let identical =
        (r_gltf.images.image.pixels.iter().zip(&r_obj.images.image.pixels)).filter(|(a, b)| a == b).count();
    println!(
        "glTF vs OBJ, same seed: relMSE {same_seed:.3e} ({identical} of {} pixels bit-identical); \
         independent renders would differ by ≈ {independent:.3e}",
        r_gltf.images.image.pixels.len()
    );
    assert!(
        same_seed < 0.01 * independent,
        "glTF and OBJ renders with the same seed differ almost like independent renders: \
         {same_seed:.3e} vs {independent:.3e}"
    );
}

/// Adaptive sampling at the same average spp: still unbiased against the Mitsuba reference
/// (each pixel tested with its own sample count), and a lower relMSE than spreading the same
/// samples evenly — what it is for.
#[test]
fn adaptive_sampling_matches_mitsuba_with_less_relative_error() {
    use glam::UVec2;
    use tracer::integrator::PathTracer;
    use tracer::lens::LensChain;
    use tracer::render::{NoProgress, RenderSettings, render};

    let reference = cornell_reference();
    let (scene, camera) = cornell_gltf();
    let tracer = PathTracer::new(&scene, cornell_config()).unwrap();
    let built = camera.build(UVec2::splat(256)).unwrap();
    let run = |adaptive: bool| {
        let settings = RenderSettings { seed: SEED + 1, adaptive, ..RenderSettings::still(SPP) };
        timed(if adaptive { "adaptive render" } else { "uniform render" }, || {
            render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap()
        })
    };
    let (uniform, adaptive) = (run(false), run(true));
    let samples = &adaptive.images.samples.pixels;
    let fewest = samples.iter().fold(f32::INFINITY, |m, &n| m.min(n));
    let most = samples.iter().fold(0.0f32, |m, &n| m.max(n));
    println!("adaptive: {fewest} to {most} samples per pixel, {} in all", adaptive.stats.samples);
    assert!(adaptive.stats.samples <= uniform.stats.samples);
    assert!(adaptive.stats.samples > uniform.stats.samples * 99 / 100, "the budget is spent");
    assert_eq!(fewest as u32, SPP / 4, "every pixel keeps its pilot samples");
    assert!(most > 2.0 * SPP as f32, "some pixels get far more than the average");

    // Per-pixel counts differ: scale each variance so that variance / fewest is the variance of
    // that pixel's mean, and test with the fewest count (the most conservative t tails).
    let mut variance = adaptive.images.variance.clone();
    for (v, &n) in variance.pixels.iter_mut().zip(samples) {
        *v *= fewest / n;
    }
    let estimate = Estimate { mean: &adaptive.images.image, variance: &variance, samples: fewest as u32 };
    let report = statistical_test(estimate, &reference);
    let (uniform_err, adaptive_err) =
        (rel_mse(&uniform.images.image, &reference), rel_mse(&adaptive.images.image, &reference));
    println!(
        "adaptive against the Mitsuba 3 reference:\n{report}\nrelMSE at {SPP} spp: uniform \
         {uniform_err:.3e}, adaptive {adaptive_err:.3e} ({:.2}x lower)",
        uniform_err / adaptive_err
    );
    assert_eq!(adaptive.stats.nonfinite_samples, 0);
    assert!(report.passed(), "adaptive sampling is biased:\n{report}");
    assert!(adaptive_err < uniform_err, "adaptive sampling did not lower relMSE");
}

/// `mcctrace render --adaptive --aovs` writes the per-pixel sample counts as a `samples` layer
/// and the total as metadata; the counts vary, keep the pilot and stay within the budget.
#[test]
fn cli_adaptive_writes_sample_counts() {
    let dir = Scratch::new("adaptive-cli");
    let out = dir.s("adaptive.exr");
    let args = ["render", "scenes/cornell/cornell.gltf", "--res", "32x32", "--spp", "16", "--max-depth", "4"];
    let mut adaptive = args.to_vec();
    adaptive.extend(["--adaptive", "--aovs", "--quiet", "--out", &out]);
    mcctrace(&adaptive).unwrap();
    let exr = tracer::image_io::read_exr(std::path::Path::new(&out)).unwrap();
    let counts = exr.gray_layer("samples").expect("--aovs writes a samples layer");
    let total: f64 = counts.pixels.iter().map(|&n| n as f64).sum();
    assert_eq!(exr.metadata.get("mcctrace/samples").map(String::as_str), Some(total.to_string().as_str()));
    assert!(total <= 16.0 * 1024.0 && total > 0.99 * 16.0 * 1024.0, "total {total}");
    assert!(counts.pixels.iter().all(|&n| n >= 4.0) && counts.pixels.iter().any(|&n| n > 32.0));
    // Without --adaptive every pixel takes --spp samples.
    let plain = dir.s("plain.exr");
    let mut uniform = args.to_vec();
    uniform.extend(["--aovs", "--quiet", "--out", &plain]);
    mcctrace(&uniform).unwrap();
    let exr = tracer::image_io::read_exr(std::path::Path::new(&plain)).unwrap();
    assert!(exr.gray_layer("samples").unwrap().pixels.iter().all(|&n| n == 16.0));
}

/// `mcctrace render --split N` records N in the EXR and traces more rays for the same camera
/// samples; a sample count the split branches would take past the sampler's range is an error
/// that names the split, and so is a split of 0. No output is left behind by a refused run.
#[test]
fn cli_split_is_recorded_and_checked() {
    let dir = Scratch::new("split-cli");
    let args = [
        "render",
        "scenes/cornell/cornell.gltf",
        "--res",
        "24x24",
        "--spp",
        "8",
        "--max-depth",
        "4",
        "--quiet",
    ];
    let run = |split: &str, out: &str| {
        let mut a = args.to_vec();
        a.extend(["--split", split, "--out", out]);
        mcctrace(&a)
    };
    let metadata = |path: &str, key: &str| -> u64 {
        let exr = tracer::image_io::read_exr(std::path::Path::new(path)).unwrap();
        exr.metadata.get(key).unwrap_or_else(|| panic!("{path}: no {key}")).parse().unwrap()
    };
    let (one, three) = (dir.s("one.exr"), dir.s("three.exr"));
    run("1", &one).unwrap();
    run("3", &three).unwrap();
    assert_eq!((metadata(&one, "mcctrace/split"), metadata(&three, "mcctrace/split")), (1, 3));
    assert_eq!(metadata(&one, "mcctrace/samples"), metadata(&three, "mcctrace/samples"));
    assert!(metadata(&three, "mcctrace/rays") > 2 * metadata(&one, "mcctrace/rays"));

    let refused = dir.s("refused.exr");
    let mut a = args.to_vec();
    assert_eq!(a[4], "--spp");
    a[5] = "30000";
    a.extend(["--split", "3", "--out", &refused]);
    let err = format!("{:#}", mcctrace(&a).unwrap_err());
    assert!(err.contains("30000 samples per pixel") && err.contains("3 paths split"), "{err}");
    let err = format!("{:#}", run("0", &refused).unwrap_err());
    assert!(err.contains("--split"), "{err}");
    assert!(!std::path::Path::new(&refused).exists());
}

/// First-vertex splitting (2 paths continued from each first hit) at 64 camera samples per
/// pixel: unbiased against the Mitsuba reference, and each camera sample's variance well below
/// the unsplit render's (its indirect light, nearly all of the Cornell box's noise, is the mean
/// of 2 paths) — what it is for. Branches that repeated one path, or a weight other than 1/2,
/// would fail one check or the other.
#[test]
fn split_paths_match_mitsuba_with_less_variance_per_sample() {
    use glam::UVec2;
    use tracer::integrator::PathTracer;
    use tracer::lens::LensChain;
    use tracer::render::{NoProgress, RenderSettings, render};

    const CAMERA_SPP: u32 = 64;
    let reference = cornell_reference();
    let (scene, camera) = cornell_gltf();
    let built = camera.build(UVec2::splat(256)).unwrap();
    let run = |split: u32| {
        let tracer = PathTracer::new(&scene, cornell_config().with_split(split)).unwrap();
        let settings = RenderSettings { seed: SEED + 2, ..RenderSettings::still(CAMERA_SPP) };
        timed(&format!("split {split} render"), || {
            render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap()
        })
    };
    let (plain, split) = (run(1), run(2));
    assert_eq!(split.stats.nonfinite_samples, 0);
    let report = statistical_test(estimate(&split), &reference);
    println!("split 2 against the Mitsuba 3 reference:\n{report}");
    assert!(report.passed(), "first-vertex splitting is biased:\n{report}");

    // Mean per-sample variance relative to the reference (relMSE's weighting).
    let relative_variance = |r: &Rendered| {
        let pixels = r.images.variance.pixels.iter().zip(&reference.pixels);
        let sum: f64 = pixels
            .map(|(v, m)| (0..3).map(|c| v[c] as f64 / (m[c] as f64 * m[c] as f64 + 0.01)).sum::<f64>())
            .sum();
        sum / (3 * reference.pixels.len()) as f64
    };
    let (v_plain, v_split) = (relative_variance(&plain), relative_variance(&split));
    println!(
        "per-sample relative variance: unsplit {v_plain:.3e}, split 2 {v_split:.3e} ({:.2}x); relMSE {:.3e} \
         and {:.3e}",
        v_split / v_plain,
        rel_mse(&plain.images.image, &reference),
        rel_mse(&split.images.image, &reference)
    );
    // (Below half is possible: a pixel's branches are consecutive points of one Sobol
    // sequence, so the 2 paths of a camera sample are stratified against each other.)
    assert!(v_split < 0.75 * v_plain, "splitting did not lower the variance per camera sample");
}
