//! The light tree (docs/design/tracer.md §3.3) in a render: the café, lit by a spot light, a ceiling
//! panel and a window of emissive triangles, rendered with lights chosen by the tree and by
//! power alone (the choice before the tree, checked against Mitsuba on the Cornell box), each
//! from its own seed, must agree pixel by pixel and in the image mean (the statistical test of
//! docs/testing.md §2 between two noisy renders). Both estimators are unbiased only if the
//! tree's probabilities for MIS (the emitter a BSDF ray finds, for the vertex it left) are the
//! ones its sampling used: a mismatch shows here as bias on everything lit by the panel and the
//! window.

use crate::common::*;
use glam::UVec2;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::light::LightChoice;
use tracer::scene::{CameraSelector, Scene};
use tracer::test_support::compare::StatTest;

#[test]
fn cafe_with_the_tree_matches_choice_by_power() {
    let scene = Scene::load(&repo_root().join("scenes/cafe/cafe.gltf")).expect("load the café");
    let camera = scene.camera(&CameraSelector::Name("wide".into())).expect("camera 'wide'");
    let job = Job { resolution: UVec2::new(96, 54), spp: 128, seed: 1, config: IntegratorConfig::DEFAULT };
    let tree = PathTracer::new(&scene, job.config).expect("prepare the café");
    let power = PathTracer::new(&scene, job.config)
        .expect("prepare the café")
        .with_light_choice(LightChoice::Power, &scene);
    let a = render_prepared(&tree, camera, &mut LensChain::new(), job);
    let b = render_prepared(&power, camera, &mut LensChain::new(), Job { seed: 2, ..job });
    print_stats("tree", &a);
    print_stats("power", &b);
    assert_eq!(a.stats.nonfinite_samples + b.stats.nonfinite_samples, 0);
    let report = StatTest::default().between(estimate(&a), estimate(&b));
    assert!(report.passed(), "the tree's café differs from power's:\n{report}");
}
