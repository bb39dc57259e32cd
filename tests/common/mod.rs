//! Helpers shared by the end-to-end tests: the bundled Cornell box and its independent reference,
//! a render wrapper on a pool of a chosen size, analytic geometry built in code (icospheres,
//! planes), and small image utilities. Each test file uses a subset; random test inputs come from
//! `tracer::test_support::Rng`.
#![allow(dead_code)]

pub mod child;
pub mod external;
pub mod golden;

use glam::{UVec2, Vec2, Vec3};
use std::path::{Path, PathBuf};
use std::time::Instant;
use tracer::camera::{CameraDesc, Projection};
use tracer::image::RgbImage;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::material::Material;
use tracer::render::{NoProgress, RenderSettings, Rendered, render};
use tracer::scene::{CameraSelector, Mesh, MeshPart, Scene};
use tracer::test_support::compare::Estimate;

/// `render` flags of the Cornell box's second view for collages: to the right of the scene's
/// camera, turned towards the box.
pub const CORNELL_SECOND_VIEW: [&str; 6] =
    ["--look-from", "0.8,2.9,-7.2", "--look-at", "2.78,2.6,2.8", "--fov", "39.3"];

/// The repository root (the suite's manifest directory).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The bundled Cornell box folder (`scenes/cornell`).
pub fn cornell_dir() -> PathBuf {
    repo_root().join("scenes/cornell")
}

/// The Cornell box as glTF, with its camera `cornell`.
pub fn cornell_gltf() -> (Scene, CameraDesc) {
    let scene = Scene::load(&cornell_dir().join("cornell.gltf")).expect("load cornell.gltf");
    let camera = scene.camera(&CameraSelector::Name("cornell".into())).expect("camera 'cornell'").clone();
    (scene, camera)
}

/// The Cornell reference camera as `scenes/cornell/README.md` gives it (look-at form).
pub fn cornell_look_at() -> CameraDesc {
    CameraDesc::look_at(
        "cornell-readme",
        Vec3::new(2.78, 2.73, -8.0),
        Vec3::new(2.78, 2.73, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 39.307_648_f32.to_radians() },
    )
    .expect("cornell look-at camera")
}

/// The Cornell box as the directory of OBJ parts, with the README's look-at camera.
pub fn cornell_obj() -> (Scene, CameraDesc) {
    let scene = Scene::load(&cornell_dir()).expect("load scenes/cornell (OBJ directory)");
    (scene, cornell_look_at())
}

/// The Cornell reference path.
pub fn reference_path() -> PathBuf {
    repo_root().join("tests/data/cornell/reference-mitsuba3-16384spp.exr")
}

/// The independent Mitsuba 3 reference of the Cornell box (256², 16384 spp).
pub fn cornell_reference() -> RgbImage {
    let image = tracer::image_io::read_exr_rgb(&reference_path()).expect("read the Mitsuba reference");
    assert_eq!((image.width, image.height), (256, 256), "reference size");
    image
}

/// The Cornell reference's integrator: 4 scattering vertices. `rr_depth` as given (the reference
/// has no roulette; roulette is unbiased, so the expected image is the same either way).
pub fn cornell_config() -> IntegratorConfig {
    IntegratorConfig::DEFAULT.with_max_depth(4)
}

/// Runs `work` on a rayon pool of `threads` threads (renders use the current pool).
pub fn with_threads<R: Send>(threads: usize, work: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool").install(work)
}

/// What to render: everything but the scene and camera.
#[derive(Clone, Copy, Debug)]
pub struct Job {
    pub resolution: UVec2,
    pub spp: u32,
    pub seed: u32,
    pub config: IntegratorConfig,
}

impl Job {
    /// A square film of `size` pixels at `spp`, seed `seed`, with the Cornell integrator.
    pub fn square(size: u32, spp: u32, seed: u32) -> Self {
        Self { resolution: UVec2::splat(size), spp, seed, config: cornell_config() }
    }

    pub fn with_config(self, config: IntegratorConfig) -> Self {
        Self { config, ..self }
    }
}

