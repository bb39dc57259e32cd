//! glTF loader tests for what materials and lights gained: images from files, data URIs and
//! buffer views (.gltf and .glb), colour spaces, samplers, texture coordinates sets and
//! `KHR_texture_transform`, tangents, alpha modes, transmission and ior, spot and directional
//! lights; and every bad input's warning or error.

use super::{Builder, TRIANGLE, base64, expect_error, glb, load_json};
use crate::material::AlphaMode;
use crate::scene::gltf::tests::TempDir;
use crate::scene::{GltfReading, PunctualLight, SpotFalloff};
use crate::texture::{Filter, TextureRef, Wrap, uv_transform};
use glam::{Vec2, Vec3, Vec4};
use image::{DynamicImage, ImageBuffer, ImageFormat, Luma, Rgb, Rgba};
use serde_json::{Value, json};
use std::f32::consts::{FRAC_1_SQRT_2, FRAC_PI_2};

/// The sRGB EOTF of 128/255.
const SRGB_128: f32 = 0.215_860_5;

pub(super) fn png(image: DynamicImage) -> Vec<u8> {
    let mut bytes = Vec::new();
    image.write_to(&mut std::io::Cursor::new(&mut bytes), ImageFormat::Png).unwrap();
    bytes
}

fn close4(a: Vec4, b: Vec4) -> bool {
    (a - b).abs().max_element() < 1e-6
}

impl Builder {
    /// A buffer view holding raw bytes (an image); returns its index.
    fn view(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend(bytes);
        self.views.len() - 1
    }

    fn vec2(&mut self, v: &[[f32; 2]]) -> usize {
        let bytes = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        self.add(bytes, 5126, "VEC2", v.len())
    }

    fn vec4(&mut self, v: &[[f32; 4]]) -> usize {
        let bytes = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        self.add(bytes, 5126, "VEC4", v.len())
    }
}

