//! Texture images for every scene loader (glTF textures, OBJ maps, environment maps): encoded
//! bytes → a decoded image → linear RGBA texels.
//!
//! - Formats: PNG and JPEG (glTF's two), and TIFF; told apart by their contents, not by a
//!   `mimeType` or file name (which are often wrong).
//! - Sizes over [`MAX_PIXELS`](crate::image_io::MAX_PIXELS), and PNG headers claiming more pixel
//!   data than the file could hold, are refused from the header, before anything is decoded.
//! - 8- and 16-bit, greyscale, grey + alpha, RGB and RGBA all become RGBA. Colour slots (base
//!   colour, emissive) are decoded from sRGB to linear (alpha stays linear, as glTF says);
//!   data slots (metallic-roughness, normal) are read as linear. Float images are linear already.
//!
//! Loaders turn a failed decode into a warning naming the image and leave the slot that wanted
//! it empty (the factor alone applies). Never an error, never a panic.

use crate::texture::{Texels, Texture};
use glam::Vec4;
use image::{DynamicImage, ImageFormat, ImageReader, Limits};
use std::io::Cursor;

/// How an image's values are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(in crate::scene) enum ColorSpace {
    /// sRGB-encoded colour (glTF base colour and emissive textures; MTL `map_Kd`, `map_Ke`).
    Srgb,
    /// Linear data (metallic-roughness, normal maps).
    Linear,
}

/// Decodes a PNG, JPEG, TIFF or WebP image from `bytes`, refusing absurd sizes from the header first.
/// The message says what is wrong (without naming the image: callers do).
pub(in crate::scene) fn decode(bytes: &[u8]) -> Result<DynamicImage, String> {
    let reader = || -> Result<ImageReader<Cursor<&[u8]>>, String> {
        let reader = ImageReader::new(Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("cannot read the image: {e}"))?;
        match reader.format() {
            Some(ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::Tiff | ImageFormat::WebP) => Ok(reader),
            Some(other) => {
                Err(format!("the image is {other:?}, which mcctrace cannot decode (PNG, JPEG, TIFF or WebP)"))
            }
            None if bytes.is_empty() => Err("the image is empty (0 bytes)".to_owned()),
            None => Err("not a PNG, JPEG, TIFF or WebP image (unrecognised contents)".to_owned()),
        }
    };
    // A PNG's claimed size first, straight from its IHDR: the decoder only reports it after
    // reading up to the first IDAT, which a damaged file may lack.
    crate::image_io::check_png_header(bytes)?;
    let (width, height) = reader()?.into_dimensions().map_err(|e| format!("malformed image header: {e}"))?;
    crate::image_io::check_claimed_size(width, height)?;
    let mut reader = reader()?;
    // Our own size cap above replaces the decoder's default allocation limit.
    reader.limits(Limits::no_limits());
    reader.decode().map_err(|e| format!("malformed image: {e}"))
}

/// True when the image has no colour channels (grey or grey + alpha).
pub(in crate::scene) fn is_greyscale(image: &DynamicImage) -> bool {
    !image.color().has_color()
}

/// Interleaved samples, `channels` per pixel (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA), to RGBA
/// with `opaque` as the alpha of images without one.
fn texels<T: Copy>(samples: &[T], channels: usize, opaque: T) -> Vec<[T; 4]> {
    samples
        .chunks_exact(channels)
        .map(|p| match *p {
            [l] => [l, l, l, opaque],
            [l, a] => [l, l, l, a],
            [r, g, b] => [r, g, b, opaque],
            [r, g, b, a, ..] => [r, g, b, a],
            [] => [opaque; 4],
        })
        .collect()
}

