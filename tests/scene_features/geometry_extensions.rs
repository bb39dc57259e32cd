//! Geometry as exporters write it: `EXT_meshopt_compression` and `KHR_mesh_quantization` files
//! written by gltfpack (tests/data/meshopt/) and the Khronos Duck in its plain and quantized
//! forms load to the same triangles as their originals; `EXT_texture_webp` images are read;
//! `EXT_mesh_gpu_instancing` draws every instance where the extension places it.

use super::harness::load;
use glam::{Quat, Vec3};
use std::path::Path;

/// Every triangle's corners in world space, each triangle rotated to start at its smallest
/// corner and the list sorted, so that a writer's reordering of vertices and triangles does
/// not matter.
fn triangles(path: &Path) -> Vec<[Vec3; 3]> {
    let scene = load(path);
    let mut tris: Vec<[Vec3; 3]> = (0..scene.mesh.triangles.len())
        .map(|t| {
            let c = scene.mesh.corners(t);
            let key = |v: Vec3| (v.x, v.y, v.z);
            let first = (0..3).min_by(|&a, &b| key(c[a]).partial_cmp(&key(c[b])).unwrap()).unwrap();
            [c[first], c[(first + 1) % 3], c[(first + 2) % 3]]
        })
        .collect();
    tris.sort_by(|a, b| {
        let k = |t: &[Vec3; 3]| t.map(|v| [v.x, v.y, v.z]);
        k(a).partial_cmp(&k(b)).unwrap()
    });
    tris
}

/// The largest distance between matching corners of two triangle lists of the same length.
fn worst_corner_distance(a: &[[Vec3; 3]], b: &[[Vec3; 3]]) -> f32 {
    assert_eq!(a.len(), b.len(), "triangle counts differ");
    a.iter().zip(b).flat_map(|(x, y)| (0..3).map(move |k| x[k].distance(y[k]))).fold(0.0, f32::max)
}

/// Adds `ext` to the `extensionsUsed` of a file the test builder wrote (its list is fixed).
fn declare_extension(path: &Path, ext: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.replacen(r#""extensionsUsed": ["#, &format!(r#""extensionsUsed": ["{ext}", "#), 1);
    std::fs::write(path, text).unwrap();
}

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshopt").join(name)
}