#[test]
fn scene_gltf_textures_sources_and_samplers() {
    let dir = TempDir::new("textures");
    // Image 0: an external file whose URI is %-encoded; 2 × 1 RGBA.
    let rgba =
        ImageBuffer::from_fn(
            2,
            1,
            |x, _| if x == 0 { Rgba([128u8, 0, 255, 255]) } else { Rgba([0, 255, 0, 128]) },
        );
    dir.write("tex a.png", png(DynamicImage::ImageRgba8(rgba)));
    dir.write("broken.png", b"\x89PNG but not really");
    let grey = png(DynamicImage::ImageLuma8(ImageBuffer::from_pixel(1, 1, Luma([128u8]))));
    let rgb = png(DynamicImage::ImageRgb8(ImageBuffer::from_pixel(1, 1, Rgb([10u8, 20, 30]))));
    let mut b = Builder::default();
    let rgb_view = b.view(&rgb);
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_texture_transform", "KHR_materials_specular"],
        "images": [
            {"uri": "tex%20a.png"},
            {"uri": format!("data:image/png;base64,{}", base64(&grey))},
            {"bufferView": rgb_view, "mimeType": "image/png"},
            {"uri": "missing.png"},
            {"uri": "broken.png", "name": "Broken"},
            {"name": "nothing"},
        ],
        "samplers": [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33648}, {"magFilter": 9729}],
        "textures": [
            {"source": 0, "sampler": 0}, {"source": 1}, {"source": 2}, {"source": 3}, {"source": 4},
            {"source": 0, "sampler": 1}, {"source": 5},
        ],
        "materials": [
            {"name": "a",
             "pbrMetallicRoughness": {
                 "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
                     {"offset": [0.5, 0], "rotation": FRAC_PI_2, "scale": [2, 2], "texCoord": 1}}},
                 "metallicRoughnessTexture": {"index": 5}},
             "emissiveFactor": [1, 1, 1],
             "emissiveTexture": {"index": 1, "texCoord": 1},
             "normalTexture": {"index": 2, "scale": 0.5,
                               "extensions": {"KHR_texture_transform": {"offset": [0.25, 0]}}},
             "occlusionTexture": {"index": 1}},
            {"name": "b",
             "pbrMetallicRoughness": {"baseColorTexture": {"index": 5}},
             "emissiveTexture": {"index": 3},
             "normalTexture": {"index": 4},
             "extensions": {"KHR_materials_specular": {"specularTexture": {"index": 1}}}},
            {"name": "c", "pbrMetallicRoughness": {"baseColorTexture": {"index": 6}}},
        ],
    }));
    let scene = load_json(&dir, "textures.gltf", &doc).unwrap();

    // One decode per image and colour space: image 0 as sRGB and linear, image 1 sRGB, image 2
    // linear, image 1 linear again (material b's specular texture, read as made last);
    // material b's base colour shares material a's texture.
    assert_eq!(scene.textures.len(), 5, "{:?}", scene.textures.iter().map(|t| &t.name).collect::<Vec<_>>());
    let t = &scene.textures;
    assert_eq!((t[0].width, t[0].height), (2, 1));
    assert!(close4(t[0].linear_texel(0), Vec4::new(SRGB_128, 0.0, 1.0, 1.0)), "{}", t[0].linear_texel(0));
    assert!(close4(t[0].linear_texel(1), Vec4::new(0.0, 1.0, 0.0, 128.0 / 255.0)), "alpha stays linear");
    assert!(close4(t[1].linear_texel(0), Vec4::new(128.0 / 255.0, 0.0, 1.0, 1.0)), "linear slot");
    assert!(close4(t[2].linear_texel(0), Vec4::new(SRGB_128, SRGB_128, SRGB_128, 1.0)), "grey → RGB");
    assert!(close4(t[3].linear_texel(0), Vec4::new(10.0, 20.0, 30.0, 255.0) / 255.0), "buffer view, linear");

    let a = &scene.materials[0].textures;
    let want = TextureRef {
        texture: 0,
        uv_set: 1,
        transform: Some(uv_transform(Vec2::new(0.5, 0.0), FRAC_PI_2, Vec2::splat(2.0))),
        wrap: [Wrap::ClampToEdge, Wrap::MirroredRepeat],
        filter: Filter::Nearest,
    };
    assert_eq!(a.base_color, Some(want));
    assert_eq!(a.metallic_roughness, Some(TextureRef { texture: 1, ..TextureRef::new(1) }));
    assert_eq!(a.emissive, Some(TextureRef { uv_set: 1, ..TextureRef::new(2) }));
    let normal = TextureRef {
        transform: Some(uv_transform(Vec2::new(0.25, 0.0), 0.0, Vec2::ONE)),
        ..TextureRef::new(3)
    };
    assert_eq!(a.normal, Some((normal, 0.5)));

    let b = &scene.materials[1].textures;
    assert_eq!(b.base_color, Some(TextureRef::new(0)));
    assert_eq!((b.emissive, b.normal), (None, None));
    assert_eq!(b.specular, Some(TextureRef::new(4)));
    assert!(scene.materials[2].textures.is_empty());

    let warnings = scene.warnings.join("\n");
    for needle in [
        "image 3 ('missing.png') (used by material 'b', emissive texture): cannot read",
        "image 4 ('Broken')",
        "not a PNG, JPEG, TIFF or WebP",
        "image 5 ('nothing')",
        "neither a uri nor a bufferView",
    ] {
        assert!(warnings.contains(needle), "no '{needle}' in:\n{warnings}");
    }
    assert!(!warnings.contains("occlusion") && !warnings.contains("KHR_texture_transform"), "{warnings}");
    assert_eq!(scene.warnings.len(), 3, "{warnings}");
    assert!(scene.warnings.iter().all(|w| w.contains("textures.gltf")), "{warnings}");
}

#[test]
fn scene_gltf_glb_image_from_the_binary_chunk() {
    let dir = TempDir::new("glb-image");
    let rgb = png(DynamicImage::ImageRgb8(ImageBuffer::from_pixel(3, 2, Rgb([255u8, 128, 0]))));
    let mut bin = rgb.clone();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": rgb.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": rgb.len()}],
        "images": [{"bufferView": 0, "mimeType": "image/png"}],
        "textures": [{"source": 0}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    });
    let scene = crate::scene::Scene::load(&dir.write("image.glb", glb(&doc, &bin))).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (3, 2));
    assert!(close4(scene.textures[0].linear_texel(5), Vec4::new(1.0, SRGB_128, 0.0, 1.0)));

    // A view running past its buffer: a warning naming the image and the view, no texture.
    let mut short = doc.clone();
    short["bufferViews"][0]["byteLength"] = json!(rgb.len() + 100);
    short["buffers"][0]["byteLength"] = json!(bin.len());
    let scene = crate::scene::Scene::load(&dir.write("short.glb", glb(&short, &bin))).unwrap();
    let warnings = scene.warnings.join("\n");
    assert!(warnings.contains("image 0") && warnings.contains("buffer view 0"), "{warnings}");
    assert!(scene.textures.is_empty() && scene.materials[0].textures.is_empty());
}

