//! Characters in motion (issue 40's targets): a 100 k-triangle skinned mesh (a 224 × 224 grid
//! of quads on a chain of four joints, smooth weights, the upper joints bending) written here as
//! glTF, then
//! 1. per frame: re-posed (skinning: `SceneSetup::pose`) and its BVH refitted (`Bvh::refit`,
//!    a rebuild beside it for comparison), the split and the CPU seconds reported;
//! 2. one frame rendered without and with geometry motion blur (`--shutter 0..0.5`, three motion
//!    steps), time per sample in paired rounds;
//! 3. the Cornell box (static) without and with a shutter, paired: the same speed.
//!
//! `cargo bench --bench motion` — rounds alternate the two versions, so load on the shared
//! machine affects both alike; best of the rounds is reported.

use glam::{UVec2, Vec3};
use std::path::Path;
use std::time::Instant;
use tracer::bvh::Bvh;
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::job::SceneSetup;
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{DEFAULT_MOTION_STEPS, Scene};

/// Quads per side: 2 × 224² = 100 352 triangles.
const GRID: u32 = 224;

#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

/// Writes the skinned grid: x in [−1, 1], y in [0, 4] at z = 0, joints at y = 0, 1, 2, 3, each
/// vertex between the two joints around its height; joints 1–3 turn 30° about z over 1 s.
fn write_character(dir: &Path) -> std::path::PathBuf {
    let n = GRID + 1;
    let mut bin: Vec<u8> = Vec::new();
    let put = |bin: &mut Vec<u8>, bytes: &[u8]| {
        let at = bin.len();
        bin.extend_from_slice(bytes);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        (at, bytes.len())
    };
    let f32s = |v: &[f32]| v.iter().flat_map(|f| f.to_le_bytes()).collect::<Vec<u8>>();
    let mut positions = Vec::new();
    let mut joints = Vec::new();
    let mut weights = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (-1.0 + 2.0 * i as f32 / GRID as f32, 4.0 * j as f32 / GRID as f32);
            positions.extend([x, y, 0.0]);
            let k = (y.floor() as u16).min(2);
            let f = (y - k as f32).clamp(0.0, 1.0);
            joints.extend([k, k + 1, 0, 0].iter().flat_map(|v| v.to_le_bytes()));
            weights.extend([1.0 - f, f, 0.0, 0.0]);
        }
    }
    let mut indices = Vec::new();
    for j in 0..GRID {
        for i in 0..GRID {
            let v = j * n + i;
            indices.extend([v, v + 1, v + n + 1, v, v + n + 1, v + n]);
        }
    }
    let ibm: Vec<f32> = (0..4)
        .flat_map(|k| {
            let mut m = [0.0f32; 16];
            (m[0], m[5], m[10], m[15]) = (1.0, 1.0, 1.0, 1.0);
            m[13] = -(k as f32);
            m
        })
        .collect();
    let half = 15f32.to_radians();
    let p = put(&mut bin, &f32s(&positions));
    let ix = put(&mut bin, &indices.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>());
    let jn = put(&mut bin, &joints);
    let wt = put(&mut bin, &f32s(&weights));
    let ib = put(&mut bin, &f32s(&ibm));
    let tm = put(&mut bin, &f32s(&[0.0, 1.0]));
    let rt = put(&mut bin, &f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, half.sin(), half.cos()]));
    std::fs::write(dir.join("character.bin"), &bin).unwrap();
    let views: Vec<String> = [p, ix, jn, wt, ib, tm, rt]
        .iter()
        .map(|(o, l)| format!(r#"{{"buffer": 0, "byteOffset": {o}, "byteLength": {l}}}"#))
        .collect();
    let (v, t) = (n * n, GRID * GRID * 6);
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [{{"name": "body", "mesh": 0, "skin": 0}}, {{"name": "j0", "children": [2]}},
            {{"name": "j1", "translation": [0, 1, 0], "children": [3]}},
            {{"name": "j2", "translation": [0, 1, 0], "children": [4]}},
            {{"name": "j3", "translation": [0, 1, 0]}}],
  "skins": [{{"joints": [1, 2, 3, 4], "inverseBindMatrices": 4}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "JOINTS_0": 2, "WEIGHTS_0": 3}},
                                "indices": 1, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.8, 0.6, 0.4, 1], "metallicFactor": 0}},
                  "doubleSided": true}}],
  "buffers": [{{"uri": "character.bin", "byteLength": {len}}}],
  "bufferViews": [{views}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": {v}, "type": "VEC3",
                  "min": [-1, 0, 0], "max": [1, 4, 0]}},
                {{"bufferView": 1, "componentType": 5125, "count": {t}, "type": "SCALAR"}},
                {{"bufferView": 2, "componentType": 5123, "count": {v}, "type": "VEC4"}},
                {{"bufferView": 3, "componentType": 5126, "count": {v}, "type": "VEC4"}},
                {{"bufferView": 4, "componentType": 5126, "count": 4, "type": "MAT4"}},
                {{"bufferView": 5, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]}},
                {{"bufferView": 6, "componentType": 5126, "count": 2, "type": "VEC4"}}],
  "animations": [{{"channels": [{{"sampler": 0, "target": {{"node": 2, "path": "rotation"}}}},
                                {{"sampler": 0, "target": {{"node": 3, "path": "rotation"}}}},
                                {{"sampler": 0, "target": {{"node": 4, "path": "rotation"}}}}],
                   "samplers": [{{"input": 5, "output": 6, "interpolation": "LINEAR"}}]}}]}}"#,
        len = bin.len(),
        views = views.join(", "),
    );
    let path = dir.join("character.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// Seconds per sample of `scene` rendered 96² at 8 spp from `camera`, shutter `shutter`.
fn seconds_per_sample(scene: &Scene, camera: &CameraDesc, shutter: (f32, f32), frame: u32) -> f64 {
    let tracer = PathTracer::new(scene, IntegratorConfig::DEFAULT.with_max_depth(4)).unwrap();
    let built = camera.build(UVec2::splat(96)).unwrap();
    let settings = RenderSettings { frame, shutter, ..RenderSettings::still(8) };
    let r = render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap();
    r.stats.seconds / r.stats.samples as f64
}

fn main() {
    let dir = std::env::temp_dir().join(format!("mcctrace-motion-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = write_character(&dir);
    let setup = SceneSetup { sky: Some(Vec3::splat(0.5)), ..SceneSetup::default() };
    let base = setup.load(&path).unwrap();
    println!(
        "character: {} triangles, {} vertices, {} threads",
        base.mesh.triangle_count(),
        base.mesh.positions.len(),
        rayon::current_num_threads()
    );

    // 1. Per frame: skinning (the whole scene flattened at the frame's time), then the BVH,
    // refitted (the tree of frame 0 kept) and, for comparison, built afresh.
    let mut tree = Bvh::build(&base.mesh);
    let (mut pose_s, mut refit_s, mut build_s) = (Vec::new(), Vec::new(), Vec::new());
    let (mut cpu_pose, mut cpu_refit, mut cpu_build) = (0.0, 0.0, 0.0);
    let frames = 12u32;
    for frame in 1..=frames {
        let (t, c) = (Instant::now(), cpu_seconds());
        let posed = setup.pose(&base, frame).unwrap();
        pose_s.push(t.elapsed().as_secs_f64());
        cpu_pose += cpu_seconds() - c;
        let (t, c) = (Instant::now(), cpu_seconds());
        assert!(tree.refit(&posed.mesh));
        refit_s.push(t.elapsed().as_secs_f64());
        cpu_refit += cpu_seconds() - c;
        let (t, c) = (Instant::now(), cpu_seconds());
        let fresh = Bvh::build(&posed.mesh);
        build_s.push(t.elapsed().as_secs_f64());
        cpu_build += cpu_seconds() - c;
        assert_eq!(fresh.len(), tree.len());
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (p, r, b) = (median(&mut pose_s), median(&mut refit_s), median(&mut build_s));
    let per = |cpu: f64| cpu / frames as f64 * 1e3;
    println!("re-pose + BVH update per frame ({frames} frames), median wall (mean CPU user + sys):");
    println!("  skinning     {:7.1} ms  ({:.1} ms CPU)", p * 1e3, per(cpu_pose));
    println!("  BVH refit    {:7.1} ms  ({:.1} ms CPU)", r * 1e3, per(cpu_refit));
    println!("  total        {:7.1} ms  (target ≤ 50 ms)", (p + r) * 1e3);
    println!("  (BVH rebuild {:7.1} ms  ({:.1} ms CPU), for comparison)", b * 1e3, per(cpu_build));

    // 2. Motion blur: frame 12, without and with the shutter (3 motion steps), paired rounds.
    let camera = CameraDesc::look_at(
        "c",
        Vec3::new(0.0, 2.0, 6.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 45f32.to_radians() },
    )
    .unwrap();
    let sharp = setup.pose(&base, 12).unwrap();
    let blurred = setup.pose_in_shutter(&base, 12, (0.0, 0.5), DEFAULT_MOTION_STEPS).unwrap();
    assert!(blurred.motion.is_some(), "the character moves within the shutter");
    let t = Instant::now();
    let blurred_tracer = PathTracer::new(&blurred, IntegratorConfig::DEFAULT).unwrap();
    println!("motion BVH (3 steps) + tracer set-up: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    drop(blurred_tracer);
    let (mut a, mut m) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        a = a.min(seconds_per_sample(&sharp, &camera, (0.0, 0.0), 12));
        m = m.min(seconds_per_sample(&blurred, &camera, (0.0, 0.5), 12));
    }
    println!("character 96², 8 spp, best of 5 paired rounds:");
    println!("  no blur            {:8.3} µs/sample", a * 1e6);
    println!("  geometry blur (3)  {:8.3} µs/sample  ratio {:.3} (target ≤ 1.5)", m * 1e6, m / a);

    // 3. A static scene: the same speed with a shutter.
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.gltf");
    let scene = SceneSetup::default().load(&cornell).unwrap();
    let cam = scene.cameras[0].clone();
    let (mut s0, mut s1) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..5 {
        s0 = s0.min(seconds_per_sample(&scene, &cam, (0.0, 0.0), 0));
        s1 = s1.min(seconds_per_sample(&scene, &cam, (0.0, 0.5), 0));
    }
    println!("Cornell 96², 8 spp, best of 5 paired rounds:");
    println!("  no shutter         {:8.3} µs/sample", s0 * 1e6);
    println!("  --shutter 0..0.5   {:8.3} µs/sample  ratio {:.3}", s1 * 1e6, s1 / s0);
    let _ = std::fs::remove_dir_all(&dir);
}
