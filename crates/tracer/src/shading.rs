//! A material evaluated at a hit (glTF 2.0 §3.9): factors times textures, alpha, and the
//! shading normal perturbed by a tangent-space normal map. Slots without a texture cost
//! nothing: each lookup happens only when its `TextureRef` is present.

use crate::material::Material;
use crate::texture::Texture;
use glam::{Vec2, Vec3, Vec4};

/// Tangent frame data at a hit, for normal mapping.
#[derive(Clone, Copy, Debug)]
pub struct TangentFrame {
    /// Interpolated vertex tangent (xyz, w = bitangent sign), if the mesh has tangents.
    pub tangent: Option<Vec4>,
    /// ∂p/∂u of the triangle (world space), for tangents derived from texture coordinates.
    pub dpdu: Vec3,
    /// ∂p/∂v of the triangle.
    pub dpdv: Vec3,
}

/// The material's parameters at one surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingPoint {
    /// Linear base colour.
    pub base_color: Vec3,
    /// Coverage (base colour alpha × texture alpha).
    pub alpha: f32,
    /// Metalness.
    pub metallic: f32,
    /// Perceptual roughness.
    pub roughness: f32,
    /// Emitted radiance.
    pub emission: Vec3,
    /// Shading normal (unit, same side as the interpolated normal).
    pub normal: Vec3,
    /// Dielectric specular weight (`KHR_materials_specular` factor × texture A).
    pub specular: f32,
    /// Dielectric specular tint (factor × texture RGB).
    pub specular_color: Vec3,
    /// Transmission (factor × texture R).
    pub transmission: f32,
    /// Coat weight (`KHR_materials_clearcoat` factor × texture R).
    pub coat: f32,
    /// Coat perceptual roughness (factor × texture G).
    pub coat_roughness: f32,
    /// The coat's normal: its own normal map's, else the surface's without the base's map
    /// (Blender's Coat Normal defaults to the unmapped normal).
    pub coat_normal: Vec3,
    /// Sheen colour (`KHR_materials_sheen` factor × texture RGB); black: no sheen.
    pub sheen: Vec3,
    /// Sheen roughness (factor × texture A).
    pub sheen_roughness: f32,
    /// `KHR_materials_anisotropy` strength (factor × texture B); 0 without anisotropy.
    pub anisotropy: f32,
    /// The anisotropy direction (unit, perpendicular to `normal`): the tangent turned by the
    /// rotation and the texture's direction; unused (zero) without anisotropy.
    pub anisotropy_direction: Vec3,
}

impl ShadingPoint {
    /// The untextured material's values, with shading normal `normal`.
    #[inline(always)]
    pub fn of(material: &Material, normal: Vec3) -> Self {
        Self {
            base_color: material.base_color,
            alpha: material.alpha,
            metallic: material.metallic,
            roughness: material.roughness,
            emission: material.emission,
            normal,
            specular: material.specular,
            specular_color: material.specular_color,
            transmission: material.transmission,
            coat: material.coat,
            coat_roughness: material.coat_roughness,
            coat_normal: normal,
            sheen: material.sheen,
            sheen_roughness: material.sheen_roughness,
            anisotropy: 0.0,
            anisotropy_direction: Vec3::ZERO,
        }
    }
}

