//! Rigid motion blur (part of tests/animation/): a black bar turning half a turn within the
//! shutter, in front of a white sky, rendered with `render --shutter`, against its
//! time-averaged coverage computed here by hand. The node is an instance moving by its
//! transform interpolated per ray time, the rotation by slerp: the coverage of a bar turning
//! at a constant rate. Interpolating its corners along chords between the motion steps (90°
//! apart) would shrink it by up to 1 − cos 45° between them, which this test tells apart.

use super::Scratch;
use super::motion_blur::render;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

/// Half length of the bar.
const HALF_L: f64 = 0.8;
/// Half width of the bar.
const HALF_W: f64 = 0.1;

/// An orthographic camera `eye` (half-extent 1, looking down −z) and a black bar at z = −2
/// turning about z: keys (seconds, angle in degrees), LINEAR (slerp between keys).
fn write_turning_bar(dir: &Path, keys: &[(f32, f32)]) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    let f32s = |bin: &mut Vec<u8>, v: &[f32]| bin.extend(v.iter().flat_map(|f| f.to_le_bytes()));
    let (l, w) = (HALF_L as f32, HALF_W as f32);
    f32s(&mut bin, &[-l, -w, -2.0, l, -w, -2.0, l, w, -2.0, -l, w, -2.0]);
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    let n = keys.len();
    f32s(&mut bin, &keys.iter().map(|k| k.0).collect::<Vec<_>>());
    let quats: Vec<f32> = keys
        .iter()
        .flat_map(|k| {
            let h = k.1.to_radians() / 2.0;
            [0.0, 0.0, h.sin(), h.cos()]
        })
        .collect();
    f32s(&mut bin, &quats);
    std::fs::write(dir.join("bar.bin"), &bin).unwrap();
    let (t_end, t_min, t_max) = (60 + 4 * n, keys[0].0, keys[n - 1].0);
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [{{"name": "bar", "mesh": 0}}, {{"name": "eye", "camera": 0}}],
  "cameras": [{{"name": "eye", "type": "orthographic",
                "orthographic": {{"xmag": 1, "ymag": 1, "znear": 0.01, "zfar": 100}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "extensionsUsed": ["KHR_materials_specular"],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}},
                  "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}},
                  "doubleSided": true}}],
  "buffers": [{{"uri": "bar.bin", "byteLength": {len}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
                  {{"buffer": 0, "byteOffset": 48, "byteLength": 12}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": {tl}}},
                  {{"buffer": 0, "byteOffset": {t_end}, "byteLength": {ql}}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [-{l}, -{w}, -2], "max": [{l}, {w}, -2]}},
                {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}},
                {{"bufferView": 2, "componentType": 5126, "count": {n}, "type": "SCALAR",
                  "min": [{t_min}], "max": [{t_max}]}},
                {{"bufferView": 3, "componentType": 5126, "count": {n}, "type": "VEC4"}}],
  "animations": [{{"channels": [{{"sampler": 0, "target": {{"node": 0, "path": "rotation"}}}}],
                   "samplers": [{{"input": 2, "output": 3, "interpolation": "LINEAR"}}]}}]}}"#,
        len = bin.len(),
        tl = 4 * n,
        ql = 16 * n,
    );
    let path = dir.join("bar.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// The time-averaged sky fraction of pixel (i, j) (the film spans ±1, y up, rows from the
/// top) while the bar's shape at a fraction s of the shutter is `placed(s)`: a map taking a
/// film point to the bar's own frame (inside when |x| ≤ HALF_L and |y| ≤ HALF_W).
fn expected(i: u32, j: u32, placed: &impl Fn(f64) -> [[f64; 2]; 2]) -> f64 {
    let (sub, times) = (6, 240);
    let mut covered = 0usize;
    for t in 0..times {
        let m = placed((t as f64 + 0.5) / times as f64);
        for a in 0..sub {
            for b in 0..sub {
                let x = -1.0 + (i as f64 + (a as f64 + 0.5) / sub as f64) / 16.0;
                let y = 1.0 - (j as f64 + (b as f64 + 0.5) / sub as f64) / 16.0;
                let (u, v) = (m[0][0] * x + m[0][1] * y, m[1][0] * x + m[1][1] * y);
                covered += (u.abs() <= HALF_L && v.abs() <= HALF_W) as usize;
            }
        }
    }
    1.0 - covered as f64 / (sub * sub * times) as f64
}

/// The inverse of a rotation by `a` scaled by `k`.
fn inverse(a: f64, k: f64) -> [[f64; 2]; 2] {
    let (s, c) = a.sin_cos();
    [[c / k, s / k], [-s / k, c / k]]
}

#[test]
fn a_turning_object_blurs_along_the_arc_not_the_chords() {
    let dir = Scratch::new("rigid-motion");
    // 24 fps; frame 12's shutter 0..0.5 is 0.5 … 0.5 + 1/48 s: half a turn, 90° a motion step
    // (3 steps: the keys' times).
    let (t0, dt) = (0.5f32, 1.0f32 / 96.0);
    let scene =
        write_turning_bar(dir.dir(), &[(0.0, 0.0), (t0, 0.0), (t0 + dt, 90.0), (t0 + 2.0 * dt, 180.0)]);
    let spp = 256;
    let blurred = render(
        &scene,
        &dir.path("blur.exr"),
        &["--frame", "12", "--shutter", "0..0.5", "--spp", &spp.to_string()],
    );
    // The arc: the angle linear in time over the half turn.
    let arc = |s: f64| inverse(PI * s, 1.0);
    // The chords: each corner linear between steps 90° apart, which is the bar turned by
    // atan(f / (1 − f)) and scaled by |(1 − f, f)| within each half of the shutter.
    let chord = |s: f64| {
        let (k, f) = if s < 0.5 { (0.0, 2.0 * s) } else { (PI / 2.0, 2.0 * s - 1.0) };
        inverse(k + f.atan2(1.0 - f), (1.0 - f).hypot(f))
    };
    let (mut worst_z, mut chord_z) = (0.0f64, 0.0f64);
    for j in 0..32 {
        for i in 0..32 {
            let want = expected(i, j, &arc);
            let got = blurred.pixels[(j * 32 + i) as usize].x as f64;
            // Every sample is 0 or 1 (black bar or white sky); floor σ for pixels the
            // reference has (nearly) constant.
            let sigma = (want * (1.0 - want) / spp as f64).sqrt().max(0.5 / spp as f64);
            worst_z = worst_z.max((got - want).abs() / sigma);
            chord_z = chord_z.max((got - expected(i, j, &chord)).abs() / sigma);
        }
    }
    assert!(worst_z <= 5.0, "a pixel is {worst_z} σ from the arc's coverage");
    assert!(chord_z > 10.0, "the chords' coverage should be far off somewhere ({chord_z} σ)");
    // Any thread count gives the same bits.
    let one = render(
        &scene,
        &dir.path("t1.exr"),
        &["--frame", "12", "--shutter", "0..0.5", "--spp", &spp.to_string(), "--threads", "1"],
    );
    assert!(one.pixels == blurred.pixels, "one thread and all differ");
}
