//! No NaN or infinite sample anywhere (docs/testing.md §4: grazing directions
//! (cos ≈ 1e-7) and degenerate triangles give no NaN; the film's NaN/Inf count is asserted zero):
//! grazing views of every material under every light type through every camera model,
//! degenerate and zero-area triangles of every material (which must also change nothing),
//! degenerate tangent frames and lying shading normals, denormal and huge coordinates.

use super::scale::{SIZE, SPP, base_all, config, render_job};
use super::scene::{
    Lighting, Model, camera, mat, materials, push_quad, showcase, sky_map, textures, transformed,
};
use crate::common::*;
use glam::{UVec2, Vec2, Vec3, Vec4};
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::PathTracer;
use tracer::lens::LensChain;
use tracer::render::Rendered;
use tracer::scene::{Environment, Mesh, MeshPart, PunctualLight, Scene};
use tracer::test_support::Rng;
use tracer::test_support::compare::StatTest;

/// What is wrong with a render's numbers (NaN/Inf samples counted by the film, or a non-finite
/// pixel or variance), if anything.
fn nonfinite(what: &str, r: &Rendered) -> Option<String> {
    let bad_pixels =
        (r.images.image.pixels.iter().chain(&r.images.variance.pixels)).filter(|p| !p.is_finite()).count();
    (r.stats.nonfinite_samples != 0 || bad_pixels != 0).then(|| {
        format!("{what}: {} NaN/Inf samples, {bad_pixels} non-finite pixels", r.stats.nonfinite_samples)
    })
}

fn assert_none(failures: Vec<String>) {
    assert!(
        failures.is_empty(),
        "{} failure(s):\n{}",
        failures.len(),
        failures.iter().take(30).cloned().collect::<Vec<_>>().join("\n")
    );
}

/// Height of the grazing plane: not 0, so hit points carry a real error bound along the normal.
const H: f32 = 1.5;

/// A 2048-wide plane y = H of material `m` (of the stress scene's list; texture coordinates
/// repeat 256 times, tangents explicit on the floor material), lit by `lighting` placed so that
/// light arrives at grazing angles too, with a double-sided emitter standing on it far ahead.
fn grazing_scene(m: u32, lighting: Lighting) -> Scene {
    let mut mesh = Mesh::default();
    let half = 1024.0;
    let (a, b) = (Vec3::X * half, Vec3::Z * -half);
    push_quad(&mut mesh, Vec3::new(0.0, H, 0.0), a, b, m, m == mat::FLOOR);
    for uv in &mut mesh.uvs {
        *uv *= 256.0;
    }
    if matches!(lighting, Lighting::Area | Lighting::All) {
        push_quad(
            &mut mesh,
            Vec3::new(0.25, H + 2.0, -200.0),
            Vec3::X * 3.0,
            Vec3::Y * 2.0,
            mat::EMIT_TWO,
            false,
        );
    }
    let mut scene = Scene { mesh, materials: materials(true), textures: textures(), ..Scene::default() };
    // A light 1e-3 above the plane 150 units ahead: incidence at cos ≈ 1e-5 and below.
    let low = Vec3::new(0.25, H + 1e-3, -150.0);
    let point = PunctualLight::Point { position: low, intensity: Vec3::splat(5e3) };
    let spot = PunctualLight::Spot {
        position: low,
        direction: Vec3::new(0.0, -1e-3, 1.0).normalize(),
        intensity: Vec3::splat(5e3),
        inner_cone: 0.2,
        outer_cone: 0.4,
        falloff: Default::default(),
    };
    // Sunlight at cos = 1e-7 to the plane.
    let sun = PunctualLight::Directional {
        direction: Vec3::new(0.0, -1e-7, 1.0).normalize(),
        irradiance: Vec3::ONE,
    };
    match lighting {
        Lighting::Area => {}
        Lighting::Point => scene.lights = vec![point],
        Lighting::Spot => scene.lights = vec![spot],
        Lighting::Directional => scene.lights = vec![sun],
        Lighting::Sky => scene.environment = Environment { color: Vec3::ONE },
        Lighting::EnvMap => scene.environment_map = Some(sky_map()),
        Lighting::All => {
            scene.lights = vec![point, spot, sun];
            scene.environment_map = Some(sky_map());
        }
    }
    scene.validate().expect("valid grazing scene");
    scene
}

