//! glTF materials to [`Material`]: the metallic-roughness factors and textures (base colour,
//! metallic-roughness, emissive, normal with its `scale`), `alphaMode`/`alphaCutoff`,
//! `KHR_texture_transform` on every texture reference, `KHR_materials_emissive_strength`,
//! `KHR_materials_specular` and `KHR_materials_transmission` (factors and textures),
//! `KHR_materials_ior`, `KHR_materials_unlit` (as Blender imports it),
//! `KHR_materials_clearcoat` and `KHR_materials_sheen` (these two read from the raw JSON: the
//! gltf crate does not parse them).
//!
//! - `KHR_materials_sheen`: colour factor × texture, roughness factor × texture (A). Blender's
//!   reading renders it with Cycles' microfibre sheen (`bsdf/sheen.rs`), as Blender's importer
//!   sets it up (Sheen Weight 1, Sheen Tint the colour); the specification's with its Charlie
//!   sheen (`bsdf/charlie.rs`; [`SheenModel`], by [`apply_reading`]).
//!
//! - `KHR_materials_volume`: a transmissive material with `thicknessFactor` > 0 bounds a solid
//!   whose medium absorbs by Beer–Lambert ([`Material::attenuation`]); the thickness texture is
//!   a rasteriser's stand-in for the distance a path tracer measures through the mesh, so it is
//!   read for nothing. Two readings ([`GltfReading`], applied by [`apply_reading`] at load and
//!   again when `--gltf-reading` overrides the file's): the specification's, where thickness 0
//!   is a thin wall and σa = −ln(colour) / distance, and Blender's importer's, where every
//!   transmissive surface bounds a refracting solid and the colour and 1 / distance become a
//!   Volume Absorption node (Cycles: σa = (1 − colour) / distance). Transmission without the
//!   extension is a thin wall by the specification (the default thickness is 0) and a solid in
//!   Blender's reading; a file meant as solid glass says so with a thickness (the café does).
//! - `KHR_materials_anisotropy` (`anisotropy.rs`): strength, rotation and texture; the strength
//!   stretches the roughness as Blender's importer and Cycles do, or as the specification says
//!   ([`AnisotropyMapping`], by the reading).
//! - Occlusion textures are ignored without a word: a path tracer computes occlusion itself.
//! - `KHR_materials_specular` and `KHR_materials_transmission` textures multiply their factors.
//! - `KHR_materials_ior` also sets the dielectric F0 of the opaque lobes, as the extension
//!   defines it: F0 = ((ior − 1)/(ior + 1))² × specular colour. The material model's F0 is
//!   0.04 × `specular_color`, so the colour is scaled by F0(ior) / 0.04 (1 at the default 1.5).

use super::textures::{TextureLoader, UvTransform};
use crate::material::{AlphaMode, AnisotropyMapping, Material, MaterialTextures, SheenModel, Volume};
use crate::scene::GltfReading;
use crate::scene::images::ColorSpace;
use crate::texture::TextureRef;
use glam::Vec3;
use serde_json::Value;

/// `KHR_materials_volume` read from the material's raw JSON, as the file gives it (`None`
/// without the extension). `Err` names what is malformed.
fn volume(raw: Option<&Value>) -> Result<Option<Volume>, String> {
    let Some(v) = raw.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_materials_volume")) else {
        return Ok(None);
    };
    let number = |key: &str, default: f64| -> Result<f64, String> {
        match v.get(key) {
            None => Ok(default),
            Some(x) => x.as_f64().ok_or_else(|| format!("'{key}' must be a number, not {x}")),
        }
    };
    let thickness = number("thicknessFactor", 0.0)?;
    if !(thickness.is_finite() && thickness >= 0.0) {
        return Err(format!("'thicknessFactor' {thickness} must be ≥ 0"));
    }
    let distance = number("attenuationDistance", f64::INFINITY)?;
    if !(distance > 0.0) {
        return Err(format!("'attenuationDistance' {distance} must be > 0"));
    }
    let colour = match v.get("attenuationColor") {
        None => Vec3::ONE,
        Some(c) => match c.as_array().map(|a| a.iter().map(Value::as_f64).collect::<Vec<_>>()) {
            Some(a) if a.len() == 3 && a.iter().all(|x| x.is_some_and(|x| (0.0..=1.0).contains(&x))) => {
                Vec3::new(a[0].unwrap_or(1.0) as f32, a[1].unwrap_or(1.0) as f32, a[2].unwrap_or(1.0) as f32)
            }
            _ => return Err(format!("'attenuationColor' must be three numbers in [0, 1], not {c}")),
        },
    };
    Ok(Some(Volume { thickness: thickness as f32, colour, distance: distance as f32 }))
}