/// Evaluates `material` at texture coordinates `uv` (sets 0, 1) with interpolated shading
/// normal `n` (unit) and the tangent frame `frame` (used only with a normal map).
#[inline]
pub fn evaluate(
    material: &Material,
    textures: &[Texture],
    uv: [Vec2; 2],
    n: Vec3,
    frame: &TangentFrame,
) -> ShadingPoint {
    let t = &material.textures;
    let mut base = material.base_color.extend(material.alpha);
    if let Some(r) = &t.base_color {
        base *= r.eval(textures, uv);
    }
    let (mut metallic, mut roughness) = (material.metallic, material.roughness);
    if let Some(r) = &t.metallic_roughness {
        let mr = r.eval(textures, uv);
        roughness *= mr.y;
        metallic *= mr.z;
    }
    let mut emission = material.emission;
    if let Some(r) = &t.emissive {
        emission *= r.eval(textures, uv).truncate();
    }
    let normal = match &t.normal {
        Some((r, scale)) => perturb(n, r.eval(textures, uv).truncate(), *scale, frame),
        None => n,
    };
    let mut specular = material.specular;
    if let Some(r) = &t.specular {
        specular *= r.eval(textures, uv).w;
    }
    let mut specular_color = material.specular_color;
    if let Some(r) = &t.specular_color {
        specular_color *= r.eval(textures, uv).truncate();
    }
    let mut transmission = material.transmission;
    if let Some(r) = &t.transmission {
        transmission *= r.eval(textures, uv).x;
    }
    let (mut coat, mut coat_roughness, mut coat_normal) = (material.coat, material.coat_roughness, n);
    if coat > 0.0 {
        if let Some(r) = &t.coat {
            coat *= r.eval(textures, uv).x;
        }
        if let Some(r) = &t.coat_roughness {
            coat_roughness *= r.eval(textures, uv).y;
        }
        if let Some((r, scale)) = &t.coat_normal {
            coat_normal = perturb(n, r.eval(textures, uv).truncate(), *scale, frame);
        }
    }
    let (mut sheen, mut sheen_roughness) = (material.sheen, material.sheen_roughness);
    if sheen != Vec3::ZERO {
        if let Some(r) = &t.sheen_color {
            sheen *= r.eval(textures, uv).truncate();
        }
        if let Some(r) = &t.sheen_roughness {
            sheen_roughness *= r.eval(textures, uv).w;
        }
    }
    let (anisotropy, anisotropy_direction) = match &material.anisotropy {
        Some(a) => {
            let texel = t.anisotropy.map(|r| r.eval(textures, uv).truncate());
            anisotropic(a.strength, a.rotation, texel, normal, frame)
        }
        None => (0.0, Vec3::ZERO),
    };
    ShadingPoint {
        base_color: base.truncate(),
        alpha: base.w.clamp(0.0, 1.0),
        metallic: metallic.clamp(0.0, 1.0),
        roughness: roughness.clamp(0.0, 1.0),
        emission,
        normal,
        specular: specular.clamp(0.0, 1.0),
        specular_color: specular_color.max(Vec3::ZERO),
        transmission: transmission.clamp(0.0, 1.0),
        coat: coat.clamp(0.0, 1.0),
        coat_roughness: coat_roughness.clamp(0.0, 1.0),
        coat_normal,
        sheen: sheen.max(Vec3::ZERO),
        sheen_roughness: sheen_roughness.clamp(0.0, 1.0),
        anisotropy,
        anisotropy_direction,
    }
}

/// The anisotropy strength and direction at a point with shading normal `n`
/// (`KHR_materials_anisotropy`): the direction (cos r, sin r) in the tangent frame, turned
/// further by the texel's RG direction (in [−1, 1]; (1, 0) when absent) and the strength scaled
/// by its B. Where the tangent frame is degenerate the strength is 0: isotropic.
#[inline]
fn anisotropic(
    strength: f32,
    rotation: f32,
    texel: Option<Vec3>,
    n: Vec3,
    frame: &TangentFrame,
) -> (f32, Vec3) {
    let (mut strength, mut direction) = (strength, Vec2::from_angle(rotation));
    if let Some(t) = texel {
        let d = Vec2::new(t.x, t.y) * 2.0 - Vec2::ONE;
        direction = direction.rotate(d.normalize_or(Vec2::X));
        strength *= t.z;
    }
    let Some((t, b)) = tangent_basis(n, frame) else { return (0.0, Vec3::ZERO) };
    match (t * direction.x + b * direction.y).normalize_or_zero() {
        d if d == Vec3::ZERO => (0.0, Vec3::ZERO),
        d => (strength.clamp(0.0, 1.0), d),
    }
}

/// The tangent and bitangent at a point with shading normal `n` (unit): the vertex tangent
/// (else ∂p/∂u) made perpendicular to `n`, and cross(n, t) times the handedness (glTF's w, else
/// from the texture coordinates: glTF's v runs down the image, so the bitangent follows −∂p/∂v).
/// `None` where the tangent lies along `n`.
#[inline]
fn tangent_basis(n: Vec3, frame: &TangentFrame) -> Option<(Vec3, Vec3)> {
    let (t, sign) = match frame.tangent {
        Some(t) if t.truncate().length_squared() > 0.0 => (t.truncate(), if t.w < 0.0 { -1.0 } else { 1.0 }),
        _ => {
            let sign = if n.cross(frame.dpdu).dot(-frame.dpdv) < 0.0 { -1.0 } else { 1.0 };
            (frame.dpdu, sign)
        }
    };
    // Gram–Schmidt: the tangent in the shading normal's plane.
    let t = (t - n * n.dot(t)).normalize_or_zero();
    (t != Vec3::ZERO).then(|| (t, n.cross(t) * sign))
}

