//! Denoising speed and what it buys (issue 44; docs/performance.md §1.7, "Denoising").
//!
//! `cargo bench -p mcctrace-suite --bench denoise` prints three tables, each a part of
//! `DENOISE_BENCH_PARTS` (comma-separated; all three by default):
//!
//! - `timing`: the café's `wide` rendered at 1 spp with albedo and normal, denoised with Intel Open
//!   Image Denoise (the library the README's one command installs, or `MCCTRACE_OIDN`) at 480×270
//!   (the studio's preview) and 1920×1080 (a final), in each quality and guide the project uses:
//!   the first call apart from the median of the rest (`DENOISE_BENCH_RUNS`, 3), wall and CPU
//!   seconds. Targets: 1920×1080 with auxiliaries ≤ 2 s on 2 cores; the 480×270 preview ≤ 40 ms.
//! - `quality`: relMSE against 1024-spp references (cached in `target/denoise-bench/`) of the café's
//!   `wide` at 240×135, the Cornell box at 128² and the Cornell box through a thin lens (depth of
//!   field), raw and denoised in every quality × guide, at 1, 4, 16 and 64 spp: what
//!   `Settings::for_final` and the default quality are chosen from.
//! - `convergence`: the café at 240×135, raw and denoised the way `render --denoise` does, at 16,
//!   64 and 256 spp (`spp,seconds_raw,rel_mse_raw,seconds_denoised,rel_mse_denoised`), for the
//!   comparison with Cycles + OIDN (benches/peers/cycles/`render.py --denoise --reference
//!   target/denoise-bench/cafe-wide-240x135-ref.exr`, the reference this writes).
//!
//! - `cycles` (not in the default list): scores the renders of `benches/peers/cycles/denoise.sh`
//!   (`DENOISE_BENCH_CYCLES`, default `target/peers/cycles/denoise`): each renderer's denoised
//!   café against its own 1024-spp reference, time × relMSE and mcctrace's over Cycles', per seed
//!   and their mean.
//!
//! Wall times stretch with the machine's load, so the timing table also gives each call's CPU
//! seconds and half of them (two cores): about the idle machine's wall time.

use glam::UVec2;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tracer::camera::{CameraDesc, Projection};
use tracer::denoise::{Aux, Denoiser, Guide, Quality, Settings};
use tracer::film::FilmImages;
use tracer::image::RgbImage;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{CameraSelector, Scene};
use tracer::test_support::compare::rel_mse;

/// A scene prepared for tracing and the camera to render it through.
struct Shot {
    name: &'static str,
    tracer: PathTracer,
    camera: CameraDesc,
}

impl Shot {
    fn new(name: &'static str, path: &Path, camera: &str, config: IntegratorConfig) -> Self {
        let scene = Scene::load(path).unwrap_or_else(|e| panic!("load {}: {e}", path.display()));
        let camera = scene.camera(&CameraSelector::Name(camera.into())).expect("camera").clone();
        let tracer = PathTracer::new(&scene, config).expect("prepare the scene");
        Self { name, tracer, camera }
    }

    fn render(&self, size: UVec2, spp: u32, seed: u32) -> (FilmImages, f64) {
        let built = self.camera.build(size).expect("build the camera");
        let settings = RenderSettings { aovs: true, seed, ..RenderSettings::still(spp) };
        let start = Instant::now();
        let r = render(&self.tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress)
            .expect("render");
        (r.images, start.elapsed().as_secs_f64())
    }

    /// The 1024-spp reference at `size`, read from `target/denoise-bench/` when rendered before.
    fn reference(&self, dir: &Path, size: UVec2) -> RgbImage {
        let path: PathBuf = dir.join(format!("{}-{}x{}-ref.exr", self.name, size.x, size.y));
        if let Ok(image) = tracer::image_io::read_exr_rgb(&path) {
            return image;
        }
        let (reference, seconds) = self.render(size, 1024, 1);
        tracer::image_io::write_exr(&path, &reference.image, &[], &[]).expect("write the reference");
        println!(
            "reference: {} {}×{} at 1024 spp ({seconds:.1} s) -> {}",
            self.name,
            size.x,
            size.y,
            path.display()
        );
        reference.image
    }
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

fn aux(images: &FilmImages) -> Aux<'_> {
    Aux { albedo: &images.albedo, normal: &images.normal }
}