/// Sets `m`'s sheen lobe ([`SheenModel`]), anisotropy mapping ([`AnisotropyMapping`]), thin
/// wall and absorption in `reading`. From its `KHR_materials_volume`: the
/// specification makes thickness 0 a thin wall and σa = −ln(colour) / distance; Blender's
/// importer makes every transmissive surface bound a solid and builds a Volume Absorption node,
/// σa = (1 − colour) / distance in Cycles. Transmission without the extension is a thin wall by
/// the specification too, a solid in Blender's reading.
pub(crate) fn apply_reading(m: &mut Material, reading: GltfReading) {
    m.sheen_model = match reading {
        GltfReading::Blender => SheenModel::Cycles,
        GltfReading::Spec => SheenModel::Charlie,
    };
    if let Some(a) = &mut m.anisotropy {
        a.mapping = match reading {
            GltfReading::Blender => AnisotropyMapping::Blender,
            GltfReading::Spec => AnisotropyMapping::Spec,
        };
    }
    // By the specification a transmissive surface without a volume's thickness is a thin wall
    // (its extension's text: "the material is thin-walled" when thickness is 0, the default);
    // Blender's importer makes every one a refracting solid.
    let thin = m.volume.is_none_or(|v| v.thickness == 0.0);
    m.thin_walled = reading == GltfReading::Spec && m.transmission > 0.0 && thin;
    let Some(v) = m.volume else {
        m.attenuation = Vec3::ZERO;
        return;
    };
    m.attenuation = if v.distance.is_infinite() {
        Vec3::ZERO
    } else {
        match reading {
            GltfReading::Blender => (Vec3::ONE - v.colour) / v.distance,
            GltfReading::Spec => -v.colour.max(Vec3::splat(1e-6)).map(f32::ln) / v.distance,
        }
    };
}

/// The material glTF prescribes for primitives without one (spec §3.9.2): white, fully metallic,
/// fully rough. (`Material::default()` is a grey diffuse for other formats' missing materials.)
pub(super) fn gltf_default() -> Material {
    Material {
        name: "glTF default".to_owned(),
        base_color: Vec3::ONE,
        metallic: 1.0,
        roughness: 1.0,
        specular: 1.0,
        specular_color: Vec3::ONE,
        emission: Vec3::ZERO,
        emission_two_sided: false,
        ..Material::default()
    }
}

/// The material's name for messages (its own, else "material<i>").
pub(super) fn name_of(m: &gltf::Material) -> String {
    match (m.name(), m.index()) {
        (Some(n), _) if !n.is_empty() => n.to_owned(),
        (_, Some(i)) => format!("material{i}"),
        (_, None) => "glTF default".to_owned(),
    }
}

fn transform_of(info: &gltf::texture::Info) -> Option<UvTransform> {
    info.texture_transform().map(|t| UvTransform {
        offset: t.offset(),
        rotation: t.rotation(),
        scale: t.scale(),
        tex_coord: t.tex_coord(),
    })
}

