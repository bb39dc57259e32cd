//! Determinism (docs/design/tracer.md §3.5): every random number is a function of
//! (pixel, sample, dimension, seed) and every pixel is computed by one task, so a render is the
//! same bit for bit whatever the thread count. Reference: the same render itself, on 1 thread.
//!
//! Checked on the Cornell box with Russian roulette on (the default from depth 3, so roulette
//! decisions are covered too) and the AOVs recorded: 1, 2 and 3 threads give bit-identical
//! images, variances, AOVs and ray counts. A different seed gives a different image — different
//! in nearly every pixel, yet the same picture statistically.
//!
//! Tiles are scheduled dynamically (rayon work stealing over the tile range), so which thread
//! renders which tile, and in what order tiles finish, varies from run to run. Order cannot
//! matter by construction: a tile's pixels depend only on their own (pixel, sample, seed) random
//! numbers, the tiles are collected by tile index (never by completion order), and the ray count
//! is an integer sum. The tile *size* is a constant of the renderer (not a setting), and for the
//! same reason it could not matter either. A test forces two opposite schedules (one worker or
//! the other slowed down) and checks the bits, and that the schedules really differed.

use crate::common::*;
use glam::UVec2;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use tracer::integrator::PathTracer;
use tracer::lens::LensChain;
use tracer::render::{NoProgress, Progress, RenderSettings, Rendered, render};
use tracer::test_support::compare::StatTest;

const SIZE: u32 = 96;
const SPP: u32 = 64;