/// Cameras looking along the plane y = H: an orthographic one whose parallel rays meet it at
/// cos = 1e-7 (as in `robustness.rs`), and every model placed 1e-3 above it looking along it
/// (their rows near the horizon meet it at every angle down to 0; the equirectangular camera
/// sees it at all angles, from above and — its lower half — nowhere else).
fn grazing_cameras() -> Vec<(&'static str, CameraDesc)> {
    let from = Vec3::new(0.25, H + 2e-5, 0.0);
    let ortho = look_at(
        from,
        from + Vec3::new(0.0, -1e-4, -1000.0),
        Vec3::Y,
        Projection::Orthographic { half_height: 1e-5 },
    );
    let eye = Vec3::new(0.25, H + 1e-3, 0.0);
    let along = |projection| look_at(eye, eye - Vec3::Z, Vec3::Y, projection);
    vec![
        ("orthographic cos 1e-7", ortho),
        ("perspective", along(Projection::Perspective { fov_y: 0.2 })),
        ("thin lens", along(Projection::ThinLens { fov_y: 0.2, lens_radius: 2e-3, focus_distance: 50.0 })),
        ("fisheye", along(Projection::Fisheye { fov: std::f32::consts::PI })),
        ("equirectangular", along(Projection::Equirectangular)),
    ]
}

#[test]
fn grazing_views_of_every_material_under_every_light_give_no_nan() {
    let cameras = grazing_cameras();
    let mut failures = Vec::new();
    let mut renders = 0;
    for m in 0..mat::COUNT as u32 {
        for lighting in Lighting::EACH.into_iter().chain([Lighting::All]) {
            let scene = grazing_scene(m, lighting);
            let tracer = PathTracer::new(&scene, config()).expect("prepare the grazing scene");
            for (i, (name, cam)) in cameras.iter().enumerate() {
                let job =
                    Job { resolution: UVec2::splat(16), spp: 8, seed: 100 * m + i as u32, config: config() };
                let r = render_prepared(&tracer, cam, &mut LensChain::new(), job);
                renders += 1;
                let what =
                    format!("material '{}' under {lighting:?}, {name}", scene.materials[m as usize].name);
                failures.extend(nonfinite(&what, &r));
            }
        }
    }
    println!("{renders} grazing renders");
    assert_none(failures);
}

/// Degenerate triangles (a point, a repeated vertex, collinear with the middle or an outer
/// vertex, a segment there and back, a sliver of denormal width) of `material`, scattered
/// through the stress scene's volume, with texture coordinates (some collapsed to a point) and
/// vertex normals (some zero, some opposite to each other).
fn push_degenerate(mesh: &mut Mesh, rng: &mut Rng, material: u32, count: usize) {
    let mut positions = Vec::new();
    let inside = |rng: &mut Rng| Vec3::new(rng.range(-2.0, 2.0), rng.range(0.05, 2.3), rng.range(-2.9, 1.0));
    for k in 0..count {
        let (a, b) = (inside(rng), inside(rng));
        positions.extend(match k % 6 {
            0 => [a, a, a],
            1 => [a, a, b],
            2 => [a, b, (a + b) * 0.5],
            3 => [a, b, a + 2.0 * (b - a)],
            4 => [a, b, a],
            _ => [a, b, b + Vec3::new(0.0, 1e-30, 0.0)],
        });
    }
    let uvs: Vec<Vec2> = (0..positions.len())
        .map(|v| if (v / 3) % 2 == 0 { Vec2::splat(0.5) } else { Vec2::new(rng.unit(), rng.unit()) })
        .collect();
    let normals: Vec<Vec3> = (0..positions.len())
        .map(|v| match (v / 3) % 3 {
            0 => Vec3::ZERO,
            1 => rng.direction(),
            _ => {
                if v % 2 == 0 {
                    Vec3::Y
                } else {
                    -Vec3::Y
                }
            }
        })
        .collect();
    let indices: Vec<u32> = (0..positions.len() as u32).collect();
    mesh.push(MeshPart {
        positions: &positions,
        normals: Some(&normals),
        uvs: Some(&uvs),
        indices: Some(&indices),
        material,
    })
    .expect("degenerate part");
}

