//! Lens shaders end to end (docs/design/tracer.md §3.8): shaders written here against
//! the public `LensShader` trait rewrite or drop the Cornell camera's eye rays, and the rendered
//! images are checked against the plain render of the same scene (itself proven against Mitsuba
//! in `cornell_reference.rs`).
//!
//! - A shader that mirrors every eye ray in the camera's vertical plane gives the mirrored image.
//!   The comparison is *statistical* (`StatTest::between`, independent seeds), not exact: the
//!   render draws pixel i's random numbers from a sequence keyed on pixel i, so the flipped
//!   image's pixel i and the plain image's pixel W−1−i average different samples of the same
//!   value. The test proves its power: the unmirrored plain image must fail the same comparison
//!   (the box is not symmetric: red wall left, green right).
//! - A shader that drops every sample on the left half of the film leaves that half exactly
//!   black, the right half unchanged (statistically), and the renderer counts exactly the samples
//!   it dropped in `dropped_samples`.
//! - Chains run in order: flip then flip is the identity *bit for bit* (exact by construction:
//!   for this camera the mirror plane is x = const, so mirroring negates one coordinate, which is
//!   exact in floating point, and twice restores every bit); "drop rays pointing left, then flip"
//!   and "flip, then drop rays pointing left" give two different images, each black on a
//!   different half and the mirrored scene on the other.

use crate::common::*;
use glam::Vec3;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use tracer::camera::{CameraDesc, CameraSample};
use tracer::error::LensError;
use tracer::image::RgbImage;
use tracer::lens::{FrameContext, LensChain, LensShader};
use tracer::ray::Ray;
use tracer::render::Rendered;
use tracer::scene::Scene;
use tracer::test_support::compare::StatTest;

const SIZE: u32 = 128;
const SPP: u32 = 64;

fn scene() -> &'static (Scene, CameraDesc) {
    static SCENE: OnceLock<(Scene, CameraDesc)> = OnceLock::new();
    SCENE.get_or_init(cornell_gltf)
}

/// The plain render every shader render is compared with (rendered once per process).
fn plain() -> &'static Rendered {
    static PLAIN: OnceLock<Rendered> = OnceLock::new();
    PLAIN.get_or_init(|| {
        let (scene, camera) = scene();
        render_plain(scene, camera, Job::square(SIZE, SPP, 1))
    })
}

fn render_chain(shaders: Vec<Box<dyn LensShader>>, seed: u32) -> Rendered {
    let (scene, camera) = scene();
    let mut chain = LensChain::new();
    for s in shaders {
        chain.push(s);
    }
    let r = render_with(scene, camera, &mut chain, Job::square(SIZE, SPP, seed));
    assert_eq!(r.stats.nonfinite_samples, 0);
    r
}

/// The camera's world-space position and unit right axis.
fn camera_frame(camera: &CameraDesc) -> (Vec3, Vec3) {
    let m = camera.world_from_camera;
    (m.translation.into(), Vec3::from(m.matrix3.x_axis).normalize())
}

/// Mirrors every eye ray in the camera's vertical plane (through its position, normal to its
/// right axis): the image flips left–right.
struct Flip {
    origin: Vec3,
    right: Vec3,
}

impl Flip {
    fn new(camera: &CameraDesc) -> Box<Self> {
        let (origin, right) = camera_frame(camera);
        Box::new(Self { origin, right })
    }
}

impl LensShader for Flip {
    fn name(&self) -> &str {
        "flip"
    }

    fn shade(&self, _sample: &CameraSample, ray: Ray) -> Option<Ray> {
        let mirror = |v: Vec3| v - 2.0 * v.dot(self.right) * self.right;
        let origin = self.origin + mirror(ray.origin - self.origin);
        Some(Ray { origin, direction: mirror(ray.direction), ..ray })
    }
}

/// Drops samples on the left half of the film, counting what it drops.
struct DropLeftFilm {
    dropped: Arc<AtomicU64>,
}

impl LensShader for DropLeftFilm {
    fn name(&self) -> &str {
        "drop-left-film"
    }

