//! Textures, samplers, `KHR_texture_transform` and second texture coordinates, read back texel by texel.

use super::assets::*;
use super::harness::*;
use glam::{UVec2, Vec2, Vec3};
use std::f32::consts::FRAC_PI_2;

/// The 2 × 2 texture of the textured-quad tests: top-left, top-right, bottom-left, bottom-right.
pub(crate) const QUADRANTS: [[u8; 4]; 4] =
    [[128, 0, 0, 255], [0, 255, 0, 255], [0, 0, 64, 255], [255, 255, 255, 255]];

/// Renders an emissive quad filling an orthographic view, textured through `texture_info`
/// (JSON after `"index": 0`), with extra primitive data, and returns the colour of each image
/// quadrant (checked uniform).
pub(crate) fn quadrant_colours(
    dir: &TempDir,
    name: &str,
    texture_info: &str,
    uv1: Option<Vec<Vec2>>,
) -> [Vec3; 4] {
    let mut g = Gltf::new("scene_features");
    let texture = g.texture("quadrants.png", Some(r#"{"magFilter": 9728, "minFilter": 9728}"#));
    let material = g.material(&format!(
        r#"{{"name": "screen", "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1]}}, "emissiveFactor": [1, 1, 1],
            "emissiveTexture": {{"index": {texture}{texture_info}}}}}"#
    ));
    // The quad, [−1.1, 1.1]² at z = 0 facing the camera at +z (u right, v down), overfills the
    // view [−1, 1]²: the image quadrants are the texture's.
    let mut prim = quad(Vec3::ZERO, Vec3::X * 1.1, -Vec3::Y * 1.1, Vec3::Z);
    if let Some(uv1) = uv1 {
        prim.uv1 = uv1;
    }
    g.mesh_node(&[(&prim, material)], "");
    let scene = load(&g.write(dir, name));
    let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, UVec2::splat(32));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    let mut colours = [Vec3::ZERO; 4];
    for (q, colour) in colours.iter_mut().enumerate() {
        let (x0, y0) = ((q as u32 % 2) * 16, (q as u32 / 2) * 16);
        *colour = r.images.image.get(x0 + 8, y0 + 8);
        // Every pixel not touching the texel boundary (a sample rounding onto u or v = 0.5 could
        // pick either texel there, legitimately).
        for y in (y0..y0 + 16).filter(|y| !(15..=16).contains(y)) {
            for x in (x0..x0 + 16).filter(|x| !(15..=16).contains(x)) {
                let p = r.images.image.get(x, y);
                assert!(
                    (p - *colour).abs().max_element() < 1e-6,
                    "{name}: quadrant {q} is not uniform at ({x}, {y})"
                );
            }
        }
    }
    colours
}

/// The linear colour of texel `t` of `QUADRANTS` (sRGB decoded by the closed form).
pub(crate) fn texel(t: usize) -> Vec3 {
    Vec3::new(srgb(QUADRANTS[t][0]), srgb(QUADRANTS[t][1]), srgb(QUADRANTS[t][2]))
}

#[test]
fn textured_quad_reads_each_texel_at_known_uvs() {
    let dir = TempDir::new("quad");
    png(&dir, "quadrants.png", 2, 2, &QUADRANTS);
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-6;

    // Plain: each image quadrant shows its texel; a code of 128 reads 0.2158605 (sRGB decoded).
    let plain = quadrant_colours(&dir, "plain", "", None);
    assert!((plain[0].x - 0.215_860_5).abs() < 1e-6, "sRGB decode of 128: {}", plain[0].x);
    for (q, &colour) in plain.iter().enumerate() {
        assert!(close(colour, texel(q)), "quadrant {q}: {colour} vs {}", texel(q));
    }

    // KHR_texture_transform, rotation π/2 and offset (0, 0.5): st = (v, 0.5 − u), wrapped (the
    // direction Blender and the sample model TextureTransformTest agree on, not the spec's
    // listing read literally). By hand: top-left (u, v < 0.5) → st.x ∈ (0, 0.5) → column 0,
    // st.y ∈ (0, 0.5) → row 0: texel 0; top-right → column 0, st.y ∈ (−0.5, 0) → row 1: texel
    // 2; bottom-left → column 1, row 0: texel 1; bottom-right → column 1, row 1: texel 3.
    let info = format!(
        r#", "extensions": {{"KHR_texture_transform": {{"rotation": {}, "offset": [0, 0.5]}}}}"#,
        FRAC_PI_2
    );
    let turned = quadrant_colours(&dir, "turned", &info, None);
    for (q, t) in [(0, 0), (1, 2), (2, 1), (3, 3)] {
        assert!(
            close(turned[q], texel(t)),
            "transformed quadrant {q}: {} vs texel {t} {}",
            turned[q],
            texel(t)
        );
    }

    // TEXCOORD_1, mirrored left–right (u1 = 1 − u0): each quadrant shows its mirror's texel.
    let mirrored = vec![Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0)];
    let second = quadrant_colours(&dir, "uv1", r#", "texCoord": 1"#, Some(mirrored.clone()));
    for (q, t) in [(0, 1), (1, 0), (2, 3), (3, 2)] {
        assert!(close(second[q], texel(t)), "TEXCOORD_1 quadrant {q}: {} vs texel {t}", second[q]);
    }
    // The transform's texCoord overrides the reference's: set 1 again through the extension.
    let info = r#", "extensions": {"KHR_texture_transform": {"texCoord": 1}}"#;
    let overridden = quadrant_colours(&dir, "override", info, Some(mirrored));
    assert_eq!(overridden, second);
}
