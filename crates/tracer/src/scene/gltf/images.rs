//! Texture images for the scene loaders (glTF here; the OBJ loader and environment maps use
//! [`decode`] and [`to_texture`] too): encoded bytes → a decoded image → linear RGBA texels.
//!
//! - Formats: PNG and JPEG (glTF's two), and TIFF; told apart by their contents, not by a
//!   `mimeType` or file name (which are often wrong).
//! - Sizes over [`MAX_PIXELS`] are refused from the header, before anything is decoded.
//! - 8- and 16-bit, greyscale, grey + alpha, RGB and RGBA all become RGBA. Colour slots (base
//!   colour, emissive) are decoded from sRGB to linear (alpha stays linear, as glTF says);
//!   data slots (metallic-roughness, normal) are read as linear. Float images are linear already.
//! - In glTF, each image is decoded once, and converted once per colour space it is used in: two
//!   materials sharing an image share its texture, whatever their samplers (the sampler lives in
//!   the [`TextureRef`]).
//!
//! An image that cannot be read or decoded is a warning naming it; the material slot that wanted
//! it is left empty (the factor alone applies). Never an error, never a panic.

use super::buffers;
use crate::image_io::{MAX_PIXELS, srgb8_to_linear};
use crate::texture::{Filter, Texture, TextureRef, Wrap};
use glam::{Vec2, Vec4};
use image::{DynamicImage, ImageFormat, ImageReader, Limits};
use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;

/// How an image's values are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(in crate::scene) enum ColorSpace {
    /// sRGB-encoded colour (glTF base colour and emissive textures; MTL `map_Kd`, `map_Ke`).
    Srgb,
    /// Linear data (metallic-roughness, normal maps).
    Linear,
}

/// Decodes a PNG, JPEG or TIFF image from `bytes`, refusing absurd sizes from the header first.
/// The message says what is wrong (without naming the image: callers do).
pub(in crate::scene) fn decode(bytes: &[u8]) -> Result<DynamicImage, String> {
    let reader = || -> Result<ImageReader<Cursor<&[u8]>>, String> {
        let reader = ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("cannot read the image: {e}"))?;
        match reader.format() {
            Some(ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::Tiff) => Ok(reader),
            Some(other) => {
                Err(format!("the image is {other:?}, which mcctrace cannot decode (PNG, JPEG or TIFF)"))
            }
            None if bytes.is_empty() => Err("the image is empty (0 bytes)".to_owned()),
            None => Err("not a PNG, JPEG or TIFF image (unrecognised contents)".to_owned()),
        }
    };
    let (width, height) = reader()?.into_dimensions().map_err(|e| format!("malformed image header: {e}"))?;
    if width == 0 || height == 0 || width as u64 * height as u64 > MAX_PIXELS {
        return Err(format!("the image claims {width} × {height} pixels; 1 to {MAX_PIXELS} are accepted"));
    }
    let mut reader = reader()?;
    // Our own size cap above replaces the decoder's default allocation limit.
    reader.limits(Limits::no_limits());
    reader.decode().map_err(|e| format!("malformed image: {e}"))
}

/// True when the image has no colour channels (grey or grey + alpha).
pub(in crate::scene) fn is_greyscale(image: &DynamicImage) -> bool {
    !image.color().has_color()
}

/// The sRGB EOTF for a 16-bit code.
fn srgb16_to_linear(v: u16) -> f32 {
    let s = v as f64 / 65535.0;
    (if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }) as f32
}

/// Interleaved samples, `channels` per pixel (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA), to RGBA.
fn texels<T: Copy>(
    samples: &[T],
    channels: usize,
    colour: impl Fn(T) -> f32,
    alpha: impl Fn(T) -> f32,
) -> Vec<Vec4> {
    samples
        .chunks_exact(channels)
        .map(|p| match p {
            [l] => Vec4::new(colour(*l), colour(*l), colour(*l), 1.0),
            [l, a] => Vec4::new(colour(*l), colour(*l), colour(*l), alpha(*a)),
            [r, g, b] => Vec4::new(colour(*r), colour(*g), colour(*b), 1.0),
            [r, g, b, a, ..] => Vec4::new(colour(*r), colour(*g), colour(*b), alpha(*a)),
            [] => Vec4::ZERO,
        })
        .collect()
}