/// `COLOR_0` in every form glTF allows (RGB or RGBA; float, normalised u8 or u16) reaches the
/// mesh as linear RGBA; a primitive without colours beside one with them gets white (no
/// change); a form glTF does not allow is an error naming the accessor.
#[test]
fn scene_gltf_vertex_colours() {
    let mut b = Builder::default();
    let pos = b.vec3(&TRIANGLE);
    let rgb = b.vec3(&[[1.0, 0.5, 0.0], [0.0, 1.0, 0.25], [0.5, 0.5, 0.5]]);
    let u8s = b.add(vec![255, 0, 51, 255, 0, 255, 0, 102, 0, 0, 255, 0], 5121, "VEC4", 3);
    let u16s = b.add(
        [65535u16, 0, 0, 0, 65535, 0, 0, 0, 65535].iter().flat_map(|v| v.to_le_bytes()).collect(),
        5123,
        "VEC3",
        3,
    );
    let doc = b.finish(json!({
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": pos}},
            {"attributes": {"POSITION": pos, "COLOR_0": rgb}},
            {"attributes": {"POSITION": pos, "COLOR_0": u8s}},
            {"attributes": {"POSITION": pos, "COLOR_0": u16s}},
        ]}],
    }));
    let mut doc = doc;
    doc["accessors"][u8s]["normalized"] = json!(true);
    doc["accessors"][u16s]["normalized"] = json!(true);
    let dir = TempDir::new("colours");
    let scene = load_json(&dir, "colours.gltf", &doc).unwrap();
    let c = &scene.mesh.colors;
    assert_eq!(c[..3], [Vec4::ONE; 3]);
    assert_eq!(
        c[3..6],
        [Vec4::new(1.0, 0.5, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.25, 1.0), Vec4::new(0.5, 0.5, 0.5, 1.0)]
    );
    assert_eq!(c[6], Vec4::new(1.0, 0.0, 0.2, 1.0));
    assert_eq!(c[7], Vec4::new(0.0, 1.0, 0.0, 0.4));
    assert_eq!(
        c[9..12],
        [Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.0, 1.0), Vec4::new(0.0, 0.0, 1.0, 1.0)]
    );

    // Unnormalised bytes are not a colour glTF allows.
    let mut bad = doc.clone();
    bad["accessors"][u8s]["normalized"] = json!(false);
    let bytes = serde_json::to_vec(&bad).unwrap();
    expect_error(&dir, "bytes.gltf", &bytes, &[&format!("accessor {u8s} used as COLOR_0")]);
}

#[test]
fn scene_gltf_tangents_second_uvs_and_mirroring() {
    let mut b = Builder::default();
    let pos = b.vec3(&TRIANGLE);
    let uv0 = b.vec2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let uv1 = b.vec2(&[[0.5, 0.5], [0.25, 0.5], [0.5, 0.25]]);
    let tan = b.vec4(&[[2.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, -1.0]]);
    let attributes = json!({"POSITION": pos, "TEXCOORD_0": uv0, "TEXCOORD_1": uv1, "TANGENT": tan});
    let doc = b.finish(json!({
        "nodes": [
            {"name": "turned", "rotation": [0, 0, FRAC_1_SQRT_2, FRAC_1_SQRT_2], "mesh": 0},
            {"name": "mirrored", "scale": [-1, 1, 1], "mesh": 0},
        ],
        "meshes": [{"primitives": [{"attributes": attributes}]}],
    }));
    let dir = TempDir::new("tangents");
    let scene = load_json(&dir, "tangents.gltf", &doc).unwrap();
    let m = &scene.mesh;
    assert_eq!(m.uvs1[..3], [Vec2::new(0.5, 0.5), Vec2::new(0.25, 0.5), Vec2::new(0.5, 0.25)]);
    // Turned 90° about +Z: +X → +Y, normalised, w kept.
    for (t, w) in m.tangents[..3].iter().zip([1.0, 1.0, -1.0]) {
        assert!(close4(*t, Vec4::new(0.0, 1.0, 0.0, w)), "{t}");
    }
    // Mirrored in x: +X → −X and the bitangent sign flips.
    for (t, w) in m.tangents[3..].iter().zip([-1.0, -1.0, 1.0]) {
        assert!(close4(*t, Vec4::new(-1.0, 0.0, 0.0, w)), "{t}");
    }

    // A TANGENT that is not VEC4: an error naming the accessor.
    let mut bad = doc.clone();
    bad["accessors"][tan]["type"] = json!("VEC3");
    bad["accessors"][tan]["count"] = json!(3);
    let bytes = serde_json::to_vec(&bad).unwrap();
    expect_error(&dir, "vec3tangent.gltf", &bytes, &[&format!("accessor {tan} used as TANGENT is Vec3")]);
}

