//! `EXT_mesh_gpu_instancing` copies share their mesh: the scene's mesh and the per-triangle
//! shading arrays hold each unique mesh once, in its own space, and a hit is shaded through its
//! copy. Memory grows with the unique meshes, not the copies, and the picture is the flattened
//! copies' picture.

use super::assets::{Gltf, TempDir, quad, sphere};
use super::harness::{load, render};
use glam::{Quat, UVec2, Vec3};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::scene::Scene;

/// A scene of `copies` copies of one sphere (vertex normals, texture coordinates) on a grid,
/// turned and scaled unevenly, every fifth mirrored; and three copies of an emitting quad.
fn spheres(dir: &TempDir, copies: usize) -> Scene {
    let mut g = Gltf::new("test");
    let grey = g.material(
        r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.5, 0.4, 1], "roughnessFactor": 0.4}}"#,
    );
    let mut ball = sphere(Vec3::ZERO, 0.4, 8, 16);
    ball.uv0 = ball.positions.iter().map(|p| glam::Vec2::new(p.x + 0.5, p.y + 0.5)).collect();
    let (mut t, mut r, mut s) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..copies {
        let (x, z) = ((k % 8) as f32, (k / 8) as f32);
        t.extend([x, 0.0, -z]);
        r.extend(Quat::from_rotation_y(0.3 * k as f32).to_array());
        let mirror = if k % 5 == 4 { -1.0 } else { 1.0 };
        s.extend([mirror * 1.0, 0.6 + 0.1 * (k % 4) as f32, 1.2]);
    }
    let (t, r, s) = (
        g.floats(&t, "VEC3", copies, ""),
        g.floats(&r, "VEC4", copies, ""),
        g.floats(&s, "VEC3", copies, ""),
    );
    let instancing = |t: usize, r: usize, s: usize| {
        format!(
            r#", "extensions": {{"EXT_mesh_gpu_instancing": {{"attributes": {{"TRANSLATION": {t}, "ROTATION": {r}, "SCALE": {s}}}}}}}"#
        )
    };
    g.mesh_node(&[(&ball, grey)], &instancing(t, r, s));
    let lamp = g.material(r#"{"emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}}"#);
    let panel = quad(Vec3::ZERO, Vec3::X * 0.5, Vec3::Z * 0.5, Vec3::NEG_Y);
    let lamp_t = g.floats(&[0.0, 3.0, 0.0, 3.5, 3.0, 0.0, 7.0, 3.0, 0.0], "VEC3", 3, "");
    let lamp_r = g.floats(&[0.0, 0.0, 0.0, 1.0].repeat(3), "VEC4", 3, "");
    let lamp_s = g.floats(&[1.0; 9], "VEC3", 3, "");
    g.mesh_node(&[(&panel, lamp)], &instancing(lamp_t, lamp_r, lamp_s));
    let path = g.write(dir, &format!("spheres{copies}"));
    let text = std::fs::read_to_string(&path).unwrap();
    let text =
        text.replacen(r#""extensionsUsed": ["#, r#""extensionsUsed": ["EXT_mesh_gpu_instancing", "#, 1);
    std::fs::write(&path, text).unwrap();
    load(&path)
}

/// Bytes of the scene's geometry and of the per-triangle shading arrays prepared from it.
fn bytes(scene: &Scene) -> usize {
    let tracer = PathTracer::new(scene, IntegratorConfig::DEFAULT).unwrap();
    scene.geometry_bytes() + tracer.shading_bytes()
}

#[test]
fn shared_copies_memory_grows_with_the_unique_meshes_not_the_copies() {
    let dir = TempDir::new("shared-memory");
    let (few, many) = (spheres(&dir, 8), spheres(&dir, 68));
    let instances = many.instances.as_deref().expect("the copies are instances");
    let per_sphere = instances.meshes[0].triangle_count();
    // The sphere is shared (as wound, and mirrored: re-wound); the emitting quad's copies stay
    // lights of their own.
    assert_eq!(instances.meshes.iter().map(|m| m.shared).collect::<Vec<_>>(), vec![true, true, false]);
    assert_eq!(many.mesh.triangles.len(), 2 * per_sphere + 3 * 2, "the sphere twice, each lamp copy");
    assert_eq!(many.drawn_triangle_count(), 68 * per_sphere + 3 * 2);
    let flat = many.with_copies_flattened();
    assert_eq!(flat.mesh.triangles.len(), 68 * per_sphere + 3 * 2);
    // 60 more copies cost their placements alone: a few hundred bytes each, where a
    // flattened copy of the sphere costs its vertices, triangles and shading arrays.
    let per_copy = (bytes(&many) - bytes(&few)) / 60;
    let flat_per_copy = (bytes(&flat) - bytes(&few.with_copies_flattened())) / 60;
    assert!(per_copy <= 400, "{per_copy} bytes per shared copy");
    assert!(flat_per_copy > 20 * per_copy, "{flat_per_copy} bytes per flattened copy, {per_copy} shared");
    assert_eq!(many.bounds(), flat.bounds(), "the copies where they are placed");
}

#[test]
fn shared_copies_render_as_their_flattened_copies() {
    let dir = TempDir::new("shared-render");
    let mut scene = spheres(&dir, 24);
    scene.environment.color = Vec3::splat(0.3);
    let flat = Scene { instances: None, ..scene.with_copies_flattened() };
    let camera = tracer::camera::CameraDesc::look_at(
        "view",
        Vec3::new(3.5, 4.0, 5.0),
        Vec3::new(3.5, 0.0, -1.5),
        Vec3::Y,
        tracer::camera::Projection::Perspective { fov_y: 0.8 },
    )
    .unwrap();
    let size = UVec2::new(64, 48);
    let (a, b) = (render(&scene, &camera, size, 16, 3), render(&flat, &camera, size, 16, 3));
    let (pa, pb) = (&a.images.image.pixels, &b.images.image.pixels);
    // The same tolerance as the instanced BVH against the flattened one: the same seed takes
    // the same paths but where a hit's last bits differ (the ray is taken into each copy's space).
    let differing = pa.iter().zip(pb).filter(|(x, y)| (**x - **y).abs().max_element() > 1e-3).count();
    let mean = |p: &[Vec3]| p.iter().map(|v| v.x as f64 + v.y as f64 + v.z as f64).sum::<f64>();
    assert!(differing * 100 <= pa.len(), "{differing} of {} pixels differ", pa.len());
    assert!((mean(pa) / mean(pb) - 1.0).abs() < 1e-3, "means {} and {}", mean(pa), mean(pb));
    let lit = pa.iter().filter(|p| p.x > 0.05 && (p.x - 0.3).abs() > 0.02).count();
    assert!(lit * 5 > pa.len(), "the spheres fill a fifth of the view: {lit} of {} pixels", pa.len());
}