/// Linear RGBA texels of a decoded image, RGB decoded from `space`.
pub(in crate::scene) fn to_texture(name: String, image: &DynamicImage, space: ColorSpace) -> Texture {
    let srgb = space == ColorSpace::Srgb;
    let c8 = |v: u8| if srgb { srgb8_to_linear(v) } else { v as f32 / 255.0 };
    let a8 = |v: u8| v as f32 / 255.0;
    let c16 = |v: u16| if srgb { srgb16_to_linear(v) } else { v as f32 / 65535.0 };
    let a16 = |v: u16| v as f32 / 65535.0;
    // Float images hold linear values already; non-finite ones would poison every lookup.
    let f = |v: f32| if v.is_finite() { v } else { 0.0 };
    let data = match image {
        DynamicImage::ImageLuma8(i) => texels(i.as_raw(), 1, c8, a8),
        DynamicImage::ImageLumaA8(i) => texels(i.as_raw(), 2, c8, a8),
        DynamicImage::ImageRgb8(i) => texels(i.as_raw(), 3, c8, a8),
        DynamicImage::ImageRgba8(i) => texels(i.as_raw(), 4, c8, a8),
        DynamicImage::ImageLuma16(i) => texels(i.as_raw(), 1, c16, a16),
        DynamicImage::ImageLumaA16(i) => texels(i.as_raw(), 2, c16, a16),
        DynamicImage::ImageRgb16(i) => texels(i.as_raw(), 3, c16, a16),
        DynamicImage::ImageRgba16(i) => texels(i.as_raw(), 4, c16, a16),
        DynamicImage::ImageRgb32F(i) => texels(i.as_raw(), 3, f, f),
        DynamicImage::ImageRgba32F(i) => texels(i.as_raw(), 4, f, f),
        // Layouts added to the image crate later: through 16-bit RGBA, which loses nothing an
        // 8/16-bit texture had.
        other => texels(other.to_rgba16().as_raw(), 4, c16, a16),
    };
    Texture::new(name, image.width(), image.height(), data)
}

/// `KHR_texture_transform` as it appears on a texture reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct UvTransform {
    pub offset: [f32; 2],
    pub rotation: f32,
    pub scale: [f32; 2],
    /// Overrides the reference's `texCoord`.
    pub tex_coord: Option<u32>,
}

/// Reads the images glTF textures refer to, each once, and makes the scene's textures.
pub(super) struct TextureLoader<'a> {
    doc: &'a gltf::Document,
    buffers: &'a [Vec<u8>],
    /// The .gltf's folder (relative image URIs resolve against it).
    base: &'a Path,
    /// The glTF file, for messages.
    path: &'a Path,
    /// Decoded images by glTF image index (`None` once decoding failed and was reported).
    decoded: HashMap<usize, Option<DynamicImage>>,
    /// Scene texture of each (image, colour space) made so far.
    made: HashMap<(usize, ColorSpace), u32>,
    /// The textures made, in order: `Scene::textures`.
    pub textures: Vec<Texture>,
    /// Warnings, each naming the file.
    pub warnings: Vec<String>,
}