#[test]
fn scene_gltf_missing_texture_coordinates_are_warnings() {
    let dir = TempDir::new("no-uvs");
    let grey = png(DynamicImage::ImageLuma8(ImageBuffer::from_pixel(1, 1, Luma([200u8]))));
    let mut b = Builder::default();
    let pos = b.vec3(&TRIANGLE);
    let uv0 = b.vec2(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let doc = b.finish(json!({
        "nodes": [{"mesh": 0}],
        "meshes": [{"name": "m", "primitives": [
            {"attributes": {"POSITION": pos}, "material": 0},
            {"attributes": {"POSITION": pos, "TEXCOORD_0": uv0}, "material": 1},
            {"attributes": {"POSITION": pos, "TEXCOORD_0": uv0}, "material": 0},
        ]}],
        "images": [{"uri": format!("data:image/png;base64,{}", base64(&grey))}],
        "textures": [{"source": 0}],
        "materials": [
            {"name": "uv0", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
            {"name": "uv1", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}}},
        ],
    }));
    let scene = load_json(&dir, "uvs.gltf", &doc).unwrap();
    let warnings = scene.warnings.join("\n");
    assert!(
        warnings.contains(
            "primitive 0: material 'uv0' has textures but the primitive has no texture coordinates"
        ),
        "{warnings}"
    );
    assert!(warnings.contains("primitive 1: material 'uv1' reads TEXCOORD_1"), "{warnings}");
    assert_eq!(warnings.matches("mesh 0 ('m') primitive").count(), 2, "{warnings}");
}