    fn shade(&self, sample: &CameraSample, ray: Ray) -> Option<Ray> {
        if sample.p_film.x < SIZE as f32 / 2.0 {
            self.dropped.fetch_add(1, Ordering::Relaxed);
            None
        } else {
            Some(ray)
        }
    }
}

/// Drops rays that point to the camera's left (a decision on the ray, so its place in a chain
/// matters).
struct DropPointingLeft {
    right: Vec3,
}

impl LensShader for DropPointingLeft {
    fn name(&self) -> &str {
        "drop-pointing-left"
    }

    fn shade(&self, _sample: &CameraSample, ray: Ray) -> Option<Ray> {
        (ray.direction.dot(self.right) >= 0.0).then_some(ray)
    }
}

/// Pixel-channels of columns `x0..x1` that are not exactly zero (mean or variance).
fn nonzero_in_columns(r: &Rendered, x0: u32, x1: u32) -> usize {
    let (image, variance) = (&r.images.image, &r.images.variance);
    (0..image.height)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .filter(|&(x, y)| image.get(x, y) != Vec3::ZERO || variance.get(x, y) != Vec3::ZERO)
        .count()
}

/// Statistical comparison of columns `x0..x1` of two estimates (`b` given as mean + variance).
fn columns_match(what: &str, a: &Rendered, b: (&RgbImage, &RgbImage), x0: u32, x1: u32) {
    let (am, av) = (crop_columns(&a.images.image, x0, x1), crop_columns(&a.images.variance, x0, x1));
    let (bm, bv) = (crop_columns(b.0, x0, x1), crop_columns(b.1, x0, x1));
    let report = StatTest::default().between(
        tracer::test_support::compare::Estimate { mean: &am, variance: &av, samples: SPP },
        tracer::test_support::compare::Estimate { mean: &bm, variance: &bv, samples: SPP },
    );
    println!("{what}:\n{report}");
    assert!(report.passed(), "{what}: images differ:\n{report}");
}

#[test]
fn flip_shader_mirrors_the_image() {
    let (_, camera) = scene();
    let flipped = render_chain(vec![Flip::new(camera)], 2);
    print_stats("flipped", &flipped);
    let plain = plain();
    let mirrored = (mirror_x(&plain.images.image), mirror_x(&plain.images.variance));
    columns_match("flipped vs mirrored plain", &flipped, (&mirrored.0, &mirrored.1), 0, SIZE);

    // Power: the flipped render is *not* the plain image.
    let report = StatTest::default().between(estimate(&flipped), estimate(plain));
    assert!(!report.passed(), "the flipped image passed as the unflipped one:\n{report}");
    assert!(report.pass_fraction() < 0.9, "{report}");
}

#[test]
fn dropping_shader_blacks_out_half_and_counts() {
    let counter = Arc::new(AtomicU64::new(0));
    let r = render_chain(vec![Box::new(DropLeftFilm { dropped: counter.clone() })], 3);
    print_stats("left half dropped", &r);
    // The renderer counts exactly the samples the shader dropped.
    assert_eq!(r.stats.dropped_samples, counter.load(Ordering::Relaxed));
    // Film positions are pixel + jitter in f32: in column 127 a jitter within 2^-18 of 1 rounds
    // the position up to 128.0 (not dropped). So columns 0–126 lose every sample, column 127
    // all or nearly all, columns 128+ none.
    let column = SIZE as u64 * SPP as u64;
    let full = (SIZE as u64 / 2) * column;
    assert!(
        r.stats.dropped_samples <= full && r.stats.dropped_samples >= full - column,
        "dropped {} samples, expected about {full}",
        r.stats.dropped_samples
    );
    assert_eq!(nonzero_in_columns(&r, 0, SIZE / 2 - 1), 0, "the dropped half is not black");
    let plain = plain();
    columns_match("right half vs plain", &r, (&plain.images.image, &plain.images.variance), SIZE / 2, SIZE);
}

