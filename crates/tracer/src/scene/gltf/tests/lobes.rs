//! glTF loader tests for the material extensions that add lobes to the stack
//! (`crate::bsdf`): `KHR_materials_clearcoat`, `KHR_materials_sheen`, and `KHR_materials_anisotropy`,
//! which stretches the base's specular lobes along tangents the loader generates where a mesh has none.

use super::{Builder, expect_error, load_json};
use crate::material::{AnisotropyMapping, SheenModel};
use crate::scene::GltfReading;
use crate::scene::gltf::tests::TempDir;
use glam::Vec3;
use glam::Vec4;
use serde_json::Value;
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
    // The lobe follows the reading: the specification's Charlie sheen for a file not from
    // Blender, Cycles' sheen in Blender's reading (by its generator, or by hand).
    assert_eq!(m("plain").sheen_model, SheenModel::Charlie);
    let mut blender = scene.clone();
    blender.set_reading(GltfReading::Blender);
    assert!(blender.materials.iter().all(|m| m.sheen_model == SheenModel::Cycles));
    let mut by_blender = doc.clone();
    by_blender["asset"]["generator"] = json!("Khronos glTF Blender I/O v5.0.21");
    let scene = load_json(&dir, "blender.gltf", &by_blender).unwrap();
    assert!(scene.materials.iter().all(|m| m.sheen_model == SheenModel::Cycles));

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

/// A quad in the xy plane (normal +z) with texture coordinates `uvs` (one per corner).
fn quad(b: &mut Builder, x: f32, uvs: [[f32; 2]; 4]) -> Value {
    let positions = b.vec3(&[[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x + 1.0, 1.0, 0.0], [x, 1.0, 0.0]]);
    let normals = b.vec3(&[[0.0, 0.0, 1.0]; 4]);
    let uv = b.add(uvs.iter().flatten().flat_map(|f| f.to_le_bytes()).collect(), 5126, "VEC2", 4);
    let indices = b.indices(&[0, 1, 2, 0, 2, 3]);
    json!({"attributes": {"POSITION": positions, "NORMAL": normals, "TEXCOORD_0": uv}, "indices": indices})
}

/// `KHR_materials_anisotropy`: strength, rotation and texture read; strength 0 without a texture
/// is no anisotropy; the mapping follows the reading (the generator, then `set_reading`); a
/// strength outside [0, 1] or a rotation that is no number is an error naming the material.
/// Primitives with an anisotropic material and no `TANGENT` get MikkTSpace tangents (w = +1 for
/// glTF's usual layout, −1 mirrored); the others get none, and a scene without anisotropy has
/// no tangents at all.
#[test]
fn scene_gltf_anisotropy_factors_mapping_and_tangents() {
    let mut b = Builder::default();
    // glTF's v runs down the image: v = 1 − y on this quad.
    let usual = quad(&mut b, 0.0, [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
    let mirrored = quad(&mut b, 2.0, [[1.0, 1.0], [0.0, 1.0], [0.0, 0.0], [1.0, 0.0]]);
    let plain = quad(&mut b, 4.0, [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
    let prim = |mut p: Value, m: u32| {
        p["material"] = json!(m);
        json!({"primitives": [p]})
    };
    let mut doc = b.finish(json!({
        "extensionsUsed": ["KHR_materials_anisotropy"],
        "images": [{"uri": "aniso.png"}],
        "textures": [{"source": 0}],
        "materials": [
            {"name": "brushed", "extensions": {"KHR_materials_anisotropy": {
                "anisotropyStrength": 0.8, "anisotropyRotation": 0.5}}},
            {"name": "textured", "extensions": {"KHR_materials_anisotropy": {
                "anisotropyTexture": {"index": 0, "texCoord": 0}}}},
            {"name": "zero", "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0}}},
            {"name": "none"},
        ],
        "meshes": [prim(usual, 0), prim(mirrored, 1), prim(plain, 3)],
        "nodes": [{"mesh": 0}, {"mesh": 1}, {"mesh": 2}],
        "scenes": [{"nodes": [0, 1, 2]}],
    }));
    doc["asset"]["generator"] = json!("Khronos glTF Blender I/O v5.0.21");
    let dir = TempDir::new("anisotropy");
    let texel = image::ImageBuffer::from_pixel(1, 1, image::Rgb([255u8, 128, 255]));
    dir.write("aniso.png", super::materials::png(image::DynamicImage::ImageRgb8(texel)));
    let mut scene = load_json(&dir, "aniso.gltf", &doc).unwrap();
    assert!(!scene.warnings.iter().any(|w| w.contains("not supported")), "{:?}", scene.warnings);
    let m = |scene: &crate::scene::Scene, name: &str| {
        scene.materials.iter().find(|m| m.name == name).unwrap().clone()
    };
    let brushed = m(&scene, "brushed").anisotropy.expect("anisotropic");
    assert_eq!((brushed.strength, brushed.rotation, brushed.mapping), (0.8, 0.5, AnisotropyMapping::Blender));
    let textured = m(&scene, "textured");
    assert_eq!(textured.anisotropy.map(|a| a.strength), Some(0.0));
    assert!(textured.textures.anisotropy.is_some());
    assert!(m(&scene, "zero").anisotropy.is_none() && m(&scene, "none").anisotropy.is_none());
    scene.set_reading(GltfReading::Spec);
    assert_eq!(m(&scene, "brushed").anisotropy.unwrap().mapping, AnisotropyMapping::Spec);

    // Tangents: the corners of each quad in file order (4 vertices per primitive).
    let t = &scene.mesh.tangents;
    assert_eq!(t.len(), 12);
    for (i, want) in
        [(0, Vec4::new(1.0, 0.0, 0.0, 1.0)), (4, Vec4::new(-1.0, 0.0, 0.0, -1.0)), (8, Vec4::ZERO)]
    {
        for v in &t[i..i + 4] {
            assert!((*v - want).length() < 1e-5, "vertex {i}: {v}, not {want}");
        }
    }
    // Without an anisotropic material nothing is generated.
    let mut iso = doc.clone();
    iso["meshes"] = json!([iso["meshes"][2].clone()]);
    iso["nodes"] = json!([{"mesh": 0}]);
    iso["scenes"] = json!([{"nodes": [0]}]);
    assert!(load_json(&dir, "iso.gltf", &iso).unwrap().mesh.tangents.is_empty());

    for (key, value, said) in [
        ("anisotropyStrength", json!(1.5), "anisotropyStrength 1.5 is not a number in [0, 1]"),
        ("anisotropyRotation", json!("x"), "anisotropyRotation \"x\" is not a finite number"),
    ] {
        let mut bad = doc.clone();
        bad["materials"][0]["extensions"]["KHR_materials_anisotropy"][key] = value;
        let bytes = serde_json::to_vec(&bad).unwrap();
        expect_error(&dir, "bad.gltf", &bytes, &["material 'brushed'", said]);
    }
}
