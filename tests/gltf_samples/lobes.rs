//! The lobe test models: ClearCoatTest (`KHR_materials_clearcoat`: rows of spheres with coat
//! factors, roughnesses, textures and coat normal maps) renders as its golden, lit by a uniform
//! sky and seen by a camera framing its bounds, and its coat is really there: the same render
//! with every coat removed fails against the golden. SheenCloth (`KHR_materials_sheen`, colour
//! and roughness from one texture, tiled by `KHR_texture_transform`) likewise, without a "not
//! supported" warning, and the same render without its sheen fails.
//! AnisotropyStrengthTest (`KHR_materials_anisotropy`) likewise, lit by a point light beside the
//! camera whose highlights the anisotropy stretches (a uniform sky shows none of it), and
//! AnisotropyRotationTest framed close on a donut whose rotation turns its grain back (the same
//! render with the rotation reversed fails too); MikkTSpace tangents generated for
//! AnisotropyStrengthTest's spheres agree with its `TANGENT`.

use super::sample;
use crate::common::golden::{Sampled, check_golden};
use crate::common::*;
use glam::{UVec2, Vec3, Vec4};
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::job::SceneSetup;
use tracer::lens::LensChain;
use tracer::scene::{PunctualLight, Scene};
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
    renderer_sized(scene, camera, SIZE)
}

