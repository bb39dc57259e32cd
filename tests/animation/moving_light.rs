//! A moving emitter (part of tests/animation/): a one-sided emissive quad sliding over a
//! Lambertian floor within the shutter lights the floor with its time-averaged illumination,
//! computed here in closed form (the form factor of a parallel rectangle, integrated over the
//! slide), through both ways the path tracer finds it (light sampling at the shadow ray's time,
//! and BSDF-sampled rays reaching it, weighted by MIS with the same density); posing it in
//! motion warns of nothing.

use super::Scratch;
use glam::UVec2;
use std::path::{Path, PathBuf};
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::job::SceneSetup;
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, Rendered, render};
use tracer::scene::{DEFAULT_MOTION_STEPS, Scene};

/// Emitted radiance of the quad and the floor's albedo.
const RADIANCE: f64 = 2.0;
const ALBEDO: f64 = 0.8;
/// The quad's height over the floor and its half-size.
const HEIGHT: f64 = 1.0;
const HALF: f64 = 0.5;
/// The floor spans ±FLOOR in x and z, and the film shows all of it.
const FLOOR: f64 = 2.0;
const SIZE: u32 = 32;
const SPP: u32 = 256;

/// A floor of albedo [`ALBEDO`] at y = 0 and a 1 × 1 quad at y = 1 emitting [`RADIANCE`]
/// downwards only (black, no specular layer: it reflects nothing), whose node slides along x
/// from −12 at 0 s to 12 at 1 s (1 unit a frame at 24 fps).
fn write_scene(dir: &Path) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    let f32s = |bin: &mut Vec<u8>, v: &[f32]| bin.extend(v.iter().flat_map(|f| f.to_le_bytes()));
    let (f, h, y) = (FLOOR as f32, HALF as f32, HEIGHT as f32);
    f32s(&mut bin, &[-f, 0.0, -f, f, 0.0, -f, f, 0.0, f, -f, 0.0, f]);
    // Counter-clockwise seen from below: the front face looks down.
    f32s(&mut bin, &[-h, y, -h, h, y, -h, h, y, h, -h, y, h]);
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    f32s(&mut bin, &[0.0, 1.0]);
    f32s(&mut bin, &[-12.0, 0.0, 0.0, 12.0, 0.0, 0.0]);
    std::fs::write(dir.join("lamp.bin"), &bin).unwrap();
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [{{"name": "floor", "mesh": 0}}, {{"name": "lamp", "mesh": 1}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 2, "material": 0}}]}},
             {{"primitives": [{{"attributes": {{"POSITION": 1}}, "indices": 2, "material": 1}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [{a}, {a}, {a}, 1], "metallicFactor": 0}},
                  "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}},
                  "doubleSided": true}},
                {{"pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}},
                  "emissiveFactor": [1, 1, 1],
                  "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}},
                                  "KHR_materials_emissive_strength": {{"emissiveStrength": {l}}}}},
                  "doubleSided": false}}],
  "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength"],
  "buffers": [{{"uri": "lamp.bin", "byteLength": {len}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
                  {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
                  {{"buffer": 0, "byteOffset": 96, "byteLength": 12}},
                  {{"buffer": 0, "byteOffset": 108, "byteLength": 8}},
                  {{"buffer": 0, "byteOffset": 116, "byteLength": 24}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [-{f}, 0, -{f}], "max": [{f}, 0, {f}]}},
                {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [-{h}, {y}, -{h}], "max": [{h}, {y}, {h}]}},
                {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}},
                {{"bufferView": 3, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]}},
                {{"bufferView": 4, "componentType": 5126, "count": 2, "type": "VEC3"}}],
  "animations": [{{"channels": [{{"sampler": 0, "target": {{"node": 1, "path": "translation"}}}}],
                   "samplers": [{{"input": 3, "output": 4, "interpolation": "LINEAR"}}]}}]}}"#,
        a = ALBEDO,
        l = RADIANCE,
        len = bin.len(),
    );
    let path = dir.join("lamp.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// `∫ cos·cos / (π r²) dA` over the rectangle [0, a] × [0, b] in a plane `HEIGHT` above a
/// point below its corner, signed by the signs of a and b (so that any rectangle is four of
/// these added and subtracted).
fn corner_factor(a: f64, b: f64) -> f64 {
    let (x, y, h) = (a.abs(), b.abs(), HEIGHT);
    let (p, q) = ((x * x + h * h).sqrt(), (y * y + h * h).sqrt());
    let f = (x / p * (y / p).atan() + y / q * (x / q).atan()) / (2.0 * std::f64::consts::PI);
    f * a.signum() * b.signum()
}

/// The floor's radiance at (x, z) lit by the quad centred at x = `c`: ρ · L · form factor.
fn floor_radiance(x: f64, z: f64, c: f64) -> f64 {
    let (x0, x1, z0, z1) = (c - HALF - x, c + HALF - x, -HALF - z, HALF - z);
    let f = corner_factor(x1, z1) - corner_factor(x0, z1) - corner_factor(x1, z0) + corner_factor(x0, z0);
    ALBEDO * RADIANCE * f
}

/// Pixel (i, j)'s expected value: the floor's radiance averaged over the pixel's footprint and
/// over the quad's centres `c0` … `c1` (uniform in time: the slide is linear).
fn expected(i: u32, j: u32, c0: f64, c1: f64) -> f64 {
    let (n, times) = (6, if c0 == c1 { 1 } else { 96 });
    let pixel = 2.0 * FLOOR / SIZE as f64;
    let mut sum = 0.0;
    for a in 0..n {
        for b in 0..n {
            let x = -FLOOR + (i as f64 + (a as f64 + 0.5) / n as f64) * pixel;
            // Film rows run down the image: −z is up (the camera looks down −y with −z up).
            let z = -FLOOR + (j as f64 + (b as f64 + 0.5) / n as f64) * pixel;
            for k in 0..times {
                let c = c0 + (c1 - c0) * (k as f64 + 0.5) / times as f64;
                sum += floor_radiance(x, z, c);
            }
        }
    }
    sum / (n * n * times) as f64
}

/// The scene at frame 12 with the shutter `0..shutter`, rendered from above (orthographic).
fn render_lamp(path: &Path, shutter: f32) -> (Rendered, Vec<String>) {
    let setup = SceneSetup::default();
    let scene = Scene::load(path).unwrap();
    let posed = setup.at_frame_in_shutter(scene, 12, (0.0, shutter), DEFAULT_MOTION_STEPS).unwrap();
    let projection = Projection::Orthographic { half_height: FLOOR as f32 };
    let camera = CameraDesc::look_at(
        "above",
        glam::Vec3::new(0.0, 3.0, 0.0),
        glam::Vec3::ZERO,
        -glam::Vec3::Z,
        projection,
    )
    .unwrap()
    .build(UVec2::splat(SIZE))
    .unwrap();
    let tracer = PathTracer::new(&posed, IntegratorConfig::DEFAULT.with_max_depth(3)).unwrap();
    let settings =
        RenderSettings { seed: 7, frame: 12, shutter: (0.0, shutter), ..RenderSettings::still(SPP) };
    let r = render(&tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap();
    (r, posed.warnings)
}

/// Pixels whose floor point the quad never hides from the camera over its slide (|z| beyond
/// its half-width and a pixel).
fn open_rows() -> impl Iterator<Item = (u32, u32)> {
    let pixel = 2.0 * FLOOR / SIZE as f64;
    (0..SIZE)
        .filter(move |&j| {
            let (z0, z1) = (-FLOOR + j as f64 * pixel, -FLOOR + (j + 1) as f64 * pixel);
            z1 < -HALF - pixel || z0 > HALF + pixel
        })
        .flat_map(|j| (0..SIZE).map(move |i| (i, j)))
}

/// The largest |z| of the render against `want` over the open pixels, and the z of their mean
/// difference.
fn z_scores(r: &Rendered, want: impl Fn(u32, u32) -> f64) -> (f64, f64) {
    let (mut worst, mut diff, mut var) = (0.0f64, 0.0, 0.0);
    for (i, j) in open_rows() {
        let k = (j * SIZE + i) as usize;
        let (got, v) = (r.images.image.pixels[k].x as f64, r.images.variance.pixels[k].x as f64 / SPP as f64);
        let e = want(i, j);
        worst = worst.max((got - e).abs() / v.max(1e-12).sqrt());
        diff += got - e;
        var += v;
    }
    (worst, diff.abs() / var.sqrt())
}

#[test]
fn a_moving_emitter_lights_with_its_time_averaged_illumination() {
    let dir = Scratch::new("moving-light");
    let path = write_scene(dir.dir());
    // Frame 12 (0.5 s): the quad's centre at x = 0; the shutter 0..1 slides it to x = 1.
    let (sharp, _) = render_lamp(&path, 0.0);
    let (blurred, warnings) = render_lamp(&path, 1.0);
    assert!(warnings.is_empty(), "posing a moving emitter warns: {warnings:?}");
    assert_eq!(blurred.stats.nonfinite_samples, 0);
    // The set-up against the closed form first: the sharp frame, quad at x = 0.
    let (worst, bias) = z_scores(&sharp, |i, j| expected(i, j, 0.0, 0.0));
    assert!(worst < 5.5 && bias < 4.0, "sharp frame against the closed form: |z| ≤ {worst}, bias z {bias}");
    let (worst, bias) = z_scores(&blurred, |i, j| expected(i, j, 0.0, 1.0));
    assert!(
        worst < 5.5 && bias < 4.0,
        "blurred frame against the time average: |z| ≤ {worst}, bias z {bias}"
    );
    // The control: the frame's pose alone (the light sharp where the frame has it) is far off.
    let (worst, off) = z_scores(&sharp, |i, j| expected(i, j, 0.0, 1.0));
    assert!(
        worst > 10.0 && off > 10.0,
        "the sharp frame passes for the blurred one: |z| ≤ {worst}, bias z {off}"
    );
}