/// The texels of a decoded image. Integer images keep their codes ([`Texels`]); integer sRGB
/// colour stays encoded, decoded after filtering (as Cycles does: docs/design/tracer.md §3.10); linear
/// data reads as code / max; float images are linear already.
pub(in crate::scene) fn to_texture(name: String, image: &DynamicImage, space: ColorSpace) -> Texture {
    // Float images hold linear values already; non-finite ones would poison every lookup.
    let float = |samples: &[f32], channels| {
        let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
        Texels::Float(
            texels(samples, channels, 1.0).into_iter().map(|t| Vec4::from_array(t.map(finite))).collect(),
        )
    };
    let data = match image {
        DynamicImage::ImageLuma8(i) => Texels::Unorm8(texels(i.as_raw(), 1, u8::MAX)),
        DynamicImage::ImageLumaA8(i) => Texels::Unorm8(texels(i.as_raw(), 2, u8::MAX)),
        DynamicImage::ImageRgb8(i) => Texels::Unorm8(texels(i.as_raw(), 3, u8::MAX)),
        DynamicImage::ImageRgba8(i) => Texels::Unorm8(texels(i.as_raw(), 4, u8::MAX)),
        DynamicImage::ImageLuma16(i) => Texels::Unorm16(texels(i.as_raw(), 1, u16::MAX)),
        DynamicImage::ImageLumaA16(i) => Texels::Unorm16(texels(i.as_raw(), 2, u16::MAX)),
        DynamicImage::ImageRgb16(i) => Texels::Unorm16(texels(i.as_raw(), 3, u16::MAX)),
        DynamicImage::ImageRgba16(i) => Texels::Unorm16(texels(i.as_raw(), 4, u16::MAX)),
        DynamicImage::ImageRgb32F(i) => float(i.as_raw(), 3),
        DynamicImage::ImageRgba32F(i) => float(i.as_raw(), 4),
        // Layouts added to the image crate later: through 16-bit RGBA, which loses nothing an
        // 8/16-bit texture had.
        other => Texels::Unorm16(texels(other.to_rgba16().as_raw(), 4, u16::MAX)),
    };
    let srgb = !matches!(data, Texels::Float(_)) && space == ColorSpace::Srgb;
    Texture::from_texels(name, image.width(), image.height(), data, srgb)
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

    fn texel(t: &Texture, i: usize) -> Vec4 {
        t.linear_texel(i)
    }

    /// Every layout becomes RGBA; sRGB applies to colour only, never to alpha or linear data;
    /// integer sRGB images stay encoded (decoded by lookups), float images are linear.
    #[test]
    fn scene_image_layouts_and_colour_spaces() {
        let srgb128 = 0.215_860_5; // the sRGB EOTF of 128/255
        let grey = DynamicImage::ImageLuma8(ImageBuffer::from_pixel(1, 1, Luma([128u8])));
        let bytes = encode(grey, ImageFormat::Png);
        let decoded = decode(&bytes).unwrap();
        assert!(is_greyscale(&decoded));
        let t = to_texture("g".into(), &decoded, ColorSpace::Srgb);
        assert!(t.srgb && (t.texels.get(0).x - 128.0 / 255.0).abs() < 1e-7);
        assert!((texel(&t, 0) - Vec4::new(srgb128, srgb128, srgb128, 1.0)).abs().max_element() < 1e-6);
        let t = to_texture("g".into(), &decoded, ColorSpace::Linear);
        assert!(!t.srgb && (t.texels.get(0).x - 128.0 / 255.0).abs() < 1e-7);

        let ga = DynamicImage::ImageLumaA8(ImageBuffer::from_pixel(1, 1, LumaA([255u8, 128])));
        let t = to_texture("ga".into(), &decode(&encode(ga, ImageFormat::Png)).unwrap(), ColorSpace::Srgb);
        assert_eq!(texel(&t, 0), Vec4::new(1.0, 1.0, 1.0, 128.0 / 255.0));

        let rgba = DynamicImage::ImageRgba8(ImageBuffer::from_pixel(2, 1, Rgba([128u8, 0, 255, 64])));
        let t =
            to_texture("rgba".into(), &decode(&encode(rgba, ImageFormat::Png)).unwrap(), ColorSpace::Srgb);
        assert_eq!((t.width, t.height, t.texels.len()), (2, 1, 2));
        assert!((texel(&t, 1) - Vec4::new(srgb128, 0.0, 1.0, 64.0 / 255.0)).abs().max_element() < 1e-6);

        // 16-bit: 32896 = 128.5 × 256 … the exact EOTF of the 16-bit code, alpha linear.
        let rgb16 =
            DynamicImage::ImageRgba16(ImageBuffer::from_pixel(1, 1, Rgba([32768u16, 65535, 0, 32768])));
        let t = to_texture("16".into(), &decode(&encode(rgb16, ImageFormat::Png)).unwrap(), ColorSpace::Srgb);
        let s = 32768.0 / 65535.0;
        let want = ((s + 0.055) / 1.055f64).powf(2.4) as f32;
        assert!(
            (texel(&t, 0) - Vec4::new(want, 1.0, 0.0, s as f32)).abs().max_element() < 1e-6,
            "{}",
            texel(&t, 0)
        );
        let l16 = DynamicImage::ImageLuma16(ImageBuffer::from_pixel(1, 1, Luma([65535u16])));
        let t =
            to_texture("l16".into(), &decode(&encode(l16, ImageFormat::Png)).unwrap(), ColorSpace::Linear);
        assert_eq!(t.texels.get(0), Vec4::ONE);

        // JPEG is lossy: a flat colour comes back within a few codes.
        let jpeg = DynamicImage::ImageRgb8(ImageBuffer::from_pixel(8, 8, Rgb([200u8, 100, 50])));
        let t =
            to_texture("j".into(), &decode(&encode(jpeg, ImageFormat::Jpeg)).unwrap(), ColorSpace::Linear);
        let want = Vec4::new(200.0, 100.0, 50.0, 255.0) / 255.0;
        assert!((t.texels.get(27) - want).abs().max_element() < 4.0 / 255.0, "{}", t.texels.get(27));
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
        assert!(decode(b"hello, world").unwrap_err().contains("not a PNG, JPEG, TIFF or WebP"));
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
