//! Shared instance meshes (issue 39 item 7): SimpleInstancing's 125 cubes rendered three ways
//! in paired rounds: as loaded (the copies share one mesh: the scene's mesh and shading arrays
//! hold it once), with the copies' triangles in the scene's mesh again but the BVH still
//! instancing them (`Scene::with_copies_flattened`, the representation before sharing), and
//! fully flattened (no instances). CPU seconds of the render alone, best and all rounds.
//!
//! `cargo bench --bench instances` (the sample under `../shared/gltf-samples/`).

use glam::{UVec2, Vec3};
use std::path::Path;
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::Scene;

#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

/// CPU seconds to render `scene` (its tracer prepared outside the clock).
fn cpu_of(scene: &Scene, camera: &CameraDesc, spp: u32) -> f64 {
    let tracer = PathTracer::new(scene, IntegratorConfig::DEFAULT).unwrap();
    let built = camera.build(UVec2::new(320, 240)).unwrap();
    let settings = RenderSettings { seed: 1, ..RenderSettings::still(spp) };
    let start = cpu_seconds();
    render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap();
    cpu_seconds() - start
}

fn main() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/gltf-samples/SimpleInstancing/glTF/SimpleInstancing.gltf");
    let mut shared = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    shared.environment.color = Vec3::ONE;
    let instanced = shared.with_copies_flattened();
    let flat = Scene { instances: None, ..instanced.clone() };
    let camera = CameraDesc::look_at(
        "view",
        Vec3::new(22.0, 16.0, 26.0),
        Vec3::splat(5.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 0.7 },
    )
    .unwrap();
    let spp: u32 = std::env::var("INSTANCES_SPP").ok().and_then(|s| s.parse().ok()).unwrap_or(16);
    let rounds: usize = std::env::var("INSTANCES_ROUNDS").ok().and_then(|s| s.parse().ok()).unwrap_or(3);
    let names = ["shared", "instanced (copies in the mesh)", "flattened"];
    let mut times = [Vec::new(), Vec::new(), Vec::new()];
    for _ in 0..rounds {
        for (k, scene) in [&shared, &instanced, &flat].into_iter().enumerate() {
            times[k].push(cpu_of(scene, &camera, spp));
        }
    }
    println!("SimpleInstancing 320x240, {spp} spp, {rounds} rounds (CPU s of the render):");
    for (name, t) in names.iter().zip(&times) {
        let best = t.iter().copied().fold(f64::INFINITY, f64::min);
        println!("  {name:32} best {best:.3}  all {t:.3?}");
    }
}