/// Prepares `scene` and renders it through `camera` and `lenses` on the current pool.
pub fn render_with(scene: &Scene, camera: &CameraDesc, lenses: &mut LensChain, job: Job) -> Rendered {
    let tracer = PathTracer::new(scene, job.config).expect("prepare the scene");
    render_prepared(&tracer, camera, lenses, job)
}

/// Renders an already prepared scene.
pub fn render_prepared(
    tracer: &PathTracer,
    camera: &CameraDesc,
    lenses: &mut LensChain,
    job: Job,
) -> Rendered {
    let built = camera.build(job.resolution).expect("build the camera");
    let settings = RenderSettings { seed: job.seed, ..RenderSettings::still(job.spp) };
    render(tracer, built.as_ref(), lenses, &settings, &NoProgress).expect("render")
}

/// Renders with no lens shaders.
pub fn render_plain(scene: &Scene, camera: &CameraDesc, job: Job) -> Rendered {
    render_with(scene, camera, &mut LensChain::new(), job)
}

/// The estimate (mean, per-sample variance, spp) of a render, for `tracer::test_support::compare`.
pub fn estimate(r: &Rendered) -> Estimate<'_> {
    Estimate { mean: &r.images.image, variance: &r.images.variance, samples: spp_of(r) }
}

/// Samples per pixel of a render (from its stats).
pub fn spp_of(r: &Rendered) -> u32 {
    let pixels = r.images.image.width as u64 * r.images.image.height as u64;
    (r.stats.samples / pixels) as u32
}

/// Prints a render's counters in one line (visible with `--nocapture`).
pub fn print_stats(what: &str, r: &Rendered) {
    let s = &r.stats;
    println!(
        "{what}: {} samples in {:.2} s ({:.2} M samples/s, {:.2} M rays/s), {} non-finite, {} dropped",
        s.samples,
        s.seconds,
        s.samples as f64 / s.seconds / 1e6,
        s.rays as f64 / s.seconds / 1e6,
        s.nonfinite_samples,
        s.dropped_samples
    );
}

/// Times a closure and prints how long it took.
pub fn timed<R>(what: &str, f: impl FnOnce() -> R) -> R {
    let start = Instant::now();
    let r = f();
    println!("[{what}: {:.2} s]", start.elapsed().as_secs_f64());
    r
}

/// Per-channel mean of an image, in f64.
pub fn mean_f64(image: &RgbImage) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for p in &image.pixels {
        for c in 0..3 {
            sum[c] += p[c] as f64;
        }
    }
    sum.map(|s| s / image.pixels.len() as f64)
}

/// Per-channel standard error of the image mean predicted by the per-sample variance image:
/// pixels are independent estimates, so Var(mean) = Σ var_i / (N · P²). Within a pixel the
/// samples are stratified (Owen-scrambled Sobol), whose mean varies less than var_i / N: the
/// figure is an upper bound, so tolerances built on it are conservative.
pub fn standard_error_of_mean(e: Estimate<'_>) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for v in &e.variance.pixels {
        for c in 0..3 {
            sum[c] += v[c] as f64;
        }
    }
    let p = e.variance.pixels.len() as f64;
    sum.map(|s| (s / e.samples as f64).sqrt() / p)
}

/// The image mirrored left–right.
pub fn mirror_x(image: &RgbImage) -> RgbImage {
    let mut out = RgbImage::new(image.width, image.height);
    for y in 0..image.height {
        for x in 0..image.width {
            out.set(image.width - 1 - x, y, image.get(x, y));
        }
    }
    out
}

/// Columns `x0..x1` of an image.
pub fn crop_columns(image: &RgbImage, x0: u32, x1: u32) -> RgbImage {
    let mut out = RgbImage::new(x1 - x0, image.height);
    for y in 0..image.height {
        for x in x0..x1 {
            out.set(x - x0, y, image.get(x, y));
        }
    }
    out
}

/// An image with every pixel multiplied by `k`.
pub fn scaled(image: &RgbImage, k: f32) -> RgbImage {
    RgbImage { pixels: image.pixels.iter().map(|p| *p * k).collect(), ..image.clone() }
}

