//! Materials as scenes describe them: the glTF 2.0 metallic-roughness model (glTF spec,
//! Appendix B) with its textures, alpha modes, `KHR_materials_specular`,
//! `KHR_materials_emissive_strength`, `KHR_materials_transmission`, `KHR_materials_ior` and
//! `KHR_materials_clearcoat`, `KHR_materials_sheen`, `KHR_materials_volume` and
//! `KHR_materials_anisotropy`.
//! OBJ/MTL materials map onto the same parameters (see `scene::obj`). The BSDF built from these
//! parameters at a hit lives in `crate::bsdf`.

use crate::texture::TextureRef;
use glam::Vec3;

/// How a material's alpha (base colour alpha × texture alpha) is used (glTF `alphaMode`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored.
    #[default]
    Opaque,
    /// Surfaces with alpha below the cut-off are absent (cut-outs, e.g. leaves).
    Mask {
        /// `alphaCutoff` (glTF default 0.5).
        cutoff: f32,
    },
    /// Partly transparent: a ray passes through with probability 1 − alpha.
    Blend,
}

/// Texture slots of a material; each multiplies its factor (glTF §3.9).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// sRGB base colour (RGB) and alpha (A).
    pub base_color: Option<TextureRef>,
    /// Linear: roughness in G, metallic in B.
    pub metallic_roughness: Option<TextureRef>,
    /// sRGB emissive colour.
    pub emissive: Option<TextureRef>,
    /// Tangent-space normal map (linear) and its `scale`.
    pub normal: Option<(TextureRef, f32)>,
    /// `KHR_materials_specular` `specularTexture`: linear, the specular factor in A.
    pub specular: Option<TextureRef>,
    /// `KHR_materials_specular` `specularColorTexture`: sRGB, the F0 tint in RGB.
    pub specular_color: Option<TextureRef>,
    /// `KHR_materials_transmission` `transmissionTexture`: linear, the factor in R.
    pub transmission: Option<TextureRef>,
    /// `KHR_materials_clearcoat` `clearcoatTexture`: linear, the factor in R.
    pub coat: Option<TextureRef>,
    /// `KHR_materials_clearcoat` `clearcoatRoughnessTexture`: linear, the roughness in G.
    pub coat_roughness: Option<TextureRef>,
    /// `KHR_materials_clearcoat` `clearcoatNormalTexture` (linear) and its `scale`: the coat's
    /// own normal map (without one the coat follows the unmapped surface, as in Blender).
    pub coat_normal: Option<(TextureRef, f32)>,
    /// `KHR_materials_sheen` `sheenColorTexture`: sRGB, the sheen colour in RGB.
    pub sheen_color: Option<TextureRef>,
    /// `KHR_materials_sheen` `sheenRoughnessTexture`: linear, the roughness in A.
    pub sheen_roughness: Option<TextureRef>,
    /// `KHR_materials_anisotropy` `anisotropyTexture`: linear, the direction in RG (mapped to
    /// [−1, 1], in the tangent frame) and the strength in B.
    pub anisotropy: Option<TextureRef>,
}

impl MaterialTextures {
    /// True when no slot holds a texture.
    pub fn is_empty(&self) -> bool {
        self.base_color.is_none()
            && self.metallic_roughness.is_none()
            && self.emissive.is_none()
            && self.normal.is_none()
            && self.specular.is_none()
            && self.specular_color.is_none()
            && self.transmission.is_none()
            && self.coat.is_none()
            && self.coat_roughness.is_none()
            && self.coat_normal.is_none()
            && self.sheen_color.is_none()
            && self.sheen_roughness.is_none()
            && self.anisotropy.is_none()
    }

    /// Every slot's reference (the normal maps' without their scale).
    pub fn all(&self) -> [Option<TextureRef>; 13] {
        [
            self.base_color,
            self.metallic_roughness,
            self.emissive,
            self.normal.map(|n| n.0),
            self.specular,
            self.specular_color,
            self.transmission,
            self.coat,
            self.coat_roughness,
            self.coat_normal.map(|n| n.0),
            self.sheen_color,
            self.sheen_roughness,
            self.anisotropy,
        ]
    }
}

