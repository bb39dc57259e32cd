//! Label images for the animation demo (docs/design.md §4.5, collages): the last key's mask, made
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

/// Writes the 8-bit label image `src` at `size` into `dst`, by nearest neighbour (every output
/// pixel copies the input pixel under its centre, so no new colours appear).
pub(crate) fn resize_labels(src: &Path, size: UVec2, dst: &Path) -> anyhow::Result<()> {
    let png = tracer::image_io::read_png8(src)?;
    let c = png.channels as usize;
    if c < 3 {
        bail!("{}: expected an RGB or RGBA label image", src.display());
    }
    let (w, h) = (size.x as usize, size.y as usize);
    let mut rgb = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        let sy = ((y as u64 * 2 + 1) * png.height as u64 / (2 * h as u64)) as usize;
        for x in 0..w {
            let sx = ((x as u64 * 2 + 1) * png.width as u64 / (2 * w as u64)) as usize;
            let at = (sy * png.width as usize + sx) * c;
            rgb.extend_from_slice(&png.pixels[at..at + 3]);
        }
    }
    tracer::image_io::write_png_rgb8(dst, size.x, size.y, &rgb)?;
    Ok(())
}
