//! Image textures (glTF 2.0 §3.8; `KHR_texture_transform`): RGBA texels looked up by texture
//! coordinates with the sampler's wrap modes and filter. Colour textures from 8- and 16-bit
//! images keep their sRGB-encoded values and are decoded after filtering, as Cycles does
//! (docs/design/tracer.md §3.10); float images and data textures hold linear values.
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
    pub texels: Texels,
    /// The texels' RGB is sRGB-encoded and decoded after filtering (alpha is always linear).
    pub srgb: bool,
}

/// Texel storage. Integer images keep their codes, read as code / max exactly as a float copy
/// would hold them: a quarter (8-bit) or half (16-bit) of the memory, so that lookups, which
/// mostly wait on memory, miss the caches less (docs/performance.md, ledger: "integer texels").
#[derive(Clone, Debug, PartialEq)]
pub enum Texels {
    /// 8-bit RGBA codes; a texel reads as code / 255.
    Unorm8(Vec<[u8; 4]>),
    /// 16-bit RGBA codes; a texel reads as code / 65535.
    Unorm16(Vec<[u16; 4]>),
    /// RGBA floats.
    Float(Vec<Vec4>),
}

impl Texels {
    /// The number of texels.
    pub fn len(&self) -> usize {
        match self {
            Self::Unorm8(t) => t.len(),
            Self::Unorm16(t) => t.len(),
            Self::Float(t) => t.len(),
        }
    }

    /// True when there is no texel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Texel `i` as stored (still sRGB-encoded where the texture is).
    #[inline]
    pub fn get(&self, i: usize) -> Vec4 {
        match self {
            Self::Unorm8(t) => unorm8(t[i]),
            Self::Unorm16(t) => unorm16(t[i]),
            Self::Float(t) => t[i],
        }
    }

    /// Every texel as stored, in order.
    pub fn iter(&self) -> impl Iterator<Item = Vec4> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }
}

/// An 8-bit texel as floats: each lane's division is the scalar `code as f32 / 255.0`.
#[inline(always)]
fn unorm8(c: [u8; 4]) -> Vec4 {
    Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) / 255.0
}

/// A 16-bit texel as floats: each lane's division is the scalar `code as f32 / 65535.0`.
#[inline(always)]
fn unorm16(c: [u16; 4]) -> Vec4 {
    Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) / 65535.0
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
        Self::from_texels(name, width, height, Texels::Float(texels), false)
    }

    /// A texture from texels in any storage; `srgb`: their RGB is sRGB-encoded (in [0, 1];
    /// alpha linear), and lookups filter the encoded values and decode the result.
    pub fn from_texels(name: impl Into<String>, width: u32, height: u32, texels: Texels, srgb: bool) -> Self {
        debug_assert_eq!(texels.len(), width as usize * height as usize);
        Self { name: name.into(), width, height, texels, srgb }
    }

    /// A texture from float texels whose RGB is sRGB-encoded (see [`Texture::from_texels`]).
    pub fn srgb_encoded(name: impl Into<String>, width: u32, height: u32, texels: Vec<Vec4>) -> Self {
        Self::from_texels(name, width, height, Texels::Float(texels), true)
    }

    /// Texel `i` (row-major) as a linear value, decoded if stored encoded.
    pub fn linear_texel(&self, i: usize) -> Vec4 {
        let t = self.texels.get(i);
        if self.srgb { srgb_to_linear(t) } else { t }
    }

    /// The same texture with linear float texels (for uses that read texels directly, such as
    /// an environment map's importance sampling).
    pub fn into_linear(self) -> Self {
        let texels = Texels::Float((0..self.texels.len()).map(|i| self.linear_texel(i)).collect());
        Self { texels, srgb: false, ..self }
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
        // One match per lookup, outside the texel reads.
        match &self.texels {
            Texels::Unorm8(t) => self.filter_with(uv, wrap, filter, |i| unorm8(t[i])),
            Texels::Unorm16(t) => self.filter_with(uv, wrap, filter, |i| unorm16(t[i])),
            Texels::Float(t) => self.filter_with(uv, wrap, filter, |i| t[i]),
        }
    }

    /// [`Texture::filtered`] over texels read by `texel(i)`.
    #[inline(always)]
    fn filter_with(&self, uv: Vec2, wrap: [Wrap; 2], filter: Filter, texel: impl Fn(usize) -> Vec4) -> Vec4 {
        if self.texels.is_empty() {
            return Vec4::ZERO;
        }
        // Texel centres sit at half-integer positions.
        let p = uv * Vec2::new(self.width as f32, self.height as f32);
        if !p.is_finite() {
            return texel(0);
        }
        let (w, h) = (self.width as i64, self.height as i64);
        match filter {
            Filter::Nearest => {
                let x = wrap_index(p.x.floor() as i64, w, wrap[0]);
                let y = wrap_index(p.y.floor() as i64, h, wrap[1]);
                texel(y * w as usize + x)
            }
            Filter::Linear => {
                let p = p - Vec2::splat(0.5);
                let (x0, y0) = (p.x.floor(), p.y.floor());
                let (fx, fy) = (p.x - x0, p.y - y0);
                let (x0, x1) = wrap_pair(x0 as i64, w, wrap[0]);
                let (y0, y1) = wrap_pair(y0 as i64, h, wrap[1]);
                let (row0, row1) = (y0 * w as usize, y1 * w as usize);
                let top = texel(row0 + x0).lerp(texel(row0 + x1), fx);
                let bottom = texel(row1 + x0).lerp(texel(row1 + x1), fx);
                top.lerp(bottom, fy)
            }
        }
    }
}

