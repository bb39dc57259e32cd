//! Denoising speed and what it buys (issue 44; docs/performance.md, "Denoising").
//!
//! `cargo bench --bench denoise` prints one table: the café's `wide` view rendered once at 1 spp
//! with albedo and normal, then denoised with Intel Open Image Denoise (the library the README's
//! one command installs, or `MCCTRACE_OIDN`): a 1920×1080 final (auxiliaries prefiltered, high
//! quality) and the studio's 480×270 preview (auxiliaries as they are, balanced quality), the
//! first call (device start-up) apart from the median of the rest. Then relMSE against a
//! 1024-spp reference of the café's `wide` at 240×135, raw and denoised, at 16, 64 and 256 spp,
//! with the render and denoise seconds (`spp,seconds_raw,rel_mse_raw,seconds_denoised,
//! rel_mse_denoised` rows), for the comparison with Cycles + OIDN (benches/peers/cycles/
//! `render.py --denoise --reference target/denoise-bench/cafe-wide-240x135-ref.exr`, the
//! reference this writes).
//!
//! Targets: 1920×1080 with auxiliaries ≤ 2 s on 2 cores; the 480×270 preview ≤ 40 ms.
//! `DENOISE_BENCH_QUICK=1` skips the convergence part; `DENOISE_BENCH_RUNS=N` sets the timed
//! calls after the first (4). Wall times stretch with the machine's load, so the table also gives
//! each call's CPU seconds and half of them (two cores): the idle machine's wall time.

use glam::UVec2;
use std::time::Instant;
use tracer::compare::rel_mse;
use tracer::denoise::{Aux, Denoiser, Mode};
use tracer::film::FilmImages;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{CameraSelector, Scene};

fn render_wide(tracer: &PathTracer, scene: &Scene, size: UVec2, spp: u32, seed: u32) -> (FilmImages, f64) {
    let camera = scene.camera(&CameraSelector::Name("wide".into())).expect("café camera 'wide'");
    let built = camera.build(size).expect("build the camera");
    let settings = RenderSettings { aovs: true, seed, ..RenderSettings::still(spp) };
    let start = Instant::now();
    let r = render(tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).expect("render");
    (r.images, start.elapsed().as_secs_f64())
}

/// This process's CPU seconds so far (user + system, from /proc/self/stat at 100 ticks a second):
/// on a machine shared with other work, CPU seconds / 2 is about what the wall time would be on
/// its two cores idle, whatever the load (OIDN keeps both cores busy).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit_once(')').map_or("", |(_, r)| r).split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// Wall seconds of the first call, and the median of `runs` more, in wall and CPU seconds.
fn time(d: &Denoiser, images: &FilmImages, mode: Mode, runs: usize) -> (f64, f64, f64) {
    let aux = Aux { albedo: &images.albedo, normal: &images.normal };
    let once = || {
        let (start, cpu) = (Instant::now(), cpu_seconds());
        let out = d.denoise(&images.image, Some(aux), mode).expect("denoise");
        assert!(out.pixels.iter().all(|p| p.is_finite()));
        (start.elapsed().as_secs_f64(), cpu_seconds() - cpu)
    };
    let first = once().0;
    let rest: Vec<(f64, f64)> = (0..runs.max(1)).map(|_| once()).collect();
    let median = |k: fn(&(f64, f64)) -> f64| {
        let mut v: Vec<f64> = rest.iter().map(k).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (first, median(|r| r.0), median(|r| r.1))
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let start = Instant::now();
    let d = Denoiser::shared().unwrap_or_else(|e| panic!("{e}"));
    println!("device start-up: {:.3} s ({}, {})", start.elapsed().as_secs_f64(), d.version(), d.origin());
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = Scene::load(&root.join("scenes/cafe/cafe.gltf")).expect("load the café");
    let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).expect("prepare the café");

    let runs: usize = std::env::var("DENOISE_BENCH_RUNS").ok().and_then(|v| v.parse().ok()).unwrap_or(4);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("\nload average at the start: {}", load.trim());
    println!(
        "{:<36} {:>9} {:>9} {:>9} {:>9}  target",
        "denoise (café wide, 1 spp)", "first s", "median s", "CPU s", "CPU s / 2"
    );
    let rows = [
        ("480×270 studio preview", UVec2::new(480, 270), Mode::Preview, "≤ 40 ms"),
        ("480×270 final (for comparison)", UVec2::new(480, 270), Mode::Final, ""),
        ("1920×1080 final, aux prefiltered", UVec2::new(1920, 1080), Mode::Final, "≤ 2 s"),
    ];
    for (what, size, mode, target) in rows {
        let (images, _) = render_wide(&tracer, &scene, size, 1, 0);
        let (first, wall, cpu) = time(d, &images, mode, runs);
        println!("{what:<36} {first:>9.3} {wall:>9.3} {cpu:>9.3} {:>9.3}  {target}", cpu / 2.0);
    }

    if std::env::var_os("DENOISE_BENCH_QUICK").is_some() {
        return;
    }
    let size = UVec2::new(240, 135);
    let (reference, seconds) = render_wide(&tracer, &scene, size, 1024, 1);
    let dir = root.join("target/denoise-bench");
    std::fs::create_dir_all(&dir).expect("create target/denoise-bench");
    let ref_path = dir.join("cafe-wide-240x135-ref.exr");
    tracer::image_io::write_exr(&ref_path, &reference.image, &[], &[]).expect("write the reference");
    println!("\nreference: café wide 240×135 at 1024 spp ({seconds:.1} s) -> {}", ref_path.display());
    println!("spp,seconds_raw,rel_mse_raw,seconds_denoised,rel_mse_denoised");
    for spp in [16, 64, 256] {
        let (images, seconds) = render_wide(&tracer, &scene, size, spp, 7);
        let t = Instant::now();
        let aux = Aux { albedo: &images.albedo, normal: &images.normal };
        let denoised = d.denoise(&images.image, Some(aux), Mode::Final).expect("denoise");
        let with = seconds + t.elapsed().as_secs_f64();
        let (raw, den) = (rel_mse(&images.image, &reference.image), rel_mse(&denoised, &reference.image));
        println!("{spp},{seconds:.3},{raw:.6},{with:.3},{den:.6}");
    }
}