/// `KHR_texture_transform` read from a texture reference's raw JSON (the gltf crate drops the
/// extensions of `normalTexture`). `Err` names what is malformed.
fn raw_transform(reference: Option<&Value>) -> Result<Option<UvTransform>, String> {
    let Some(t) = reference.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_texture_transform"))
    else {
        return Ok(None);
    };
    let pair = |key: &str, default: [f32; 2]| -> Result<[f32; 2], String> {
        match t.get(key) {
            None => Ok(default),
            Some(v) => match v.as_array().map(|a| a.iter().map(Value::as_f64).collect::<Vec<_>>()) {
                Some(a) if a.len() == 2 && a.iter().all(Option::is_some) => {
                    Ok([a[0].unwrap_or(0.0) as f32, a[1].unwrap_or(0.0) as f32])
                }
                _ => Err(format!("'{key}' must be an array of two numbers, not {v}")),
            },
        }
    };
    let rotation = match t.get("rotation") {
        None => 0.0,
        Some(v) => v.as_f64().ok_or_else(|| format!("'rotation' must be a number, not {v}"))? as f32,
    };
    let tex_coord = match t.get("texCoord") {
        None => None,
        Some(v) => Some(
            v.as_u64()
                .and_then(|n| u32::try_from(n).ok())
                .ok_or_else(|| format!("'texCoord' must be a non-negative integer, not {v}"))?,
        ),
    };
    Ok(Some(UvTransform {
        offset: pair("offset", [0.0; 2])?,
        rotation,
        scale: pair("scale", [1.0; 2])?,
        tex_coord,
    }))
}

/// Converts one material. `raw` is the material's JSON object (for what the gltf crate does not
/// parse). Textures are decoded through `textures`, which also collects the warnings. `Err` is a
/// message naming the material (the caller adds the file).
pub(super) fn convert(
    m: &gltf::Material,
    raw: Option<&Value>,
    textures: &mut TextureLoader,
    reading: GltfReading,
) -> Result<Material, String> {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, alpha] = pbr.base_color_factor();
    let specular = m.specular();
    let name = name_of(m);
    let label = format!("material '{name}'");

    let mut slots = MaterialTextures::default();
    // A slot's reference from its texture info: the info's own coordinate set and transform.
    let mut slot = |info: Option<gltf::texture::Info>, what: &str, space: ColorSpace| {
        let info = info?;
        let user = format!("{label}, {what}");
        textures.reference(&info.texture(), info.tex_coord(), transform_of(&info), space, &user)
    };
    slots.base_color = slot(pbr.base_color_texture(), "base colour texture", ColorSpace::Srgb);
    slots.metallic_roughness =
        slot(pbr.metallic_roughness_texture(), "metallic-roughness texture", ColorSpace::Linear);
    slots.emissive = slot(m.emissive_texture(), "emissive texture", ColorSpace::Srgb);
    // KHR_materials_specular's and KHR_materials_transmission's textures multiply their
    // factors (specular in A, its colour in sRGB RGB, transmission in R).
    let transmission = m.transmission();
    slots.specular = slot(
        specular.as_ref().and_then(|s| s.specular_texture()),
        "KHR_materials_specular specularTexture",
        ColorSpace::Linear,
    );
    slots.specular_color = slot(
        specular.as_ref().and_then(|s| s.specular_color_texture()),
        "KHR_materials_specular specularColorTexture",
        ColorSpace::Srgb,
    );
    slots.transmission = slot(
        transmission.as_ref().and_then(|t| t.transmission_texture()),
        "KHR_materials_transmission transmissionTexture",
        ColorSpace::Linear,
    );
    if let Some(normal) = m.normal_texture() {
        let user = format!("{label}, normal texture");
        let transform = match raw_transform(raw.and_then(|r| r.get("normalTexture"))) {
            Ok(t) => t,
            Err(e) => {
                textures.warn(format!("{user}: malformed KHR_texture_transform ({e}); ignored"));
                None
            }
        };
        let scale = normal.scale();
        let scale = if scale.is_finite() {
            scale
        } else {
            textures.warn(format!("{user}: scale {scale} is not finite; 1 is used"));
            1.0
        };
        slots.normal = textures
            .reference(&normal.texture(), normal.tex_coord(), transform, ColorSpace::Linear, &user)
            .map(|r| (r, scale));
    }
    // Occlusion: ignored on purpose (path tracing computes it).

    let alpha_mode = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
        gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        gltf::material::AlphaMode::Mask => {
            let cutoff = m.alpha_cutoff().unwrap_or(0.5);
            if !(cutoff.is_finite() && cutoff >= 0.0) {
                return Err(format!("{label}: alphaCutoff {cutoff} is out of range (it must be ≥ 0)"));
            }
            if cutoff > 1.0 {
                textures.warn(format!(
                    "{label}: alphaCutoff {cutoff} is above 1, so no alpha passes it: the surface is invisible"
                ));
            }
            AlphaMode::Mask { cutoff }
        }
    };
    if !(0.0..=1.0).contains(&alpha) {
        return Err(format!("{label}: baseColorFactor alpha {alpha} is outside [0, 1]"));
    }

    let mut ior = m.ior().unwrap_or(1.5);
    if !(ior.is_finite() && ior >= 1.0) {
        textures.warn(format!("{label}: KHR_materials_ior ior {ior} is below 1; the default 1.5 is used"));
        ior = 1.5;
    }
    // Exactly 1 at the default, so files without the extension keep their factors bit for bit.
    let f0_scale = if ior == 1.5 { 1.0 } else { ((ior - 1.0) / (ior + 1.0)).powi(2) / 0.04 };
    let transmission = transmission.map_or(0.0, |t| t.transmission_factor());
    let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
    let volume = match volume(raw) {
        Ok(v) => v,
        Err(e) => {
            textures.warn(format!("{label}: malformed KHR_materials_volume ({e}); it is ignored"));
            None
        }
    };

    let (coat, coat_roughness) = clearcoat(raw, textures, &label, &mut slots)?;
    let (sheen, sheen_roughness) = sheen(raw, textures, &label, &mut slots)?;
    let anisotropy = super::anisotropy::anisotropy(raw, textures, &label, &mut slots)?;

    // KHR_materials_unlit: Blender imports it as an emission of the base colour that camera
    // rays alone see (a Light Path "Is Camera Ray" mix with a transparent BSDF); the emissive
    // factors do not take part.
    let unlit = raw.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_materials_unlit")).is_some();
    let mut material = Material {
        base_color: Vec3::new(r, g, b),
        unlit,
        metallic,
        roughness,
        // Without the extension glTF's dielectric layer is the plain F0 = 0.04 one.
        specular: specular.as_ref().map_or(1.0, |s| s.specular_factor()),
        specular_color: specular.as_ref().map_or(Vec3::ONE, |s| Vec3::from(s.specular_color_factor()))
            * f0_scale,
        emission: if unlit {
            Vec3::ZERO
        } else {
            Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0)
        },
        // A one-sided emitter must stay one-sided (docs/design/tracer.md §3.9: a two-sided Cornell light
        // is too bright), so emission follows `doubleSided`.
        emission_two_sided: m.double_sided(),
        alpha,
        alpha_mode,
        transmission,
        ior,
        coat,
        coat_roughness,
        sheen,
        sheen_roughness,
        sheen_model: SheenModel::Cycles,
        volume,
        thin_walled: false,
        attenuation: Vec3::ZERO,
        anisotropy,
        textures: slots,
        name,
    };
    apply_reading(&mut material, reading);
    Ok(material)
}