/// Coverage alone (for alpha tests during traversal): base colour alpha × texture alpha.
#[inline]
pub fn alpha(material: &Material, textures: &[Texture], uv: [Vec2; 2]) -> f32 {
    let mut a = material.alpha;
    if let Some(r) = &material.textures.base_color {
        a *= r.eval(textures, uv).w;
    }
    a
}

/// The normal from a tangent-space normal-map texel (glTF: RGB in [0, 1] → [−1, 1], +Y along
/// the bitangent, xy scaled by `scale`).
#[inline]
fn perturb(n: Vec3, texel: Vec3, scale: f32, frame: &TangentFrame) -> Vec3 {
    let m = texel * 2.0 - Vec3::ONE;
    let m = Vec3::new(m.x * scale, m.y * scale, m.z);
    let Some((t, b)) = tangent_basis(n, frame) else { return n };
    (t * m.x + b * m.y + n * m.z).normalize_or(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::MaterialTextures;
    use crate::texture::TextureRef;

    fn texture(rgba: Vec4) -> Texture {
        Texture::new("t", 1, 1, vec![rgba])
    }

    #[test]
    fn factors_times_textures() {
        let textures = vec![texture(Vec4::new(0.5, 0.25, 1.0, 0.5)), texture(Vec4::new(0.0, 0.5, 0.25, 1.0))];
        let material = Material {
            base_color: Vec3::new(1.0, 1.0, 0.5),
            alpha: 0.8,
            metallic: 1.0,
            roughness: 0.8,
            textures: MaterialTextures {
                base_color: Some(TextureRef::new(0)),
                metallic_roughness: Some(TextureRef::new(1)),
                ..Default::default()
            },
            ..Material::default()
        };
        let frame = TangentFrame { tangent: None, dpdu: Vec3::X, dpdv: Vec3::Y };
        let s = evaluate(&material, &textures, [Vec2::ZERO; 2], Vec3::Z, &frame);
        assert_eq!(s.base_color, Vec3::new(0.5, 0.25, 0.5));
        assert_eq!(s.alpha, 0.4);
        assert_eq!(s.roughness, 0.4);
        assert_eq!(s.metallic, 0.25);
        assert_eq!(alpha(&material, &textures, [Vec2::ZERO; 2]), 0.4);
    }

    /// `KHR_materials_specular`'s and `KHR_materials_transmission`'s textures multiply their
    /// factors: specular by A, its colour by RGB, transmission by R.
    #[test]
    fn specular_and_transmission_textures_multiply_their_factors() {
        let textures = vec![texture(Vec4::new(0.5, 0.25, 0.75, 0.4))];
        let material = Material {
            specular: 0.5,
            specular_color: Vec3::new(1.0, 2.0, 0.5),
            transmission: 0.8,
            textures: MaterialTextures {
                specular: Some(TextureRef::new(0)),
                specular_color: Some(TextureRef::new(0)),
                transmission: Some(TextureRef::new(0)),
                ..Default::default()
            },
            ..Material::default()
        };
        let frame = TangentFrame { tangent: None, dpdu: Vec3::X, dpdv: Vec3::Y };
        let s = evaluate(&material, &textures, [Vec2::ZERO; 2], Vec3::Z, &frame);
        assert_eq!((s.specular, s.transmission), (0.5 * 0.4, 0.8 * 0.5));
        assert_eq!(s.specular_color, Vec3::new(0.5, 0.5, 0.375));
        assert_eq!(ShadingPoint::of(&material, Vec3::Z).transmission, 0.8);
    }

    /// A flat normal-map texel (0.5, 0.5, 1) leaves the normal alone; one leaning towards +X
    /// in tangent space tilts the normal towards the tangent (∂p/∂u), and +Y (green) towards
    /// −∂p/∂v (glTF's v runs down the image).
    #[test]
    fn normal_map_tilts_towards_the_tangent_frame() {
        let frame = TangentFrame { tangent: None, dpdu: Vec3::X, dpdv: -Vec3::Y };
        let flat = perturb(Vec3::Z, Vec3::new(0.5, 0.5, 1.0), 1.0, &frame);
        assert!((flat - Vec3::Z).length() < 1e-6);
        let towards_u = perturb(Vec3::Z, Vec3::new(1.0, 0.5, 0.5), 1.0, &frame);
        assert!((towards_u - Vec3::X).length() < 1e-6, "{towards_u}");
        let towards_v = perturb(Vec3::Z, Vec3::new(0.5, 1.0, 0.5), 1.0, &frame);
        assert!((towards_v - Vec3::Y).length() < 1e-6, "{towards_v}");
        // Explicit tangents with w = −1 mirror the bitangent.
        let mirrored = TangentFrame { tangent: Some(Vec4::new(1.0, 0.0, 0.0, -1.0)), ..frame };
        let v = perturb(Vec3::Z, Vec3::new(0.5, 1.0, 0.5), 1.0, &mirrored);
        assert!((v + Vec3::Y).length() < 1e-6, "{v}");
        // scale 0 flattens the map.
        assert!((perturb(Vec3::Z, Vec3::new(1.0, 0.5, 0.5), 0.0, &frame) - Vec3::Z).length() < 1e-6);
    }

    /// `KHR_materials_clearcoat`'s textures multiply their factors (weight by R, roughness by
    /// G); without its own normal map the coat keeps the unmapped normal even where the base
    /// has a map, and with one it tilts by that map alone.
    #[test]
    fn coat_textures_multiply_and_the_coat_keeps_its_own_normal() {
        let textures = vec![texture(Vec4::new(0.5, 0.25, 0.75, 1.0)), texture(Vec4::new(1.0, 0.5, 0.5, 1.0))];
        let mut material = Material {
            coat: 0.8,
            coat_roughness: 0.6,
            textures: MaterialTextures {
                coat: Some(TextureRef::new(0)),
                coat_roughness: Some(TextureRef::new(0)),
                normal: Some((TextureRef::new(1), 1.0)),
                ..Default::default()
            },
            ..Material::default()
        };
        let frame = TangentFrame { tangent: None, dpdu: Vec3::X, dpdv: -Vec3::Y };
        let s = evaluate(&material, &textures, [Vec2::ZERO; 2], Vec3::Z, &frame);
        assert_eq!((s.coat, s.coat_roughness), (0.8 * 0.5, 0.6 * 0.25));
        assert!(
            (s.normal - Vec3::X).length() < 1e-6 && s.coat_normal == Vec3::Z,
            "{} {}",
            s.normal,
            s.coat_normal
        );
        material.textures.coat_normal = Some((TextureRef::new(1), 1.0));
        let s = evaluate(&material, &textures, [Vec2::ZERO; 2], Vec3::Z, &frame);
        assert!((s.coat_normal - Vec3::X).length() < 1e-6, "{}", s.coat_normal);
        assert_eq!(ShadingPoint::of(&material, Vec3::Y).coat_normal, Vec3::Y);
    }

    /// `KHR_materials_sheen`'s textures multiply their factors (colour by RGB, roughness by A,
    /// as SheenCloth packs them in one image); a black colour factor leaves no sheen whatever
    /// the texture says.
    #[test]
    fn sheen_textures_multiply_their_factors() {
        const FLAT: TangentFrame = TangentFrame { tangent: None, dpdu: Vec3::X, dpdv: Vec3::Y };
        let textures = vec![texture(Vec4::new(0.5, 0.25, 0.75, 0.4))];
        let slot = Some(TextureRef::new(0));
        let mut material = Material {
            sheen: Vec3::new(1.0, 0.8, 0.6),
            sheen_roughness: 0.5,
            textures: MaterialTextures { sheen_color: slot, sheen_roughness: slot, ..Default::default() },
            ..Material::default()
        };
        let s = evaluate(&material, &textures, [Vec2::ZERO; 2], Vec3::Z, &FLAT);
        assert_eq!(s.sheen, Vec3::new(0.5, 0.8 * 0.25, 0.6 * 0.75));
        assert_eq!(s.sheen_roughness, 0.5 * 0.4);
        material.sheen = Vec3::ZERO;
        assert_eq!(evaluate(&material, &textures, [Vec2::ZERO; 2], Vec3::Z, &FLAT).sheen, Vec3::ZERO);
    }
}
