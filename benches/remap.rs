//! Remapper, ray-file and lens-reader speed, and the remapper's peak memory (docs/design/mcc.md §5,
//! §4.2, §6).
//!
//! `cargo bench --bench remap` prints one table. Everything is synthetic and deterministic:
//! cameras on a circle around the origin (some facing each other), elliptical blobs of each
//! camera on a black background, a three-colour region image. Peak memory is the `VmHWM` of a
//! child process that runs the whole remap stage from files (collage PNG, region PNG, 16 ray files
//! read one at a time) at 4K, so nothing the parent allocated is counted.
//!
//! Targets: remap ≤ 1 s at 1080p with 8 cameras, growing linearly with the pixel count; ≤ 4 GiB
//! peak for a 4K collage with 16 cameras; a 1080p binary ray file loads in ≤ 30 ms. The seamless
//! blend (issue 28): ≤ 2× the column's remap time at 1080p with 8 cameras and regions (rounds of
//! both, interleaved), and seam ratio p99 ≤ 3, max ≤ 20 on the café's demo collage, a ring and two
//! blobs of one view (section `seams`; docs/design/mcc.md §5.8).

use glam::{UVec2, Vec2, Vec3};
use mcc::collage::Collage;
use mcc::image;
use mcc::job::CollageFiles;
use mcc::ray_file::{RayFile, RayFormat, StoredRay};
use mcc::regions::Regions;
use mcc::remap::{RemapConfig, SourceRays, remap, remap_sources};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

const CHILD_ENV: &str = "MCC_REMAP_BENCH_CHILD";

/// Camera `id`'s eye ray at pixel (x, y) of a `w × h` view: a pinhole on a circle of radius 5,
/// looking at the origin (cameras k and k + n/2 face each other).
fn view_ray(id: u32, cameras: u32, x: u32, y: u32, w: u32, h: u32) -> StoredRay {
    let a = std::f32::consts::TAU * (id - 1) as f32 / cameras as f32;
    let eye = Vec3::new(5.0 * a.cos(), 1.0 + 0.1 * id as f32, 5.0 * a.sin());
    let forward = (-eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tan = 0.4f32;
    let sx = (2.0 * (x as f32 + 0.5) / w as f32 - 1.0) * tan * w as f32 / h as f32;
    let sy = (1.0 - 2.0 * (y as f32 + 0.5) / h as f32) * tan;
    StoredRay::new(eye, (forward + sx * right + sy * up).normalize())
}

/// Elliptical blobs of each camera (later cameras on top) over about half the picture.
fn synthetic_collage(w: u32, h: u32, cameras: u32) -> Collage {
    let mut ids = vec![0u32; (w * h) as usize];
    for id in 1..=cameras {
        let t = (id - 1) as f32 / cameras as f32;
        let (cx, cy) = (0.15 + 0.7 * t, 0.5 + 0.3 * (t * 11.0).sin());
        let (rx, ry) = (0.13, 0.22);
        for y in 0..h {
            let v = (y as f32 + 0.5) / h as f32;
            for x in 0..w {
                let u = (x as f32 + 0.5) / w as f32;
                if ((u - cx) / rx).powi(2) + ((v - cy) / ry).powi(2) <= 1.0 {
                    ids[(y * w + x) as usize] = id;
                }
            }
        }
    }
    Collage::new(w, h, ids).expect("collage")
}

/// Three regions: left, right, and a wavy band across the bottom.
fn synthetic_regions(w: u32, h: u32) -> image::RgbImage {
    image::RgbImage::from_fn(w, h, |x, y| {
        let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
        let colour = if v > 0.8 + 0.05 * (u * 20.0).sin() {
            [0, 0, 255]
        } else if u < 0.5 {
            [255, 0, 0]
        } else {
            [0, 255, 0]
        };
        image::Rgb(colour)
    })
}

fn sources(collage: &Collage, cameras: u32) -> SourceRays {
    let (w, h) = (collage.width, collage.height);
    let rays = collage
        .ids
        .iter()
        .enumerate()
        .map(|(p, &id)| {
            if id == 0 {
                StoredRay::default()
            } else {
                view_ray(id, cameras, p as u32 % w, p as u32 / w, w, h)
            }
        })
        .collect();
    SourceRays { width: w, height: h, rays, cameras: collage.cameras() }
}

fn view_file(id: u32, cameras: u32, w: u32, h: u32, frame: u32) -> RayFile {
    let rays = (0..w * h).map(|p| view_ray(id, cameras, p % w, p / w, w, h)).collect();
    RayFile::new(w, h, frame, id, rays).expect("ray file")
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// CPU time of the whole process so far (all threads), in ms: on a shared machine wall time
/// also measures the neighbours, CPU time does not.
fn cpu_ms() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else { return 0.0 };
    let ns: u64 = tasks
        .flatten()
        .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum();
    ns as f64 / 1e6
}

/// Timings of `n` runs of `f`, in ms.
struct Timing {
    best: f64,
    median: f64,
    /// Mean CPU time per run (all threads).
    cpu: f64,
}

fn time<T>(n: usize, mut f: impl FnMut() -> T) -> Timing {
    let cpu0 = cpu_ms();
    let mut times: Vec<f64> = (0..n)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(f());
            ms(start.elapsed())
        })
        .collect();
    let cpu = (cpu_ms() - cpu0) / n as f64;
    times.sort_by(f64::total_cmp);
    Timing { best: times[0], median: times[n / 2], cpu }
}