/// The sRGB EOTF on RGB, alpha unchanged. Applied after filtering, not to each texel at load:
/// Cycles keeps 8- and 16-bit sRGB images encoded and decodes the interpolated value, and a
/// blend of encoded values decodes darker than the blend of decoded ones (the curve is convex),
/// which shifted Blender scenes' colours by up to 14 % on checker textures (docs/design/tracer.md §3.10).
#[inline]
fn srgb_to_linear(v: Vec4) -> Vec4 {
    let eotf =
        |s: f32| if s <= 0.04045 { s * (1.0 / 12.92) } else { ((s + 0.055) * (1.0 / 1.055)).powf(2.4) };
    Vec4::new(eotf(v.x), eotf(v.y), eotf(v.z), v.w)
}

/// The wrapped indices of `i` and `i + 1`, with one division where two would do.
#[inline(always)]
fn wrap_pair(i: i64, n: i64, wrap: Wrap) -> (usize, usize) {
    match wrap {
        Wrap::Repeat => {
            let a = i.rem_euclid(n);
            (a as usize, if a + 1 == n { 0 } else { a as usize + 1 })
        }
        _ => (wrap_index(i, n, wrap), wrap_index(i.wrapping_add(1), n, wrap)),
    }
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
/// `T · R · S` matrix, with R turning the way implementations and the sample model agree on:
/// s' = cos·u + sin·v, t' = −sin·u + cos·v.
pub fn uv_transform(offset: Vec2, rotation: f32, scale: Vec2) -> Affine2 {
    let (s, c) = rotation.sin_cos();
    // Not the extension's GLSL listing read literally (`mat3(cos, sin, 0, -sin, cos, 0, …)`,
    // column-major: columns (cos, sin), (−sin, cos)): that is the known erratum (KhronosGroup/glTF
    // issue 1563) and turns the other way. Blender's importer (its Mapping node, v flipped),
    // three.js and TextureTransformTest's "correct" marker all take columns (cos, −sin), (sin, cos).
    let r = glam::Mat2::from_cols(Vec2::new(c, -s), Vec2::new(s, c));
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

    /// Integer texels read exactly as the float copy a loader would have made of them (code as
    /// f32 / max), through every filter and wrap, encoded or not: the storage saves memory
    /// and changes no bit.
    #[test]
    fn integer_texels_filter_as_their_float_copies() {
        let mut rng = crate::test_support::Rng::new(0x9e37_79b9);
        let (w, h) = (5, 3);
        let codes8: Vec<[u8; 4]> =
            (0..w * h).map(|_| [0; 4].map(|_: u8| (rng.unit() * 256.0) as u8)).collect();
        let codes16: Vec<[u16; 4]> =
            (0..w * h).map(|_| [0; 4].map(|_: u16| (rng.unit() * 65536.0) as u16)).collect();
        let float8: Vec<Vec4> =
            codes8.iter().map(|c| Vec4::from_array(c.map(|v| v as f32 / 255.0))).collect();
        let float16: Vec<Vec4> =
            codes16.iter().map(|c| Vec4::from_array(c.map(|v| v as f32 / 65535.0))).collect();
        for srgb in [false, true] {
            let pairs = [
                (Texels::Unorm8(codes8.clone()), Texels::Float(float8.clone())),
                (Texels::Unorm16(codes16.clone()), Texels::Float(float16.clone())),
            ];
            for (codes, floats) in pairs {
                let a = Texture::from_texels("codes", w, h, codes, srgb);
                let b = Texture::from_texels("floats", w, h, floats, srgb);
                for _ in 0..2000 {
                    let uv = Vec2::new(rng.unit(), rng.unit()) * 6.0 - 3.0;
                    for wrap in [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat] {
                        for filter in [Filter::Nearest, Filter::Linear] {
                            let (x, y) = (a.sample(uv, [wrap; 2], filter), b.sample(uv, [wrap; 2], filter));
                            assert_eq!(
                                x.to_array().map(f32::to_bits),
                                y.to_array().map(f32::to_bits),
                                "{uv}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// The pair of wrapped neighbours is the two wraps taken one at a time.
    #[test]
    fn wrapped_pairs_are_single_wraps() {
        for n in 1..6 {
            for i in -20..20 {
                for wrap in [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat] {
                    assert_eq!(wrap_pair(i, n, wrap), (wrap_index(i, n, wrap), wrap_index(i + 1, n, wrap)));
                }
            }
        }
    }

    /// By hand, as Blender's importer builds it (glTF v runs down, Blender's up: a Mapping node
    /// rotating counter-clockwise in Blender's UV space, offset (o.x + sy·sin, 1 − o.y − sy·cos)):
    /// offset (0.5, 0), rotation π/2, scale 2 takes (1, 0) → S → (2, 0) → R → (0, −2) → T →
    /// (0.5, −2), and (0, 1) → (0, 2) → (2, 0) → (2.5, 0).
    #[test]
    fn texture_transform_matches_the_extension() {
        let t = uv_transform(Vec2::new(0.5, 0.0), std::f32::consts::FRAC_PI_2, Vec2::splat(2.0));
        let p = t.transform_point2(Vec2::new(1.0, 0.0));
        assert!((p - Vec2::new(0.5, -2.0)).length() < 1e-6, "{p}");
        let q = t.transform_point2(Vec2::new(0.0, 1.0));
        assert!((q - Vec2::new(2.5, 0.0)).length() < 1e-6, "{q}");
    }
}
