//! Geometry motion blur (part of tests/animation/): a black square sliding along x in front of
//! a white sky, rendered with `render --shutter`, against its time-averaged coverage computed
//! here by hand; the same bits for any thread count; a static scene's bits unchanged by a
//! shutter; the pose past the last key held (so the last frame needs nothing after it).

use super::{Scratch, mcctrace};
use std::path::{Path, PathBuf};
use tracer::image::RgbImage;
use tracer::image_io::read_exr;

/// An orthographic camera `eye` (half-extent 1, at the origin looking down −z) and a black
/// (no diffuse, no specular layer: it reflects nothing) 0.5 × 0.5 square at z = −2 whose node
/// moves along x LINEARly through the keys `(s, x)`.
fn write_sliding_square(dir: &Path, keys: &[(f32, f32)]) -> PathBuf {
    write_square(dir, keys, false)
}

/// [`write_sliding_square`] lit by itself, for workflows that take no `--env` (the studio): an
/// emissive 4 × 4 backdrop of radiance 1 at z = −3, which reflects nothing, stands in for the
/// white sky.
pub(crate) fn write_lit_sliding_square(dir: &Path, keys: &[(f32, f32)]) -> PathBuf {
    write_square(dir, keys, true)
}

fn write_square(dir: &Path, keys: &[(f32, f32)], backdrop: bool) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    let f32s = |bin: &mut Vec<u8>, v: &[f32]| bin.extend(v.iter().flat_map(|f| f.to_le_bytes()));
    f32s(&mut bin, &[-0.25, -0.25, -2.0, 0.25, -0.25, -2.0, 0.25, 0.25, -2.0, -0.25, 0.25, -2.0]);
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    let times: Vec<f32> = keys.iter().map(|k| k.0).collect();
    let xs: Vec<f32> = keys.iter().flat_map(|k| [k.1, 0.0, 0.0]).collect();
    f32s(&mut bin, &times);
    f32s(&mut bin, &xs);
    let n = keys.len();
    let (t_end, x_end) = (60 + 4 * n, 60 + 16 * n);
    assert_eq!(x_end, bin.len());
    f32s(&mut bin, &[-2.0, -2.0, -3.0, 2.0, -2.0, -3.0, 2.0, 2.0, -3.0, -2.0, 2.0, -3.0]);
    std::fs::write(dir.join("slide.bin"), &bin).unwrap();
    let (nodes, extra_node, extra_mesh, extra_material) = if backdrop {
        (
            "[0, 1, 2]",
            r#", {"name": "backdrop", "mesh": 1}"#,
            r#", {"primitives": [{"attributes": {"POSITION": 4}, "indices": 1, "material": 1}]}"#,
            r#", {"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0},
                  "emissiveFactor": [1, 1, 1],
                  "extensions": {"KHR_materials_specular": {"specularFactor": 0}},
                  "doubleSided": true}"#,
        )
    } else {
        ("[0, 1]", "", "", "")
    };
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": {nodes}}}],
  "nodes": [{{"name": "square", "mesh": 0}}, {{"name": "eye", "camera": 0}}{extra_node}],
  "cameras": [{{"name": "eye", "type": "orthographic",
                "orthographic": {{"xmag": 1, "ymag": 1, "znear": 0.01, "zfar": 100}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}{extra_mesh}],
  "extensionsUsed": ["KHR_materials_specular"],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}},
                  "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}},
                  "doubleSided": true}}{extra_material}],
  "buffers": [{{"uri": "slide.bin", "byteLength": {len}}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
                  {{"buffer": 0, "byteOffset": 48, "byteLength": 12}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": {tl}}},
                  {{"buffer": 0, "byteOffset": {t_end}, "byteLength": {xl}}},
                  {{"buffer": 0, "byteOffset": {x_end}, "byteLength": 48}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [-0.25, -0.25, -2], "max": [0.25, 0.25, -2]}},
                {{"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}},
                {{"bufferView": 2, "componentType": 5126, "count": {n}, "type": "SCALAR",
                  "min": [{t0}], "max": [{t1}]}},
                {{"bufferView": 3, "componentType": 5126, "count": {n}, "type": "VEC3"}},
                {{"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [-2, -2, -3], "max": [2, 2, -3]}}],
  "animations": [{{"channels": [{{"sampler": 0, "target": {{"node": 0, "path": "translation"}}}}],
                   "samplers": [{{"input": 2, "output": 3, "interpolation": "LINEAR"}}]}}]}}"#,
        len = bin.len(),
        tl = 4 * n,
        xl = 12 * n,
        t0 = times[0],
        t1 = times[n - 1],
    );
    let path = dir.join("slide.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

/// Renders `scene` from `eye` at 32² under a white sky; `extra` flags added.
pub(super) fn render(scene: &Path, out: &Path, extra: &[&str]) -> RgbImage {
    let (s, exr) = (scene.display().to_string(), out.display().to_string());
    let mut args = vec![
        "render",
        &s,
        "--camera",
        "eye",
        "--res",
        "32x32",
        "--env",
        "1,1,1",
        "--max-depth",
        "2",
        "--quiet",
        "--out",
        &exr,
    ];
    args.extend_from_slice(extra);
    mcctrace(&args).unwrap();
    read_exr(out).unwrap().rgb
}

/// The mean of rows 12..20 (y within the square's ±0.25) of column `i`.
fn column(img: &RgbImage, i: u32) -> f64 {
    (12..20).map(|j| img.pixels[(j * img.width + i) as usize].x as f64).sum::<f64>() / 8.0
}

/// The square (centre c, half-width 0.25) slides at a constant speed from c0 to c1 while the
/// shutter is open. A point x of the film is dark for the fraction of the shutter when
/// |x − c| ≤ 0.25; a pixel's value is 1 minus that, averaged over its width (1/16).
fn expected_column(i: u32, c0: f64, c1: f64) -> f64 {
    let n = 512;
    let covered = |x: f64| {
        let (lo, hi) = ((x - 0.25).max(c0.min(c1)), (x + 0.25).min(c0.max(c1)));
        ((hi - lo).max(0.0)) / (c1 - c0).abs()
    };
    let x0 = -1.0 + i as f64 / 16.0;
    1.0 - (0..n).map(|k| covered(x0 + (k as f64 + 0.5) / (16.0 * n as f64))).sum::<f64>() / n as f64
}

#[test]
fn moving_geometry_blurs_as_its_time_averaged_coverage() {
    let dir = Scratch::new("motion-blur");
    // 24 fps; the square moves 1 unit per frame: centre x = frame − 12.
    let scene = write_sliding_square(dir.dir(), &[(0.0, -12.0), (1.0, 12.0)]);
    let spp = "256";
    // Frame 12, shutter 0..0.5: the centre slides from 0 to 0.5 (rays at 12 … 12.5 frames).
    let blurred =
        render(&scene, &dir.path("blur.exr"), &["--frame", "12", "--shutter", "0..0.5", "--spp", spp]);
    let sharp = render(&scene, &dir.path("sharp.exr"), &["--frame", "12", "--spp", spp]);
    let mut worst = 0.0f64;
    for i in 0..32 {
        let want = expected_column(i, 0.0, 0.5);
        // Every sample is 0 or 1 (black square or white sky): 2048 Bernoulli samples a column.
        let sigma = (want * (1.0 - want) / 2048.0).sqrt();
        let got = column(&blurred, i);
        assert!((got - want).abs() <= 5.0 * sigma + 1e-6, "column {i}: {got}, expected {want} (σ {sigma})");
        worst = worst.max((column(&sharp, i) - want).abs());
    }
    assert!(worst > 0.4, "the sharp frame is far from the blurred one somewhere ({worst})");
    // Outside the square's rows, and far from its path, the sky is untouched: exactly 1.
    assert!(blurred.pixels[..32 * 8].iter().all(|p| p.x == 1.0), "rows above the square");
    assert!((0..32).all(|j| blurred.pixels[(j * 32) as usize].x == 1.0), "column 0");
    // Wholly covered pixels are black: the square reflects nothing.
    assert!(sharp.pixels[(16 * 32 + 16) as usize].x == 0.0);
    // Any thread count gives the same bits.
    let one = render(
        &scene,
        &dir.path("t1.exr"),
        &["--frame", "12", "--shutter", "0..0.5", "--spp", spp, "--threads", "1"],
    );
    assert!(one.pixels == blurred.pixels, "one thread and all differ");

    // Past the last key (1 s = frame 24) the pose holds: frame 30 is sharp, the square at 12.
    let held = render(&scene, &dir.path("held.exr"), &["--frame", "30", "--shutter", "0..0.5", "--spp", "4"]);
    let still = render(&scene, &dir.path("still.exr"), &["--frame", "30", "--spp", "4"]);
    assert!(held.pixels == still.pixels, "past the end nothing moves: no blur, the same bits");
    // The last key's frame blurs towards the held pose: centre 12 throughout, out of view.
    // Frame 23.5 … 24: from 11.5 to 12, also out of view; a square ending in view instead:
    let ending = write_sliding_square(dir.dir(), &[(0.0, -1.0), (0.5, 0.0)]);
    // Frame 12 (0.5 s) is the last key: centre 0, held for the whole shutter: sharp.
    let last =
        render(&ending, &dir.path("last.exr"), &["--frame", "12", "--shutter", "0..0.5", "--spp", "4"]);
    let last_sharp = render(&ending, &dir.path("last-sharp.exr"), &["--frame", "12", "--spp", "4"]);
    assert!(last.pixels == last_sharp.pixels);
    // Frame 11.5 is not a frame; frame 11's shutter 0..1 runs into the last key and blurs
    // over centres −1/12 … 0 (rays at 11 … 12 frames), with no frame after it needed.
    let before =
        render(&ending, &dir.path("before.exr"), &["--frame", "11", "--shutter", "0..1", "--spp", spp]);
    for i in 0..32 {
        let want = expected_column(i, -1.0 / 12.0, 0.0);
        let sigma = (want * (1.0 - want) / 2048.0).sqrt();
        let got = column(&before, i);
        assert!((got - want).abs() <= 5.0 * sigma + 1e-6, "frame 11, column {i}: {got} vs {want}");
    }
}

/// A static scene renders the same bits with a shutter as without one.
#[test]
fn a_shutter_leaves_a_static_scene_bit_for_bit() {
    let dir = Scratch::new("motion-static");
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join(super::CORNELL);
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path(name);
        let (s, o) = (cornell.display().to_string(), out.display().to_string());
        let mut args = vec!["render", &s, "--res", "48x48", "--spp", "8", "--quiet", "--out", &o];
        args.extend_from_slice(extra);
        mcctrace(&args).unwrap();
        read_exr(&out).unwrap().rgb
    };
    let plain = run("plain.exr", &[]);
    let shut = run("shutter.exr", &["--shutter", "0..0.5"]);
    assert!(plain.pixels.iter().any(|p| p.max_element() > 0.01), "the box is lit");
    assert!(plain.pixels == shut.pixels, "a shutter changed a static scene's bits");
}

/// `rerender --shutter` blurs the moving geometry as `render --shutter` does: the sliding
/// square seen through the ray file `render --lens-writer` recorded of its camera (one ray per
/// pixel, the lens reader spreading samples over the pixel as the camera does) matches the
/// time-averaged coverage; without the shutter it is sharp; the header records the shutter.
#[test]
fn rerender_blurs_moving_geometry_within_the_shutter() {
    let dir = Scratch::new("motion-rerender");
    let scene = write_sliding_square(dir.dir(), &[(0.0, -12.0), (1.0, 12.0)]);
    let views = dir.path("views");
    render(&scene, &views.join("frame0012camera01.exr"), &["--frame", "12", "--spp", "1", "--lens-writer"]);
    let lens = views.join("frame0012camera01.mcr");
    assert!(lens.is_file(), "the lens writer wrote {}", lens.display());
    let rerender = |name: &str, extra: &[&str]| {
        let (s, l, o) = (scene.display().to_string(), lens.display().to_string(), dir.s(name));
        let mut args = vec![
            "rerender",
            &s,
            "--lens",
            &l,
            "--frame",
            "12",
            "--env",
            "1,1,1",
            "--max-depth",
            "2",
            "--spp",
            "256",
            "--quiet",
            "--out",
            &o,
        ];
        args.extend_from_slice(extra);
        mcctrace(&args).unwrap();
        read_exr(&dir.path(name)).unwrap()
    };
    let blurred = rerender("blur.exr", &["--shutter", "0..0.5"]);
    let sharp = rerender("sharp.exr", &[]);
    let mut worst = 0.0f64;
    for i in 0..32 {
        let want = expected_column(i, 0.0, 0.5);
        let sigma = (want * (1.0 - want) / 2048.0).sqrt();
        let got = column(&blurred.rgb, i);
        assert!((got - want).abs() <= 5.0 * sigma + 1e-6, "column {i}: {got}, expected {want} (σ {sigma})");
        worst = worst.max((column(&sharp.rgb, i) - want).abs());
    }
    assert!(worst > 0.4, "without --shutter the square is sharp ({worst})");
    assert_eq!(blurred.metadata["mcctrace/shutter"], "0..0.5");
}