fn render_on(
    threads: usize,
    tracer: &PathTracer,
    camera: &tracer::camera::CameraDesc,
    seed: u32,
) -> Rendered {
    let built = camera.build(UVec2::splat(SIZE)).unwrap();
    let settings = RenderSettings { seed, aovs: true, ..RenderSettings::still(SPP) };
    with_threads(threads, || {
        render(tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap()
    })
}

#[test]
fn thread_count_does_not_change_a_single_bit() {
    let (scene, camera) = cornell_gltf();
    let tracer = PathTracer::new(&scene, cornell_config()).unwrap();
    let one = render_on(1, &tracer, &camera, 42);
    print_stats("1 thread", &one);
    for threads in [2, 3] {
        let many = render_on(threads, &tracer, &camera, 42);
        print_stats(&format!("{threads} threads"), &many);
        let (a, b) = (&one.images, &many.images);
        assert!(a.image == b.image, "{threads} threads: image differs from 1 thread");
        assert!(a.variance == b.variance, "{threads} threads: variance differs from 1 thread");
        assert!(
            a.albedo == b.albedo && a.normal == b.normal && a.depth == b.depth,
            "{threads} threads: AOVs differ"
        );
        assert_eq!(one.stats.rays, many.stats.rays, "{threads} threads: ray count differs");
        assert_eq!(one.stats.samples, many.stats.samples);
    }
}

#[test]
fn another_seed_gives_another_image_of_the_same_scene() {
    let (scene, camera) = cornell_gltf();
    let tracer = PathTracer::new(&scene, cornell_config()).unwrap();
    let a = render_on(2, &tracer, &camera, 42);
    let b = render_on(2, &tracer, &camera, 43);
    let pixels = a.images.image.pixels.len();
    // Pixels whose every sample is the same whatever the seed (the background outside the box,
    // the light seen directly) legitimately agree; everything else must differ.
    let constant = a.images.variance.pixels.iter().filter(|v| v.max_element() == 0.0).count();
    let differ = (a.images.image.pixels.iter().zip(&b.images.image.pixels)).filter(|(x, y)| x != y).count();
    println!("{differ} of {pixels} pixels differ; {constant} pixels have zero variance");
    assert!(differ + constant >= pixels * 99 / 100, "seeds 42 and 43 agree in too many noisy pixels");
    assert!(differ > pixels / 2);
    let report = StatTest::default().between(estimate(&a), estimate(&b));
    println!("seed 42 vs 43:\n{report}");
    assert!(report.passed(), "two seeds render different scenes:\n{report}");
}

/// Counts the pixel samples each worker of a 2-thread pool finished, and holds worker `slow` after its
/// first tile until the other worker has finished half the image (stealing what `slow` had
/// queued; rayon's adaptive splitting leaves at most a quarter of the tiles in `slow`'s running
/// chunk): the schedule is chosen on purpose, not left to timing.
struct SkewedSchedule {
    slow: usize,
    total: u64,
    held: AtomicBool,
    samples_by_worker: [AtomicU64; 2],
}

impl Progress for SkewedSchedule {
    fn advance(&self, samples: u64) {
        let worker = rayon::current_thread_index().expect("called on a pool worker");
        self.samples_by_worker[worker].fetch_add(samples, Ordering::SeqCst);
        if worker == self.slow && !self.held.swap(true, Ordering::SeqCst) {
            let start = std::time::Instant::now();
            // The time limit only guards against a hang if the renderer ever stopped stealing.
            while 2 * self.samples_by_worker[1 - worker].load(Ordering::SeqCst) < self.total
                && start.elapsed().as_secs() < 60
            {
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
        }
    }
}

#[test]
fn tile_schedule_does_not_change_a_single_bit() {
    let (scene, camera) = cornell_gltf();
    let tracer = PathTracer::new(&scene, cornell_config()).unwrap();
    let built = camera.build(UVec2::splat(SIZE)).unwrap();
    let settings = RenderSettings { seed: 9, aovs: true, ..RenderSettings::still(16) };
    let run = |slow: usize| {
        let schedule = SkewedSchedule {
            slow,
            total: (SIZE * SIZE * settings.spp) as u64,
            held: AtomicBool::new(false),
            samples_by_worker: [AtomicU64::new(0), AtomicU64::new(0)],
        };
        let r = with_threads(2, || {
            render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &schedule).unwrap()
        });
        (r, schedule.samples_by_worker.map(|a| a.into_inner()))
    };
    let (a, by_worker_a) = run(0);
    let (b, by_worker_b) = run(1);
    println!("samples per worker: worker 0 slowed {by_worker_a:?}, worker 1 slowed {by_worker_b:?}");
    // The held worker rendered the smaller share each time: the two runs took the tiles in
    // different orders on different threads.
    assert!(
        by_worker_a[0] < by_worker_a[1] && by_worker_b[1] < by_worker_b[0],
        "the schedule was not forced"
    );
    assert!(a.images.image == b.images.image, "image depends on the tile schedule");
    assert!(a.images.variance == b.images.variance, "variance depends on the tile schedule");
    assert!(
        a.images.albedo == b.images.albedo
            && a.images.normal == b.images.normal
            && a.images.depth == b.images.depth,
        "AOVs depend on the tile schedule"
    );
    assert_eq!(a.stats.rays, b.stats.rays);
}

/// Adaptive sampling's second pass depends on the first pass's film only, so 1 and 2 threads
/// still give the same bits, sample counts included.
#[test]
fn adaptive_sampling_does_not_change_a_single_bit() {
    let (scene, camera) = cornell_gltf();
    let tracer = PathTracer::new(&scene, cornell_config()).unwrap();
    let built = camera.build(UVec2::splat(SIZE)).unwrap();
    let settings = RenderSettings { seed: 5, aovs: true, adaptive: true, ..RenderSettings::still(16) };
    let run = |threads| {
        with_threads(threads, || {
            render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap()
        })
    };
    let (one, two) = (run(1), run(2));
    let (a, b) = (&one.images, &two.images);
    assert!(a.samples.pixels.iter().any(|&n| n != 16.0), "the counts are adaptive");
    assert!(a.samples == b.samples, "sample counts differ");
    assert!(a.image == b.image && a.variance == b.variance, "image or variance differs");
    assert_eq!(one.stats.rays, two.stats.rays);
}

/// First-vertex splitting draws each branch's numbers from its own sample index, a function of
/// the camera sample's: 1 and 3 threads give the same bits, with adaptive sampling too.
#[test]
fn split_paths_do_not_change_a_single_bit() {
    let (scene, camera) = cornell_gltf();
    let tracer = PathTracer::new(&scene, cornell_config().with_split(4)).unwrap();
    let built = camera.build(UVec2::splat(SIZE)).unwrap();
    for adaptive in [false, true] {
        let settings = RenderSettings { seed: 9, aovs: true, adaptive, ..RenderSettings::still(8) };
        let run = |threads| {
            with_threads(threads, || {
                render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap()
            })
        };
        let (one, three) = (run(1), run(3));
        let (a, b) = (&one.images, &three.images);
        assert!(a.samples == b.samples, "sample counts differ (adaptive {adaptive})");
        assert!(
            a.image == b.image && a.variance == b.variance,
            "image or variance differs (adaptive {adaptive})"
        );
        assert!(a.albedo == b.albedo && a.depth == b.depth, "AOVs differ (adaptive {adaptive})");
        assert_eq!(one.stats.rays, three.stats.rays);
    }
}