#[test]
fn scene_gltf_alpha_transmission_and_ior() {
    let doc = Builder::default().finish(json!({
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"],
        "images": [{"uri": "t.png"}],
        "textures": [{"source": 0}],
        "materials": [
            {"name": "mask", "alphaMode": "MASK"},
            {"name": "mask3", "alphaMode": "MASK", "alphaCutoff": 0.3},
            {"name": "blend", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 1, 0.25]}},
            {"name": "opaque", "alphaCutoff": 0.9, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}},
            {"name": "glass", "extensions": {
                "KHR_materials_transmission": {"transmissionFactor": 1},
                "KHR_materials_ior": {"ior": 1.33}}},
            {"name": "plain-glass", "extensions": {"KHR_materials_transmission": {"transmissionFactor": 0.5}}},
            {"name": "badior", "extensions": {"KHR_materials_ior": {"ior": 0.5}}},
            {"name": "high", "alphaMode": "MASK", "alphaCutoff": 1.5},
            {"name": "ttex", "extensions": {"KHR_materials_transmission": {"transmissionTexture": {"index": 0}}}},
            {"name": "frosted", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.25},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}},
        ],
    }));
    let dir = TempDir::new("alpha");
    let scene = load_json(&dir, "alpha.gltf", &doc).unwrap();
    let m = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap();
    assert_eq!(m("mask").alpha_mode, AlphaMode::Mask { cutoff: 0.5 });
    assert_eq!(m("mask3").alpha_mode, AlphaMode::Mask { cutoff: 0.3 });
    assert_eq!((m("blend").alpha_mode, m("blend").alpha), (AlphaMode::Blend, 0.25));
    assert_eq!((m("opaque").alpha_mode, m("opaque").alpha), (AlphaMode::Opaque, 0.5));
    let glass = m("glass");
    assert_eq!((glass.transmission, glass.ior), (1.0, 1.33));
    // F0 = ((1.33 − 1)/(1.33 + 1))² = 0.020059…, i.e. the specular colour × 0.5015.
    let f0 = (0.33f32 / 2.33).powi(2);
    assert!(
        (glass.specular_color * 0.04 - Vec3::splat(f0)).abs().max_element() < 1e-7,
        "{}",
        glass.specular_color
    );
    assert_eq!((m("plain-glass").transmission, m("plain-glass").ior), (0.5, 1.5));
    assert_eq!(m("plain-glass").specular_color, Vec3::ONE);
    assert_eq!(m("badior").ior, 1.5);
    assert_eq!(m("high").alpha_mode, AlphaMode::Mask { cutoff: 1.5 });
    let warnings = scene.warnings.join("\n");
    assert!(warnings.contains("material 'badior': KHR_materials_ior ior 0.5 is below 1"), "{warnings}");
    assert!(warnings.contains("material 'high': alphaCutoff 1.5 is above 1"), "{warnings}");
    assert!(warnings.contains("material 'ttex'") && warnings.contains("transmissionTexture"), "{warnings}");
    // Rough glass is rendered rough (`bsdf/rough_dielectric.rs`), without a word.
    assert_eq!((m("frosted").roughness, m("frosted").transmission), (0.25, 1.0));
    assert!(!warnings.contains("rough transmission"), "{warnings}");
    assert_eq!(scene.warnings.len(), 3, "{warnings}");

    let mut negative = doc.clone();
    negative["materials"][1]["alphaCutoff"] = json!(-0.5);
    let bytes = serde_json::to_vec(&negative).unwrap();
    expect_error(&dir, "cutoff.gltf", &bytes, &["material 'mask3'", "alphaCutoff -0.5 is out of range"]);
    let mut alpha = doc;
    alpha["materials"][2]["pbrMetallicRoughness"]["baseColorFactor"] = json!([1, 1, 1, 1.5]);
    let bytes = serde_json::to_vec(&alpha).unwrap();
    expect_error(&dir, "alpha.gltf", &bytes, &["material 'blend'", "alpha 1.5"]);
}

/// `KHR_materials_volume` in both readings: Blender's files (generator) make every transmissive
/// material a solid and absorb σa = (1 − colour)/distance, as its Volume Absorption node does;
/// other files follow the specification: a thin wall at thickness 0 or without the extension,
/// σa = −ln(colour)/distance.
/// A malformed extension is named and ignored.
#[test]
fn scene_gltf_volume_in_both_readings() {
    let glass = |name: &str, volume: Value| {
        let mut ext = json!({"KHR_materials_transmission": {"transmissionFactor": 1}});
        if !volume.is_null() {
            ext["KHR_materials_volume"] = volume;
        }
        json!({"name": name, "pbrMetallicRoughness": {"metallicFactor": 0}, "extensions": ext})
    };
    let doc = |generator: &str| {
        let mut doc = Builder::default().finish(json!({
            "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume"],
            "materials": [
                glass("clear", Value::Null),
                glass("thin", json!({"thicknessFactor": 0, "attenuationColor": [0.5, 0.5, 0.5], "attenuationDistance": 2})),
                glass("amber", json!({"thicknessFactor": 1, "attenuationColor": [0.9, 0.5, 0.25], "attenuationDistance": 2})),
                glass("endless", json!({"thicknessFactor": 1, "attenuationColor": [0.5, 0.5, 0.5]})),
                glass("bad", json!({"thicknessFactor": 1, "attenuationDistance": -1})),
            ],
        }));
        doc["asset"]["generator"] = json!(generator);
        doc
    };
    let dir = TempDir::new("volume");
    for (generator, blender) in [("Khronos glTF Blender I/O v4.2", true), ("Adobe Dimension", false)] {
        let scene = load_json(&dir, "volume.gltf", &doc(generator)).unwrap();
        let m = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap();
        // Without the extension: a thin wall by the specification, a solid in Blender's reading.
        assert_eq!(m("clear").thin_walled, !blender, "{generator}");
        assert_eq!(m("thin").thin_walled, !blender, "{generator}");
        assert!(!m("amber").thin_walled && m("amber").has_volume(), "{generator}");
        let colour = Vec3::new(0.9, 0.5, 0.25);
        let sigma = if blender { (Vec3::ONE - colour) / 2.0 } else { -colour.map(f32::ln) / 2.0 };
        assert!((m("amber").attenuation - sigma).abs().max_element() < 1e-6, "{}", m("amber").attenuation);
        assert_eq!(m("endless").attenuation, Vec3::ZERO, "no distance: clear");
        assert!(!m("endless").has_volume());
        let warnings = scene.warnings.join("\n");
        assert!(
            warnings.contains(
                "material 'bad': malformed KHR_materials_volume ('attenuationDistance' -1 must be > 0)"
            ),
            "{warnings}"
        );
        assert!(!warnings.contains("not supported"), "{warnings}");
    }
}

