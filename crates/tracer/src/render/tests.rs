//! Unit tests of the tile renderer: Lambert fast path, split branches, adaptive counts, CPU
//! dispatch and cancellation.

use super::*;
use crate::camera::{CameraDesc, CameraSample, Projection};
use crate::integrator::IntegratorConfig;
use crate::material::{AlphaMode, Material};
use crate::scene::{MeshPart, Scene};
use glam::Vec3;
use std::sync::atomic::Ordering;

/// A quad (two triangles) with corner `o` and edges `u`, `v`.
fn quad(scene: &mut Scene, o: Vec3, u: Vec3, v: Vec3, material: u32) {
    let positions = [o, o + u, o + u + v, o + v];
    let indices = [0, 1, 2, 0, 2, 3];
    let part =
        MeshPart { positions: &positions, normals: None, uvs: None, indices: Some(&indices), material };
    scene.mesh.push(part).unwrap();
}

/// Every kind of vertex the integrator has: diffuse, rough metal, glass, alpha-blended,
/// one-sided emitter, and a constant environment seen through the open side.
fn scene(alpha: bool) -> Scene {
    let mut scene = Scene::default();
    let mut light = Material::diffuse("light", Vec3::ZERO);
    light.emission = Vec3::new(8.0, 6.0, 3.0);
    let mut metal = Material::diffuse("metal", Vec3::new(0.9, 0.6, 0.3));
    (metal.metallic, metal.roughness) = (1.0, 0.3);
    let mut glass = Material::diffuse("glass", Vec3::ONE);
    (glass.transmission, glass.roughness, glass.ior) = (1.0, 0.0, 1.5);
    let mut veil = Material::diffuse("veil", Vec3::new(0.2, 0.5, 0.8));
    if alpha {
        (veil.alpha, veil.alpha_mode) = (0.5, AlphaMode::Blend);
    }
    scene.materials = vec![Material::diffuse("white", Vec3::splat(0.7)), light, metal, glass, veil];
    scene.environment.color = Vec3::new(0.1, 0.2, 0.3);
    quad(&mut scene, Vec3::new(-2.0, 0.0, -2.0), Vec3::X * 4.0, Vec3::Z * 4.0, 0);
    quad(&mut scene, Vec3::new(-0.5, 2.0, -0.5), Vec3::Z, Vec3::X, 1);
    quad(&mut scene, Vec3::new(-1.5, 0.0, 0.5), Vec3::X, Vec3::new(0.3, 1.0, 0.2), 2);
    quad(&mut scene, Vec3::new(0.3, 0.2, -0.5), Vec3::X, Vec3::Y, 3);
    quad(&mut scene, Vec3::new(-1.0, 0.1, -1.0), Vec3::new(0.8, 0.0, 0.5), Vec3::Y, 4);
    scene
}

/// The 40 × 32 perspective view of [`scene`] the bit-for-bit tests render.
fn test_camera() -> Box<dyn Camera> {
    CameraDesc::look_at(
        "c",
        Vec3::new(0.5, 1.2, 4.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 50f32.to_radians() },
    )
    .unwrap()
    .build(UVec2::new(40, 32))
    .unwrap()
}

/// An image's bits, for comparisons that must be exact (NaN-proof, unlike `==` on floats).
fn bits(image: &crate::image::RgbImage) -> Vec<u32> {
    image.pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect()
}

/// [`scene`] with every surface an untextured, opaque Lambertian (the metal, glass and
/// veil made diffuse): a scene for the Lambert-only path.
fn lambert_scene() -> Scene {
    let mut scene = scene(false);
    for m in &mut scene.materials[2..] {
        *m = Material::diffuse(&m.name, m.base_color);
    }
    scene
}

