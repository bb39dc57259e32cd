//! VertexColorTest: the top row's checkmarks are textured with an "X" in the other two channels
//! and multiplied by pure red, green or blue vertex colours (`COLOR_0`, float RGBA), which must
//! zero those channels; a renderer that drops the colours shows the X. Checked on what the
//! renderer sees: the base colour the camera ray's first hit records (the albedo AOV), shot at
//! every vertex-coloured triangle.

use super::sample;
use glam::{UVec2, Vec2, Vec3};
use tracer::integrator::{FirstHit, IntegratorConfig, PathTracer};
use tracer::ray::Ray;
use tracer::sampler::Sampler;
use tracer::scene::Scene;

#[test]
fn vertex_colours_multiply_the_base_colour() {
    let scene = Scene::load(&sample("VertexColorTest")).unwrap_or_else(|e| panic!("{e}"));
    let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).unwrap();
    let mesh = &scene.mesh;
    assert_eq!(mesh.colors.len(), mesh.positions.len(), "COLOR_0 read");
    let checks = scene.materials.iter().position(|m| m.name == "VC_Checks_Mat").expect("VC_Checks_Mat");
    let texture = scene.materials[checks].textures.base_color.expect("textured checks");
    let (mut primaries, mut x_hidden) = (0, 0);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let c = tri.map(|i| mesh.colors[i as usize]);
        // The test row: a triangle whose corners share one pure primary colour.
        let primary = c[0].truncate();
        let is_primary =
            c.iter().all(|v| *v == c[0]) && primary.element_sum() == 1.0 && primary.max_element() == 1.0;
        if mesh.material_ids[t] as usize != checks || !is_primary {
            continue;
        }
        primaries += 1;
        let [a, b, d] = mesh.corners(t);
        let centre = (a + b + d) / 3.0;
        let n = (b - a).cross(d - a).normalize();
        let uv = tri.iter().map(|&i| mesh.uvs[i as usize]).sum::<Vec2>() / 3.0;
        let textured = texture.eval(&scene.textures, [uv, uv]).truncate();
        let ray = Ray::new(centre + n * 1e-2, -n, 0.0);
        let mut first = FirstHit::default();
        let sampler = Sampler::new(UVec2::ZERO, 0, 0);
        tracer.radiance::<true, false, false>(ray, &sampler, Vec2::splat(0.5), &mut first);
        assert!(
            (first.depth - 1e-2).abs() < 1e-3,
            "triangle {t}: the ray hit something else at {}",
            first.depth
        );
        // The channels the colour zeroes are zero, the kept one is the texture's.
        let off = Vec3::ONE - primary;
        assert_eq!(first.albedo * off, Vec3::ZERO, "triangle {t}: colour {primary}, albedo {}", first.albedo);
        assert!(((first.albedo - textured * primary).abs()).max_element() < 0.02, "triangle {t}");
        if (textured * off).max_element() > 0.1 {
            x_hidden += 1;
        }
    }
    assert!(primaries >= 6, "{primaries} vertex-coloured triangles found");
    // Without the colours these would show the X.
    println!("{primaries} vertex-coloured triangles, {x_hidden} with the X in a zeroed channel");
    assert!(x_hidden > 0, "no triangle where the texture's X shows through: the check proves nothing");
}
