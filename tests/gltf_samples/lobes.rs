//! The lobe test models: ClearCoatTest (`KHR_materials_clearcoat`: rows of spheres with coat
//! factors, roughnesses, textures and coat normal maps) renders as its golden, lit by a uniform
//! sky and seen by a camera framing its bounds, and its coat is really there: the same render
//! with every coat removed fails against the golden.

use super::sample;
use crate::common::golden::{Sampled, check_golden};
use crate::common::*;
use glam::{UVec2, Vec3};
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::job::SceneSetup;
use tracer::lens::LensChain;
use tracer::scene::Scene;
use tracer::test_support::compare::StatTest;

const SIZE: UVec2 = UVec2::new(96, 72);
const SPP: u32 = 64;

/// Sample model `name` under a uniform white sky, with a camera framing its bounds from the front.
fn lit(name: &str) -> (Scene, CameraDesc) {
    let setup = SceneSetup { sky: Some(Vec3::splat(1.0)), ..SceneSetup::default() };
    let scene = setup.load(&sample(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (lo, hi) = scene.bounds().expect("geometry");
    let (centre, radius) = ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(1e-3));
    let from = centre + Vec3::new(0.0, 0.0, 1.0) * radius * 1.6;
    let camera =
        CameraDesc::look_at("front", from, centre, Vec3::Y, Projection::Perspective { fov_y: 0.8 }).unwrap();
    (scene, camera)
}

fn renderer(scene: &Scene, camera: &CameraDesc) -> impl Fn(u32, u32) -> Sampled {
    let tracer = PathTracer::new(scene, IntegratorConfig::DEFAULT).expect("prepare");
    let camera = camera.clone();
    move |spp, seed| {
        let job = Job { resolution: SIZE, spp, seed, config: IntegratorConfig::DEFAULT };
        Sampled::from_rendered(render_prepared(&tracer, &camera, &mut LensChain::new(), job), spp)
    }
}

#[test]
fn clearcoat_test_model() {
    let (mut scene, camera) = lit("ClearCoatTest");
    assert!(scene.materials.iter().filter(|m| m.coat > 0.0).count() >= 6, "the coated spheres");
    assert!(scene.materials.iter().any(|m| m.textures.coat_normal.is_some()), "a coat normal map");
    let (_, golden, _) = check_golden(
        "sample-ClearCoatTest",
        "ClearCoatTest.gltf, front, sky 1",
        SPP,
        renderer(&scene, &camera),
    );
    // Without its coats the model is another picture.
    for m in &mut scene.materials {
        m.coat = 0.0;
    }
    let bare = renderer(&scene, &camera)(SPP, 1);
    let report = StatTest::default().between(bare.estimate(), golden.estimate());
    assert!(!report.passed(), "ClearCoatTest without its coats passes as the golden:\n{report}");
}
