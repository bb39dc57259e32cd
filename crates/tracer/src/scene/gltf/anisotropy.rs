//! `KHR_materials_anisotropy` read from a material's raw JSON (the gltf crate does not parse
//! it): `anisotropyStrength`, `anisotropyRotation` and `anisotropyTexture`. The mapping of the
//! strength onto the roughness follows the file's reading ([`AnisotropyMapping`], set by
//! `apply_reading`); the tangents it turns are the mesh's `TANGENT`, or MikkTSpace's from the
//! texture coordinates (`scene::tangents`).

use super::material::raw_reference;
use super::textures::TextureLoader;
use crate::material::{Anisotropy, AnisotropyMapping, MaterialTextures};
use crate::scene::images::ColorSpace;
use serde_json::Value;

/// The material's anisotropy (`None` without the extension, or when it cannot change the
/// picture: strength 0 and no texture), its texture into `slots`. `Err` names a strength outside
/// [0, 1] or a rotation that is not a finite number.
pub(super) fn anisotropy(
    raw: Option<&Value>,
    textures: &mut TextureLoader,
    label: &str,
    slots: &mut MaterialTextures,
) -> Result<Option<Anisotropy>, String> {
    let Some(ext) = raw.and_then(|r| r.get("extensions")).and_then(|e| e.get("KHR_materials_anisotropy"))
    else {
        return Ok(None);
    };
    let strength = match ext.get("anisotropyStrength") {
        None => 0.0,
        Some(v) => match v.as_f64() {
            Some(x) if (0.0..=1.0).contains(&x) => x as f32,
            _ => {
                return Err(format!(
                    "{label}: KHR_materials_anisotropy anisotropyStrength {v} is not a number in [0, 1]"
                ));
            }
        },
    };
    let rotation = match ext.get("anisotropyRotation") {
        None => 0.0,
        Some(v) => match v.as_f64() {
            Some(x) if x.is_finite() => x as f32,
            _ => {
                return Err(format!(
                    "{label}: KHR_materials_anisotropy anisotropyRotation {v} is not a finite number"
                ));
            }
        },
    };
    let user = format!("{label}, KHR_materials_anisotropy anisotropyTexture");
    slots.anisotropy = raw_reference(ext.get("anisotropyTexture"), textures, ColorSpace::Linear, &user);
    if strength == 0.0 && slots.anisotropy.is_none() {
        return Ok(None);
    }
    Ok(Some(Anisotropy { strength, rotation, mapping: AnisotropyMapping::default() }))
}
