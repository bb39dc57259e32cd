//! The golden-image regression suite (issue 6 item 1; docs/testing.md §2): every bundled scene and
//! camera, each camera model, and an in-between MCC frame rendered through the lens reader, at
//! small size and modest spp, each compared with its golden EXR in `tests/data/golden/` (converged
//! mean + per-sample variance + spp, ZIP-compressed) by the per-pixel Šidák z-test and the
//! image-level bias check (`common/golden.rs`). The MCC collage rerender's golden is checked by
//! `tests/mcc_pipeline.rs` with the same machinery.
//!
//! Re-bless (prints how each golden changed; a name filter narrows it to some goldens):
//!
//! ```sh
//! UPDATE_GOLDEN=1 cargo test --release -p mcctrace-suite --test suite -- golden:: --nocapture
//! ```
//!
//! What would fail: any change of the expected image beyond noise — light transport, materials,
//! textures, camera models, scene loading, the in-betweener or lens reader — as soon as it moves
//! enough pixels or a channel's mean by 5 standard errors. NaN/Inf samples fail outright. Every
//! test prints the smallest global gain error its bias check can see; where that is well under 2 %
//! by design (Cornell glTF front view, OBJ corner view, orthographic, equirectangular, café left
//! and wide, and the collage in `mcc_pipeline.rs`) the test also proves it: the same render made
//! 2 % darker must fail against the same golden.

use crate::common::golden::{
    Sampled, assert_darker_fails, check_golden, golden_path, read_golden, write_golden,
};
use crate::common::*;
use glam::{UVec2, Vec3};
use std::f32::consts::PI;
use std::sync::{Arc, OnceLock};
use tracer::camera::{CameraDesc, CameraSample, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::scene::{CameraSelector, Scene};
use tracer::test_support::Rng;

/// Cornell renders: 48² at 256 spp (590k samples). Where the light is not in view, a 2 % gain
/// error is a ≈ 20σ shift of the mean. Where it is, the pixels straddling its edge (samples of 17
/// and of 0.5: per-sample variance ≈ 70) dominate the bias check's noise, and 256 spp can only
/// see ≈ 2.5 %; the front view gets [`CORNELL_FRONT_SPP`] for the 2 % power test.
const CORNELL_SIZE: UVec2 = UVec2::new(48, 48);
const CORNELL_SPP: u32 = 256;
const CORNELL_FRONT_SPP: u32 = 512;
/// Café renders: 16:9 like its cameras.
const CAFE_SIZE: UVec2 = UVec2::new(64, 36);
const CAFE_SPP: u32 = 256;

/// The Cornell glTF scene, prepared once per test binary.
fn cornell() -> &'static (Scene, PathTracer) {
    static CORNELL: OnceLock<(Scene, PathTracer)> = OnceLock::new();
    CORNELL.get_or_init(|| {
        let (scene, _) = cornell_gltf();
        let tracer = PathTracer::new(&scene, cornell_config()).expect("prepare the Cornell box");
        (scene, tracer)
    })
}

/// The café (361k triangles): loaded and its BVH built once per test binary, not per camera.
fn cafe() -> &'static (Scene, PathTracer) {
    static CAFE: OnceLock<(Scene, PathTracer)> = OnceLock::new();
    CAFE.get_or_init(|| {
        timed("load and prepare the café", || {
            let scene = Scene::load(&repo_root().join("scenes/cafe/cafe.gltf")).expect("load cafe.gltf");
            let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).expect("prepare the café");
            (scene, tracer)
        })
    })
}

/// A `render(spp, seed)` closure for `check_golden`: `camera` at `size` through `tracer`.
fn plain<'a>(
    tracer: &'a PathTracer,
    camera: &'a CameraDesc,
    size: UVec2,
) -> impl Fn(u32, u32) -> Sampled + 'a {
    move |spp, seed| {
        let job = Job { resolution: size, spp, seed, config: cornell_config() };
        Sampled::from_rendered(render_prepared(tracer, camera, &mut LensChain::new(), job), spp)
    }
}

/// Checks golden `name` (it prints the smallest gain error its bias check can see).
fn golden(name: &str, what: &str, spp: u32, render: impl Fn(u32, u32) -> Sampled) {
    check_golden(name, what, spp, render);
}

/// Checks golden `name` and that the same render 2 % darker fails: for the views whose test has
/// that power by design (a detectable gain error well under 2 %).
fn golden_with_power(name: &str, what: &str, spp: u32, render: impl Fn(u32, u32) -> Sampled) {
    let (test, golden, _) = check_golden(name, what, spp, render);
    assert_darker_fails(name, &test, &golden);
}

