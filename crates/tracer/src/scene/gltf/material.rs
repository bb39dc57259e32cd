//! glTF materials to [`Material`]: the metallic-roughness factors and textures (base colour,
//! metallic-roughness, emissive, normal with its `scale`), `alphaMode`/`alphaCutoff`,
//! `KHR_texture_transform` on every texture reference, `KHR_materials_emissive_strength`,
//! `KHR_materials_specular` and `KHR_materials_transmission` (factors and textures),
//! `KHR_materials_ior` and `KHR_materials_unlit` (as Blender imports it).
//!
//! - `KHR_materials_volume`: a transmissive material with `thicknessFactor` > 0 bounds a solid
//!   whose medium absorbs by Beer–Lambert ([`Material::attenuation`]); the thickness texture is
//!   a rasteriser's stand-in for the distance a path tracer measures through the mesh, so it is
//!   read for nothing. Two readings (see [`Reading`]): the specification's, where thickness 0
//!   is a thin wall and σa = −ln(colour) / distance, and Blender's importer's, where every
//!   transmissive surface bounds a refracting solid and the colour and 1 / distance become a
//!   Volume Absorption node (Cycles: σa = (1 − colour) / distance). Transmission without the
//!   extension is a solid in both for now (the specification's thin wall there waits for the
//!   reading flag: it would change the café's glass).
//! - Occlusion textures are ignored without a word: a path tracer computes occlusion itself.
//! - `KHR_materials_specular` and `KHR_materials_transmission` textures multiply their factors.
//! - `KHR_materials_ior` also sets the dielectric F0 of the opaque lobes, as the extension
//!   defines it: F0 = ((ior − 1)/(ior + 1))² × specular colour. The material model's F0 is
//!   0.04 × `specular_color`, so the colour is scaled by F0(ior) / 0.04 (1 at the default 1.5).

use super::textures::{TextureLoader, UvTransform};
use crate::material::{AlphaMode, Material, MaterialTextures};
use crate::scene::images::ColorSpace;
use glam::Vec3;
use serde_json::Value;

/// Whose reading of the file's transmission and volume the material follows: Blender's
/// importer's for files Blender wrote (`asset.generator`), the specification's otherwise, as the
/// spot falloff does (module docs of `gltf`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Reading {
    /// The glTF specification's.
    Spec,
    /// Blender's glTF importer rendered by Cycles.
    Blender,
}

/// `KHR_materials_volume` read from the material's raw JSON: (thin wall, absorption σa). `Err`
/// names what is malformed.
fn volume(raw: Option<&Value>, reading: Reading) -> Result<(bool, Vec3), String> {
    let Some(v) = raw.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_materials_volume")) else {
        // The specification makes such a surface a thin wall, Blender a solid. Until the
        // command line chooses the reading (issue 39's "two readings" flag), every file keeps
        // the solid, as before: the café's glass (not from Blender) must not change.
        return Ok((false, Vec3::ZERO));
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
    let thin = reading == Reading::Spec && thickness == 0.0;
    let sigma = if distance.is_infinite() {
        Vec3::ZERO
    } else {
        let d = distance as f32;
        match reading {
            // Cycles' Volume Absorption: σa = (1 − colour) · density, density = 1 / distance.
            Reading::Blender => (Vec3::ONE - colour) / d,
            // The specification: the colour is what remains after the distance.
            Reading::Spec => -colour.max(Vec3::splat(1e-6)).map(f32::ln) / d,
        }
    };
    Ok((thin, sigma))
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
    reading: Reading,
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
    let (thin_walled, attenuation) = match volume(raw, reading) {
        Ok(v) => v,
        Err(e) => {
            textures.warn(format!("{label}: malformed KHR_materials_volume ({e}); it is ignored"));
            (false, Vec3::ZERO)
        }
    };

    // KHR_materials_unlit: Blender imports it as an emission of the base colour that camera
    // rays alone see (a Light Path "Is Camera Ray" mix with a transparent BSDF); the emissive
    // factors do not take part.
    let unlit = raw.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_materials_unlit")).is_some();
    Ok(Material {
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
        // A one-sided emitter must stay one-sided (docs/design.md §3.9: a two-sided Cornell light
        // is too bright), so emission follows `doubleSided`.
        emission_two_sided: m.double_sided(),
        alpha,
        alpha_mode,
        transmission,
        ior,
        thin_walled,
        attenuation,
        textures: slots,
        name,
    })
}