impl<'a> TextureLoader<'a> {
    pub(super) fn new(
        doc: &'a gltf::Document,
        buffers: &'a [Vec<u8>],
        base: &'a Path,
        path: &'a Path,
    ) -> Self {
        Self {
            doc,
            buffers,
            base,
            path,
            decoded: HashMap::new(),
            made: HashMap::new(),
            textures: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// Records a warning about the file.
    pub(super) fn warn(&mut self, message: String) {
        self.warnings.push(format!("{}: {message}", self.path.display()));
    }

    /// "image 2 ('wood.png')" for messages (a data URI is not spelled out).
    fn image_label(&self, image: usize) -> String {
        let json = self.doc.as_json().images.get(image);
        let name = json.and_then(|i| i.name.as_deref()).filter(|n| !n.is_empty());
        let uri = json.and_then(|i| i.uri.as_deref()).filter(|u| !u.starts_with("data:"));
        match name.or(uri) {
            Some(n) => format!("image {image} ('{n}')"),
            None => format!("image {image}"),
        }
    }

    /// The encoded bytes of glTF image `image`: an external file, a data URI, or a buffer view.
    fn image_bytes(&self, image: usize) -> Result<Vec<u8>, String> {
        let json = self.doc.as_json().images.get(image).ok_or("no such image")?;
        match (&json.uri, &json.buffer_view) {
            (Some(uri), _) => buffers::read_uri(uri, self.base).map(|(bytes, _)| bytes),
            (None, Some(view)) => {
                let view = self.doc.views().nth(view.value()).ok_or("its buffer view does not exist")?;
                let b = view.buffer().index();
                let buffer = self.buffers.get(b).ok_or_else(|| format!("buffer {b} is missing"))?;
                view.offset()
                    .checked_add(view.length())
                    .and_then(|end| buffer.get(view.offset()..end))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| {
                        format!(
                            "buffer view {} (bytes {}..{}) runs past the end of buffer {b} ({} bytes)",
                            view.index(),
                            view.offset(),
                            view.offset().saturating_add(view.length()),
                            buffer.len()
                        )
                    })
            }
            (None, None) => Err("it has neither a uri nor a bufferView".to_owned()),
        }
    }

    /// The scene texture holding glTF image `image` in `space`, decoding it on first use;
    /// `None` (after one warning per image) when it cannot be read.
    fn texture_of_image(&mut self, image: usize, space: ColorSpace, user: &str) -> Option<u32> {
        if let Some(&t) = self.made.get(&(image, space)) {
            return Some(t);
        }
        if !self.decoded.contains_key(&image) {
            let decoded = self.image_bytes(image).and_then(|bytes| decode(&bytes));
            let decoded = match decoded {
                Ok(d) => Some(d),
                Err(m) => {
                    let label = self.image_label(image);
                    self.warn(format!("{label} (used by {user}): {m}; the texture is left out"));
                    None
                }
            };
            self.decoded.insert(image, decoded);
        }
        let decoded = self.decoded.get(&image)?.as_ref()?;
        let space_name = if space == ColorSpace::Srgb { "sRGB" } else { "linear" };
        let name = format!("{}: {} ({space_name})", self.path.display(), self.image_label(image));
        let texture = to_texture(name, decoded, space);
        let index = u32::try_from(self.textures.len()).ok()?;
        self.textures.push(texture);
        self.made.insert((image, space), index);
        Some(index)
    }

    /// A material slot's texture reference: the texture's image in `space`, its sampler, the
    /// coordinate set and `KHR_texture_transform`. `user` names the material and slot for
    /// messages. `None` when the image cannot be used (warned).
    pub(super) fn reference(
        &mut self,
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<UvTransform>,
        space: ColorSpace,
        user: &str,
    ) -> Option<TextureRef> {
        let image = texture.source().index();
        let index = self.texture_of_image(image, space, user)?;
        let sampler = texture.sampler();
        let wrap = |mode| match mode {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let filter = match sampler.mag_filter() {
            Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        };
        let mut uv_set = transform.and_then(|t| t.tex_coord).unwrap_or(tex_coord);
        if uv_set > 1 {
            self.warn(format!(
                "{user} reads TEXCOORD_{uv_set}; only sets 0 and 1 are supported, so set 0 is used"
            ));
            uv_set = 0;
        }
        let transform = transform.and_then(|t| {
            let finite = t.offset.iter().chain(&t.scale).all(|v| v.is_finite()) && t.rotation.is_finite();
            if !finite {
                self.warn(format!("{user}: KHR_texture_transform has a non-finite value; ignored"));
                return None;
            }
            let identity = t.offset == [0.0; 2] && t.rotation == 0.0 && t.scale == [1.0; 2];
            (!identity)
                .then(|| crate::texture::uv_transform(Vec2::from(t.offset), t.rotation, Vec2::from(t.scale)))
        });
        Some(TextureRef {
            texture: index,
            uv_set,
            transform,
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
            filter,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{ImageBuffer, Luma, LumaA, Rgb, Rgba};

    fn encode(image: DynamicImage, format: ImageFormat) -> Vec<u8> {
        let mut bytes = Vec::new();
        image.write_to(&mut Cursor::new(&mut bytes), format).unwrap();
        bytes
    }

    /// Every layout becomes RGBA; sRGB applies to colour only, never to alpha or linear data.
    #[test]
    fn scene_image_layouts_and_colour_spaces() {
        let srgb128 = 0.215_860_5; // the sRGB EOTF of 128/255
        let grey = DynamicImage::ImageLuma8(ImageBuffer::from_pixel(1, 1, Luma([128u8])));
        let bytes = encode(grey, ImageFormat::Png);
        let decoded = decode(&bytes).unwrap();
        assert!(is_greyscale(&decoded));
        let t = to_texture("g".into(), &decoded, ColorSpace::Srgb);
        assert!((t.texels[0] - Vec4::new(srgb128, srgb128, srgb128, 1.0)).abs().max_element() < 1e-6);
        let t = to_texture("g".into(), &decoded, ColorSpace::Linear);
        assert!((t.texels[0].x - 128.0 / 255.0).abs() < 1e-7);

        let ga = DynamicImage::ImageLumaA8(ImageBuffer::from_pixel(1, 1, LumaA([255u8, 128])));
        let t = to_texture("ga".into(), &decode(&encode(ga, ImageFormat::Png)).unwrap(), ColorSpace::Srgb);
        assert_eq!(t.texels[0], Vec4::new(1.0, 1.0, 1.0, 128.0 / 255.0));

        let rgba = DynamicImage::ImageRgba8(ImageBuffer::from_pixel(2, 1, Rgba([128u8, 0, 255, 64])));
        let t =
            to_texture("rgba".into(), &decode(&encode(rgba, ImageFormat::Png)).unwrap(), ColorSpace::Srgb);
        assert_eq!((t.width, t.height, t.texels.len()), (2, 1, 2));
        assert!((t.texels[1] - Vec4::new(srgb128, 0.0, 1.0, 64.0 / 255.0)).abs().max_element() < 1e-6);

        // 16-bit: 32896 = 128.5 × 256 … the exact EOTF of the 16-bit code, alpha linear.
        let rgb16 =
            DynamicImage::ImageRgba16(ImageBuffer::from_pixel(1, 1, Rgba([32768u16, 65535, 0, 32768])));
        let t = to_texture("16".into(), &decode(&encode(rgb16, ImageFormat::Png)).unwrap(), ColorSpace::Srgb);
        let s = 32768.0 / 65535.0;
        let want = ((s + 0.055) / 1.055f64).powf(2.4) as f32;
        assert!(
            (t.texels[0] - Vec4::new(want, 1.0, 0.0, s as f32)).abs().max_element() < 1e-6,
            "{}",
            t.texels[0]
        );
        let l16 = DynamicImage::ImageLuma16(ImageBuffer::from_pixel(1, 1, Luma([65535u16])));
        let t =
            to_texture("l16".into(), &decode(&encode(l16, ImageFormat::Png)).unwrap(), ColorSpace::Linear);
        assert_eq!(t.texels[0], Vec4::ONE);

        // JPEG is lossy: a flat colour comes back within a few codes.
        let jpeg = DynamicImage::ImageRgb8(ImageBuffer::from_pixel(8, 8, Rgb([200u8, 100, 50])));
        let t =
            to_texture("j".into(), &decode(&encode(jpeg, ImageFormat::Jpeg)).unwrap(), ColorSpace::Linear);
        let want = Vec4::new(200.0, 100.0, 50.0, 255.0) / 255.0;
        assert!((t.texels[27] - want).abs().max_element() < 4.0 / 255.0, "{}", t.texels[27]);
    }

    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 != 0 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
            }
        }
        !crc
    }

    #[test]
    fn scene_image_bad_bytes_are_messages() {
        assert!(decode(b"").unwrap_err().contains("empty"));
        assert!(decode(b"hello, world").unwrap_err().contains("not a PNG, JPEG or TIFF"));
        let png = encode(DynamicImage::new_rgb8(4, 4), ImageFormat::Png);
        assert!(decode(&png[..png.len() - 30]).unwrap_err().contains("malformed image"));
        // A header claiming 100000 × 100000 pixels is refused before decoding.
        let mut huge = png.clone();
        huge[16..20].copy_from_slice(&100_000u32.to_be_bytes());
        huge[20..24].copy_from_slice(&100_000u32.to_be_bytes());
        // Keep the IHDR checksum valid, so only the size is wrong.
        let crc = crc32(&huge[12..29]);
        huge[29..33].copy_from_slice(&crc.to_be_bytes());
        let m = decode(&huge).unwrap_err();
        assert!(m.contains("100000 × 100000"), "{m}");
        // A GIF's magic is recognised, and refused by name.
        let m = decode(b"GIF89a\x01\x00\x01\x00\x00\x00\x00;").unwrap_err();
        assert!(m.contains("Gif"), "{m}");
    }
}