fn row(name: &str, t: &Timing, per: f64, unit_count: f64) {
    println!(
        "{name:<46} {:>9.1} {:>9.1} {:>9.1} {:>10.1}",
        t.best,
        t.median,
        t.cpu,
        t.best * per / unit_count
    );
}

fn vm_hwm_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Writes a frame's inputs to `dir`: collage PNG (tagged), region PNG, one binary ray file per camera.
fn write_inputs(dir: &Path, w: u32, h: u32, cameras: u32, frame: u32) -> PathBuf {
    std::fs::create_dir_all(dir).expect("bench dir");
    let collage = synthetic_collage(w, h, cameras);
    let code = mcc::TagCode::default();
    let img = image::RgbImage::from_fn(w, h, |x, y| {
        let id = collage.id(x, y);
        image::Rgb(if id == 0 { [0, 0, 0] } else { code.encode([128, 96, 64], id).expect("tag") })
    });
    let collage_path = dir.join("collage.png");
    mcc::png::write_png(&collage_path, &image::DynamicImage::ImageRgb8(img)).expect("collage png");
    let regions = image::DynamicImage::ImageRgb8(synthetic_regions(w, h));
    mcc::png::write_png(&dir.join("collage-regions.png"), &regions).expect("regions png");
    for id in 1..=cameras {
        let path = dir.join(mcc::names::view_rays_name(frame, id, RayFormat::Binary));
        view_file(id, cameras, w, h, frame).write(&path, RayFormat::Binary).expect("ray file");
    }
    collage_path
}

/// The child: the whole remap stage from files in `dir`; prints "ms kib".
fn child(dir: &Path) {
    let collage = dir.join("collage.png");
    let inputs = CollageFiles::new(collage, dir, 1);
    let (start, cpu0) = (Instant::now(), cpu_ms());
    let out = inputs.remap(&RemapConfig::GLASSNER).expect("remap");
    let (elapsed, cpu) = (ms(start.elapsed()), cpu_ms() - cpu0);
    out.rays.write(&dir.join("rerender-frame0001.mcr"), RayFormat::Binary).expect("write");
    drop(out);
    println!("{elapsed:.1} {} {cpu:.1}", vm_hwm_kib().unwrap_or(0));
}

/// Renders the Cornell box (256², 8 spp) with and without a lens reader of a 128² ray file of the
/// same camera in the chain (so every sample is interpolated), alternating six times and keeping
/// the least CPU time of each; prints both and the reader's share.
fn lens_reader_in_a_render() {
    use tracer::camera::CameraDesc;
    use tracer::integrator::{IntegratorConfig, PathTracer};
    use tracer::lens::{FrameInfo, LensChain};
    use tracer::render::{NoProgress, RenderSettings, render};
    use tracer::scene::{CameraSelector, Scene};
    let scene_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.gltf");
    let Ok(scene) = Scene::load(&scene_path) else {
        println!("{:<46} (skipped: cannot load {})", "lens reader in a render", scene_path.display());
        return;
    };
    let desc: CameraDesc = scene.camera(&CameraSelector::Index(0)).expect("camera").clone();
    let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).expect("tracer");
    let camera = desc.build(UVec2::new(256, 256)).expect("camera");
    // The rays: the same camera's pixel centres at half resolution, recorded by a lens writer.
    let dir = std::env::temp_dir().join(format!("mcc-reader-bench-{}", std::process::id()));
    let small = desc.build(UVec2::new(128, 128)).expect("camera");
    let mut writer = LensChain::new();
    writer.push(Box::new(mcc::LensWriter::new(&dir, RayFormat::Binary)));
    let info = FrameInfo { frame: 0, camera_id: 1, shutter: (0.0, 0.0) };
    writer.begin_frame(small.as_ref(), info).expect("writer");
    writer.end_frame(small.as_ref(), info).expect("writer");
    let rays = RayFile::read(&dir.join("frame0000camera01.mcr")).expect("rays");
    let _ = std::fs::remove_dir_all(&dir);
    let source = mcc::lens_reader::RaySource::Rays(Arc::new(rays));
    let settings = RenderSettings::still(8);
    let mut plain = LensChain::new();
    let mut reading = LensChain::new();
    reading.push(Box::new(mcc::LensReader::new(source)));
    let (mut best_plain, mut best_reading) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..6 {
        for (chain, best) in [(&mut plain, &mut best_plain), (&mut reading, &mut best_reading)] {
            let cpu0 = cpu_ms();
            render(&tracer, camera.as_ref(), chain, &settings, &NoProgress).expect("render");
            *best = best.min(cpu_ms() - cpu0);
        }
    }
    let samples = 256.0 * 256.0 * 8.0;
    let per = |ms: f64| Timing { best: ms, median: ms, cpu: ms };
    row("render Cornell 256² 8 spp, plain (cpu)", &per(best_plain), 1e6, samples);
    row("render Cornell 256² 8 spp, lens reader (cpu)", &per(best_reading), 1e6, samples);
    println!("{:<46} reader share {:+.1} % of the render", "", (best_reading / best_plain - 1.0) * 100.0);
}

