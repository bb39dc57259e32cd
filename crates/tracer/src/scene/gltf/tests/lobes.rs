//! glTF loader tests for the material extensions that add lobes to the stack
//! (`crate::bsdf`): `KHR_materials_clearcoat`.

use super::{Builder, expect_error, load_json};
use crate::scene::gltf::tests::TempDir;
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