fn lights_doc(generator: &str, lights: Value) -> Value {
    let h = FRAC_1_SQRT_2;
    let mut doc = Builder::default().finish(json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensionsRequired": ["KHR_lights_punctual", "KHR_texture_transform", "KHR_materials_transmission",
                               "KHR_materials_ior", "KHR_materials_specular", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "nodes": [
            // −90° about +X: local −Z → world −Y.
            {"translation": [0, 3, 0], "rotation": [-h, 0, 0, h], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            // +90° about +Y: local −Z → world −X.
            {"rotation": [0, h, 0, h], "extensions": {"KHR_lights_punctual": {"light": 1}}},
        ],
    }));
    doc["asset"]["generator"] = json!(generator);
    doc
}

#[test]
fn scene_gltf_spot_and_directional_lights() {
    let lights = json!([
        {"type": "spot", "color": [1, 0.5, 1], "intensity": 1366, "range": 10,
         "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.5}},
        {"type": "directional", "name": "sun", "intensity": 2049},
    ]);
    let dir = TempDir::new("spots");
    let blender =
        load_json(&dir, "blender.gltf", &lights_doc("Khronos glTF Blender I/O v4.2.69", lights.clone()))
            .unwrap();
    assert!(blender.warnings.is_empty(), "range is ignored silently: {:?}", blender.warnings);
    let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
    match blender.lights[..] {
        [
            PunctualLight::Spot { position, direction, intensity, inner_cone, outer_cone, falloff },
            PunctualLight::Directional { direction: sun, irradiance },
        ] => {
            assert!(
                close(position, Vec3::new(0.0, 3.0, 0.0)) && close(direction, Vec3::NEG_Y),
                "{direction}"
            );
            // 1366 cd = 2 × 683: 2 W/sr times the colour.
            assert!(close(intensity, Vec3::new(2.0, 1.0, 2.0)), "{intensity}");
            assert_eq!((inner_cone, outer_cone, falloff), (0.3, 0.5, SpotFalloff::Blender));
            // 2049 lux = 3 × 683: 3 W/m².
            assert!(close(sun, Vec3::NEG_X) && close(irradiance, Vec3::splat(3.0)), "{sun} {irradiance}");
        }
        ref other => panic!("{other:?}"),
    }
    let other = load_json(&dir, "other.gltf", &lights_doc("some exporter", lights.clone())).unwrap();
    assert!(matches!(other.lights[0], PunctualLight::Spot { falloff: SpotFalloff::Gltf, .. }));
    // The reading the falloff follows is the scene's, for the rest of the file's differences.
    assert_eq!((blender.reading, other.reading), (GltfReading::Blender, GltfReading::Spec));

    let bytes = |doc: &Value| serde_json::to_vec(doc).unwrap();
    let mut wide = lights.clone();
    wide[0]["spot"]["outerConeAngle"] = json!(2.0);
    expect_error(
        &dir,
        "wide.gltf",
        &bytes(&lights_doc("x", wide)),
        &["light 0", "outerConeAngle 2 must be in (0, π/2]"],
    );
    let mut inverted = lights.clone();
    inverted[0]["spot"]["innerConeAngle"] = json!(0.6);
    expect_error(
        &dir,
        "inverted.gltf",
        &bytes(&lights_doc("x", inverted)),
        &["light 0", "innerConeAngle 0.6"],
    );
    let mut negative = lights;
    negative[1]["intensity"] = json!(-1);
    expect_error(
        &dir,
        "negative.gltf",
        &bytes(&lights_doc("x", negative)),
        &["light 1 ('sun')", "non-negative"],
    );
}
