//! The pictures the engine sends (docs/studio.md, "Pictures"): PNG encoding, the label and
//! region maps in colour, and the coarse preview's composite, where painted pixels take their
//! camera's view.

use crate::camera::colour;
use crate::error::{Result, StudioError};
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ImageEncoder, Rgb, RgbImage as Rgb8};
use mcc::Regions;
use mcc::regions::RegionInfo;
use std::sync::LazyLock;
use tracer::image::RgbImage;
use tracer::image_io::linear_to_srgb8;

/// PNG bytes of an 8-bit RGB picture, compressed fast: the pictures go over loopback, where
/// encoding time counts and size hardly does.
pub fn png(image: &Rgb8) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive)
        .write_image(image.as_raw(), image.width(), image.height(), image::ExtendedColorType::Rgb8)
        .map_err(|e| StudioError::request(format!("encoding a picture: {e}")))?;
    Ok(out)
}

/// `THRESHOLDS[k − 1]`: the smallest f32 that [`linear_to_srgb8`] maps to code k or above. The
/// function is monotone, so a value's code is the number of thresholds at or below it: a binary
/// search that gives its very bits without a `powf` per channel.
static THRESHOLDS: LazyLock<[f32; 255]> = LazyLock::new(|| {
    std::array::from_fn(|k| {
        // Bisect on the bit patterns of [0, 1]: non-negative floats order as their bits.
        let (mut low, mut high) = (0u32, 1f32.to_bits());
        while low < high {
            let mid = low + (high - low) / 2;
            if linear_to_srgb8(f32::from_bits(mid)) as usize > k { high = mid } else { low = mid + 1 }
        }
        f32::from_bits(low)
    })
});

/// [`linear_to_srgb8`], bit for bit, from [`THRESHOLDS`].
fn srgb8(v: f32) -> u8 {
    if !v.is_finite() {
        return 0;
    }
    THRESHOLDS.partition_point(|&t| t <= v) as u8
}

/// A linear render as 8-bit sRGB (exactly [`linear_to_srgb8`] per channel).
pub fn srgb(image: &RgbImage) -> Rgb8 {
    let bytes = image.pixels.iter().flat_map(|p| p.to_array().map(srgb8)).collect();
    Rgb8::from_raw(image.width, image.height, bytes).expect("the size matches the pixels")
}

/// The colour of region `k` in `collage-regions.png`: distinct for every byte (the red channel
/// is `k`), so the batch tools find one region per painted value.
pub fn region_colour(k: u8) -> [u8; 3] {
    [k, 128u8.wrapping_add(k.wrapping_mul(37)), 255 - k]
}

/// The region map as the image `collage-regions.png` holds.
pub fn region_image(w: u32, h: u32, regions: &[u8]) -> Rgb8 {
    Rgb8::from_fn(w, h, |x, y| Rgb(region_colour(regions[(y * w + x) as usize])))
}

/// The regions the remapper reads from the region map: those of its image, exactly as the
/// batch tools read `collage-regions.png` (numbered by first pixel, colours widened to 16-bit
/// RGBA), made from the bytes without drawing the image (every byte has its own colour).
pub fn regions(w: u32, h: u32, map: &[u8]) -> Regions {
    let mut number = [u32::MAX; 256];
    let mut info = Vec::new();
    let index = map
        .iter()
        .enumerate()
        .map(|(p, &k)| {
            if number[k as usize] == u32::MAX {
                number[k as usize] = info.len() as u32;
                let [r, g, b] = region_colour(k).map(|c| c as u16 * 257);
                let first = (p as u32 % w, p as u32 / w);
                info.push(RegionInfo { colour: [r, g, b, u16::MAX], first, layer: None });
            }
            number[k as usize]
        })
        .collect();
    Regions { width: w, height: h, index, info }
}

/// The label map in the cameras' colours, background black.
pub fn label_image(w: u32, h: u32, labels: &[u8]) -> Rgb8 {
    Rgb8::from_fn(w, h, |x, y| match labels[(y * w + x) as usize] {
        0 => Rgb([0, 0, 0]),
        k => Rgb(colour(k as u32)),
    })
}

/// Nearest-pixel lookup of `image` at pixel (x, y) of a `w × h` picture.
fn nearest(image: &RgbImage, x: u32, y: u32, w: u32, h: u32) -> glam::Vec3 {
    let sx = (x as u64 * image.width as u64 / w as u64) as u32;
    let sy = (y as u64 * image.height as u64 / h as u64) as u32;
    image.pixels[(sy * image.width + sx) as usize]
}

/// The coarse preview at `w × h`: the rerender `coarse` (any size) scaled up, painted pixels
/// replaced by their camera's view (`view(k)`, any size) where there is one.
pub fn composite<'a>(
    w: u32,
    h: u32,
    coarse: &RgbImage,
    labels: &[u8],
    view: impl Fn(u8) -> Option<&'a RgbImage>,
) -> RgbImage {
    let mut pixels = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h {
        for x in 0..w {
            let label = labels[(y * w + x) as usize];
            let source = if label == 0 { None } else { view(label) };
            pixels.push(nearest(source.unwrap_or(coarse), x, y, w, h));
        }
    }
    RgbImage { width: w, height: h, pixels }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn region_colours_are_distinct_and_read_back_as_regions() {
        let colours: std::collections::BTreeSet<_> = (0..=255u8).map(region_colour).collect();
        assert_eq!(colours.len(), 256);
        let map = [0, 0, 3, 3, 7, 0];
        let r = regions(3, 2, &map);
        assert_eq!(r.count(), 3);
        assert_eq!(r.index, [0, 0, 1, 1, 2, 0]);
        // Exactly what the batch tools read from the region image, for any map.
        let (w, h) = (37u32, 11u32);
        for seed in 0..20u32 {
            let map: Vec<u8> = (0..w * h)
                .map(|p| (((p / 5).wrapping_mul(2654435761) ^ seed) >> 13) as u8 % 9 * 31)
                .collect();
            let image = image::DynamicImage::ImageRgb8(region_image(w, h, &map));
            assert_eq!(regions(w, h, &map), Regions::from_image(&image), "seed {seed}");
        }
    }

    #[test]
    fn the_threshold_table_is_linear_to_srgb8_bit_for_bit() {
        // Around every threshold, on a stride through every float in [0, 1], and the specials.
        for &t in THRESHOLDS.iter() {
            for bits in t.to_bits().saturating_sub(300)..t.to_bits() + 300 {
                let v = f32::from_bits(bits);
                assert_eq!(srgb8(v), linear_to_srgb8(v), "{v:e}");
            }
        }
        for bits in (0..=1f32.to_bits() + 1000).step_by(997) {
            let v = f32::from_bits(bits);
            assert_eq!(srgb8(v), linear_to_srgb8(v), "{v:e}");
        }
        for v in [-0.0, -1e-30, -1.0, 1.0, 1.5, 1e30, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::MAX] {
            assert_eq!(srgb8(v), linear_to_srgb8(v), "{v:e}");
        }
    }

    #[test]
    fn the_composite_takes_painted_pixels_from_their_view() {
        let coarse = RgbImage { width: 1, height: 1, pixels: vec![Vec3::ONE] };
        let view = RgbImage { width: 2, height: 1, pixels: vec![Vec3::X, Vec3::Y] };
        let out = composite(2, 1, &coarse, &[0, 1], |k| (k == 1).then_some(&view));
        assert_eq!(out.pixels, [Vec3::ONE, Vec3::Y]);
        assert!(png(&label_image(2, 1, &[0, 1])).unwrap().starts_with(b"\x89PNG"));
    }
}
