//! Scene time (part of tests/animation/): a glTF whose square or camera moves LINEARly along
//! x renders where the hand-computed pose at frame / fps puts it.

use super::{Scratch, mcctrace};
use std::path::{Path, PathBuf};
use tracer::image::RgbImage;
use tracer::image_io::read_exr;

/// An orthographic camera `eye` (x and y half-extent 1, at the origin looking down −z) and an
/// emissive 0.5 × 0.5 square at z = −2; `animated` ("quad" or "eye") translates along x
/// LINEARly from `from` at 0 s to `to` at 1 s.
fn write_animated_gltf(dir: &Path, animated: &str, from: f32, to: f32) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    let f32s = |bin: &mut Vec<u8>, v: &[f32]| bin.extend(v.iter().flat_map(|f| f.to_le_bytes()));
    f32s(&mut bin, &[-0.25, -0.25, -2.0, 0.25, -0.25, -2.0, 0.25, 0.25, -2.0, -0.25, 0.25, -2.0]);
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    f32s(&mut bin, &[0.0, 1.0]);
    f32s(&mut bin, &[from, 0.0, 0.0, to, 0.0, 0.0]);
    assert_eq!(bin.len(), 92);
    std::fs::write(dir.join("anim.bin"), &bin).unwrap();
    let node = if animated == "quad" { 0 } else { 1 };
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
  "nodes": [{{"name": "quad", "mesh": 0}}, {{"name": "eye", "camera": 0}}],
  "cameras": [{{"name": "eye", "type": "orthographic",
                "orthographic": {{"xmag": 1, "ymag": 1, "znear": 0.01, "zfar": 100}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}},
                  "emissiveFactor": [1, 1, 1], "doubleSided": true}}],
  "buffers": [{{"uri": "anim.bin", "byteLength": 92}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
                  {{"buffer": 0, "byteOffset": 48, "byteLength": 12}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": 8}},
                  {{"buffer": 0, "byteOffset": 68, "byteLength": 24}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [-0.25, -0.25, -2], "max": [0.25, 0.25, -2]}},
                {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}},
                {{"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]}},
                {{"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}}],
  "animations": [{{"channels": [{{"sampler": 0, "target": {{"node": {node}, "path": "translation"}}}}],
                   "samplers": [{{"input": 2, "output": 3, "interpolation": "LINEAR"}}]}}]}}"#
    );
    let path = dir.join(format!("{animated}.gltf"));
    std::fs::write(&path, json).unwrap();
    path
}

/// Renders `scene` at `frame` and `fps` (32², camera `eye`); returns the image.
fn render_frame(scene: &Path, out: &Path, frame: u32, fps: &str) -> RgbImage {
    let (f, exr) = (frame.to_string(), out.display().to_string());
    let s = scene.display().to_string();
    mcctrace(&[
        "render", &s, "--camera", "eye", "--frame", &f, "--fps", fps, "--res", "32x32", "--spp", "16",
        "--env", "0,0,0", "--quiet", "--out", &exr,
    ])
    .unwrap();
    read_exr(out).unwrap().rgb
}

/// The brightness-weighted mean column of `img` (pixel centres at i + 0.5).
fn centroid_x(img: &RgbImage) -> f64 {
    let (mut sum, mut weight) = (0.0f64, 0.0f64);
    for (i, p) in img.pixels.iter().enumerate() {
        let x = (i % img.width as usize) as f64 + 0.5;
        sum += x * p.x as f64;
        weight += p.x as f64;
    }
    assert!(weight > 10.0, "the square is in view");
    sum / weight
}

#[test]
fn scene_time_poses_animated_meshes_and_cameras_at_frame_over_fps() {
    let dir = Scratch::new("scene-time");
    // The square moves from x = −0.5 (0 s) to 0.5 (1 s): its image centre is at 16·(1 + x) px.
    let quad = write_animated_gltf(dir.dir(), "quad", -0.5, 0.5);
    let mut images = Vec::new();
    for (frame, fps, x) in
        [(0, "24", -0.5), (12, "24", 0.0), (24, "24", 0.5), (6, "24", -0.25), (24, "48", 0.0)]
    {
        let img = render_frame(&quad, &dir.path(&format!("q{frame}-{fps}.exr")), frame, fps);
        let c = centroid_x(&img);
        assert!(
            (c - 16.0 * (1.0 + x)).abs() < 0.1,
            "frame {frame} at {fps} fps: centre {c}, expected x = {x}"
        );
        images.push(img);
    }
    // Frame 24 at 48 fps is frame 12 at 24 fps (both 0.5 s): the same image bit for bit, and
    // not frame 24 at 24 fps.
    assert_eq!(images[4].pixels, images[1].pixels);
    assert_ne!(images[4].pixels, images[2].pixels);
    // A frame rate that is not a positive number is refused.
    let q = quad.display().to_string();
    for fps in ["0", "-24", "nan"] {
        let out = dir.s("bad.exr");
        let flag = format!("--fps={fps}");
        let err = mcctrace(&["render", &q, &flag, "--res", "8x8", "--spp", "1", "--quiet", "--out", &out]);
        let message = format!("{:#}", err.unwrap_err());
        assert!(message.contains("frame rate"), "{fps}: {message}");
    }
    // Past the last key the pose holds (glTF clamps).
    let c = centroid_x(&render_frame(&quad, &dir.path("late.exr"), 48, "24"));
    assert!((c - 24.0).abs() < 0.1, "2 s holds the 1 s pose: {c}");

    // The camera moves from x = 0 to 1 past a still square: the square's image moves left.
    let eye = write_animated_gltf(dir.dir(), "eye", 0.0, 1.0);
    for (frame, x) in [(0, 0.0), (12, 0.5), (18, 0.75)] {
        let c = centroid_x(&render_frame(&eye, &dir.path(&format!("e{frame}.exr")), frame, "24"));
        assert!((c - 16.0 * (1.0 - x)).abs() < 0.1, "camera at x = {x}: centre {c}");
    }
}