#[test]
fn chains_run_in_order() {
    let (_, camera) = scene();
    let (_, right) = camera_frame(camera);
    // Exactness of the double flip rests on the mirror plane being axis-aligned.
    assert!(right.abs() == Vec3::X, "the Cornell camera's right axis {right} is not ±x");

    // Flip then flip: the identity, bit for bit, with the plain render's seed.
    let twice = render_chain(vec![Flip::new(camera), Flip::new(camera)], 1);
    let plain = plain();
    assert!(twice.images.image == plain.images.image, "flip ∘ flip changed the image");
    assert!(twice.images.variance == plain.images.variance, "flip ∘ flip changed the variance");

    // Drop-left then flip vs flip then drop-left.
    let drop = || Box::new(DropPointingLeft { right });
    let drop_then_flip = render_chain(vec![drop(), Flip::new(camera)], 5);
    let flip_then_drop = render_chain(vec![Flip::new(camera), drop()], 6);
    print_stats("drop then flip", &drop_then_flip);
    print_stats("flip then drop", &flip_then_drop);
    let half = SIZE / 2;
    let mirrored = (mirror_x(&plain.images.image), mirror_x(&plain.images.variance));
    // Drop first: samples on the left (rays pointing left) are gone; the right half's rays are
    // then mirrored, so it shows the mirrored scene.
    assert_eq!(nonzero_in_columns(&drop_then_flip, 0, half - 1), 0, "drop→flip: left half not black");
    columns_match(
        "drop→flip right half vs mirrored plain",
        &drop_then_flip,
        (&mirrored.0, &mirrored.1),
        half,
        SIZE,
    );
    // Flip first: the left half's rays now point right and survive (mirrored scene), the right
    // half's point left and are dropped.
    assert_eq!(nonzero_in_columns(&flip_then_drop, half + 1, SIZE), 0, "flip→drop: right half not black");
    columns_match(
        "flip→drop left half vs mirrored plain",
        &flip_then_drop,
        (&mirrored.0, &mirrored.1),
        0,
        half,
    );
    let (a, b) = (drop_then_flip.stats.dropped_samples, flip_then_drop.stats.dropped_samples);
    let full = half as u64 * SIZE as u64 * SPP as u64;
    for d in [a, b] {
        assert!(d.abs_diff(full) <= SIZE as u64 * SPP as u64, "dropped {d}, expected about {full}");
    }
}

#[test]
fn per_frame_hooks_run_once_per_render() {
    let (scene, camera) = scene();
    let tracer = tracer::integrator::PathTracer::new(scene, cornell_config()).unwrap();
    struct Hooks {
        begun: Arc<AtomicU32>,
        ended: Arc<AtomicU32>,
    }
    impl LensShader for Hooks {
        fn name(&self) -> &str {
            "hooks"
        }
        fn begin_frame(&mut self, ctx: &FrameContext<'_>) -> Result<(), LensError> {
            // Set-up sees the upstream camera: the pixel-centre ray of (0, 0) is the camera's.
            let ray = ctx.upstream.generate(&CameraSample::pixel_centre(0, 0, 0.0)).expect("a ray");
            assert!(ray.is_valid());
            self.begun.fetch_add(1, Ordering::Relaxed);
            Ok(())
        }
        fn shade(&self, _s: &CameraSample, ray: Ray) -> Option<Ray> {
            assert_eq!(self.ended.load(Ordering::Relaxed), self.begun.load(Ordering::Relaxed) - 1);
            Some(ray)
        }
        fn end_frame(&mut self, _ctx: &FrameContext<'_>) -> Result<(), LensError> {
            self.ended.fetch_add(1, Ordering::Relaxed);
            Ok(())
        }
    }
    let begun = Arc::new(AtomicU32::new(0));
    let ended = Arc::new(AtomicU32::new(0));
    let mut chain = LensChain::new();
    chain.push(Box::new(Hooks { begun: begun.clone(), ended: ended.clone() }));
    for n in 1..=3 {
        render_prepared(&tracer, camera, &mut chain, Job::square(16, 1, 8));
        assert_eq!((begun.load(Ordering::Relaxed), ended.load(Ordering::Relaxed)), (n, n));
    }
}
