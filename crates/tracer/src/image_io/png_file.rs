//! PNG: 8-bit sRGB previews of linear renders, and lossless 8-bit images as they are.

use super::{MAX_PIXELS, check_dimensions, check_png_data_size};
use crate::atomic::write_atomically;
use crate::error::{Result, TracerError};
use crate::image::RgbImage;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{DynamicImage, ExtendedColorType, ImageEncoder, ImageFormat, ImageReader, Limits};
use std::path::Path;
use std::sync::LazyLock;

/// An 8-bit image read by [`read_png8`]: `channels` interleaved bytes per pixel, rows from the top.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Png8 {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Bytes per pixel: 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
    pub channels: u8,
    /// `width × height × channels` bytes, row by row from the top.
    pub pixels: Vec<u8>,
}

/// Linear value → 8-bit sRGB code: the exact piecewise sRGB OETF (IEC 61966-2-1) of the value
/// clamped to [0, 1], rounded to nearest. NaN and ±∞ give 0 (a broken sample shows black, it does
/// not saturate to white); tests count non-finite samples separately.
pub fn linear_to_srgb8(v: f32) -> u8 {
    if !v.is_finite() {
        return 0;
    }
    // f64 so that codes exactly on a rounding boundary do not depend on f32 `powf` error.
    let v = (v as f64).clamp(0.0, 1.0);
    let s = if v <= 0.0031308 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round() as u8
}

/// 8-bit sRGB code → linear value, the exact inverse EOTF, from a 256-entry table.
pub fn srgb8_to_linear(v: u8) -> f32 {
    static TABLE: LazyLock<[f32; 256]> = LazyLock::new(|| {
        std::array::from_fn(|i| {
            let s = i as f64 / 255.0;
            (if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }) as f32
        })
    });
    TABLE[v as usize]
}

/// Writes a linear image as an 8-bit sRGB PNG preview ([`linear_to_srgb8`] per channel),
/// atomically. Non-finite values are written as 0.
pub fn write_png_srgb(path: &Path, image: &RgbImage) -> Result<()> {
    check_dimensions(image.width, image.height, image.pixels.len(), 1, "the image")
        .map_err(|m| TracerError::image(path, m))?;
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|p| p.to_array().map(linear_to_srgb8)).collect();
    write_png8(path, image.width, image.height, &bytes, ExtendedColorType::Rgb8)
}

/// Writes 8-bit RGB bytes (3 per pixel, rows from the top) to a PNG losslessly, atomically.
pub fn write_png_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    write_png8(path, width, height, rgb, ExtendedColorType::Rgb8)
}

/// Writes 8-bit RGBA bytes (4 per pixel, rows from the top, straight alpha) to a PNG losslessly,
/// atomically.
pub fn write_png_rgba8(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    write_png8(path, width, height, rgba, ExtendedColorType::Rgba8)
}

fn write_png8(path: &Path, width: u32, height: u32, bytes: &[u8], color: ExtendedColorType) -> Result<()> {
    let per_pixel = color.channel_count() as usize;
    check_dimensions(width, height, bytes.len(), per_pixel, "the image")
        .map_err(|m| TracerError::image(path, m))?;
    write_atomically(path, |w| {
        // Fast: previews are rewritten often and PNG compression level barely changes their size.
        PngEncoder::new_with_quality(w, CompressionType::Fast, FilterType::Adaptive)
            .write_image(bytes, width, height, color)
            .map_err(std::io::Error::other)
    })
}