/// `KHR_materials_volume`'s parameters, as the file gives them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Volume {
    /// `thicknessFactor`: 0 makes the surface a thin wall in the specification's reading.
    pub thickness: f32,
    /// `attenuationColor`: what white light keeps after `distance` inside.
    pub colour: Vec3,
    /// `attenuationDistance` (infinite: no absorption).
    pub distance: f32,
}

/// How an anisotropy strength s stretches the GGX roughness α = roughness² along the tangent:
/// the two readings of `KHR_materials_anisotropy` (docs/cycles.md, "Two readings of one file").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AnisotropyMapping {
    /// Blender's importer: s becomes the Principled BSDF's Anisotropic input, which Cycles maps
    /// to α_t = α / a, α_b = α · a with a = √(1 − 0.9 s) (the area α_t·α_b stays α²).
    #[default]
    Blender,
    /// The specification: α_t = mix(α, 1, s²), α_b = α.
    Spec,
}

impl AnisotropyMapping {
    /// (α along the tangent, α along the bitangent) for perceptual `roughness` and strength
    /// `strength` in [0, 1], before the GGX lobe's lower bound on α.
    pub fn alphas(self, roughness: f32, strength: f32) -> (f32, f32) {
        let alpha = roughness * roughness;
        let s = strength.clamp(0.0, 1.0);
        match self {
            Self::Blender => {
                let aspect = (1.0 - 0.9 * s).sqrt();
                (alpha / aspect, alpha * aspect)
            }
            Self::Spec => (alpha + (1.0 - alpha) * s * s, alpha),
        }
    }
}

/// `KHR_materials_anisotropy`'s factors: the specular lobes' roughness stretched along a
/// direction in the tangent plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anisotropy {
    /// `anisotropyStrength` in [0, 1] (times the texture's B).
    pub strength: f32,
    /// `anisotropyRotation`: radians counter-clockwise from the tangent towards the bitangent.
    pub rotation: f32,
    /// How the strength stretches the roughness (by the file's reading).
    pub mapping: AnisotropyMapping,
}

/// The lobe `KHR_materials_sheen` is rendered with: the extension's two readings (docs/cycles.md,
/// "Two readings of one file").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SheenModel {
    /// Cycles' microfibre lobe, as Blender's importer renders the extension (`bsdf/sheen.rs`).
    #[default]
    Cycles,
    /// The specification's Charlie sheen (`bsdf/charlie.rs`).
    Charlie,
}

