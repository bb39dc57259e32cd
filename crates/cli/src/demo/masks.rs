//! Label images for the animation demo (docs/design/mcc.md §4.5, collages): the last key's mask, made
//! here, and the bundled mask and regions brought to the views' size without new colours.

use anyhow::bail;
use glam::UVec2;
use std::path::Path;

/// Writes the last key's label mask at `size`: camera 1 (red) on the left, camera 2 (green) on
/// the right, each edge a gentle wave, and a black band between them for the remapper to blend.
pub(crate) fn write_second_mask(path: &Path, size: UVec2) -> anyhow::Result<()> {
    let (w, h) = (size.x as usize, size.y as usize);
    let mut rgb = vec![0u8; w * h * 3];
    for y in 0..h {
        let fy = y as f32 / h as f32;
        // Edges at about 40 % and 62 % of the width, waving by 3 % of it.
        let left_edge = w as f32 * (0.40 + 0.03 * (fy * 9.0).sin());
        let right_edge = w as f32 * (0.62 + 0.03 * (fy * 7.0 + 1.0).cos());
        for x in 0..w {
            let fx = x as f32 + 0.5;
            let px = &mut rgb[(y * w + x) * 3..][..3];
            if fx < left_edge {
                px.copy_from_slice(&[255, 0, 0]);
            } else if fx > right_edge {
                px.copy_from_slice(&[0, 255, 0]);
            }
        }
    }
    tracer::image_io::write_png_rgb8(path, size.x, size.y, &rgb)?;
    Ok(())
}

/// The café's collage mask (480 x 270; red = camera 1, green = camera 2, black = background),
/// inside the binary so the demo needs no source tree.
pub(crate) const CAFE_MASK: &[u8] = include_bytes!("../../../../scenes/cafe/collage-mask.png");
/// The café's region image for that mask (480 x 270).
pub(crate) const CAFE_REGIONS: &[u8] = include_bytes!("../../../../scenes/cafe/collage-mask-regions.png");

/// Writes the PNG label image `png` (bytes) at `size` into `dst`, by nearest neighbour (every
/// output pixel copies the input pixel under its centre, so no new colours appear).
pub(crate) fn resize_labels(png: &[u8], size: UVec2, dst: &Path) -> anyhow::Result<()> {
    let Ok(image) = image::load_from_memory_with_format(png, image::ImageFormat::Png) else {
        bail!("the bundled label image cannot be decoded");
    };
    let src = image.to_rgb8();
    let (w, h) = (size.x as u64, size.y as u64);
    let resized = image::RgbImage::from_fn(size.x, size.y, |x, y| {
        let sx = (x as u64 * 2 + 1) * src.width() as u64 / (2 * w);
        let sy = (y as u64 * 2 + 1) * src.height() as u64 / (2 * h);
        *src.get_pixel(sx as u32, sy as u32)
    });
    tracer::image_io::write_png_rgb8(dst, size.x, size.y, resized.as_raw())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    fn colours(path: &Path) -> (u32, u32, BTreeSet<[u8; 3]>) {
        let img = image::open(path).unwrap().to_rgb8();
        (img.width(), img.height(), img.pixels().map(|p| p.0).collect())
    }

    /// The bundled labels scale to any size by nearest neighbour: at their own size they come
    /// back unchanged, at others with their colours only (every one still present at 160x90).
    #[test]
    fn bundled_labels_scale_without_new_colours() {
        let dir = std::env::temp_dir().join(format!("mcctrace-demo-masks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for bundled in [CAFE_MASK, CAFE_REGIONS] {
            let original = dir.join("original.png");
            std::fs::write(&original, bundled).unwrap();
            let (w, h, palette) = colours(&original);
            assert_eq!((w, h), (480, 270));
            let same = dir.join("same.png");
            resize_labels(bundled, UVec2::new(480, 270), &same).unwrap();
            let a = image::open(&original).unwrap().to_rgb8();
            assert_eq!(image::open(&same).unwrap().to_rgb8().as_raw(), a.as_raw());
            for (size, all) in [((160, 90), true), ((37, 23), false), ((1000, 700), true)] {
                let out = dir.join("resized.png");
                resize_labels(bundled, UVec2::new(size.0, size.1), &out).unwrap();
                let (w, h, got) = colours(&out);
                assert_eq!((w, h), size);
                assert!(got.is_subset(&palette), "{size:?}: new colours {:?}", got.difference(&palette));
                if all {
                    assert_eq!(got, palette, "{size:?}");
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
