//! Image textures (glTF 2.0 §3.8; `KHR_texture_transform`): RGBA texels looked up by texture
//! coordinates with the sampler's wrap modes and filter. Colour textures from 8- and 16-bit
//! images keep their sRGB-encoded values and are decoded after filtering, as Cycles does
//! (docs/design.md §3.10); float images and data textures hold linear values.
//!
//! Texture coordinates follow glTF: (0, 0) is the top-left corner of the image, u right, v down.

use glam::{Affine2, Vec2, Vec4};

/// How coordinates outside [0, 1] map back into the image (glTF sampler `wrapS`/`wrapT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Tile the image (glTF's default).
    #[default]
    Repeat,
    /// Repeat the edge texels.
    ClampToEdge,
    /// Tile, mirroring every other copy.
    MirroredRepeat,
}

/// How texels are combined (glTF sampler `magFilter`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// Bilinear interpolation of the four nearest texels.
    #[default]
    Linear,
}

/// A decoded image: RGBA, row-major from the top-left corner.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it came from, for messages.
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width × height` RGBA texels: linear, or with sRGB-encoded RGB when `srgb` is set.
    pub texels: Vec<Vec4>,
    /// The texels' RGB is sRGB-encoded and decoded after filtering (alpha is always linear).
    pub srgb: bool,
}

/// A material's use of a texture: which image, which coordinate set, how it is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    /// Index into `Scene::textures`.
    pub texture: u32,
    /// Texture-coordinate set (0 or 1: `TEXCOORD_0`/`TEXCOORD_1`).
    pub uv_set: u32,
    /// `KHR_texture_transform`, applied to the coordinates before the lookup.
    pub transform: Option<Affine2>,
    /// Wrap modes along u and v.
    pub wrap: [Wrap; 2],
    /// Filter.
    pub filter: Filter,
}

impl TextureRef {
    /// A plain reference to `texture` through coordinate set 0 with glTF's default sampler.
    pub fn new(texture: u32) -> Self {
        Self { texture, uv_set: 0, transform: None, wrap: [Wrap::Repeat; 2], filter: Filter::Linear }
    }

    /// The texture's value at the hit with coordinates `uv` (sets 0 and 1).
    #[inline]
    pub fn eval(&self, textures: &[Texture], uv: [Vec2; 2]) -> Vec4 {
        let mut st = uv[(self.uv_set as usize).min(1)];
        if let Some(t) = &self.transform {
            st = t.transform_point2(st);
        }
        textures[self.texture as usize].sample(st, self.wrap, self.filter)
    }
}

impl Texture {
    /// A texture from linear texels (`width × height`, row-major from the top).
    pub fn new(name: impl Into<String>, width: u32, height: u32, texels: Vec<Vec4>) -> Self {
        debug_assert_eq!(texels.len(), width as usize * height as usize);
        Self { name: name.into(), width, height, texels, srgb: false }
    }

    /// A texture from texels whose RGB is sRGB-encoded (in [0, 1]; alpha linear): lookups
    /// filter the encoded values and decode the result.
    pub fn srgb_encoded(name: impl Into<String>, width: u32, height: u32, texels: Vec<Vec4>) -> Self {
        Self { srgb: true, ..Self::new(name, width, height, texels) }
    }

    /// Texel `i` (row-major) as a linear value, decoded if stored encoded.
    pub fn linear_texel(&self, i: usize) -> Vec4 {
        if self.srgb { srgb_to_linear(self.texels[i]) } else { self.texels[i] }
    }

    /// The same texture with linear texels (for uses that read texels directly, such as an
    /// environment map's importance sampling).
    pub fn into_linear(mut self) -> Self {
        if self.srgb {
            for t in &mut self.texels {
                *t = srgb_to_linear(*t);
            }
            self.srgb = false;
        }
        self
    }

    #[inline]
    fn texel(&self, x: i64, y: i64, wrap: [Wrap; 2]) -> Vec4 {
        let x = wrap_index(x, self.width as i64, wrap[0]);
        let y = wrap_index(y, self.height as i64, wrap[1]);
        self.texels[y * self.width as usize + x]
    }

    /// The linear value at texture coordinates `uv`.
    #[inline]
    pub fn sample(&self, uv: Vec2, wrap: [Wrap; 2], filter: Filter) -> Vec4 {
        let v = self.filtered(uv, wrap, filter);
        if self.srgb { srgb_to_linear(v) } else { v }
    }

    /// The texels' filtered value at `uv`, still encoded as stored.
    #[inline]
    fn filtered(&self, uv: Vec2, wrap: [Wrap; 2], filter: Filter) -> Vec4 {
        if self.texels.is_empty() {
            return Vec4::ZERO;
        }
        // Texel centres sit at half-integer positions.
        let p = uv * Vec2::new(self.width as f32, self.height as f32);
        if !p.is_finite() {
            return self.texels[0];
        }
        match filter {
            Filter::Nearest => self.texel(p.x.floor() as i64, p.y.floor() as i64, wrap),
            Filter::Linear => {
                let p = p - Vec2::splat(0.5);
                let (x0, y0) = (p.x.floor(), p.y.floor());
                let (fx, fy) = (p.x - x0, p.y - y0);
                let (x0, y0) = (x0 as i64, y0 as i64);
                let top = self.texel(x0, y0, wrap).lerp(self.texel(x0 + 1, y0, wrap), fx);
                let bottom = self.texel(x0, y0 + 1, wrap).lerp(self.texel(x0 + 1, y0 + 1, wrap), fx);
                top.lerp(bottom, fy)
            }
        }
    }
}

/// The sRGB EOTF on RGB, alpha unchanged. Applied after filtering, not to each texel at load:
/// Cycles keeps 8- and 16-bit sRGB images encoded and decodes the interpolated value, and a
/// blend of encoded values decodes darker than the blend of decoded ones (the curve is convex),
/// which shifted Blender scenes' colours by up to 14 % on checker textures (docs/design.md §3.10).
#[inline]
fn srgb_to_linear(v: Vec4) -> Vec4 {
    let eotf =
        |s: f32| if s <= 0.04045 { s * (1.0 / 12.92) } else { ((s + 0.055) * (1.0 / 1.055)).powf(2.4) };
    Vec4::new(eotf(v.x), eotf(v.y), eotf(v.z), v.w)
}

#[inline]
fn wrap_index(i: i64, n: i64, wrap: Wrap) -> usize {
    (match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let m = i.rem_euclid(2 * n);
            if m < n { m } else { 2 * n - 1 - m }
        }
    }) as usize
}

/// `KHR_texture_transform` as an affine map: scale, then rotate, then offset — the extension's
/// `T · R · S` matrix.
pub fn uv_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
    let (s, c) = rotation.sin_cos();
    // The extension's GLSL `mat3(cos, sin, 0, -sin, cos, 0, …)` is column-major: columns
    // (cos, sin) and (−sin, cos).
    let r = glam::Mat2::from_cols(Vec2::new(c, s), Vec2::new(-s, c));
    Affine2::from_mat2_translation(r * glam::Mat2::from_diagonal(scale), offset)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Texture {
        // 2 × 2: red, green / blue, white.
        let t = vec![
            Vec4::new(1.0, 0.0, 0.0, 1.0),
            Vec4::new(0.0, 1.0, 0.0, 1.0),
            Vec4::new(0.0, 0.0, 1.0, 1.0),
            Vec4::ONE,
        ];
        Texture::new("checker", 2, 2, t)
    }

    #[test]
    fn texel_centres_and_wraps() {
        let t = checker();
        let w = [Wrap::Repeat; 2];
        assert_eq!(t.sample(Vec2::new(0.25, 0.25), w, Filter::Linear), Vec4::new(1.0, 0.0, 0.0, 1.0));
        assert_eq!(t.sample(Vec2::new(0.75, 0.75), w, Filter::Linear), Vec4::ONE);
        // Half-way between the top two texels.
        assert_eq!(t.sample(Vec2::new(0.5, 0.25), w, Filter::Linear), Vec4::new(0.5, 0.5, 0.0, 1.0));
        // Repeat: u = 1.25 is u = 0.25.
        assert_eq!(t.sample(Vec2::new(1.25, 0.25), w, Filter::Nearest), Vec4::new(1.0, 0.0, 0.0, 1.0));
        // Clamp: far outside stays on the edge texel.
        assert_eq!(
            t.sample(Vec2::new(-3.0, 0.25), [Wrap::ClampToEdge; 2], Filter::Linear),
            Vec4::new(1.0, 0.0, 0.0, 1.0)
        );
        // Mirror: u in [1, 2) reads the image backwards.
        assert_eq!(
            t.sample(Vec2::new(1.25, 0.25), [Wrap::MirroredRepeat; 2], Filter::Nearest),
            Vec4::new(0.0, 1.0, 0.0, 1.0)
        );
    }

    /// An sRGB texture filters encoded values and decodes the result: half-way between codes 0
    /// and 255 is the EOTF of 0.5 (0.214), not 0.5; at texel centres it is each texel's EOTF.
    #[test]
    fn srgb_textures_decode_after_filtering() {
        let t = Texture::srgb_encoded("s", 2, 1, vec![Vec4::new(0.0, 0.0, 0.0, 0.0), Vec4::ONE]);
        let w = [Wrap::ClampToEdge; 2];
        let mid = t.sample(Vec2::new(0.5, 0.5), w, Filter::Linear);
        let want = ((0.5f64 + 0.055) / 1.055).powf(2.4) as f32;
        assert!((mid.x - want).abs() < 1e-6 && (mid.w - 0.5).abs() < 1e-7, "{mid}");
        let code = 60.0 / 255.0;
        let t = Texture::srgb_encoded("s", 1, 1, vec![Vec4::new(code, code, code, 1.0)]);
        let v = t.sample(Vec2::splat(0.5), w, Filter::Nearest);
        assert!((v.x - crate::image_io::srgb8_to_linear(60)).abs() < 1e-6, "{v}");
    }

    /// The extension's GLSL, evaluated by hand: offset (0.5, 0), rotation π/2, scale 2 takes
    /// (1, 0) → S → (2, 0) → R (columns (cos, sin), (−sin, cos)) → (0, 2) → T → (0.5, 2).
    #[test]
    fn texture_transform_matches_the_extension() {
        let t = uv_transform(Vec2::new(0.5, 0.0), std::f32::consts::FRAC_PI_2, Vec2::splat(2.0));
        let p = t.transform_point2(Vec2::new(1.0, 0.0));
        assert!((p - Vec2::new(0.5, 2.0)).length() < 1e-6, "{p}");
    }
}