/// A surface material: linear-RGB factors of the glTF metallic-roughness model.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name from the scene file, for messages.
    pub name: String,
    /// Base colour (linear RGB): diffuse albedo of dielectrics, F0 of metals.
    pub base_color: Vec3,
    /// 0 = dielectric, 1 = metal; values between blend the two BSDFs.
    pub metallic: f32,
    /// Perceptual roughness in [0, 1]; the GGX α is its square.
    pub roughness: f32,
    /// `KHR_materials_specular` `specularFactor`: strength of the dielectric specular layer and
    /// its grazing reflectance F90 (0 leaves a pure Lambertian dielectric).
    pub specular: f32,
    /// `KHR_materials_specular` `specularColorFactor`: tints the dielectric F0 (0.04 × this,
    /// clamped to 1); black leaves the layer's grazing rim (F90 is the factor).
    pub specular_color: Vec3,
    /// Emitted radiance (glTF `emissiveFactor` × `emissiveStrength`; MTL `Ke`).
    pub emission: Vec3,
    /// Whether emission leaves both faces (glTF `doubleSided`); otherwise only the front face,
    /// the one whose counter-clockwise winding faces the viewer.
    pub emission_two_sided: bool,
    /// Base colour alpha factor.
    pub alpha: f32,
    /// How alpha is used.
    pub alpha_mode: AlphaMode,
    /// `KHR_materials_transmission` factor: the share of the dielectric's diffuse part that
    /// refracts through the surface instead (glass: 1).
    pub transmission: f32,
    /// `KHR_materials_ior` index of refraction (glTF default 1.5).
    pub ior: f32,
    /// `KHR_materials_clearcoat` `clearcoatFactor`: the weight of a clear dielectric coat
    /// (index 1.5, untinted, as Blender's Principled coat imports it) over everything else.
    pub coat: f32,
    /// `KHR_materials_clearcoat` `clearcoatRoughnessFactor`: the coat's perceptual roughness.
    pub coat_roughness: f32,
    /// `KHR_materials_sheen` `sheenColorFactor`: the colour of the sheen over everything else
    /// (Blender's importer: Cycles' Sheen Weight 1, Sheen Tint this colour). Black: no sheen.
    pub sheen: Vec3,
    /// `KHR_materials_sheen` `sheenRoughnessFactor`: the sheen's roughness.
    pub sheen_roughness: f32,
    /// The sheen's lobe, by the file's reading.
    pub sheen_model: SheenModel,
    /// `KHR_materials_volume` as the file gives it; [`Material::thin_walled`] and
    /// [`Material::attenuation`] are derived from it in the file's reading.
    pub volume: Option<Volume>,
    /// The transmissive surface is a thin wall, not the boundary of a solid: light passes
    /// through unbent (the glTF spec's reading of transmission without `KHR_materials_volume`,
    /// or with `thicknessFactor` 0); otherwise it refracts into the enclosed medium.
    pub thin_walled: bool,
    /// Absorption coefficient σa (per world unit, linear RGB) of the medium a closed
    /// transmissive mesh encloses (`KHR_materials_volume`, as Cycles' Volume Absorption): light
    /// inside keeps exp(−σa·distance). Zero: clear.
    pub attenuation: Vec3,
    /// `KHR_materials_unlit`, as Blender imports it: camera rays see the base colour (× texture
    /// × vertex colour) as emitted radiance and end there; every other ray passes through, so
    /// the surface neither lights nor shadows the scene.
    pub unlit: bool,
    /// `KHR_materials_anisotropy`; `None` without the extension (or with zero strength and no
    /// texture), which costs nothing: no tangents are generated or looked up for it.
    pub anisotropy: Option<Anisotropy>,
    /// Texture slots.
    pub textures: MaterialTextures,
}

impl Default for Material {
    /// glTF's default material: white, fully metallic, fully rough (spec §3.9.2) — but as the
    /// default for *missing* materials we follow renderers' practice of a grey diffuse surface.
    fn default() -> Self {
        Self {
            name: "default".to_owned(),
            base_color: Vec3::splat(0.8),
            metallic: 0.0,
            roughness: 1.0,
            specular: 0.0,
            specular_color: Vec3::ONE,
            emission: Vec3::ZERO,
            emission_two_sided: false,
            alpha: 1.0,
            alpha_mode: AlphaMode::Opaque,
            transmission: 0.0,
            ior: 1.5,
            coat: 0.0,
            coat_roughness: 0.0,
            sheen: Vec3::ZERO,
            sheen_roughness: 0.0,
            sheen_model: SheenModel::Cycles,
            volume: None,
            thin_walled: false,
            attenuation: Vec3::ZERO,
            unlit: false,
            anisotropy: None,
            textures: MaterialTextures::default(),
        }
    }
}

impl Material {
    /// A two-sided Lambertian surface with the given albedo (no specular layer).
    pub fn diffuse(name: &str, albedo: Vec3) -> Self {
        Self { name: name.to_owned(), base_color: albedo, ..Self::default() }
    }

