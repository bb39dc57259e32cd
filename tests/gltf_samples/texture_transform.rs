//! TextureTransformTest: three quads show an arrow texture through `KHR_texture_transform`
//! (rotation 22.5°; scale 1.5; offset, rotation and scale together), each beside small marker
//! quads: the arrow must point at the green "Correct" marker, not at "NotSupported" (the
//! transform ignored) or "Error" (the rotation turned the wrong way: the spec's listing read
//! literally, KhronosGroup/glTF issue 1563). The arrow is found by evaluating the base colour
//! on a fine grid of each quad through the loaded scene's texture coordinates and texture
//! references; no rendering, so the check is exact and quick.

use super::sample;
use glam::{Vec2, Vec3};
use tracer::scene::Scene;

/// World positions on the quads of material `name` where the base colour is the arrow's black.
fn arrow_points(scene: &Scene, name: &str) -> Vec<Vec3> {
    let m = scene.materials.iter().position(|m| m.name == name).unwrap_or_else(|| panic!("material {name}"));
    let material = &scene.materials[m];
    let texture = material.textures.base_color.expect("the arrow quads are textured");
    let mesh = &scene.mesh;
    let n = 160;
    let mut points = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if mesh.material_ids[t] as usize != m {
            continue;
        }
        let [a, b, c] = tri.map(|i| i as usize);
        for i in 0..n {
            for j in 0..n - i {
                let (u, v) = ((i as f32 + 1.0 / 3.0) / n as f32, (j as f32 + 1.0 / 3.0) / n as f32);
                let w = 1.0 - u - v;
                let p = mesh.positions[a] * w + mesh.positions[b] * u + mesh.positions[c] * v;
                let uv = mesh.uvs[a] * w + mesh.uvs[b] * u + mesh.uvs[c] * v;
                let colour = material.base_color * texture.eval(&scene.textures, [uv, Vec2::ZERO]).truncate();
                if colour.max_element() < 0.05 {
                    points.push(p);
                }
            }
        }
    }
    assert!(points.len() > 100, "{name}: no arrow found ({} black points)", points.len());
    points
}

/// The centre of every marker triangle, with the marker's material name.
fn markers(scene: &Scene) -> Vec<(String, Vec3)> {
    let mesh = &scene.mesh;
    let mut out = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let name = &scene.materials[mesh.material_ids[t] as usize].name;
        if ["Correct", "NotSupported", "Error"].contains(&name.as_str()) {
            let centre = tri.iter().map(|&i| mesh.positions[i as usize]).sum::<Vec3>() / 3.0;
            out.push((name.clone(), centre));
        }
    }
    out
}

#[test]
fn texture_transform_arrows_point_at_the_correct_markers() {
    let scene = Scene::load(&sample("TextureTransformTest")).unwrap_or_else(|e| panic!("{e}"));
    let markers = markers(&scene);
    assert_eq!(
        markers.iter().filter(|m| m.0 == "Correct").count(),
        6,
        "three Correct markers, two triangles each"
    );
    for quad in ["Rotation", "Scale", "All"] {
        let arrow = arrow_points(&scene, quad);
        let distance = |p: Vec3| arrow.iter().map(|a| a.distance(p)).fold(f32::INFINITY, f32::min);
        let mut by_distance: Vec<(f32, &str)> =
            markers.iter().map(|(n, p)| (distance(*p), n.as_str())).collect();
        by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (nearest, kind) = by_distance[0];
        assert_eq!(
            kind, "Correct",
            "{quad}: the arrow points at the '{kind}' marker ({nearest:.3} away): {by_distance:?}"
        );
        // And reaches it: the tip lies within about a marker's size (0.1–0.15) of its centre.
        assert!(nearest < 0.2, "{quad}: the arrow ends {nearest:.3} from the Correct marker");
    }
}