/// Reads an 8-bit PNG (grey, grey + alpha, RGB or RGBA) losslessly, bytes as stored.
///
/// Refuses, naming what the file is: other bit depths (1, 2, 4, 16), palette (indexed-colour)
/// images, sizes over [`MAX_PIXELS`], headers claiming more pixels than the file could hold
/// ([`check_png_data_size`], before anything is allocated), and malformed files. Gamma and
/// colour-profile chunks are ignored; a `tRNS` chunk becomes an alpha channel (so an RGB file
/// may read as 4 channels).
pub fn read_png8(path: &Path) -> Result<Png8> {
    let bad = |message: String| TracerError::image(path, message);
    let bytes = std::fs::read(path).map_err(|e| TracerError::io(path, e))?;
    // The IHDR chunk must come first: signature (8), length (4), "IHDR", width, height, depth, type.
    const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
    if bytes.len() < 26 || &bytes[..8] != SIGNATURE || &bytes[12..16] != b"IHDR" {
        return Err(bad("not a PNG file (no PNG signature and IHDR header)".into()));
    }
    let be32 = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let (width, height, depth, color_type) = (be32(16), be32(20), bytes[24], bytes[25]);
    let kind = match color_type {
        0 => "greyscale",
        2 => "RGB",
        3 => "palette (indexed-colour)",
        4 => "greyscale + alpha",
        6 => "RGBA",
        _ => "unknown colour type",
    };
    if color_type == 3 {
        return Err(bad(format!(
            "a {depth}-bit palette (indexed-colour) PNG; only 8-bit grey/RGB/RGBA are read"
        )));
    }
    if depth != 8 {
        return Err(bad(format!("a {depth}-bit {kind} PNG; only 8-bit images are read")));
    }
    if width == 0 || height == 0 || width as u64 * height as u64 > MAX_PIXELS {
        return Err(bad(format!("header claims {width} × {height} pixels; 1 to {MAX_PIXELS} are accepted")));
    }
    check_png_data_size(&bytes).map_err(bad)?;
    let mut reader = ImageReader::with_format(std::io::Cursor::new(&bytes), ImageFormat::Png);
    reader.limits(Limits::no_limits()); // Our own size cap above replaces the decoder's.
    let decoded = reader.decode().map_err(|e| bad(format!("malformed PNG: {e}")))?;
    let (channels, pixels) = match decoded {
        DynamicImage::ImageLuma8(i) => (1, i.into_raw()),
        DynamicImage::ImageLumaA8(i) => (2, i.into_raw()),
        DynamicImage::ImageRgb8(i) => (3, i.into_raw()),
        DynamicImage::ImageRgba8(i) => (4, i.into_raw()),
        other => return Err(bad(format!("decoded as {:?}, not 8-bit", other.color()))),
    };
    Ok(Png8 { width, height, channels, pixels })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn temp_dir(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("mcctrace-png-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn srgb_transfer_known_values_and_round_trip() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(0.5), 188); // 0.7354 × 255 = 187.5…
        assert_eq!(linear_to_srgb8(0.18), 118); // middle grey
        assert_eq!(linear_to_srgb8(0.001), 3); // linear segment: 12.92 × 0.001 × 255 = 3.29
        assert_eq!(linear_to_srgb8(-1.0), 0);
        assert_eq!(linear_to_srgb8(7.0), 255);
        for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(linear_to_srgb8(v), 0);
        }
        for code in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb8_to_linear(code)), code);
        }
        assert_eq!(srgb8_to_linear(0), 0.0);
        assert_eq!(srgb8_to_linear(255), 1.0);
        assert!((srgb8_to_linear(188) - 0.5029).abs() < 1e-4);
    }

    #[test]
    fn png_round_trips_losslessly_and_atomically() {
        let dir = temp_dir("roundtrip");
        let (w, h) = (7u32, 5u32);
        let rgba: Vec<u8> = (0..w * h * 4).map(|i| (i * 37 % 256) as u8).collect();
        let path = dir.join("ids.png");
        write_png_rgba8(&path, w, h, &rgba).unwrap();
        assert_eq!(
            read_png8(&path).unwrap(),
            Png8 { width: w, height: h, channels: 4, pixels: rgba.clone() }
        );
        let rgb: Vec<u8> = rgba.iter().take((w * h * 3) as usize).copied().collect();
        write_png_rgb8(&path, w, h, &rgb).unwrap();
        assert_eq!(read_png8(&path).unwrap(), Png8 { width: w, height: h, channels: 3, pixels: rgb });
        // A wrong buffer length is refused before anything is written; the old file survives.
        let err = write_png_rgb8(&path, w, h, &rgba).unwrap_err().to_string();
        assert!(err.contains("ids.png") && err.contains("values instead of"), "{err}");
        assert_eq!(read_png8(&path).unwrap().channels, 3);
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary left behind");

        let mut image = RgbImage::new(3, 1);
        image.pixels =
            vec![Vec3::new(0.5, f32::NAN, 2.0), Vec3::splat(0.18), Vec3::new(-1.0, f32::INFINITY, 0.0)];
        let preview = dir.join("preview.png");
        write_png_srgb(&preview, &image).unwrap();
        let read = read_png8(&preview).unwrap();
        assert_eq!(read.pixels, vec![188, 0, 255, 118, 118, 118, 0, 0, 0]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn header_claiming_more_than_the_file_holds_is_refused_before_decoding() {
        let dir = temp_dir("claims");
        let tiny = dir.join("tiny.png");
        write_png_rgb8(&tiny, 2, 1, &[1, 2, 3, 4, 5, 6]).unwrap();
        assert_eq!(read_png8(&tiny).unwrap().pixels, vec![1, 2, 3, 4, 5, 6]);

        // 50 bytes whose IHDR claims 16384 × 16384 RGBA: exactly MAX_PIXELS, so only the data
        // size check stands between it and a 1 GiB reservation by the decoder.
        let mut bytes = std::fs::read(&tiny).unwrap();
        bytes[16..20].copy_from_slice(&16384u32.to_be_bytes());
        bytes[20..24].copy_from_slice(&16384u32.to_be_bytes());
        bytes[25] = 6;
        bytes.resize(50, 0);
        let short = dir.join("short.png");
        std::fs::write(&short, &bytes).unwrap();
        let err = read_png8(&short).unwrap_err().to_string();
        assert!(
            err.contains("short.png")
                && err.contains("header claims 16384 × 16384 pixels but the file is only 50 bytes")
                && !err.contains("malformed PNG"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn highly_compressed_real_pngs_still_load() {
        // Flat 4096 × 4096 images written by the image crate: a flat colour with its default
        // settings, and black (all-zero data) at best compression without filtering, which
        // comes within 3 % of deflate's best case (1032:1; checked below to be over 1000:1). A
        // bound tighter than what deflate can really do would refuse the black one.
        let dir = temp_dir("flat");
        let (w, h) = (4096u32, 4096u32);
        let colour: Vec<u8> = [200u8, 120, 40].repeat((w * h) as usize);
        let flat = dir.join("flat.png");
        DynamicImage::ImageRgb8(image::RgbImage::from_raw(w, h, colour.clone()).unwrap())
            .save_with_format(&flat, ImageFormat::Png)
            .unwrap();
        let black = vec![0u8; (w * h * 3) as usize];
        let zeros = dir.join("black.png");
        PngEncoder::new_with_quality(
            std::fs::File::create(&zeros).unwrap(),
            CompressionType::Best,
            FilterType::NoFilter,
        )
        .write_image(&black, w, h, ExtendedColorType::Rgb8)
        .unwrap();
        let raw = h as u64 * (w as u64 * 3 + 1);
        let zeros_len = std::fs::metadata(&zeros).unwrap().len();
        assert!(raw / zeros_len > 1000, "{raw} bytes compressed to {zeros_len}: not near deflate's limit");
        for (path, pixels) in [(&flat, &colour), (&zeros, &black)] {
            let read = read_png8(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert_eq!((read.width, read.height, read.channels), (w, h, 3));
            assert!(&read.pixels == pixels, "{} decoded to other pixels", path.display());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn png_reader_refuses_what_it_cannot_take() {
        let dir = temp_dir("refuse");
        let save = |name: &str, image: DynamicImage| {
            let path = dir.join(name);
            image.save_with_format(&path, ImageFormat::Png).unwrap();
            path
        };
        let sixteen = save("sixteen.png", DynamicImage::new_rgb16(4, 4));
        let err = read_png8(&sixteen).unwrap_err().to_string();
        assert!(err.contains("sixteen.png") && err.contains("16-bit RGB"), "{err}");
        let grey = save("grey.png", DynamicImage::new_luma8(4, 2));
        assert_eq!(read_png8(&grey).unwrap().channels, 1);

        // A palette PNG and a header claiming 10^6 × 10^6 pixels: patch IHDR of a valid file.
        let bytes = std::fs::read(&grey).unwrap();
        let patched = |name: &str, patch: &dyn Fn(&mut Vec<u8>)| {
            let mut b = bytes.clone();
            patch(&mut b);
            let path = dir.join(name);
            std::fs::write(&path, b).unwrap();
            read_png8(&path).unwrap_err().to_string()
        };
        let err = patched("palette.png", &|b| b[25] = 3);
        assert!(err.contains("palette"), "{err}");
        let err = patched("huge.png", &|b| {
            b[16..20].copy_from_slice(&1_000_000u32.to_be_bytes());
            b[20..24].copy_from_slice(&1_000_000u32.to_be_bytes());
        });
        assert!(err.contains("1000000 × 1000000"), "{err}");
        let err = patched("truncated.png", &|b| b.truncate(b.len() - 20));
        assert!(err.contains("truncated.png") && err.contains("malformed PNG"), "{err}");
        let err = patched("text.png", &|b| *b = b"hello".to_vec());
        assert!(err.contains("not a PNG"), "{err}");
        let err = read_png8(&dir.join("missing.png")).unwrap_err();
        assert!(matches!(err, TracerError::Io { .. }) && err.to_string().contains("missing.png"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