/// An image of one constant colour.
pub fn constant_image(width: u32, height: u32, value: Vec3) -> RgbImage {
    RgbImage { width, height, pixels: vec![value; (width * height) as usize] }
}

/// An icosphere: the icosahedron subdivided `levels` times (20 · 4^levels triangles), every
/// vertex projected onto the sphere of `radius` about `centre`, in f64 before rounding. Triangles
/// are counter-clockwise seen from outside, or from inside when `inward`.
pub fn icosphere(levels: u32, centre: Vec3, radius: f32, inward: bool) -> (Vec<Vec3>, Vec<u32>) {
    use std::collections::HashMap;
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut verts: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let normalise = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] / l, v[1] / l, v[2] / l]
    };
    for v in &mut verts {
        *v = normalise(*v);
    }
    // Counter-clockwise seen from outside.
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, verts: &mut Vec<[f64; 3]>| -> u32 {
            let key = (a.min(b), a.max(b));
            *midpoints.entry(key).or_insert_with(|| {
                let (p, q) = (verts[a as usize], verts[b as usize]);
                verts.push(normalise([(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0, (p[2] + q[2]) / 2.0]));
                verts.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let ab = midpoint(a, b, &mut verts);
            let bc = midpoint(b, c, &mut verts);
            let ca = midpoint(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let positions = verts
        .iter()
        .map(|v| {
            Vec3::new(
                (centre.x as f64 + radius as f64 * v[0]) as f32,
                (centre.y as f64 + radius as f64 * v[1]) as f32,
                (centre.z as f64 + radius as f64 * v[2]) as f32,
            )
        })
        .collect();
    let indices = faces.iter().flat_map(|&[a, b, c]| if inward { [a, c, b] } else { [a, b, c] }).collect();
    (positions, indices)
}

/// A scene of one mesh part with one material.
pub fn single_part_scene(name: &str, positions: &[Vec3], indices: &[u32], material: Material) -> Scene {
    let mut mesh = Mesh::default();
    mesh.push(MeshPart { positions, normals: None, uvs: None, indices: Some(indices), material: 0 })
        .expect("mesh part");
    let scene = Scene { path: PathBuf::from(name), mesh, materials: vec![material], ..Scene::default() };
    scene.validate().expect("valid scene");
    scene
}

/// A camera at `from` looking at `at`.
pub fn look_at(from: Vec3, at: Vec3, up: Vec3, projection: Projection) -> CameraDesc {
    CameraDesc::look_at("test", from, at, up, projection).expect("look-at camera")
}

/// Writes an image as EXR under `target/test-output/` when `MCCTRACE_TEST_OUTPUT` is set, for a
/// person to look at a failing case; does nothing otherwise.
pub fn maybe_save(name: &str, image: &RgbImage) {
    if std::env::var_os("MCCTRACE_TEST_OUTPUT").is_none() {
        return;
    }
    let dir = repo_root().join("target/test-output");
    std::fs::create_dir_all(&dir).expect("create target/test-output");
    let path: &Path = &dir.join(format!("{name}.exr"));
    tracer::image_io::write_exr(path, image, &[], &[]).expect("write test output");
    println!("wrote {}", path.display());
}

/// A 2-D point on the unit square from two numbers (for lens samples).
pub fn v2(x: f32, y: f32) -> Vec2 {
    Vec2::new(x, y)
}

/// Runs `mcctrace ARGS…` in-process (what the binary's `main` does, without exiting).
pub fn mcctrace(args: &[&str]) -> anyhow::Result<()> {
    mcctrace_cli::try_run(std::iter::once("mcctrace").chain(args.iter().copied()))
}

/// A scratch directory under the system temporary directory, unique per test process and
/// name, removed on drop.
pub struct Scratch(PathBuf);

impl Scratch {
    /// An empty directory `mcctrace-NAME-PID`.
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("mcctrace-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
    /// The directory itself.
    pub fn dir(&self) -> &Path {
        &self.0
    }
    /// `name` inside the directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
    /// `name` inside the directory, as a string for a command line.
    pub fn s(&self, name: &str) -> String {
        self.path(name).display().to_string()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
