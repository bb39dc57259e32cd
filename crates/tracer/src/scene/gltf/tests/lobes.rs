//! glTF loader tests for the material extensions that add lobes to the stack
//! (`crate::bsdf`): `KHR_materials_clearcoat` and `KHR_materials_sheen`.

use super::{Builder, expect_error, load_json};
use crate::scene::gltf::tests::TempDir;
use glam::Vec3;
use serde_json::json;

#[test]
fn scene_gltf_clearcoat_factors_textures_and_errors() {
    let doc = Builder::default().finish(json!({
        "extensionsUsed": ["KHR_materials_clearcoat", "KHR_texture_transform"],
        "images": [{"uri": "coat.png"}],
        "textures": [{"source": 0}],
        "materials": [
            {"name": "none"},
            {"name": "plain", "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.75}}},
            {"name": "textured", "extensions": {"KHR_materials_clearcoat": {
                "clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.4,
                "clearcoatTexture": {"index": 0},
                "clearcoatRoughnessTexture": {"index": 0, "texCoord": 1},
                "clearcoatNormalTexture": {"index": 0, "scale": 0.5,
                    "extensions": {"KHR_texture_transform": {"scale": [2, 2]}}}}}},
            {"name": "dangling", "extensions": {"KHR_materials_clearcoat": {
                "clearcoatFactor": 1, "clearcoatTexture": {"index": 7}}}},
        ],
    }));
    let dir = TempDir::new("clearcoat");
    let grey = image::ImageBuffer::from_pixel(1, 1, image::Luma([128u8]));
    dir.write("coat.png", super::materials::png(image::DynamicImage::ImageLuma8(grey)));
    let scene = load_json(&dir, "coat.gltf", &doc).unwrap();
    let m = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap();
    assert_eq!((m("none").coat, m("none").coat_roughness), (0.0, 0.0));
    assert!(m("none").textures.coat.is_none());
    assert_eq!((m("plain").coat, m("plain").coat_roughness), (0.75, 0.0));
    let t = m("textured");
    assert_eq!((t.coat, t.coat_roughness), (1.0, 0.4));
    let (coat, rough) = (t.textures.coat.unwrap(), t.textures.coat_roughness.unwrap());
    assert_eq!((coat.uv_set, rough.uv_set), (0, 1));
    let (normal, scale) = t.textures.coat_normal.unwrap();
    assert!(scale == 0.5 && normal.transform.is_some() && coat.transform.is_none());
    assert!(!scene.warnings.iter().any(|w| w.contains("not supported")), "{:?}", scene.warnings);
    assert_eq!(m("dangling").coat, 1.0);
    assert!(m("dangling").textures.coat.is_none());
    let warnings = scene.warnings.join("\n");
    assert!(
        warnings.contains(
            "material 'dangling', KHR_materials_clearcoat clearcoatTexture: 'index' 7 names no texture"
        ),
        "{warnings}"
    );

    for (key, value, said) in [
        ("clearcoatFactor", json!(1.5), "clearcoatFactor 1.5 is not a number in [0, 1]"),
        ("clearcoatRoughnessFactor", json!("rough"), "clearcoatRoughnessFactor \"rough\" is not a number"),
    ] {
        let mut bad = doc.clone();
        bad["materials"][1]["extensions"]["KHR_materials_clearcoat"][key] = value;
        let bytes = serde_json::to_vec(&bad).unwrap();
        expect_error(&dir, "bad.gltf", &bytes, &["material 'plain'", said]);
    }
}

#[test]
fn scene_gltf_sheen_factors_textures_and_errors() {
    let doc = Builder::default().finish(json!({
        "extensionsUsed": ["KHR_materials_sheen"],
        "images": [{"uri": "sheen.png"}],
        "textures": [{"source": 0}],
        "materials": [
            {"name": "none"},
            {"name": "plain", "extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": [0.9, 0.3, 0.5], "sheenRoughnessFactor": 0.3}}},
            {"name": "textured", "extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": [1, 1, 1],
                "sheenColorTexture": {"index": 0},
                "sheenRoughnessTexture": {"index": 0, "texCoord": 1}}}},
            {"name": "defaults", "extensions": {"KHR_materials_sheen": {}}},
        ],
    }));
    let dir = TempDir::new("sheen");
    let grey = image::ImageBuffer::from_pixel(1, 1, image::Rgba([128u8, 128, 128, 200]));
    dir.write("sheen.png", super::materials::png(image::DynamicImage::ImageRgba8(grey)));
    let scene = load_json(&dir, "sheen.gltf", &doc).unwrap();
    let m = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap();
    assert!(!m("none").has_sheen() && m("none").textures.sheen_color.is_none());
    assert_eq!((m("plain").sheen, m("plain").sheen_roughness), (Vec3::new(0.9, 0.3, 0.5), 0.3));
    let t = m("textured");
    assert_eq!((t.sheen, t.sheen_roughness), (Vec3::ONE, 0.0));
    let (color, rough) = (t.textures.sheen_color.unwrap(), t.textures.sheen_roughness.unwrap());
    assert_eq!((color.uv_set, rough.uv_set), (0, 1));
    // The extension's defaults: black, roughness 0, which is no sheen at all.
    assert!(!m("defaults").has_sheen());
    assert!(!scene.warnings.iter().any(|w| w.contains("not supported")), "{:?}", scene.warnings);

    for (key, value, said) in [
        (
            "sheenColorFactor",
            json!([0.5, 2.0, 0.5]),
            "sheenColorFactor [0.5,2.0,0.5] is not three numbers in [0, 1]",
        ),
        ("sheenColorFactor", json!([0.5, 0.5]), "is not three numbers"),
        ("sheenRoughnessFactor", json!(-0.1), "sheenRoughnessFactor -0.1 is not a number in [0, 1]"),
    ] {
        let mut bad = doc.clone();
        bad["materials"][1]["extensions"]["KHR_materials_sheen"][key] = value;
        let bytes = serde_json::to_vec(&bad).unwrap();
        expect_error(&dir, "bad.gltf", &bytes, &["material 'plain'", said]);
    }
}