fn main() {
    if let Ok(dir) = std::env::var(CHILD_ENV) {
        child(Path::new(&dir));
        return;
    }
    // `cargo bench --bench remap -- NAME` runs only the sections whose name contains NAME.
    let filter: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    let wanted = |section: &str| filter.is_empty() || filter.iter().any(|f| section.contains(f.as_str()));
    let threads = rayon::current_num_threads();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "mcc remap benchmark: {threads} threads, load average {}\n",
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
    );
    println!("{:<46} {:>9} {:>9} {:>9} {:>10}", "case", "best ms", "median ms", "cpu ms", "ns/pixel");
    let dir = std::env::temp_dir().join(format!("mcc-remap-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("bench dir");
    if wanted("remap") {
        remap_scaling();
    }
    if wanted("seams") {
        seam_figures(&dir);
    }
    if wanted("load") {
        ray_file_loading(&dir);
    }
    if wanted("reader") {
        lens_reader_per_ray();
    }
    if wanted("render") {
        lens_reader_in_a_render();
    }
    if wanted("files") {
        remap_from_files(&dir);
    }
    // Only when named exactly: one 1080p remap in one blend, for instruction counts
    // (`valgrind --tool=callgrind --toggle-collect='*remap_sources*' BENCH one-seamless`).
    for (section, config) in
        [("one-glassner", &RemapConfig::GLASSNER), ("one-seamless", &RemapConfig::SEAMLESS)]
    {
        if filter.iter().any(|f| f == section) {
            one_remap(config);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The remapper proper (rays already gathered), 8 cameras with regions, at three sizes, in both
/// blends: rounds alternate the column's and the seamless blend, so both see the same load; the
/// ratio is the median of the rounds' ratios (wall and CPU time).
fn remap_scaling() {
    for (label, w, h, runs) in [("480p", 854, 480, 7), ("1080p", 1920, 1080, 5), ("4K", 3840, 2160, 3)] {
        let collage = synthetic_collage(w, h, 8);
        let regions = Regions::from_image(&image::DynamicImage::ImageRgb8(synthetic_regions(w, h)));
        let src = sources(&collage, 8);
        let bg = collage.ids.iter().filter(|&&id| id == 0).count() as f64 / collage.ids.len() as f64;
        let mut rounds: Vec<[Timing; 2]> = Vec::new();
        for _ in 0..runs {
            let run = |config: &RemapConfig| {
                time(1, || remap_sources(&collage, &regions, &src, 0, config).expect("remap"))
            };
            rounds.push([run(&RemapConfig::GLASSNER), run(&RemapConfig::SEAMLESS)]);
        }
        for (k, name) in ["remap", "remap seamless"].iter().enumerate() {
            let mut wall: Vec<f64> = rounds.iter().map(|r| r[k].best).collect();
            wall.sort_by(f64::total_cmp);
            let cpu = rounds.iter().map(|r| r[k].cpu).sum::<f64>() / runs as f64;
            let t = Timing { best: wall[0], median: wall[runs / 2], cpu };
            row(
                &format!("{name} {label} {w}x{h}, 8 cams, 3 regions, {:.0}% bg", bg * 100.0),
                &t,
                1e6,
                (w * h) as f64,
            );
        }
        let median_ratio = |f: fn(&Timing) -> f64| {
            let mut r: Vec<f64> = rounds.iter().map(|r| f(&r[1]) / f(&r[0])).collect();
            r.sort_by(f64::total_cmp);
            r[runs / 2]
        };
        println!(
            "{:<46} seamless / glassner: {:.2}x wall, {:.2}x cpu (median of {runs} rounds)",
            "",
            median_ratio(|t| t.best),
            median_ratio(|t| t.cpu)
        );
    }
}

/// One remap of the 1080p, 8-camera, 3-region case of [`remap_scaling`] in `config`'s blend.
fn one_remap(config: &RemapConfig) {
    let (w, h) = (1920, 1080);
    let collage = synthetic_collage(w, h, 8);
    let regions = Regions::from_image(&image::DynamicImage::ImageRgb8(synthetic_regions(w, h)));
    let src = sources(&collage, 8);
    let t = time(1, || remap_sources(&collage, &regions, &src, 0, config).expect("remap"));
    row("one remap 1080p, 8 cams, 3 regions", &t, 1e6, (w * h) as f64);
}

/// The café's two facing views at the demo's 480x270: every pixel's eye ray, as the lens writer
/// records it (no rendering needed), camera 1 `left` and camera 2 `right`.
fn cafe_views(dir: &Path, w: u32, h: u32) -> Option<BTreeMap<u32, RayFile>> {
    use tracer::lens::{FrameInfo, LensChain};
    use tracer::scene::{CameraSelector, Scene};
    let scene = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cafe/cafe.gltf")).ok()?;
    let mut files = BTreeMap::new();
    for (id, name) in [(1u32, "left"), (2, "right")] {
        let camera = scene.camera(&CameraSelector::Name(name.into())).ok()?.build(UVec2::new(w, h)).ok()?;
        let mut writer = LensChain::new();
        writer.push(Box::new(mcc::LensWriter::new(dir, RayFormat::Binary)));
        let info = FrameInfo { frame: 0, camera_id: id, shutter: (0.0, 0.0) };
        writer.begin_frame(camera.as_ref(), info).ok()?;
        writer.end_frame(camera.as_ref(), info).ok()?;
        files
            .insert(id, RayFile::read(&dir.join(mcc::names::view_rays_name(0, id, RayFormat::Binary))).ok()?);
    }
    Some(files)
}

/// The three collages of the seam targets on a `w × h` picture: the demo's (its label mask, red =
/// camera 1, green = camera 2, and its region image), a ring of camera 1 inside a frame of camera
/// 2, and two blobs of camera 1 above a strip of camera 2.
fn seam_collages(w: u32, h: u32) -> Vec<(&'static str, Collage, Regions)> {
    let cafe = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cafe");
    let mut out = Vec::new();
    if let (Ok(mask), Ok(regions)) = (
        mcc::png::read_image(&cafe.join("collage-mask.png")),
        mcc::png::read_image(&cafe.join("collage-mask-regions.png")),
    ) && (mask.width(), mask.height()) == (w, h)
    {
        let ids = mask
            .to_rgb8()
            .pixels()
            .map(|p| match p.0 {
                [255, 0, 0] => 1,
                [0, 255, 0] => 2,
                _ => 0,
            })
            .collect();
        out.push((
            "demo (mask + regions)",
            Collage::new(w, h, ids).expect("collage"),
            Regions::from_image(&regions),
        ));
    }
    let (fw, fh) = (w as f32, h as f32);
    let ring = (0..w * h)
        .map(|p| {
            let (x, y) = ((p % w) as f32 + 0.5 - fw / 2.0, (p / w) as f32 + 0.5 - fh / 2.0);
            let r = (x * x + y * y).sqrt() / fh;
            let frame = (x / (0.47 * fw)).powi(2) + (y / (0.47 * fh)).powi(2) > 1.0;
            if (0.17..0.37).contains(&r) {
                1
            } else if frame {
                2
            } else {
                0
            }
        })
        .collect();
    out.push(("ring of camera 1", Collage::new(w, h, ring).expect("collage"), Regions::single(w, h)));
    let blobs = (0..w * h)
        .map(|p| {
            let (x, y) = (((p % w) as f32 + 0.5) / fw, ((p / w) as f32 + 0.5) / fh);
            let d1 = ((x - 0.25) * fw).hypot((y - 0.42) * fh) / fh;
            let d2 = ((x - 0.72) * fw).hypot((y - 0.45) * fh) / fh;
            if d1 < 0.26 || d2 < 0.2 {
                1
            } else if y > 0.9 {
                2
            } else {
                0
            }
        })
        .collect();
    out.push(("two blobs of camera 1", Collage::new(w, h, blobs).expect("collage"), Regions::single(w, h)));
    out
}

/// Seam ratio and remap time of both blends on the café collages.
fn seam_figures(dir: &Path) {
    let (w, h) = (480, 270);
    let views = dir.join("cafe-views");
    std::fs::create_dir_all(&views).expect("bench dir");
    let Some(files) = cafe_views(&views, w, h) else {
        println!("{:<46} (skipped: cannot load the café scene)", "seams");
        return;
    };
    println!(
        "\n{:<24} {:<9} {:>7} {:>7} {:>7} {:>9}",
        "café collage 480x270", "blend", "p99", "p99.9", "max", "best ms"
    );
    for (name, collage, regions) in seam_collages(w, h) {
        for (blend, preset) in [("glassner", RemapConfig::GLASSNER), ("seamless", RemapConfig::SEAMLESS)] {
            let t = time(3, || remap(&collage, &regions, &files, 0, &preset).expect("remap"));
            let config = RemapConfig { report: true, ..preset };
            let s =
                remap(&collage, &regions, &files, 0, &config).expect("remap").seams.expect("seam figures");
            println!("{name:<24} {blend:<9} {:>7.2} {:>7.2} {:>7.1} {:>9.1}", s.p99, s.p999, s.max, t.best);
        }
    }
}

/// Loading a 1080p ray file (warm page cache, as right after a render), binary and text.
fn ray_file_loading(dir: &Path) {
    let path = dir.join("frame0001camera01.mcr");
    view_file(1, 8, 1920, 1080, 1).write(&path, RayFormat::Binary).expect("ray file");
    let pixels = 1920.0 * 1080.0;
    row(
        "load 1080p binary ray file (49.8 MB)",
        &time(10, || RayFile::read(&path).expect("read")),
        1e6,
        pixels,
    );
    let text = dir.join("frame0001camera01.txt");
    RayFile::read(&path).expect("read").write(&text, RayFormat::Text).expect("text");
    row("load 1080p text ray file", &time(2, || RayFile::read(&text).expect("read")), 1e6, pixels);
}

/// The lens reader's per-ray cost, one thread: a 960×540 file at 1920×1080, film positions in
/// scanline order with jitter (as a renderer visits them), then at random (cache-hostile).
fn lens_reader_per_ray() {
    let file = Arc::new(view_file(3, 8, 960, 540, 0));
    let sampler = mcc::lens_reader::RaySampler::new(file, UVec2::new(1920, 1080)).expect("sampler");
    let mut state = 0x1234_5678u64;
    let mut uniform = move || {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let scan: Vec<Vec2> = (0..1920 * 1080)
        .map(|p| Vec2::new((p % 1920) as f32 + uniform(), (p / 1920) as f32 + uniform()))
        .collect();
    let random: Vec<Vec2> = (0..1 << 21).map(|_| Vec2::new(uniform() * 1920.0, uniform() * 1080.0)).collect();
    for (name, positions) in
        [("lens reader, scanline order, per ray", &scan), ("lens reader, random order, per ray", &random)]
    {
        let t = time(5, || positions.iter().map(|&p| sampler.at(p).direction.x).sum::<f32>());
        row(name, &t, 1e6, positions.len() as f64);
    }
}

/// End to end from files at 1080p (PNG decode, 8 ray files, remap), then the 4K/16-camera peak
/// memory, each in a fresh child process.
fn remap_from_files(dir: &Path) {
    for (label, w, h, cameras) in [("1080p", 1920, 1080, 8), ("4K", 3840, 2160, 16)] {
        let case = dir.join(label);
        write_inputs(&case, w, h, cameras, 1);
        let out = std::process::Command::new(std::env::current_exe().expect("exe"))
            .env(CHILD_ENV, &case)
            .output()
            .expect("child");
        let stdout = String::from_utf8_lossy(&out.stdout);
        let fields: Vec<f64> = stdout.split_whitespace().filter_map(|s| s.parse().ok()).collect();
        let [t, kib, cpu] = fields[..] else {
            panic!("child failed: {}", String::from_utf8_lossy(&out.stderr))
        };
        let name = format!("remap from files {label}, {cameras} cams (child)");
        let timing = Timing { best: t, median: t, cpu };
        row(&name, &timing, 1e6, (w * h) as f64);
        println!("{:<46} peak RSS (VmHWM) {:.2} GiB", "", kib / (1u64 << 20) as f64);
        let _ = std::fs::remove_dir_all(&case);
    }
}