/// A texture reference read from raw JSON (`{"index", "texCoord", "extensions"}`, as the gltf
/// crate leaves extensions it does not parse): `None`, warned, when it is malformed.
pub(super) fn raw_reference(
    info: Option<&Value>,
    textures: &mut TextureLoader,
    space: ColorSpace,
    user: &str,
) -> Option<TextureRef> {
    let info = info?;
    let texture = info.get("index").and_then(Value::as_u64).and_then(|i| textures.texture(i as usize));
    let Some(texture) = texture else {
        textures.warn(format!(
            "{user}: 'index' {} names no texture; ignored",
            info.get("index").unwrap_or(&Value::Null)
        ));
        return None;
    };
    let tex_coord = match info.get("texCoord") {
        None => 0,
        Some(v) => match v.as_u64().and_then(|n| u32::try_from(n).ok()) {
            Some(n) => n,
            None => {
                textures.warn(format!("{user}: 'texCoord' {v} is not a non-negative integer; ignored"));
                return None;
            }
        },
    };
    let transform = match raw_transform(Some(info)) {
        Ok(t) => t,
        Err(e) => {
            textures.warn(format!("{user}: malformed KHR_texture_transform ({e}); ignored"));
            None
        }
    };
    textures.reference(&texture, tex_coord, transform, space, user)
}