/// Degenerate triangles of every material, the emitters included, added to the fully lit scene
/// change nothing (statistically, against the unit-scale base render) and give no NaN.
#[test]
fn degenerate_triangles_of_every_material_change_nothing() {
    let mut scene = showcase(Lighting::All);
    let before = scene.mesh.triangle_count();
    let mut rng = Rng::new(91);
    for m in 0..mat::COUNT as u32 {
        push_degenerate(&mut scene.mesh, &mut rng, m, 30);
    }
    scene.validate().unwrap();
    println!("{} degenerate triangles added to {before}", scene.mesh.triangle_count() - before);
    let r = render_job(&scene, &camera(Model::Perspective), 5000);
    let mut failures: Vec<String> = nonfinite("with degenerate triangles", &r).into_iter().collect();
    let report = StatTest::default().between(estimate(&r), estimate(base_all()));
    println!("with degenerate triangles vs without ({SIZE}² × {SPP} spp):\n{report}");
    if !report.passed() {
        failures.push(format!("degenerate triangles changed the image:\n{report}"));
    }
    assert_none(failures);
}

/// Normal mapping with no usable tangent frame (texture coordinates collapsed to a point,
/// tangents parallel to the normal or zero) and shading normals that lie (vertex normals
/// pointing into the surface) give no NaN, through every camera model.
#[test]
fn degenerate_tangent_frames_and_lying_normals_give_no_nan() {
    let mut scene = showcase(Lighting::All);
    let mesh = &mut scene.mesh;
    // Each vertex once (spheres share vertices between triangles), by its material.
    let mut material_of = vec![u32::MAX; mesh.positions.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            material_of[v as usize] = mesh.material_ids[t];
        }
    }
    for (v, &m) in material_of.iter().enumerate() {
        match m {
            mat::BUMPY => mesh.uvs[v] = Vec2::splat(0.5),
            mat::FLOOR => {
                mesh.tangents[v] = if v % 2 == 0 { Vec4::new(0.0, 1.0, 0.0, 1.0) } else { Vec4::ZERO }
            }
            mat::METAL | mat::GLASS | mat::ROUGH => mesh.normals[v] = -mesh.normals[v],
            _ => {}
        }
    }
    scene.validate().unwrap();
    let tracer = PathTracer::new(&scene, config()).unwrap();
    let mut failures = Vec::new();
    for (i, model) in Model::EACH.into_iter().enumerate() {
        let job = Job { resolution: UVec2::splat(SIZE), spp: 16, seed: 6000 + i as u32, config: config() };
        let r = render_prepared(&tracer, &camera(model), &mut LensChain::new(), job);
        failures.extend(nonfinite(&format!("{model:?}"), &r));
    }
    assert_none(failures);
}

/// The fully lit scene at denormal and huge scales and far offsets, through every camera
/// model: the geometry may round to nothing (a 1e-39 scene lives on the denormal grid; 1e30
/// away from the origin every vertex rounds to the same point) and the arithmetic overflows
/// (squared lengths past 3.4e38), but no sample may be NaN or infinite.
#[test]
fn denormal_and_huge_coordinates_give_no_nan() {
    let variants: [(f64, f64); 8] = [
        (1e-39, 0.0),
        (1e-30, 0.0),
        (1e-20, 0.0),
        (1e20, 0.0),
        (1e30, 0.0),
        (1e37, 0.0),
        (1.0, 1e20),
        (1.0, 1e30),
    ];
    let scene = showcase(Lighting::All);
    let mut failures = Vec::new();
    for (i, model) in Model::EACH.into_iter().enumerate() {
        for (k, (scale, offset)) in variants.into_iter().enumerate() {
            let what = format!("{model:?} × {scale:e} + {offset:e}");
            let (s, c) = transformed(&scene, &camera(model), scale, offset);
            let tracer = match PathTracer::new(&s, config()) {
                Ok(t) => t,
                Err(e) => {
                    failures.push(format!("{what}: the scene was refused: {e}"));
                    continue;
                }
            };
            // Below ~1e-36 a scene is smaller than one quantum of the compressed BVH nodes
            // (2^-126): every box holds everything and each ray tests every triangle, ~1000×
            // slower. That is a performance limit, not an error; keep those films tiny.
            let (size, spp) = if scale < 1e-36 { (8, 2) } else { (16, 8) };
            let job = Job {
                resolution: UVec2::splat(size),
                spp,
                seed: 7000 + 10 * i as u32 + k as u32,
                config: config(),
            };
            let r = render_prepared(&tracer, &c, &mut LensChain::new(), job);
            failures.extend(nonfinite(&what, &r));
        }
    }
    assert_none(failures);
}