#[test]
fn meshopt_compressed_cornell_box_has_the_originals_triangles() {
    let original = triangles(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.gltf"));
    let noq = triangles(&data("cornell-noq.gltf"));
    // Float positions survive the vertex codec bit for bit.
    assert_eq!(noq, original);
    assert!(!original.is_empty());
}

#[test]
fn quantized_and_compressed_cornell_box_is_within_one_quantization_step() {
    let original = triangles(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell/cornell.gltf"));
    let quantized = load(&data("cornell-q.gltf"));
    assert!(quantized.warnings.is_empty(), "{:?}", quantized.warnings);
    let q = triangles(&data("cornell-q.gltf"));
    // gltfpack stores positions as 14-bit integers over the scene's extent, dequantised by the
    // node's scale: the error is at most half a step along each axis.
    let (lo, hi) = load(&data("cornell-q.gltf")).bounds().unwrap();
    let step = (hi - lo).max_element() / ((1 << 14) - 1) as f32;
    let worst = worst_corner_distance(&q, &original);
    assert!(worst <= step * 0.5 * 3f32.sqrt() + 1e-6, "worst corner {worst} against step {step}");
    assert!(worst > 0.0, "the quantized file is expected to differ by rounding");
}

#[test]
fn quantized_duck_matches_the_plain_duck() {
    let samples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/gltf-samples/Duck");
    if !samples.exists() {
        // The sample corpus lies beside the checkout (CI has it); say so rather than pass silently.
        assert!(std::env::var_os("MCCTRACE_CI").is_none(), "{} is missing under CI", samples.display());
        eprintln!("skipped: {} is not here", samples.display());
        return;
    }
    let plain = load(&samples.join("glTF/Duck.gltf"));
    let quantized = load(&samples.join("glTF-Quantized/Duck.gltf"));
    assert!(quantized.warnings.is_empty(), "{:?}", quantized.warnings);
    assert_eq!(quantized.mesh.triangles.len(), plain.mesh.triangles.len());
    let (lo, hi) = plain.bounds().unwrap();
    let (qlo, qhi) = quantized.bounds().unwrap();
    let extent = (hi - lo).max_element();
    assert!((qlo - lo).abs().max_element() < extent * 1e-3 && (qhi - hi).abs().max_element() < extent * 1e-3);
    // Normals are normalised signed bytes or shorts: each is still unit length after loading.
    for n in &quantized.mesh.normals {
        assert!((n.length() - 1.0).abs() < 1e-3, "normal {n}");
    }
}

#[test]
fn quantized_attributes_without_the_extension_are_refused_by_name() {
    let dir = super::assets::TempDir::new("quantized-undeclared");
    let text = std::fs::read_to_string(data("cornell-q.gltf")).unwrap();
    let stripped = text
        .replace("\"KHR_mesh_quantization\",", "")
        .replace(",\"KHR_mesh_quantization\"", "")
        .replace("\"KHR_mesh_quantization\"", "");
    assert!(!stripped.contains("KHR_mesh_quantization"));
    dir.write("cornell-q.bin", std::fs::read(data("cornell-q.bin")).unwrap());
    let path = dir.write("cornell-q.gltf", stripped);
    let err = tracer::scene::Scene::load(&path).unwrap_err().to_string();
    assert!(err.contains("POSITION") && err.contains("KHR_mesh_quantization"), "{err}");
}

#[test]
fn webp_textures_are_read_in_place_of_their_fallback() {
    use super::assets::{Gltf, Prim, TempDir, png};
    use glam::Vec2;
    let dir = TempDir::new("webp");
    // The fallback PNG is pure red; the WebP (lossless, so exact) a 2×2 pattern.
    png(&dir, "fallback.png", 2, 2, &[[255, 0, 0, 255]; 4]);
    let texels: [[u8; 4]; 4] = [[0, 0, 255, 255], [0, 255, 0, 255], [255, 255, 255, 255], [0, 0, 0, 255]];
    let mut webp = Vec::new();
    image::codecs::webp::WebPEncoder::new_lossless(&mut webp)
        .encode(texels.as_flattened(), 2, 2, image::ExtendedColorType::Rgba8)
        .unwrap();
    dir.write("pattern.webp", &webp);

    let mut g = Gltf::new("test");
    let fallback = super::assets::push(&mut g.images, r#"{"uri": "fallback.png"}"#.to_owned());
    let pattern =
        super::assets::push(&mut g.images, r#"{"uri": "pattern.webp", "mimeType": "image/webp"}"#.to_owned());
    let texture = super::assets::push(
        &mut g.textures,
        format!(r#"{{"source": {fallback}, "extensions": {{"EXT_texture_webp": {{"source": {pattern}}}}}}}"#),
    );
    let m =
        g.material(&format!(r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {texture}}}}}}}"#));
    let quad = Prim {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        uv0: vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Prim::default()
    };
    g.mesh_node(&[(&quad, m)], "");
    let path = g.write(&dir, "webp");
    declare_extension(&path, "EXT_texture_webp");
    let scene = load(&path);
    assert_eq!(scene.textures.len(), 1);
    let t = &scene.textures[0];
    assert!(t.name.contains("pattern.webp"), "{}", t.name);
    let got: Vec<[u8; 4]> =
        t.texels.iter().map(|v| (v * 255.0).round().to_array().map(|c| c as u8)).collect();
    assert_eq!(got, texels);
}

#[test]
fn gpu_instances_are_drawn_where_the_extension_places_them() {
    use super::assets::{Gltf, Prim, TempDir, arr};
    let dir = TempDir::new("instancing");
    let mut g = Gltf::new("test");
    let m = g.material(r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}"#);
    let tri =
        Prim { positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y], indices: vec![0, 1, 2], ..Prim::default() };
    let translations = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -3.0)];
    let rotations = [Quat::IDENTITY, Quat::from_rotation_z(std::f32::consts::FRAC_PI_2), Quat::IDENTITY];
    let scales = [Vec3::ONE, Vec3::ONE, Vec3::splat(2.0)];
    let flat3 = |v: &[Vec3]| v.iter().flat_map(|v| v.to_array()).collect::<Vec<f32>>();
    let t = g.floats(&flat3(&translations), "VEC3", 3, "");
    let r = g.floats(&rotations.iter().flat_map(|q| q.to_array()).collect::<Vec<_>>(), "VEC4", 3, "");
    let s = g.floats(&flat3(&scales), "VEC3", 3, "");
    let node_translation = Vec3::new(0.0, 10.0, 0.0);
    g.mesh_node(
        &[(&tri, m)],
        &format!(
            r#", "translation": {}, "extensions": {{"EXT_mesh_gpu_instancing": {{"attributes": {{"TRANSLATION": {t}, "ROTATION": {r}, "SCALE": {s}}}}}}}"#,
            arr(&node_translation.to_array())
        ),
    );
    let path = g.write(&dir, "instanced");
    declare_extension(&path, "EXT_mesh_gpu_instancing");
    // The copies share one triangle; flattened, each is where the extension places it.
    let shared = load(&path);
    assert_eq!((shared.mesh.triangles.len(), shared.drawn_triangle_count()), (1, 3));
    let scene = shared.with_copies_flattened();
    assert_eq!(scene.mesh.triangles.len(), 3);
    // glTF: world = node · T · R · S of the instance, computed here by hand.
    let p = &tri.positions;
    let mut want: Vec<[Vec3; 3]> = (0..3)
        .map(|i| {
            let f = |v: Vec3| node_translation + translations[i] + rotations[i] * (scales[i] * v);
            [f(p[0]), f(p[1]), f(p[2])]
        })
        .collect();
    let mut got: Vec<[Vec3; 3]> = (0..3).map(|t| scene.mesh.corners(t)).collect();
    let key = |t: &[Vec3; 3]| t.map(|v| [v.x, v.y, v.z]);
    want.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
    got.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
    assert!(worst_corner_distance(&got, &want) < 1e-5, "{got:?} against {want:?}");
}

