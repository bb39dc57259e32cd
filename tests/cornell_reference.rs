//! The tracer core against an independent renderer: the bundled Cornell box, loaded both as glTF
//! (`scenes/cornell/cornell.gltf`, camera `cornell`) and as the directory of OBJ parts (with the
//! README's look-at camera), rendered at 256², 4 scattering vertices, and compared with Mitsuba
//! 3's converged 16384-spp reference (`tests/data/cornell/`) by `tracer::compare`'s statistical
//! test (NOTES.md: per-pixel Šidák-corrected z-test on the render's own per-sample variance, plus
//! an image-level bias check).
//!
//! What would fail: any bias in light transport (BSDF, light sampling, MIS weights, emission
//! sidedness, camera mapping, pixel filter …) large enough to show at 128 spp per pixel or as a
//! shift of the image mean. The test proves it has that power: the same render darkened by 2 %
//! must fail. No NaN/Inf sample may occur. The two formats describe the same geometry and
//! materials, so with the same seed (the same random numbers) they must agree far more closely
//! than two independent renders do.

mod common;

use common::*;
use tracer::compare::{Estimate, rel_mse, statistical_test};
use tracer::image::RgbImage;
use tracer::render::Rendered;

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