/// The camera list bundled with the OBJ Cornell box.
fn cornell_camera_list() -> Vec<CameraDesc> {
    tracer::scene::camera_list::load(&cornell_dir().join("cameras.json")).expect("load cameras.json")
}

#[test]
fn cornell_gltf_camera() {
    let (_, tracer) = cornell();
    let (_, camera) = cornell_gltf();
    golden_with_power(
        "cornell-gltf",
        "cornell.gltf, camera 'cornell'",
        CORNELL_FRONT_SPP,
        plain(tracer, &camera, CORNELL_SIZE),
    );
}

#[test]
fn cornell_obj_corner_camera() {
    // The OBJ directory (its own loader, MTL materials) through the second camera of the
    // camera-list file, so both the format and the camera file are covered.
    let (scene, _) = cornell_obj();
    let tracer = PathTracer::new(&scene, cornell_config()).expect("prepare the OBJ box");
    let camera = cornell_camera_list().into_iter().find(|c| c.name == "corner").expect("camera 'corner'");
    golden_with_power(
        "cornell-obj-corner",
        "scenes/cornell OBJ, cameras.json 'corner'",
        CORNELL_SPP,
        plain(&tracer, &camera, CORNELL_SIZE),
    );
}

/// Where the Cornell README's camera stands and looks.
const EYE: Vec3 = Vec3::new(2.78, 2.73, -8.0);
const TARGET: Vec3 = Vec3::new(2.78, 2.73, 0.0);
/// The middle of the box (it spans 0 … 5.56 in x and z, 0 … 5.49 in y).
const INSIDE: Vec3 = Vec3::new(2.78, 2.74, 2.8);

#[test]
fn cornell_orthographic() {
    let (_, tracer) = cornell();
    let camera = look_at(EYE, TARGET, Vec3::Y, Projection::Orthographic { half_height: 2.9 });
    golden_with_power(
        "cornell-orthographic",
        "Cornell glTF, orthographic",
        CORNELL_SPP,
        plain(tracer, &camera, CORNELL_SIZE),
    );
}

#[test]
fn cornell_thin_lens() {
    let (_, tracer) = cornell();
    // Focused on the short box (8.7 … 10.7 from the eye), with an aperture wide enough to blur
    // the back wall (13.6 away) by several pixels.
    let projection =
        Projection::ThinLens { fov_y: 39.3f32.to_radians(), lens_radius: 0.25, focus_distance: 9.5 };
    let camera = look_at(EYE, TARGET, Vec3::Y, projection);
    // The light is in view: the bias check sees ≈ 2.5 % (printed), the per-pixel test far less.
    golden("cornell-thin-lens", "Cornell glTF, thin lens", CORNELL_SPP, plain(tracer, &camera, CORNELL_SIZE));
}

#[test]
fn cornell_fisheye() {
    let (_, tracer) = cornell();
    // From just inside the open front, 180° across: the whole box, and dropped samples (black)
    // outside the image circle. The light is in view (bias check ≈ 2.3 %, printed).
    let camera = look_at(
        Vec3::new(2.78, 2.74, 0.3),
        Vec3::new(2.78, 2.74, 5.0),
        Vec3::Y,
        Projection::Fisheye { fov: PI },
    );
    golden(
        "cornell-fisheye",
        "Cornell glTF, 180° fisheye",
        CORNELL_SPP,
        plain(tracer, &camera, CORNELL_SIZE),
    );
}

#[test]
fn cornell_equirectangular() {
    let (_, tracer) = cornell();
    let camera = look_at(INSIDE, INSIDE + Vec3::Z, Vec3::Y, Projection::Equirectangular);
    golden_with_power(
        "cornell-equirectangular",
        "Cornell glTF, equirectangular from the middle of the box",
        CORNELL_SPP,
        plain(tracer, &camera, UVec2::new(64, 32)),
    );
}

/// Café camera `name`; `power`: also require that a 2 % darker render fails.
fn cafe_camera(name: &str, power: bool) {
    let (scene, tracer) = cafe();
    let camera = scene.camera(&CameraSelector::Name(name.into())).expect("café camera").clone();
    let (name, what) = (format!("cafe-{name}"), format!("cafe.gltf, camera '{name}'"));
    let render = plain(tracer, &camera, CAFE_SIZE);
    if power {
        golden_with_power(&name, &what, CAFE_SPP, render)
    } else {
        golden(&name, &what, CAFE_SPP, render)
    }
}

#[test]
fn cafe_left() {
    // The bright window (sky seen directly, near-zero variance) fails pixel by pixel at 2 %.
    cafe_camera("left", true);
}