/// `KHR_materials_clearcoat` of the material whose raw JSON is `raw`: its (factor, roughness)
/// (0, 0 without the extension), and its three textures into `slots`. `Err` names a factor that
/// is not a number in [0, 1].
fn clearcoat(
    raw: Option<&Value>,
    textures: &mut TextureLoader,
    label: &str,
    slots: &mut MaterialTextures,
) -> Result<(f32, f32), String> {
    let Some(ext) = raw.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_materials_clearcoat"))
    else {
        return Ok((0.0, 0.0));
    };
    let factor = |key: &str| -> Result<f32, String> {
        match ext.get(key) {
            None => Ok(0.0),
            Some(v) => match v.as_f64() {
                Some(x) if (0.0..=1.0).contains(&x) => Ok(x as f32),
                _ => Err(format!("{label}: KHR_materials_clearcoat {key} {v} is not a number in [0, 1]")),
            },
        }
    };
    let (coat, roughness) = (factor("clearcoatFactor")?, factor("clearcoatRoughnessFactor")?);
    let user = |what: &str| format!("{label}, KHR_materials_clearcoat {what}");
    slots.coat =
        raw_reference(ext.get("clearcoatTexture"), textures, ColorSpace::Linear, &user("clearcoatTexture"));
    slots.coat_roughness = raw_reference(
        ext.get("clearcoatRoughnessTexture"),
        textures,
        ColorSpace::Linear,
        &user("clearcoatRoughnessTexture"),
    );
    let normal = ext.get("clearcoatNormalTexture");
    if let Some(r) = raw_reference(normal, textures, ColorSpace::Linear, &user("clearcoatNormalTexture")) {
        let scale = normal.and_then(|n| n.get("scale")).map_or(Some(1.0), Value::as_f64);
        let scale = match scale {
            Some(s) if s.is_finite() => s as f32,
            _ => {
                textures.warn(format!(
                    "{}: scale is not a finite number; 1 is used",
                    user("clearcoatNormalTexture")
                ));
                1.0
            }
        };
        slots.coat_normal = Some((r, scale));
    }
    Ok((coat, roughness))
}

/// `KHR_materials_sheen` of the material whose raw JSON is `raw`: its (colour, roughness)
/// factors (black, 0 without the extension: no sheen), and its two textures into `slots`.
/// `Err` names a factor that is not a number (or three) in [0, 1].
fn sheen(
    raw: Option<&Value>,
    textures: &mut TextureLoader,
    label: &str,
    slots: &mut MaterialTextures,
) -> Result<(Vec3, f32), String> {
    let Some(ext) = raw.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_materials_sheen")) else {
        return Ok((Vec3::ZERO, 0.0));
    };
    let unit = |v: &Value| v.as_f64().filter(|x| (0.0..=1.0).contains(x)).map(|x| x as f32);
    let color = match ext.get("sheenColorFactor") {
        None => Vec3::ZERO,
        Some(v) => match v.as_array().map(|a| a.iter().map(unit).collect::<Option<Vec<_>>>()) {
            Some(Some(c)) if c.len() == 3 => Vec3::new(c[0], c[1], c[2]),
            _ => {
                return Err(format!(
                    "{label}: KHR_materials_sheen sheenColorFactor {v} is not three numbers in [0, 1]"
                ));
            }
        },
    };
    let roughness = match ext.get("sheenRoughnessFactor") {
        None => 0.0,
        Some(v) => unit(v).ok_or_else(|| {
            format!("{label}: KHR_materials_sheen sheenRoughnessFactor {v} is not a number in [0, 1]")
        })?,
    };
    for (key, space, slot) in [
        ("sheenColorTexture", ColorSpace::Srgb, &mut slots.sheen_color),
        ("sheenRoughnessTexture", ColorSpace::Linear, &mut slots.sheen_roughness),
    ] {
        *slot = raw_reference(ext.get(key), textures, space, &format!("{label}, KHR_materials_sheen {key}"));
    }
    Ok((color, roughness))
}