#[test]
fn the_simple_instancing_sample_draws_its_125_cubes() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/gltf-samples/SimpleInstancing/glTF/SimpleInstancing.gltf");
    if !path.exists() {
        assert!(std::env::var_os("MCCTRACE_CI").is_none(), "{} is missing under CI", path.display());
        eprintln!("skipped: {} is not here", path.display());
        return;
    }
    let scene = load(&path);
    // One unit cube (12 triangles) per instance, translated over 0..10 on each axis: the
    // scene's mesh holds it once.
    assert_eq!((scene.mesh.triangles.len(), scene.drawn_triangle_count()), (12, 125 * 12));
    let (lo, hi) = scene.bounds().unwrap();
    assert!((hi - lo).min_element() >= 10.0, "instances spread over {lo}..{hi}");
    // Drawn as 125 instances of one cube: the BVH stores its 12 triangles once.
    let instances = scene.instances.as_deref().expect("the copies are instances");
    assert_eq!((instances.meshes.len(), instances.instances.len()), (1, 125));
    let config = tracer::integrator::IntegratorConfig::DEFAULT;
    let bvh_of = |s: &tracer::scene::Scene| tracer::integrator::PathTracer::new(s, config).unwrap();
    let flat = tracer::scene::Scene { instances: None, ..scene.with_copies_flattened() };
    let (instanced, flattened) = (bvh_of(&scene), bvh_of(&flat));
    assert_eq!(instanced.bvh().stored_triangles(), 12);
    assert_eq!(flattened.bvh().stored_triangles(), 125 * 12);
    let (small, large) = (instanced.bvh().bytes(), flattened.bvh().bytes());
    assert!(small * 4 < large, "{small} bytes instanced, {large} flattened");
    // The same picture as the flattened copies: the same seed takes the same paths but where
    // a hit's last bits differ (the ray is taken into each copy's space).
    let mut lit = scene.clone();
    lit.environment.color = Vec3::ONE;
    let camera = tracer::camera::CameraDesc::look_at(
        "view",
        Vec3::new(22.0, 16.0, 26.0),
        Vec3::splat(5.0),
        Vec3::Y,
        tracer::camera::Projection::Perspective { fov_y: 0.7 },
    )
    .unwrap();
    let size = glam::UVec2::new(64, 48);
    let a = super::harness::render(&lit, &camera, size, 16, 3);
    let flat_lit = tracer::scene::Scene { instances: None, ..lit.with_copies_flattened() };
    let b = super::harness::render(&flat_lit, &camera, size, 16, 3);
    let (pa, pb) = (&a.images.image.pixels, &b.images.image.pixels);
    let differing = pa.iter().zip(pb).filter(|(x, y)| (**x - **y).abs().max_element() > 1e-3).count();
    let mean = |p: &[Vec3]| p.iter().map(|v| v.x as f64 + v.y as f64 + v.z as f64).sum::<f64>();
    assert!(differing * 100 <= pa.len(), "{differing} of {} pixels differ", pa.len());
    assert!((mean(pa) / mean(pb) - 1.0).abs() < 1e-3, "means {} and {}", mean(pa), mean(pb));
    assert!(pa.iter().any(|p| p.x < 0.9) && pa.iter().any(|p| p.x >= 0.99), "cubes against the sky");
}