fn renderer_sized(scene: &Scene, camera: &CameraDesc, size: UVec2) -> impl Fn(u32, u32) -> Sampled {
    let tracer = PathTracer::new(scene, IntegratorConfig::DEFAULT).expect("prepare");
    let camera = camera.clone();
    move |spp, seed| {
        let job = Job { resolution: size, spp, seed, config: IntegratorConfig::DEFAULT };
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

#[test]
fn sheen_cloth_model() {
    let (mut scene, camera) = lit("SheenCloth");
    for w in &scene.warnings {
        assert!(!w.contains("not supported"), "SheenCloth: {w}");
    }
    let cloth = scene.materials.iter().find(|m| m.has_sheen()).expect("the sheen material");
    assert!(
        cloth.textures.sheen_color.is_some() && cloth.textures.sheen_roughness.is_some(),
        "its sheen texture"
    );
    let (_, golden, _) =
        check_golden("sample-SheenCloth", "SheenCloth.gltf, front, sky 1", SPP, renderer(&scene, &camera));
    // Without its sheen the cloth is another picture.
    for m in &mut scene.materials {
        m.sheen = Vec3::ZERO;
    }
    let bare = renderer(&scene, &camera)(SPP, 1);
    let report = StatTest::default().between(bare.estimate(), golden.estimate());
    assert!(!report.passed(), "SheenCloth without its sheen passes as the golden:\n{report}");
}

/// Sample model `name` as [`lit`], with a dim sky and a point light above and beside the camera
/// (2 W/m² on the model's centre) for highlights to stretch.
fn lit_by_a_point(name: &str) -> (Scene, CameraDesc) {
    let (mut scene, camera) = lit(name);
    scene.environment.color = Vec3::splat(0.1);
    let (lo, hi) = scene.bounds().expect("geometry");
    let (centre, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
    let position = centre + Vec3::new(0.4, 0.5, 1.6) * radius;
    let intensity = Vec3::splat(2.0 * (position - centre).length_squared());
    scene.lights.push(PunctualLight::Point { position, intensity });
    (scene, camera)
}

/// The golden of sample model `name` under [`lit_by_a_point`], and the same render with every
/// material's anisotropy removed failing it.
fn anisotropy_golden(name: &str) {
    let (mut scene, camera) = lit_by_a_point(name);
    assert!(scene.materials.iter().filter(|m| m.anisotropy.is_some()).count() >= 4, "{name}: anisotropic");
    assert!(!scene.warnings.iter().any(|w| w.contains("not supported")), "{:?}", scene.warnings);
    let (_, golden, _) = check_golden(
        &format!("sample-{name}"),
        &format!("{name}.gltf, front, point light, sky 0.1"),
        SPP,
        renderer(&scene, &camera),
    );
    for m in &mut scene.materials {
        m.anisotropy = None;
    }
    let isotropic = renderer(&scene, &camera)(SPP, 1);
    let report = StatTest::default().between(isotropic.estimate(), golden.estimate());
    assert!(!report.passed(), "{name} without its anisotropy passes as the golden:\n{report}");
}

#[test]
fn anisotropy_strength_test_model() {
    anisotropy_golden("AnisotropyStrengthTest");
}

/// The tangents mcctrace generates where a mesh has no `TANGENT` (MikkTSpace from the texture
/// coordinates, as Blender makes them) are the ones AnisotropyStrengthTest's exporter wrote: the
/// file loaded as it is and with its `TANGENT` attributes removed give the same tangent, within
/// 2°, with the same sign w, at 99 % of the vertices of its anisotropic spheres (all 45654 of
/// them: MikkTSpace may split a vertex's corners at poles and seams, which these spheres' UV
/// layout avoids). Its seven spheres of strength 0 and the
/// label, which are not anisotropic, get none: they pay nothing.
#[test]
fn generated_tangents_match_the_files() {
    let file = sample("AnisotropyStrengthTest");
    let folder = file.parent().unwrap();
    let scratch = Scratch::new("tangents");
    let mut doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    let mut removed = 0;
    for mesh in doc["meshes"].as_array_mut().unwrap() {
        for prim in mesh["primitives"].as_array_mut().unwrap() {
            removed += usize::from(prim["attributes"].as_object_mut().unwrap().remove("TANGENT").is_some());
        }
    }
    assert_eq!(removed, 49, "the spheres have TANGENT");
    for entry in std::fs::read_dir(folder).unwrap() {
        let path = entry.unwrap().path();
        if path != file {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            std::os::unix::fs::symlink(&path, scratch.path(&name)).unwrap();
        }
    }
    let stripped = scratch.path("stripped.gltf");
    std::fs::write(&stripped, serde_json::to_vec(&doc).unwrap()).unwrap();
    let (given, generated) = (Scene::load(&file).unwrap(), Scene::load(&stripped).unwrap());
    let (a, b) = (&given.mesh.tangents, &generated.mesh.tangents);
    assert_eq!(a.len(), b.len());
    // Vertices of anisotropic materials: generated; the others: none.
    let anisotropic: Vec<bool> = {
        let mut v = vec![false; a.len()];
        for (t, &m) in generated.mesh.triangles.iter().zip(&generated.mesh.material_ids) {
            if generated.materials[m as usize].anisotropy.is_some() {
                for &i in t {
                    v[i as usize] = true;
                }
            }
        }
        v
    };
    let count = anisotropic.iter().filter(|&&x| x).count();
    assert!(count >= 42 * 1000, "{count} vertices of anisotropic spheres");
    for (i, t) in b.iter().enumerate() {
        assert_eq!(*t != Vec4::ZERO, anisotropic[i], "vertex {i}: generated {t}");
    }
    let agree = (0..a.len())
        .filter(|&i| anisotropic[i])
        .filter(|&i| {
            a[i].w == b[i].w
                && a[i].truncate().normalize().dot(b[i].truncate().normalize()) > 2f32.to_radians().cos()
        })
        .count();
    println!("generated tangents agree with the file's at {agree} of {count} vertices");
    assert!(agree as f64 >= 0.99 * count as f64, "{agree} of {count} vertices agree");
}

/// AnisotropyRotationTest's "Tangents + Rotation" donut (its tangents lean 30° clockwise and
/// `anisotropyRotation` turns the grain back, README), framed close under a point light beside
/// the camera, in the file's reading (Blender's: strength 0.5 at roughness 0.1 stretches α only
/// 1.8×, so the whole model at 96 × 72 shows too few pixels of it to fail without it). The same
/// render with the rotation reversed (the grain 60° off) and without anisotropy fails the golden
/// (measured: 200 and 90 of 13824 pixel-channels out, where 35 fail it).
#[test]
fn anisotropy_rotation_test_model() {
    let name = "AnisotropyRotationTest";
    let (mut scene, _) = lit(name);
    assert_eq!(scene.reading, tracer::scene::GltfReading::Blender, "written by Blender");
    assert!(!scene.warnings.iter().any(|w| w.contains("not supported")), "{:?}", scene.warnings);
    scene.environment.color = Vec3::splat(0.1);
    let at = Vec3::new(-1.5, -1.0, 0.0);
    let from = at + Vec3::Z * 1.8;
    let camera =
        CameraDesc::look_at("rotation", from, at, Vec3::Y, Projection::Perspective { fov_y: 0.8 }).unwrap();
    let position = at + Vec3::new(0.3, 0.8, 1.0) * 1.8;
    let intensity = Vec3::splat(2.0 * (position - at).length_squared());
    scene.lights.push(PunctualLight::Point { position, intensity });
    let size = UVec2::new(96, 48);
    let (_, golden, _) = check_golden(
        "sample-AnisotropyRotationTest",
        "AnisotropyRotationTest.gltf, the Tangents + Rotation donut, point light, sky 0.1",
        SPP,
        renderer_sized(&scene, &camera, size),
    );
    let mut reversed = scene.clone();
    for a in reversed.materials.iter_mut().filter_map(|m| m.anisotropy.as_mut()) {
        a.rotation = -a.rotation;
    }
    assert!(reversed.materials.iter().any(|m| m.anisotropy.is_some_and(|a| a.rotation != 0.0)));
    let render = renderer_sized(&reversed, &camera, size)(SPP, 1);
    let report = StatTest::default().between(render.estimate(), golden.estimate());
    assert!(!report.passed(), "{name} with its rotation reversed passes as the golden:\n{report}");
    for m in &mut scene.materials {
        m.anisotropy = None;
    }
    let render = renderer_sized(&scene, &camera, size)(SPP, 1);
    let report = StatTest::default().between(render.estimate(), golden.estimate());
    assert!(!report.passed(), "{name} without its anisotropy passes as the golden:\n{report}");
}