    /// True when the material emits light.
    pub fn is_emissive(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// True when the material has a specular (GGX) lobe at all. (A metallic-roughness texture
    /// can only scale the metallic factor, so the factor decides.)
    pub fn has_specular(&self) -> bool {
        self.metallic > 0.0 || self.specular > 0.0 || self.transmission > 0.0 || self.coat > 0.0
    }

    /// True when the material has a sheen layer.
    pub fn has_sheen(&self) -> bool {
        self.sheen != Vec3::ZERO
    }

    /// True when the material's transmission encloses an absorbing medium.
    pub fn has_volume(&self) -> bool {
        self.transmission > 0.0 && !self.thin_walled && self.attenuation != Vec3::ZERO
    }

    /// True when some of the surface may be missing for some rays (alpha mask or blend, or an
    /// unlit surface, which only camera rays see).
    pub fn has_alpha(&self) -> bool {
        !matches!(self.alpha_mode, AlphaMode::Opaque) || self.unlit
    }

    /// Checks the factors are finite and in range; returns what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let finite = self.base_color.is_finite()
            && self.metallic.is_finite()
            && self.roughness.is_finite()
            && self.specular.is_finite()
            && self.specular_color.is_finite()
            && self.emission.is_finite()
            && self.coat.is_finite()
            && self.coat_roughness.is_finite()
            && self.sheen.is_finite()
            && self.sheen_roughness.is_finite()
            && self.attenuation.is_finite()
            && self.anisotropy.is_none_or(|a| a.strength.is_finite() && a.rotation.is_finite());
        if !finite {
            return Err(format!("material '{}' has a non-finite factor", self.name));
        }
        if self.base_color.min_element() < 0.0
            || self.emission.min_element() < 0.0
            || self.specular_color.min_element() < 0.0
            || self.attenuation.min_element() < 0.0
            || self.sheen.min_element() < 0.0
        {
            return Err(format!("material '{}' has a negative colour", self.name));
        }
        if !(self.ior.is_finite() && self.ior >= 1.0) {
            return Err(format!("material '{}': index of refraction {} must be ≥ 1", self.name, self.ior));
        }
        if let AlphaMode::Mask { cutoff } = self.alpha_mode
            && (!cutoff.is_finite() || cutoff < 0.0)
        {
            return Err(format!("material '{}': alpha cut-off {cutoff} must be ≥ 0", self.name));
        }
        for (what, v) in [
            ("metallic", self.metallic),
            ("roughness", self.roughness),
            ("specular", self.specular),
            ("alpha", self.alpha),
            ("transmission", self.transmission),
            ("coat", self.coat),
            ("coat roughness", self.coat_roughness),
            ("sheen roughness", self.sheen_roughness),
            ("anisotropy strength", self.anisotropy.map_or(0.0, |a| a.strength)),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(format!("material '{}': {what} {v} is outside [0, 1]", self.name));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The figures: roughness 0.3 with anisotropy 0.8 becomes α 0.170 / 0.048 in
    /// Blender's reading (Cycles' Principled BSDF) and 0.672 / 0.090 in the specification's;
    /// strength 0 leaves α = roughness² in both, and strength 1 at roughness 1 stays within α 1 in
    /// the specification's.
    #[test]
    fn anisotropy_mappings_match_blender_and_the_specification() {
        let round = |(t, b): (f32, f32)| ((t * 1000.0).round() / 1000.0, (b * 1000.0).round() / 1000.0);
        assert_eq!(round(AnisotropyMapping::Blender.alphas(0.3, 0.8)), (0.170, 0.048));
        assert_eq!(round(AnisotropyMapping::Spec.alphas(0.3, 0.8)), (0.672, 0.090));
        for m in [AnisotropyMapping::Blender, AnisotropyMapping::Spec] {
            assert_eq!(m.alphas(0.5, 0.0), (0.25, 0.25), "{m:?}");
        }
        assert_eq!(AnisotropyMapping::Spec.alphas(1.0, 1.0), (1.0, 1.0));
        let (t, b) = AnisotropyMapping::Blender.alphas(0.4, 0.6);
        assert!((t * b - 0.4f32.powi(4)).abs() < 1e-7, "Blender keeps the area α_t·α_b = α²");
    }
}
