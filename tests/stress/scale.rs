//! Scale and offset invariance for every light type and camera model (docs/testing.md §4: "a scene
//! scaled by 10^−4 … 10^4 (lights scaled to match) renders the same image statistically"), and
//! exact invisibility of index-matched glass and cut-out surfaces at every scale (a refracted ray
//! re-hitting its own surface would show).
//!
//! Reference: the same scene at unit scale, rendered with another seed; the comparison is
//! `StatTest::between` (per-pixel Šidák z-test plus the image-level bias check, docs/testing.md
//! §2).

use super::scene::{Lighting, Model, camera, showcase, transformed};
use crate::common::*;
use glam::{UVec2, Vec3};
use std::sync::OnceLock;
use tracer::camera::CameraDesc;
use tracer::integrator::IntegratorConfig;
use tracer::material::{AlphaMode, Material, MaterialTextures};
use tracer::render::Rendered;
use tracer::scene::{Environment, Mesh, MeshPart, Scene};
use tracer::test_support::compare::{Estimate, StatTest};
use tracer::texture::{Texture, TextureRef};

/// Film size and samples of the comparisons: 32² at 64 spp (docs/testing.md §2: N ≥ 64 for the
/// z-test).
pub const SIZE: u32 = 32;
pub const SPP: u32 = 64;

/// Six scattering vertices: enough for light through the glass sphere and back.
pub fn config() -> IntegratorConfig {
    IntegratorConfig::DEFAULT.with_max_depth(6)
}

/// (scale, offset) of every variant compared with the unit-scale render.
const VARIANTS: [(f64, f64); 5] = [(1e-4, 0.0), (1e-2, 0.0), (1e2, 0.0), (1e4, 0.0), (1.0, 1e4)];

pub fn render_job(scene: &Scene, camera: &CameraDesc, seed: u32) -> Rendered {
    let job = Job { resolution: UVec2::splat(SIZE), spp: SPP, seed, config: config() };
    render_plain(scene, camera, job)
}

/// The unit-scale render of the fully lit scene through the perspective camera (shared by the
/// degenerate-triangle test).
pub fn base_all() -> &'static Rendered {
    static BASE: OnceLock<Rendered> = OnceLock::new();
    BASE.get_or_init(|| {
        let r = render_job(&showcase(Lighting::All), &camera(Model::Perspective), 100);
        assert_eq!(r.stats.nonfinite_samples, 0, "NaN/Inf samples in the base render");
        r
    })
}

/// Renders `lighting` through `model` at unit scale and at every variant; returns a line per
/// variant that differs from the unit-scale image (or has NaN/Inf samples).
fn scale_failures(lighting: Lighting, model: Model, seed: u32) -> Vec<String> {
    let (scene, cam) = (showcase(lighting), camera(model));
    let owned;
    let base = if (lighting, model) == (Lighting::All, Model::Perspective) {
        base_all()
    } else {
        owned = render_job(&scene, &cam, seed);
        &owned
    };
    let mut failures = Vec::new();
    if base.stats.nonfinite_samples != 0 {
        failures
            .push(format!("{lighting:?}/{model:?} at unit scale: {} NaN/Inf", base.stats.nonfinite_samples));
    }
    for (i, (scale, offset)) in VARIANTS.into_iter().enumerate() {
        let what = format!("{lighting:?}/{model:?} × {scale:e} + {offset:e}");
        let (s, c) = transformed(&scene, &cam, scale, offset);
        let r = render_job(&s, &c, seed + 1 + i as u32);
        let report = StatTest::default().between(estimate(&r), estimate(base));
        println!(
            "{what}: {:.4} of pixel-channels pass, bias z {:.2?}, {} NaN/Inf",
            report.pass_fraction(),
            report.bias_z,
            r.stats.nonfinite_samples
        );
        maybe_save(&what, &r.images.image);
        if r.stats.nonfinite_samples != 0 {
            failures.push(format!("{what}: {} NaN/Inf samples", r.stats.nonfinite_samples));
        }
        if !report.passed() {
            failures.push(format!("{what} differs from unit scale:\n{report}"));
        }
    }
    failures
}

