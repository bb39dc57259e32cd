//! Test helpers: a deterministic generator, scratch directories and synthetic views (tests only).

use crate::ray_file::{RayFile, StoredRay};
use glam::Vec3;
use std::path::PathBuf;

/// The deterministic generator of test inputs: the tracer's one (same SplitMix64 streams).
pub use tracer::test_support::Rng;

/// A fresh, empty scratch directory unique to this process and `name`.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mcc-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// A pinhole-like view: camera `id` at its own position, looking along its own axis.
pub fn view(id: u32, w: u32, h: u32) -> RayFile {
    let eye = Vec3::new(id as f32, -(id as f32) * 0.5, 2.0 * id as f32);
    let forward = if id.is_multiple_of(2) { Vec3::Z } else { -Vec3::Z }; // even and odd cameras face each other
    let rays = (0..w * h)
        .map(|p| {
            let (x, y) = ((p % w) as f32 + 0.5, (p / w) as f32 + 0.5);
            let d = forward + Vec3::new(x / w as f32 - 0.5, 0.5 - y / h as f32, 0.0) * 0.8;
            StoredRay::new(eye, d.normalize())
        })
        .collect();
    RayFile::new(w, h, 5, id, rays).unwrap()
}

/// A scene that shows nothing but a constant sky of radiance `sky` (one small triangle far
/// behind every test camera keeps the BVH non-empty).
pub fn sky_scene(sky: Vec3) -> tracer::scene::Scene {
    let mut scene = tracer::scene::Scene {
        materials: vec![tracer::material::Material::diffuse("far", Vec3::splat(0.5))],
        environment: tracer::scene::Environment { color: sky },
        ..Default::default()
    };
    let positions = [Vec3::new(0.0, 0.0, 100.0), Vec3::new(1.0, 0.0, 100.0), Vec3::new(0.0, 1.0, 100.0)];
    let part = tracer::scene::MeshPart {
        positions: &positions,
        normals: None,
        uvs: None,
        indices: None,
        material: 0,
    };
    scene.mesh.push(part).unwrap();
    scene
}

/// A perspective camera at the origin looking down −Z at `res`.
pub fn forward_camera(res: glam::UVec2) -> Box<dyn tracer::camera::Camera> {
    let projection = tracer::camera::Projection::Perspective { fov_y: 0.8 };
    tracer::camera::CameraDesc::look_at("forward", Vec3::ZERO, -Vec3::Z, Vec3::Y, projection)
        .unwrap()
        .build(res)
        .unwrap()
}

/// Step 3's weights by the product formula of docs/design/mcc.md §5.3 as written, in f64:
/// g_i = d_i / Σ d, v_i = (1 − g_i)·Π_{j≠i} g_j, α_i = v_i / Σ v. The oracle of
/// [`crate::remap::weights::interpolation_weights`], which avoids the product: it underflows
/// (to 0/0, NaN) for a few thousand cameras, but not for 63 at the distances the tests use.
pub fn weights_by_product(d: &[f64]) -> Vec<f64> {
    let total: f64 = d.iter().sum();
    let g: Vec<f64> = d.iter().map(|x| x / total).collect();
    let v: Vec<f64> = (0..d.len())
        .map(|i| (1.0 - g[i]) * (0..d.len()).filter(|&j| j != i).map(|j| g[j]).product::<f64>())
        .collect();
    let sum: f64 = v.iter().sum();
    v.iter().map(|x| x / sum).collect()
}
