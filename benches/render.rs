//! Render throughput on the Cornell box (the scene of the Mitsuba and Cycles figures in
//! `docs/performance.md`): `scenes/cornell/cornell.gltf`, camera `cornell`, 256², at most 4
//! scattering vertices, 16 spp (about a million camera samples per frame), on the default rayon
//! pool (all cores).
//!
//! `cargo bench -p mcctrace-suite --bench render` renders one frame to warm up, then `RUNS`
//! frames, and reports the median and fastest wall time per frame, camera samples per second at
//! the median, and rays per second from the renders' own statistics (camera, continuation and
//! shadow rays over tracing time). The integrator is the default one limited to 4 vertices, the
//! reference's depth; the line printed names its roulette depth.

use glam::UVec2;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{CameraSelector, Scene};

const SIZE: u32 = 256;
const SPP: u32 = 16;
/// Timed frames after the warm-up frame.
const RUNS: usize = 10;

fn main() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.gltf");
    let scene = Scene::load(&path).expect("load the Cornell glTF");
    let camera = scene.camera(&CameraSelector::Name("cornell".into())).expect("camera 'cornell'");
    let camera = camera.build(UVec2::splat(SIZE)).expect("build the camera");
    let samples = SIZE as f64 * SIZE as f64 * SPP as f64;
    let config = IntegratorConfig::DEFAULT.with_max_depth(4);
    let tracer = PathTracer::new(&scene, config).expect("prepare the scene");
    let settings = RenderSettings::still(SPP);

    let frame = || {
        let start = Instant::now();
        let r =
            render(&tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress).expect("render");
        black_box(r.images.image.pixels[0]);
        (start.elapsed().as_secs_f64(), r.stats.rays, r.stats.seconds)
    };
    frame();
    let mut walls = Vec::with_capacity(RUNS);
    let (mut rays, mut tracing) = (0u64, 0f64);
    for _ in 0..RUNS {
        let (wall, r, s) = frame();
        walls.push(wall);
        rays += r;
        tracing += s;
    }
    walls.sort_by(f64::total_cmp);
    let median = (walls[(RUNS - 1) / 2] + walls[RUNS / 2]) / 2.0;
    println!(
        "cornell_256/gltf_d4_{SPP}spp (max depth {}, roulette from {}), {RUNS} frames on {} threads: \
         median {:.1} ms, fastest {:.1} ms per frame; {:.2} M samples/s at the median; {:.2} M rays/s \
         ({:.2} rays per sample) from the render stats",
        config.max_depth,
        config.rr_depth,
        rayon::current_num_threads(),
        1e3 * median,
        1e3 * walls[0],
        samples / median / 1e6,
        rays as f64 / tracing / 1e6,
        rays as f64 / (samples * RUNS as f64),
    );
}
