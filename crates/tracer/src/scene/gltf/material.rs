//! glTF materials to [`Material`]: the metallic-roughness factors, `KHR_materials_specular` and
//! `KHR_materials_emissive_strength`. Texture slots are reported, not yet used.

use crate::material::Material;
use glam::Vec3;
use std::path::Path;

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

/// Converts one material, pushing a warning naming the texture slots it uses (ignored for now).
pub(super) fn convert(m: &gltf::Material, path: &Path, warnings: &mut Vec<String>) -> Material {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, _alpha] = pbr.base_color_factor();
    let specular = m.specular();
    let name = match (m.name(), m.index()) {
        (Some(n), _) if !n.is_empty() => n.to_owned(),
        (_, Some(i)) => format!("material{i}"),
        (_, None) => "glTF default".to_owned(),
    };

    let slots = [
        ("base colour", pbr.base_color_texture().is_some()),
        ("metallic-roughness", pbr.metallic_roughness_texture().is_some()),
        ("normal", m.normal_texture().is_some()),
        ("occlusion", m.occlusion_texture().is_some()),
        ("emissive", m.emissive_texture().is_some()),
        ("specular", specular.as_ref().is_some_and(|s| s.specular_texture().is_some())),
        ("specular colour", specular.as_ref().is_some_and(|s| s.specular_color_texture().is_some())),
    ];
    let used: Vec<&str> = slots.iter().filter(|(_, used)| *used).map(|(slot, _)| *slot).collect();
    if !used.is_empty() {
        warnings.push(format!(
            "{}: material '{name}': textures are not supported yet; ignoring the {} texture{}",
            path.display(),
            used.join(", "),
            if used.len() == 1 { "" } else { "s" }
        ));
    }
    if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
        warnings.push(format!(
            "{}: material '{name}': alpha mode {:?} is not supported; rendered opaque",
            path.display(),
            m.alpha_mode()
        ));
    }

    Material {
        base_color: Vec3::new(r, g, b),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        // Without the extension glTF's dielectric layer is the plain F0 = 0.04 one.
        specular: specular.as_ref().map_or(1.0, |s| s.specular_factor()),
        specular_color: specular.as_ref().map_or(Vec3::ONE, |s| Vec3::from(s.specular_color_factor())),
        emission: Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
        // A one-sided emitter must stay one-sided (NOTES.md: a two-sided Cornell light is too
        // bright), so emission follows `doubleSided`.
        emission_two_sided: m.double_sided(),
        name,
        ..Material::default()
    }
}