fn assert_none(failures: Vec<String>) {
    assert!(failures.is_empty(), "{} failure(s):\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn every_light_type_renders_the_same_at_every_scale_and_offset() {
    let mut failures = Vec::new();
    for (i, lighting) in Lighting::EACH.into_iter().enumerate() {
        failures.extend(scale_failures(lighting, Model::Perspective, 1000 + 10 * i as u32));
    }
    assert_none(failures);
}

#[test]
fn every_camera_model_renders_the_same_at_every_scale_and_offset() {
    let mut failures = Vec::new();
    for (i, model) in Model::EACH.into_iter().enumerate() {
        failures.extend(scale_failures(Lighting::All, model, 2000 + 10 * i as u32));
    }
    assert_none(failures);
}

/// The comparison above has power at this size: a unit-scale render of the fully lit scene
/// with a 3 % bias fails against the base, and so does the point light left unscaled at scale
/// 0.98 (the inverse-square law forgotten: 4 % too bright where it lights; measured bias
/// z ≈ 7–9 against the limit 5). Not claimed: a 2 % error in one light's scaling (scaled by s
/// instead of s² at 0.98) gives z ≈ 4–5 at 32² × 64 spp and may pass.
#[test]
fn the_scale_comparison_detects_small_errors() {
    let (scene, cam) = (showcase(Lighting::All), camera(Model::Perspective));
    let r = render_job(&scene, &cam, 3000);
    let same = StatTest::default().between(estimate(&r), estimate(base_all()));
    assert!(same.passed(), "two unit-scale renders disagree:\n{same}");
    let darker = scaled(&r.images.image, 0.97);
    let darker_var = scaled(&r.images.variance, 0.97 * 0.97);
    let biased = StatTest::default()
        .between(Estimate { mean: &darker, variance: &darker_var, samples: SPP }, estimate(base_all()));
    println!("× 0.97:\n{biased}");
    assert!(!biased.passed(), "a 3 % bias went unnoticed at {SIZE}² × {SPP} spp:\n{biased}");

    let point = showcase(Lighting::Point);
    let base = render_job(&point, &cam, 3001);
    let (mut s, c) = transformed(&point, &cam, 0.98, 0.0);
    for light in &mut s.lights {
        if let tracer::scene::PunctualLight::Point { intensity, .. } = light {
            *intensity /= 0.98 * 0.98; // undo the s² the transform applied
        }
    }
    let wrong = render_job(&s, &c, 3002);
    let report = StatTest::default().between(estimate(&wrong), estimate(&base));
    println!("point light not scaled by s² at s = 0.98:\n{report}");
    assert!(!report.passed(), "the point light left unscaled at s = 0.98 went unnoticed:\n{report}");
}

/// An index-matched (ior 1, white) glass sphere, flat-shaded, and a quad whose texture is fully
/// cut out, under a constant sky: both are invisible, so every pixel is exactly the sky colour.
/// With at most 2 scattering vertices a camera path has room for the sphere's front and back
/// faces only: one refracted ray re-hitting its own surface (or hitting the cut-out) ends the
/// path black and the pixel darker. (At eta = 1, Fresnel is exactly 0 except where
/// cos θ < ~3e-4, where f32's 1 − cos² rounds to 1 and it reflects: about 1e-7 of the disc.)
#[test]
fn index_matched_glass_and_cut_outs_are_invisible_at_every_scale() {
    let sky = Vec3::new(0.3, 0.6, 0.9);
    let glass =
        Material { transmission: 1.0, ior: 1.0, roughness: 0.0, ..Material::diffuse("glass", Vec3::ONE) };
    let cut_out = Material {
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        textures: MaterialTextures { base_color: Some(TextureRef::new(0)), ..Default::default() },
        ..Material::diffuse("cut-out", Vec3::ONE)
    };
    let (positions, indices) = icosphere(3, Vec3::new(0.0, 0.5, -1.0), 0.8, false);
    let mut mesh = Mesh::default();
    mesh.push(MeshPart {
        positions: &positions,
        normals: None,
        uvs: None,
        indices: Some(&indices),
        material: 0,
    })
    .unwrap();
    let quad = [
        Vec3::new(-1.5, -0.5, 0.5),
        Vec3::new(1.5, -0.5, 0.5),
        Vec3::new(1.5, 1.5, 0.5),
        Vec3::new(-1.5, 1.5, 0.5),
    ];
    let uvs = [glam::Vec2::ZERO, glam::Vec2::X, glam::Vec2::ONE, glam::Vec2::Y];
    mesh.push(MeshPart {
        positions: &quad,
        normals: None,
        uvs: Some(&uvs),
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material: 1,
    })
    .unwrap();
    let transparent = Texture::new("clear", 2, 2, vec![glam::Vec4::new(1.0, 0.0, 0.0, 0.0); 4]);
    let scene = Scene {
        mesh,
        materials: vec![glass, cut_out],
        textures: vec![transparent],
        environment: Environment { color: sky },
        ..Scene::default()
    };
    scene.validate().unwrap();
    let job = |seed| Job {
        resolution: UVec2::splat(SIZE),
        spp: 16,
        seed,
        config: IntegratorConfig::DEFAULT.with_max_depth(2),
    };
    let mut failures = Vec::new();
    for model in [Model::Perspective, Model::Orthographic, Model::ThinLens] {
        for (i, (scale, offset)) in [(1.0, 0.0)].into_iter().chain(VARIANTS).enumerate() {
            let (s, c) = transformed(&scene, &camera(model), scale, offset);
            let r = render_plain(&s, &c, job(4000 + i as u32));
            // A pixel's samples are all exactly `sky` or the path was cut short (≤ 15/16 of it).
            let wrong =
                r.images.image.pixels.iter().filter(|p| (**p - sky).abs().max_element() > 1e-6).count();
            if wrong > 0 || r.stats.nonfinite_samples > 0 {
                let darkest =
                    r.images.image.pixels.iter().map(|p| p.min_element()).fold(f32::INFINITY, f32::min);
                failures.push(format!(
                    "{model:?} × {scale:e} + {offset:e}: {wrong} pixels are not the sky (darkest channel \
                     {darkest}), {} NaN/Inf",
                    r.stats.nonfinite_samples
                ));
            }
        }
    }
    assert_none(failures);
}