/// Wall seconds of the first call, and the median of `runs` more, in wall and CPU seconds.
fn time(d: &Denoiser, images: &FilmImages, settings: Settings, runs: usize) -> (f64, f64, f64) {
    let once = || {
        let (start, cpu) = (Instant::now(), cpu_seconds());
        let out = d.denoise(&images.image, Some(aux(images)), settings).expect("denoise");
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

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim().to_owned()
}

const fn s(quality: Quality, guide: Guide) -> Settings {
    Settings { quality, guide }
}

fn timing(d: &Denoiser, cafe: &Shot) {
    let runs: usize = std::env::var("DENOISE_BENCH_RUNS").ok().and_then(|v| v.parse().ok()).unwrap_or(3);
    println!("\nload average at the start: {}", load());
    println!(
        "{:<44} {:>9} {:>9} {:>9} {:>9}",
        "denoise (café wide, 1 spp)", "first s", "median s", "CPU s", "CPU s / 2"
    );
    let rows = [
        (UVec2::new(480, 270), Settings::PREVIEW),
        (UVec2::new(480, 270), s(Quality::High, Guide::Clean)),
        (UVec2::new(480, 270), s(Quality::High, Guide::Prefiltered)),
        (UVec2::new(1920, 1080), s(Quality::Fast, Guide::AsRendered)),
        (UVec2::new(1920, 1080), s(Quality::Balanced, Guide::Clean)),
        (UVec2::new(1920, 1080), s(Quality::High, Guide::Clean)),
    ];
    let mut last = None;
    for (size, settings) in rows {
        if last.as_ref().is_none_or(|(s, _)| *s != size) {
            last = Some((size, cafe.render(size, 1, 0).0));
        }
        let images = &last.as_ref().expect("rendered").1;
        let (first, wall, cpu) = time(d, images, settings, runs);
        let what = format!("{}×{} {} {}", size.x, size.y, settings.quality.name(), settings.guide.name());
        println!("{what:<44} {first:>9.3} {wall:>9.3} {cpu:>9.3} {:>9.3}", cpu / 2.0);
    }
    println!("load average at the end: {}", load());
}

fn quality(d: &Denoiser, dir: &Path, shots: &[(&Shot, UVec2)]) {
    let guides = [Guide::AsRendered, Guide::Clean, Guide::Prefiltered];
    println!("\nrelMSE against the 1024-spp reference (seed 7), raw and denoised; load {}", load());
    let mut header = "scene,spp,raw".to_owned();
    for q in Quality::ALL {
        for g in guides {
            header += &format!(",{}/{}", q.name(), g.name());
        }
    }
    println!("{header}");
    for (shot, size) in shots {
        let reference = shot.reference(dir, *size);
        for spp in [1, 4, 16, 64] {
            let (images, _) = shot.render(*size, spp, 7);
            let mut row = format!("{},{spp},{:.5}", shot.name, rel_mse(&images.image, &reference));
            for q in Quality::ALL {
                for g in guides {
                    let out = d.denoise(&images.image, Some(aux(&images)), s(q, g)).expect("denoise");
                    row += &format!(",{:.5}", rel_mse(&out, &reference));
                }
            }
            println!("{row}");
        }
    }
}

fn convergence(d: &Denoiser, dir: &Path, cafe: &Shot) {
    let size = UVec2::new(240, 135);
    let reference = cafe.reference(dir, size);
    println!("\ncafé wide 240×135 against its 1024-spp reference; load {}", load());
    println!("spp,seconds_raw,rel_mse_raw,seconds_denoised,rel_mse_denoised,denoiser");
    for spp in [16, 64, 256] {
        let (images, seconds) = cafe.render(size, spp, 7);
        let settings = Settings::for_final(Quality::DEFAULT, spp, false, false);
        let t = Instant::now();
        let denoised = d.denoise(&images.image, Some(aux(&images)), settings).expect("denoise");
        let with = seconds + t.elapsed().as_secs_f64();
        let (raw, den) = (rel_mse(&images.image, &reference), rel_mse(&denoised, &reference));
        println!("{spp},{seconds:.3},{raw:.6},{with:.3},{den:.6},{}", d.describe(settings, true));
    }
}

/// The time × relMSE table of `benches/peers/cycles/denoise.sh`'s folder `dir`: per spp, each
/// seed's run of both renderers (the whole process's wall and CPU seconds, the denoised
/// picture's relMSE against the renderer's own 1024-spp reference) and the mean over the seeds.
fn cycles(dir: &Path) {
    let read = |name: &str| {
        tracer::image_io::read_exr(&dir.join(name))
            .unwrap_or_else(|e| panic!("{}: {e}", dir.join(name).display()))
    };
    let times = std::fs::read_to_string(dir.join("times.csv")).expect("times.csv (run denoise.sh first)");
    let rows: Vec<Vec<&str>> = times.lines().map(|l| l.split(',').collect()).collect();
    let refs = [("mcc", read("mcc-ref.exr").rgb), ("cycles", read("cycles-ref.exr").rgb)];
    println!(
        "\n{}: café wide 240×135, denoised, against each renderer's own 1024-spp reference",
        dir.display()
    );
    println!("spp,seed,renderer,wall_s,cpu_s,rel_mse,wall_x_rel_mse,cpu_x_rel_mse,ratio_wall,ratio_cpu");
    let number = |v: &str| v.parse::<f64>().expect("a number");
    let mut spps: Vec<&str> = rows.iter().map(|r| r[1]).collect();
    spps.dedup();
    for spp in spps {
        let mut seeds: Vec<&str> = rows.iter().filter(|r| r[1] == spp).map(|r| r[2]).collect();
        seeds.dedup();
        // (wall, cpu, relMSE) per renderer, summed over the seeds for the mean.
        let mut sums = [[0.0; 3]; 2];
        for seed in &seeds {
            let mut run = [[0.0; 3]; 2];
            for (i, (who, reference)) in refs.iter().enumerate() {
                let row = rows
                    .iter()
                    .find(|r| r[0] == *who && r[1] == spp && r[2] == *seed)
                    .unwrap_or_else(|| panic!("times.csv lacks {who} at {spp} spp, seed {seed}"));
                let exr = read(&format!("{who}-{spp}-{seed}.exr"));
                let image = if *who == "mcc" {
                    exr.rgb_layer("denoised").expect("layer denoised").clone()
                } else {
                    exr.rgb
                };
                run[i] = [number(row[3]), number(row[4]), rel_mse(&image, reference)];
                (0..3).for_each(|k| sums[i][k] += run[i][k]);
            }
            print_pair(spp, seed, &run);
        }
        let n = seeds.len() as f64;
        print_pair(spp, &format!("mean of {}", seeds.len()), &sums.map(|r| r.map(|v| v / n)));
    }
}

/// Two rows of the table: mcctrace's and Cycles' (wall, CPU, relMSE), the ratio of their
/// time × relMSE on the second.
fn print_pair(spp: &str, seed: &str, run: &[[f64; 3]; 2]) {
    let product = |r: &[f64; 3]| (r[0] * r[2], r[1] * r[2]);
    let (ours, theirs) = (product(&run[0]), product(&run[1]));
    for (name, r, ratio) in [
        ("mcctrace", &run[0], String::new()),
        ("cycles", &run[1], format!("{:.3},{:.3}", ours.0 / theirs.0, ours.1 / theirs.1)),
    ] {
        let (pw, pc) = product(r);
        println!("{spp},{seed},{name},{:.2},{:.2},{:.4e},{pw:.4e},{pc:.4e},{ratio}", r[0], r[1], r[2]);
    }
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let parts = std::env::var("DENOISE_BENCH_PARTS").unwrap_or_else(|_| "timing,quality,convergence".into());
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    if parts == "cycles" {
        let dir = std::env::var_os("DENOISE_BENCH_CYCLES")
            .map_or_else(|| root.join("target/peers/cycles/denoise"), PathBuf::from);
        return cycles(&dir);
    }
    let start = Instant::now();
    let d = Denoiser::shared().unwrap_or_else(|e| panic!("{e}"));
    println!("device start-up: {:.3} s ({}, {})", start.elapsed().as_secs_f64(), d.version(), d.origin());
    let dir = root.join("target/denoise-bench");
    std::fs::create_dir_all(&dir).expect("create target/denoise-bench");
    let cafe = Shot::new("cafe-wide", &root.join("scenes/cafe/cafe.gltf"), "wide", IntegratorConfig::DEFAULT);
    for part in parts.split(',') {
        match part {
            "timing" => timing(d, &cafe),
            "quality" => {
                let cornell_path = root.join("scenes/cornell/cornell.gltf");
                let config = IntegratorConfig::DEFAULT.with_max_depth(4);
                let cornell = Shot::new("cornell", &cornell_path, "cornell", config);
                let mut lens = Shot::new("cornell-lens", &cornell_path, "cornell", config);
                let Projection::Perspective { fov_y } = lens.camera.projection else {
                    panic!("the Cornell camera is a perspective one")
                };
                // Focused on the front of the short box, an aperture that blurs the back wall.
                lens.camera.projection =
                    Projection::ThinLens { fov_y, lens_radius: 0.15, focus_distance: 9.5 };
                let square = UVec2::new(128, 128);
                quality(d, &dir, &[(&cafe, UVec2::new(240, 135)), (&cornell, square), (&lens, square)]);
            }
            "convergence" => convergence(d, &dir, &cafe),
            other => panic!(
                "DENOISE_BENCH_PARTS: unknown part {other:?} (timing, quality, convergence; cycles alone)"
            ),
        }
    }
}