/// The Lambert-only path gives the same bits as the general one (image, variance, AOVs,
/// ray counts, with roulette, adaptive sampling and first-vertex splitting) on a scene of
/// diffuse surfaces, one emitter and a constant environment; it is taken only where every
/// surface is an untextured, flat-shaded Lambertian lit by emissive triangles.
#[test]
fn lambert_path_is_the_general_path_bit_for_bit() {
    let scene = lambert_scene();
    let camera = test_camera();
    let config = IntegratorConfig::DEFAULT.with_rr_depth(2);
    for (settings, split) in [
        (RenderSettings { aovs: true, ..RenderSettings::still(16) }, 1),
        (RenderSettings { adaptive: true, seed: 3, ..RenderSettings::still(8) }, 1),
        (RenderSettings { adaptive: true, aovs: true, seed: 4, ..RenderSettings::still(8) }, 2),
    ] {
        let lambert = PathTracer::new(&scene, config.with_split(split)).unwrap();
        assert!(lambert.lambert_only());
        let general = PathTracer::new(&scene, config.with_split(split)).unwrap().without_lambert_path();
        assert!(!general.lambert_only());
        let run = |tracer: &PathTracer| {
            render(tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap()
        };
        let (a, b) = (run(&lambert), run(&general));
        assert!(a.images.image.pixels.iter().any(|p| p.max_element() > 0.05), "the scene is lit");
        assert_eq!(a.stats.rays, b.stats.rays);
        assert!(bits(&a.images.image) == bits(&b.images.image), "image bits differ");
        assert!(bits(&a.images.variance) == bits(&b.images.variance), "variance bits differ");
        assert!(
            bits(&a.images.albedo) == bits(&b.images.albedo)
                && bits(&a.images.normal) == bits(&b.images.normal)
        );
        assert!(a.images.depth == b.images.depth && a.images.samples == b.images.samples);
    }
    // What the path leaves out, any of which takes a scene off it.
    assert!(!PathTracer::new(&self::scene(false), config).unwrap().lambert_only(), "metal and glass");
    let mut with_normals = scene.clone();
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let normals = [Vec3::Z; 3];
    let part =
        MeshPart { positions: &positions, normals: Some(&normals), uvs: None, indices: None, material: 0 };
    with_normals.mesh.push(part).unwrap();
    assert!(!PathTracer::new(&with_normals, config).unwrap().lambert_only(), "vertex normals");
    let mut textured = scene.clone();
    textured.textures.push(crate::texture::Texture::new("t", 1, 1, vec![glam::Vec4::ONE]));
    textured.materials[0].textures.base_color = Some(crate::texture::TextureRef::new(0));
    assert!(!PathTracer::new(&textured, config).unwrap().lambert_only(), "a texture");
    let mut masked = scene.clone();
    masked.materials[0].alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
    assert!(!PathTracer::new(&masked, config).unwrap().lambert_only(), "an alpha test");
    let mut lamp = scene;
    lamp.lights.push(crate::scene::PunctualLight::Point { position: Vec3::Y, intensity: Vec3::ONE });
    assert!(!PathTracer::new(&lamp, config).unwrap().lambert_only(), "a point light");
}

/// First-vertex splitting resumes every branch at the camera ray's hit. Inside a closed,
/// unlit box with at most 2 scattering vertices, each camera sample traces its own ray once
/// and each of its N branches one continuation (the last vertex takes no BSDF ray, and there
/// is no light to sample): 1 + N rays. A camera ray that misses splits into nothing.
/// Branches take sample indices of their own, so spp × N beyond the sampler's range is
/// refused, with the split named; at the range's edge the render runs.
#[test]
fn split_branches_resume_at_the_first_hit() {
    let mut boxed = Scene::default();
    boxed.materials = vec![Material::diffuse("white", Vec3::splat(0.5))];
    let (o, x, y, z) = (Vec3::splat(-1.0), Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0);
    for (corner, u, v) in [
        (o, y, x),
        (o, x, z),
        (o, z, y),
        (o + x + y + z, -x, -y),
        (o + x + y + z, -y, -z),
        (o + x + y + z, -z, -x),
    ] {
        quad(&mut boxed, corner, u, v, 0);
    }
    let camera = CameraDesc::look_at(
        "inside",
        Vec3::ZERO,
        Vec3::new(0.2, 0.1, -1.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 60f32.to_radians() },
    )
    .unwrap();
    let inside = camera.build(UVec2::new(8, 6)).unwrap();
    let config = IntegratorConfig::DEFAULT.with_max_depth(2);
    for split in [1, 2, 5] {
        let tracer = PathTracer::new(&boxed, config.with_split(split)).unwrap();
        let r =
            render(&tracer, inside.as_ref(), &mut LensChain::new(), &RenderSettings::still(4), &NoProgress)
                .unwrap();
        assert_eq!(r.stats.samples, 8 * 6 * 4);
        assert_eq!(r.stats.rays, r.stats.samples * (1 + split as u64), "split {split}");
    }
    // Roulette judges a branch against its own first throughput, in which its 1/N is too: at
    // the first vertex every branch goes on (β / β₁ = 1), at the second it survives with
    // probability √(albedo) = √½ whatever N (with the 1/N in a rule on β alone, far less: the
    // split undone). Three vertices, the last by light sampling alone: a sample traces the
    // camera ray, N branch rays, and N·√½ rays from the second vertex.
    let tracer = PathTracer::new(&boxed, config.with_max_depth(3).with_rr_depth(1).with_split(4)).unwrap();
    let r = render(&tracer, inside.as_ref(), &mut LensChain::new(), &RenderSettings::still(64), &NoProgress)
        .unwrap();
    let per_sample = r.stats.rays as f64 / r.stats.samples as f64;
    let expected = 1.0 + 4.0 + 4.0 * 0.5f64.sqrt();
    assert!(
        (per_sample - expected).abs() < 0.1,
        "{per_sample} rays per sample with roulette, not {expected}"
    );
    // The camera outside the box, looking away: every camera ray misses.
    let away = CameraDesc::look_at(
        "away",
        Vec3::Z * 5.0,
        Vec3::Z * 6.0,
        Vec3::Y,
        Projection::Perspective { fov_y: 30f32.to_radians() },
    )
    .unwrap()
    .build(UVec2::new(4, 4))
    .unwrap();
    let tracer = PathTracer::new(&boxed, config.with_split(4)).unwrap();
    let r = render(&tracer, away.as_ref(), &mut LensChain::new(), &RenderSettings::still(2), &NoProgress)
        .unwrap();
    assert_eq!(r.stats.rays, r.stats.samples);

    let one = camera.build(UVec2::new(1, 1)).unwrap();
    let tracer = PathTracer::new(&boxed, config.with_split(4)).unwrap();
    let too_many = RenderSettings::still(MAX_SAMPLES_PER_PIXEL / 4 + 1);
    let err = render(&tracer, one.as_ref(), &mut LensChain::new(), &too_many, &NoProgress).unwrap_err();
    assert!(err.to_string().contains("4 paths split"), "{err}");
    for adaptive in [false, true] {
        let most = RenderSettings { adaptive, ..RenderSettings::still(MAX_SAMPLES_PER_PIXEL / 4) };
        let r = render(&tracer, one.as_ref(), &mut LensChain::new(), &most, &NoProgress).unwrap();
        assert_eq!(r.stats.samples, (MAX_SAMPLES_PER_PIXEL / 4) as u64);
    }
    for split in [0, MAX_SAMPLES_PER_PIXEL + 1] {
        assert!(PathTracer::new(&boxed, config.with_split(split)).is_err(), "split {split}");
    }
}

/// Adaptive sampling keeps every pixel's count within the sampler's range divided by the
/// split: with 4096 branches per sample, 16 samples a pixel at most, which is the average
/// here, so the noisiest pixels (which would take up to 28) are held to it while the
/// quietest still give theirs up.
#[test]
fn adaptive_counts_stay_in_the_split_range() {
    let scene = lambert_scene();
    let tracer =
        PathTracer::new(&scene, IntegratorConfig::DEFAULT.with_max_depth(2).with_split(4096)).unwrap();
    let camera = CameraDesc::look_at(
        "c",
        Vec3::new(0.5, 1.2, 4.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 50f32.to_radians() },
    )
    .unwrap()
    .build(UVec2::new(6, 5))
    .unwrap();
    let settings = RenderSettings { adaptive: true, ..RenderSettings::still(16) };
    let r = render(&tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress).unwrap();
    let counts = &r.images.samples.pixels;
    let most = counts.iter().fold(0.0f32, |m, &n| m.max(n));
    assert_eq!(most, (MAX_SAMPLES_PER_PIXEL / 4096) as f32, "the cap binds: {counts:?}");
    assert!(counts.iter().all(|&n| n >= 4.0) && counts.iter().any(|&n| n < 10.0), "{counts:?}");
}

/// Every level of the tile loop this CPU runs (x86-64-v3 and -v4 builds) gives the same
/// bits as the baseline one: AOVs and alpha tests on and off, roulette on, and the
/// Lambert-only path. On a CPU without them only the baseline runs, and the test says so.
#[test]
fn cpu_dispatch_does_not_change_a_single_bit() {
    let levels: Vec<cpu::Level> =
        [cpu::Level::V3, cpu::Level::V4].into_iter().filter(|&l| l <= cpu::level()).collect();
    if levels.len() < 2 {
        eprintln!("this CPU runs only the levels {levels:?} beside the baseline");
    }
    let camera = test_camera();
    for (alpha, aovs, lambert) in [(false, false, false), (true, true, false), (false, true, true)] {
        let scene = if lambert { lambert_scene() } else { scene(alpha) };
        let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT.with_rr_depth(2)).unwrap();
        assert_eq!((tracer.has_alpha(), tracer.lambert_only()), (alpha, lambert));
        let settings = RenderSettings { aovs, ..RenderSettings::still(16) };
        let run = |cap: cpu::Level| {
            cpu::CAP.store(cap as u8, Ordering::Relaxed);
            let r = render(&tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress);
            cpu::CAP.store(cpu::Level::V4 as u8, Ordering::Relaxed);
            r.unwrap()
        };
        let baseline = run(cpu::Level::Baseline);
        assert!(baseline.images.image.pixels.iter().any(|p| p.max_element() > 0.05), "the scene is lit");
        for &level in &levels {
            let r = run(level);
            let what = format!("{level:?}, alpha {alpha}, Lambert {lambert}");
            assert_eq!(r.stats.rays, baseline.stats.rays, "{what}: ray counts differ");
            assert!(bits(&r.images.image) == bits(&baseline.images.image), "{what}: image bits differ");
            assert!(
                bits(&r.images.variance) == bits(&baseline.images.variance),
                "{what}: variance bits differ"
            );
            assert!(r.images.albedo == baseline.images.albedo && r.images.depth == baseline.images.depth);
        }
    }
}

