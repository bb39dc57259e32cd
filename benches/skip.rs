//! "Skip what the scene doesn't need" (issue: scenes as users author them, item 5): the Cornell
//! box (diffuse, untextured, opaque, flat-shaded) rendered as it is, against the same box
//! dressed so that none of the tracer's shortcuts apply — a white 1×1 texture in every slot, a
//! flat normal map, an alpha test with cut-off 0, per-vertex normals equal to the face normals
//! and a vanishingly small specular lobe. Both render the same image (checked statistically);
//! the difference in samples per second is what the shortcuts save.
//!
//! `cargo bench --bench skip` — timings interleave the two versions (best of several runs each)
//! so load on the shared machine affects both alike.

use glam::{UVec2, Vec3, Vec4};
use std::path::Path;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::material::{AlphaMode, MaterialTextures};
use tracer::render::{NoProgress, RenderSettings, Rendered, render};
use tracer::scene::{CameraSelector, Scene};
use tracer::test_support::compare::{Estimate, StatTest};
use tracer::texture::{Texture, TextureRef};

/// The same scene with every general code path switched on and every value neutral.
fn without_shortcuts(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    let white = s.textures.len() as u32;
    s.textures.push(Texture::new("white", 1, 1, vec![Vec4::ONE]));
    let flat = s.textures.len() as u32;
    s.textures.push(Texture::new("flat normal", 1, 1, vec![Vec4::new(0.5, 0.5, 1.0, 1.0)]));
    for m in &mut s.materials {
        m.textures = MaterialTextures {
            base_color: Some(TextureRef::new(white)),
            metallic_roughness: Some(TextureRef::new(white)),
            emissive: Some(TextureRef::new(white)),
            normal: Some((TextureRef::new(flat), 1.0)),
            ..MaterialTextures::default()
        };
        m.alpha_mode = AlphaMode::Mask { cutoff: 0.0 };
        // A specular lobe too faint to matter: it is evaluated and sampled at every hit.
        m.specular = 1.0;
        m.specular_color = Vec3::splat(1e-6);
    }
    // Vertex normals (and texture coordinates) everywhere: unweld so each equals its face's.
    let mesh = &scene.mesh;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for t in 0..mesh.triangle_count() {
        let c = mesh.corners(t);
        let n = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
        positions.extend(c);
        normals.extend([n; 3]);
    }
    s.mesh.triangles = (0..mesh.triangle_count() as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    s.mesh.uvs = vec![glam::Vec2::ZERO; positions.len()];
    s.mesh.positions = positions;
    s.mesh.normals = normals;
    s
}

fn main() {
    let scene = Scene::load(Path::new("scenes/cornell/cornell.gltf")).expect("bundled Cornell scene");
    let general = without_shortcuts(&scene);
    let config = IntegratorConfig::DEFAULT.with_max_depth(4);
    let fast = PathTracer::new(&scene, config).expect("prepare");
    let slow = PathTracer::new(&general, config).expect("prepare");
    let camera = scene.camera(&CameraSelector::Index(0)).unwrap().build(UVec2::new(256, 256)).unwrap();
    let spp = 16;
    let run = |t: &PathTracer| -> Rendered {
        render(t, camera.as_ref(), &mut LensChain::new(), &RenderSettings::still(spp), &NoProgress).unwrap()
    };
    // Warm up, then interleave.
    run(&fast);
    run(&slow);
    let (mut best_fast, mut best_slow) = (f64::INFINITY, f64::INFINITY);
    let (mut img_fast, mut img_slow) = (None, None);
    for _ in 0..5 {
        let a = run(&fast);
        best_fast = best_fast.min(a.stats.seconds);
        let b = run(&slow);
        best_slow = best_slow.min(b.stats.seconds);
        img_fast = Some(a);
        img_slow = Some(b);
    }
    let (a, b) = (img_fast.unwrap(), img_slow.unwrap());
    let samples = a.stats.samples as f64;
    println!("Cornell 256x256, {spp} spp, max depth 4, best of 5 (interleaved):");
    println!("  with shortcuts    {:7.3} s  {:6.3} M samples/s", best_fast, samples / best_fast / 1e6);
    println!("  without shortcuts {:7.3} s  {:6.3} M samples/s", best_slow, samples / best_slow / 1e6);
    println!("  speed-up          {:7.3}x", best_slow / best_fast);
    let report = StatTest::default().between(
        Estimate { mean: &a.images.image, variance: &a.images.variance, samples: spp },
        Estimate { mean: &b.images.image, variance: &b.images.variance, samples: spp },
    );
    println!("  same image (statistically): {}", if report.passed() { "yes" } else { "NO" });
    println!("{report}");
    assert!(report.passed(), "the two versions must render the same image");
}
