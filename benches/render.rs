//! Render throughput on the Cornell box (the scene of the Mitsuba and Cycles figures in
//! `docs/performance.md`): `scenes/cornell/cornell.gltf`, camera `cornell`, 256², at most 4
//! scattering vertices, 16 spp (about a million camera samples per measurement), on the default
//! rayon pool (all cores).
//!
//! `cargo bench -p mcctrace-suite --bench render` reports time per frame and throughput in camera
//! samples per second (criterion `Throughput::Elements`), then prints rays per second from the
//! renders' own statistics (camera, continuation and shadow rays over tracing time). The integrator
//! is the default one limited to 4 vertices (its roulette, from depth 5, then never fires: the
//! reference's integrator).

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use glam::UVec2;
use std::cell::Cell;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{CameraSelector, Scene};

const SIZE: u32 = 256;
const SPP: u32 = 16;

fn cornell(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.gltf");
    let scene = Scene::load(&path).expect("load the Cornell glTF");
    let camera = scene.camera(&CameraSelector::Name("cornell".into())).expect("camera 'cornell'");
    let camera = camera.build(UVec2::splat(SIZE)).expect("build the camera");
    let samples = SIZE as u64 * SIZE as u64 * SPP as u64;

    let mut group = c.benchmark_group("cornell_256");
    group
        .throughput(Throughput::Elements(samples))
        .sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(6));
    let config = IntegratorConfig::DEFAULT.with_max_depth(4);
    let tracer = PathTracer::new(&scene, config).expect("prepare the scene");
    let settings = RenderSettings::still(SPP);
    let (rays, seconds, runs) = (Cell::new(0u64), Cell::new(0f64), Cell::new(0u32));
    group.bench_function(format!("gltf_d4_{SPP}spp"), |b| {
        b.iter(|| {
            let r = render(&tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress)
                .expect("render");
            rays.set(rays.get() + r.stats.rays);
            seconds.set(seconds.get() + r.stats.seconds);
            runs.set(runs.get() + 1);
            black_box(r.images.image.pixels[0])
        })
    });
    group.finish();
    let (rays, seconds, runs) = (rays.get(), seconds.get(), runs.get());
    println!(
        "cornell_256/gltf_d4_{SPP}spp (max depth {}, roulette from {}): {:.2} M samples/s, {:.2} M rays/s \
         ({:.2} rays per sample), from the render stats of {runs} frames on {} threads",
        config.max_depth,
        config.rr_depth,
        samples as f64 * runs as f64 / seconds / 1e6,
        rays as f64 / seconds / 1e6,
        rays as f64 / (samples as f64 * runs as f64),
        rayon::current_num_threads()
    );
}

criterion_group!(benches, cornell);
criterion_main!(benches);
