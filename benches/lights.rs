//! The light tree against choosing lights by power alone (docs/performance.md, ledger: "light
//! tree"), at equal samples per pixel: error does not depend on machine load, so this needs no
//! quiet machine; cost per sample is counted separately with callgrind (below).
//!
//! `cargo bench -p mcctrace-suite --bench lights` renders, with each light choice and seeds 1
//! and 2 (default integrator settings, box filter):
//!
//! - the café (`scenes/cafe/cafe.gltf`), camera `wide` at 240×135 and 64 spp, `left` and
//!   `right` at 480×270 and 16 spp. Its error is the variance part of relMSE from two seeds:
//!   the mean over pixels and channels of (a − b)² / 2 / (r² + 0.01), r the mean of all four
//!   renders of the view (the same r for both choices; both are unbiased);
//! - the Cornell box (256², at most 4 vertices, 64 spp) against the Mitsuba 3 reference,
//!   relMSE averaged over the two seeds;
//!
//! and prints per view and choice: seconds per render (wall, noisy on a shared machine),
//! relMSE, their product, and the tree's relMSE ratio against power.
//!
//! `LIGHTS_ONE=VIEW,CHOICE,SPP` (VIEW `wide`, `left`, `right` or `cornell`; CHOICE `tree` or
//! `power`) renders that view once on one thread and exits: run it under
//! `valgrind --tool=callgrind` for instructions per sample.

use glam::UVec2;
use std::path::{Path, PathBuf};
use tracer::image::RgbImage;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::light::LightChoice;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{CameraSelector, Scene};
use tracer::test_support::compare::{rel_mse, two_seed_rel_mse};

/// A view of a scene and how it is measured.
struct View {
    name: &'static str,
    scene: &'static str,
    camera: &'static str,
    size: UVec2,
    spp: u32,
    config: IntegratorConfig,
}

const VIEWS: [View; 4] = [
    View {
        name: "wide",
        scene: "scenes/cafe/cafe.gltf",
        camera: "wide",
        size: UVec2::new(240, 135),
        spp: 64,
        config: IntegratorConfig::DEFAULT,
    },
    View {
        name: "left",
        scene: "scenes/cafe/cafe.gltf",
        camera: "left",
        size: UVec2::new(480, 270),
        spp: 16,
        config: IntegratorConfig::DEFAULT,
    },
    View {
        name: "right",
        scene: "scenes/cafe/cafe.gltf",
        camera: "right",
        size: UVec2::new(480, 270),
        spp: 16,
        config: IntegratorConfig::DEFAULT,
    },
    View {
        name: "cornell",
        scene: "scenes/cornell/cornell.gltf",
        camera: "cornell",
        size: UVec2::new(256, 256),
        spp: 64,
        config: IntegratorConfig::DEFAULT.with_max_depth(4),
    },
];

/// Renders `view` with the light tree or by power; (image, seconds).
fn render_view(root: &Path, view: &View, by_power: bool, spp: u32, seed: u32) -> (RgbImage, f64) {
    let scene = Scene::load(&root.join(view.scene)).expect("load the scene");
    let camera = scene.camera(&CameraSelector::Name(view.camera.into())).expect("the camera");
    let camera = camera.build(view.size).expect("build the camera");
    let choice = if by_power { LightChoice::Power } else { LightChoice::Tree };
    let tracer =
        PathTracer::new(&scene, view.config).expect("prepare the scene").with_light_choice(choice, &scene);
    let settings = RenderSettings { seed, ..RenderSettings::still(spp) };
    let r = render(&tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress).expect("render");
    assert_eq!(r.stats.nonfinite_samples, 0, "{}: NaN/Inf samples", view.name);
    (r.images.image, r.stats.seconds)
}

fn mean(images: &[&RgbImage]) -> RgbImage {
    let mut m = RgbImage::new(images[0].width, images[0].height);
    for (k, p) in m.pixels.iter_mut().enumerate() {
        *p = images.iter().map(|i| i.pixels[k]).sum::<glam::Vec3>() / images.len() as f32;
    }
    m
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    if let Ok(one) = std::env::var("LIGHTS_ONE") {
        let parts: Vec<&str> = one.split(',').collect();
        let [name, choice, spp] = parts[..] else { panic!("LIGHTS_ONE=VIEW,CHOICE,SPP") };
        let view = VIEWS.iter().find(|v| v.name == name).expect("a view: wide, left, right, cornell");
        let spp = spp.parse().expect("spp");
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a pool");
        let (_, seconds) = pool.install(|| render_view(&root, view, choice == "power", spp, 1));
        println!("{name} {choice} {spp} spp: {seconds:.3} s");
        return;
    }
    let reference =
        tracer::image_io::read_exr_rgb(&root.join("tests/data/cornell/reference-mitsuba3-16384spp.exr"))
            .expect("read the Mitsuba reference");
    println!(
        "{} threads; seconds are wall time per render, relMSE at equal spp",
        rayon::current_num_threads()
    );
    println!(
        "{:>8} {:>6} {:>5} {:>9} {:>11} {:>13}",
        "view", "choice", "spp", "seconds", "relMSE", "s × relMSE"
    );
    for view in &VIEWS {
        // [choice][seed]: power first, then the tree.
        let renders: Vec<Vec<(RgbImage, f64)>> = [true, false]
            .iter()
            .map(|&by_power| {
                [1, 2].iter().map(|&seed| render_view(&root, view, by_power, view.spp, seed)).collect()
            })
            .collect();
        let all: Vec<&RgbImage> = renders.iter().flatten().map(|(i, _)| i).collect();
        let r = mean(&all);
        let mut errors = [0.0; 2];
        for (k, (choice, pair)) in ["power", "tree"].iter().zip(&renders).enumerate() {
            let error = if view.name == "cornell" {
                0.5 * (rel_mse(&pair[0].0, &reference) + rel_mse(&pair[1].0, &reference))
            } else {
                two_seed_rel_mse(&pair[0].0, &pair[1].0, &r)
            };
            let seconds = 0.5 * (pair[0].1 + pair[1].1);
            errors[k] = error;
            println!(
                "{:>8} {choice:>6} {:>5} {seconds:>9.3} {error:>11.4e} {:>13.4e}",
                view.name,
                view.spp,
                seconds * error
            );
        }
        println!("{:>8} relMSE tree / power: {:.3}", view.name, errors[1] / errors[0]);
    }
}
