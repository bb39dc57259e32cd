//! `animate` refits each frame's BVH from the previous frame's (part of tests/animation/): a
//! resumed shot renders the same bits as a continuous one, whatever the thread count, even
//! where every hit is a tie (two coincident grids: closest hits break ties by triangle index,
//! not by the tree's shape).

use super::{Scratch, mcctrace, rerender_file};
use glam::Vec3;
use mcc::{RayFile, StoredRay};
use std::path::{Path, PathBuf};
use tracer::image_io::read_exr;

/// Two 4 × 4 grids of quads over [−1, 1]² at z = −2: `blue` (emitting blue, first in the mesh)
/// still, and `red` (emitting red) sliding along x from −3 at 0 s onto the blue one at 3/24 s
/// (frame 3 at 24 fps), where it holds: from frame 3 on every ray through the grids hits two
/// triangles at exactly the same distance.
fn write_grids(dir: &Path) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    let f32s = |bin: &mut Vec<u8>, v: &[f32]| bin.extend(v.iter().flat_map(|f| f.to_le_bytes()));
    for j in 0..=4 {
        for i in 0..=4 {
            f32s(&mut bin, &[-1.0 + 0.5 * i as f32, -1.0 + 0.5 * j as f32, -2.0]);
        }
    }
    let positions = bin.len();
    for j in 0..4u16 {
        for i in 0..4u16 {
            let v = j * 5 + i;
            bin.extend([v, v + 1, v + 6, v, v + 6, v + 5].iter().flat_map(|i| i.to_le_bytes()));
        }
    }
    let indices = bin.len() - positions;
    f32s(&mut bin, &[0.0, 0.125]);
    f32s(&mut bin, &[-3.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    std::fs::write(dir.join("grids.bin"), &bin).unwrap();
    let material = |c: &str| {
        format!(
            r#"{{"pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}},
                 "emissiveFactor": [{c}], "doubleSided": true,
                 "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}}}}"#
        )
    };
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [{{"name": "blue", "mesh": 0}}, {{"name": "red", "mesh": 1}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}},
             {{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 1}}]}}],
  "extensionsUsed": ["KHR_materials_specular"],
  "materials": [{blue}, {red}],
  "buffers": [{{"uri": "grids.bin", "byteLength": {len}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {positions}}},
                  {{"buffer": 0, "byteOffset": {positions}, "byteLength": {indices}}},
                  {{"buffer": 0, "byteOffset": {t0}, "byteLength": 8}},
                  {{"buffer": 0, "byteOffset": {x0}, "byteLength": 24}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 25, "type": "VEC3",
                  "min": [-1, -1, -2], "max": [1, 1, -2]}},
                {{"bufferView": 1, "componentType": 5123, "count": 96, "type": "SCALAR"}},
                {{"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [0.125]}},
                {{"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}}],
  "animations": [{{"channels": [{{"sampler": 0, "target": {{"node": 1, "path": "translation"}}}}],
                   "samplers": [{{"input": 2, "output": 3, "interpolation": "LINEAR"}}]}}]}}"#,
        blue = material("0, 0, 1"),
        red = material("1, 0, 0"),
        len = bin.len(),
        t0 = positions + indices,
        x0 = positions + indices + 8,
    );
    let path = dir.join("grids.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// Orthographic rays down −z over [−1.5, 1.5]², one per pixel of a 24², for frames 1 … 4.
fn write_rays(dir: &Path) {
    let n = 24;
    let rays = (0..n * n)
        .map(|p| {
            let (x, y) = ((p % n) as f32 + 0.5, (p / n) as f32 + 0.5);
            let at = |c: f32| -1.5 + 3.0 * c / n as f32;
            StoredRay::new(Vec3::new(at(x), -at(y), 0.0), -Vec3::Z)
        })
        .collect();
    let file = RayFile::new(n, n, 0, 1, rays).unwrap();
    std::fs::create_dir_all(dir).unwrap();
    for f in 1..=4 {
        file.write(&rerender_file(dir, f), mcc::RayFormat::Binary).unwrap();
    }
}

#[test]
fn a_resumed_shot_keeps_a_continuous_runs_bits() {
    let dir = Scratch::new("animate-refit");
    let scene = write_grids(dir.dir()).display().to_string();
    write_rays(&dir.path("lens"));
    let lens = dir.s("lens");
    let animate = |out: &str, frames: &str, threads: &str| {
        let out = dir.s(out);
        mcctrace(&[
            "animate",
            &scene,
            "--lens-dir",
            &lens,
            "--frames",
            frames,
            "--out",
            &out,
            "--spp",
            "4",
            "--threads",
            threads,
            "--preview",
            "none",
            "--quiet",
        ])
        .unwrap();
    };
    let pixels =
        |out: &str, f: u32| read_exr(&dir.path(out).join(format!("frame{f:04}.exr"))).unwrap().rgb.pixels;
    animate("continuous", "1..=4", "2");
    animate("resumed", "1..=2", "2");
    animate("resumed", "1..=4", "2");
    animate("one-thread", "1..=4", "1");
    for f in 1..=4 {
        let a = pixels("continuous", f);
        assert!(a == pixels("resumed", f), "frame {f}: the resumed run differs from the continuous one");
        assert!(a == pixels("one-thread", f), "frame {f}: one thread differs from two");
    }
    // Frame 1 has the grids apart; from frame 3 on they coincide, and blue (the lower triangle
    // indices) wins every tie, wherever the walk meets the red triangle first.
    let blue = Vec3::new(0.0, 0.0, 1.0);
    let last = pixels("continuous", 4);
    assert!(last.iter().filter(|p| **p == blue).count() > 100, "the grids show blue");
    assert!(!last.iter().any(|p| p.x > 0.0), "a tie went to the red grid");
    assert!(pixels("continuous", 1).iter().any(|p| p.x > 0.0), "frame 1 shows the red grid apart");
}
