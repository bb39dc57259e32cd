//! Camera lists, and bad inputs that must name the file and entry in their error or warning.

use super::assets::*;
use super::harness::*;
use glam::{UVec2, Vec3};
use std::path::Path;
use tracer::scene::Scene;

#[test]
fn camera_list_loads_and_bad_files_name_file_and_entry() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cams = tracer::scene::camera_list::load(&root.join("scenes/cornell/cameras.json")).unwrap();
    assert_eq!(cams.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), ["cornell", "corner"]);
    // The list's `cornell` is the glTF's camera: the same eye ray for every pixel tested.
    let gltf = Scene::load(&root.join("scenes/cornell/cornell.gltf")).unwrap();
    let (a, b) = (cams[0].build(UVec2::splat(64)).unwrap(), gltf.cameras[0].build(UVec2::splat(64)).unwrap());
    for (i, j) in [(0, 0), (63, 0), (20, 40), (63, 63)] {
        let s = tracer::camera::CameraSample::pixel_centre(i, j, 0.0);
        let (ra, rb) = (a.generate_ray(&s).unwrap(), b.generate_ray(&s).unwrap());
        assert!((ra.origin - rb.origin).length() < 1e-5 && (ra.direction - rb.direction).length() < 1e-5);
    }
    let dir = TempDir::new("camlist");
    let bad = dir.write(
        "views.json",
        r#"{"cameras": [{"name": "a", "look_from": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40},
                         {"name": "b", "look_from": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40, "lookat": [1, 1, 1]}]}"#,
    );
    let message = tracer::scene::camera_list::load(&bad).unwrap_err().to_string();
    assert!(
        message.contains("views.json")
            && message.contains("camera 1 ('b')")
            && message.contains("unknown key 'lookat'"),
        "{message}"
    );
}

/// A broken image and a missing one are warnings naming them, and the scene still renders (the
/// slots fall back to their factors); an alpha cut-off below zero is an error naming the file and
/// the material.
#[test]
fn bad_inputs_give_the_right_error_or_warning() {
    let dir = TempDir::new("bad");
    dir.write("broken.png", b"\x89PNG\r\n\x1a\n truncated");
    let mut g = Gltf::new("scene_features");
    let broken = g.texture("broken.png", None);
    let missing = g.texture("missing%20file.png", None);
    let material = g.material(&format!(
        r#"{{"name": "patchy", "emissiveFactor": [0.5, 0.5, 0.5], "emissiveTexture": {{"index": {broken}}},
            "pbrMetallicRoughness": {{"baseColorTexture": {{"index": {missing}}}}}}}"#
    ));
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X, -Vec3::Y, Vec3::Z), material)], "");
    let path = g.write(&dir, "bad");
    let scene = Scene::load(&path).unwrap();
    let warnings = scene.warnings.join("\n");
    assert!(
        warnings.contains("bad.gltf") && warnings.contains("broken.png") && warnings.contains("malformed"),
        "{warnings}"
    );
    assert!(warnings.contains("missing%20file.png") && warnings.contains("missing file.png"), "{warnings}");
    // Renders: the emissive factor alone (0.5) where the texture would have been.
    let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.5, UVec2::splat(8));
    let r = render(&scene, &cam.desc, cam.size, 1, 1);
    assert!(r.images.image.pixels.iter().all(|p| (*p - Vec3::splat(0.5)).abs().max_element() < 1e-6));

    let mut g = Gltf::new("scene_features");
    let material = g.material(r#"{"name": "leafy", "alphaMode": "MASK", "alphaCutoff": -0.25}"#);
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z), material)], "");
    let message = Scene::load(&g.write(&dir, "cutoff")).unwrap_err().to_string();
    assert!(
        message.contains("cutoff.gltf")
            && message.contains("'leafy'")
            && message.contains("alphaCutoff -0.25"),
        "{message}"
    );
}