/// Cancels once the first tile is done.
struct CancelAfterFirstTile(std::sync::atomic::AtomicBool);

impl Progress for CancelAfterFirstTile {
    fn advance(&self, _samples: u64) {
        self.0.store(true, Ordering::Relaxed);
    }
    fn cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// Counts its tear-downs (a stand-in for the lens writer, which writes its file there).
struct TearDowns(std::sync::Arc<std::sync::atomic::AtomicU32>);

impl crate::lens::LensShader for TearDowns {
    fn name(&self) -> &str {
        "tear-downs"
    }
    fn shade(&self, _sample: &CameraSample, ray: crate::ray::Ray) -> Option<crate::ray::Ray> {
        Some(ray)
    }
    fn end_frame(&mut self, _ctx: &crate::lens::FrameContext<'_>) -> Result<(), crate::error::LensError> {
        self.0.fetch_add(1, Ordering::Relaxed);
        Ok(())
    }
}

/// A cancelled render stops early with `Cancelled`, uniform or adaptive, and skips the
/// lens chain's tear-down (so a lens writer writes nothing); one that is not cancelled
/// tears down once.
#[test]
fn cancelled_renders_stop_with_an_error() {
    let scene = scene(false);
    let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).unwrap();
    let camera = test_camera();
    let count = std::sync::Arc::new(std::sync::atomic::AtomicU32::new(0));
    let mut lenses = LensChain::new();
    lenses.push(Box::new(TearDowns(count.clone())));
    for settings in [RenderSettings::still(4), RenderSettings { adaptive: true, ..RenderSettings::still(8) }]
    {
        let cancel = CancelAfterFirstTile(std::sync::atomic::AtomicBool::new(false));
        let err = render(&tracer, camera.as_ref(), &mut lenses, &settings, &cancel).unwrap_err();
        assert!(matches!(err, TracerError::Cancelled), "{err}");
    }
    assert_eq!(count.load(Ordering::Relaxed), 0);
    render(&tracer, camera.as_ref(), &mut lenses, &RenderSettings::still(4), &NoProgress).unwrap();
    assert_eq!(count.load(Ordering::Relaxed), 1);
}