#[test]
fn cafe_right() {
    // No window in view (the sky, seen directly and noiseless, is what fails cafe-left and
    // cafe-wide pixel by pixel at 2 %), and at 256 spp the bias check sees ≈ 4.5 % (printed);
    // 2 % would need ≈ 5× the samples, for this test and its golden.
    cafe_camera("right", false);
}

#[test]
fn cafe_wide() {
    cafe_camera("wide", true);
}

/// The rays a lens writer would record for `camera` at `size`: one per pixel centre.
fn key_rays(camera: &CameraDesc, size: UVec2, frame: u32, id: u32) -> mcc::RayFile {
    let built = camera.build(size).expect("build the key camera");
    let rays = (0..size.y)
        .flat_map(|j| (0..size.x).map(move |i| (i, j)))
        .map(|(i, j)| {
            let ray = built.generate_ray(&CameraSample::pixel_centre(i, j, 0.0)).expect("a pinhole ray");
            mcc::StoredRay::new(ray.origin, ray.direction)
        })
        .collect();
    mcc::RayFile::new(size.x, size.y, frame, id, rays).expect("key ray file")
}

#[test]
fn inbetween_frame_through_the_lens_reader() {
    // docs/design/workflow.md §7 and §6: keys at frames 0 (the 'cornell' camera) and 8 (the 'corner' camera
    // of the camera list); frame 3 of the smooth in-between is rendered through the lens reader —
    // the MCC rerender path, fed rays that no camera model produces.
    let (scene, tracer) = cornell();
    let size = CORNELL_SIZE;
    let front = scene.camera(&CameraSelector::Name("cornell".into())).expect("camera 'cornell'");
    let corner = cornell_camera_list().into_iter().find(|c| c.name == "corner").expect("camera 'corner'");
    let keys =
        mcc::Keys::new(vec![(0, key_rays(front, size, 0, 1)), (8, key_rays(&corner, size, 8, 2))], None)
            .expect("keys");
    let frame = Arc::new(keys.frame(3, mcc::InbetweenMode::Smooth));
    // The lens reader replaces every ray: the camera only carries the film size.
    let carrier = look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, Projection::Perspective { fov_y: 1.0 });
    let render = |spp, seed| {
        let mut lenses = LensChain::new();
        lenses.push(Box::new(mcc::LensReader::new(mcc::lens_reader::RaySource::Rays(frame.clone()))));
        let job = Job { resolution: size, spp, seed, config: cornell_config() };
        Sampled::from_rendered(render_prepared(tracer, &carrier, &mut lenses, job), spp)
    };
    // The light is in view: the bias check sees ≈ 2.6 % (printed).
    golden(
        "cornell-inbetween-frame3",
        "Cornell glTF, smooth in-between frame 3 of keys 0 and 8",
        CORNELL_SPP,
        render,
    );
}

#[test]
fn golden_files_round_trip_and_stay_compact() {
    // A golden written and read back is the same estimate, bit for bit, spp included.
    let mut rng = Rng::new(7);
    let mut noise = |_| Vec3::new(rng.unit(), rng.unit(), rng.unit());
    let (w, h) = (5, 3);
    let written = Sampled {
        mean: tracer::image::RgbImage { width: w, height: h, pixels: (0..w * h).map(&mut noise).collect() },
        variance: tracer::image::RgbImage {
            width: w,
            height: h,
            pixels: (0..w * h).map(&mut noise).collect(),
        },
        spp: 4096,
        nonfinite_samples: 0,
    };
    let path = std::env::temp_dir().join(format!("mcctrace-golden-round-trip-{}.exr", std::process::id()));
    write_golden(&path, &written, "round trip");
    let read = read_golden(&path).expect("read back");
    let _ = std::fs::remove_file(&path);
    assert!(read.mean == written.mean && read.variance == written.variance && read.spp == 4096);

    // Every stored golden is readable, converged (≥ 1024 spp), finite, and small.
    let dir = golden_path("x").parent().expect("golden directory").to_path_buf();
    let mut total = 0;
    for entry in std::fs::read_dir(&dir).expect("list the goldens") {
        let path = entry.expect("directory entry").path();
        if path.extension().is_none_or(|e| e != "exr") {
            continue;
        }
        let golden = read_golden(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(golden.spp >= 1024, "{}: only {} spp", path.display(), golden.spp);
        assert!(golden.mean.pixels.iter().chain(&golden.variance.pixels).all(|p| p.is_finite()));
        let bytes = std::fs::metadata(&path).expect("golden size").len();
        assert!(bytes < 256 << 10, "{}: {bytes} bytes", path.display());
        total += bytes;
    }
    println!("goldens: {total} bytes in {}", dir.display());
    assert!(total < 2 << 20, "goldens take {total} bytes, over 2 MiB");
}
