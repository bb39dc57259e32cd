//! The animation preview (docs/design/workflow.md §8, `animate`): an animated GIF of every finished frame in
//! an output folder, made from the frames' sRGB PNG previews (so its tone mapping is theirs: linear
//! radiance clamped to [0, 1], sRGB-encoded), scaled down to a small size, written atomically.

use anyhow::Context;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage, imageops};
use std::path::{Path, PathBuf};

/// The widest preview, in pixels (larger frames are scaled down, keeping their aspect ratio).
pub const MAX_WIDTH: u32 = 480;

/// Name of the preview GIF in the output folder.
pub const GIF_NAME: &str = "preview.gif";

/// The finished frames in `dir`, as (frame, PNG path) in frame order: `frameFFFF.png` files
/// whose EXR is there too.
pub fn finished_frames(dir: &Path) -> anyhow::Result<Vec<(u32, PathBuf)>> {
    let mut frames = Vec::new();
    let entries = std::fs::read_dir(dir).with_context(|| format!("listing {}", dir.display()))?;
    for entry in entries {
        let path = entry.with_context(|| format!("listing {}", dir.display()))?.path();
        let Some(name) = path.file_name().and_then(|n| n.to_str()) else { continue };
        let Some(frame) = parse_frame_png(name) else { continue };
        if path.with_extension("exr").is_file() {
            frames.push((frame, path));
        }
    }
    frames.sort();
    Ok(frames)
}

/// `frameFFFF.png` → FFFF (at least four digits).
fn parse_frame_png(name: &str) -> Option<u32> {
    let digits = name.strip_prefix("frame")?.strip_suffix(".png")?;
    if digits.len() < 4 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// Writes `out` (an animated GIF looping forever at `fps`) from the PNGs `frames`; returns the
/// number of frames it holds.
pub fn write_gif(frames: &[(u32, PathBuf)], fps: f32, out: &Path) -> anyhow::Result<usize> {
    anyhow::ensure!(!frames.is_empty(), "no finished frames to make {} from", out.display());
    // GIF delays are whole hundredths of a second (the encoder rounds): 24 fps plays at 25.
    let ms = (1000.0 / fps as f64).clamp(10.0, 655_350.0);
    let delay = Delay::from_numer_denom_ms((ms * 1000.0) as u32, 1000);
    let mut gif_frames = Vec::with_capacity(frames.len());
    for (_, png) in frames {
        let decoded = tracer::image_io::read_png8(png)?;
        let rgba =
            to_rgba(&decoded).with_context(|| format!("{}: unexpected channel layout", png.display()))?;
        let small = if rgba.width() > MAX_WIDTH {
            let h = ((rgba.height() as u64 * MAX_WIDTH as u64) / rgba.width() as u64).max(1) as u32;
            imageops::resize(&rgba, MAX_WIDTH, h, imageops::FilterType::Triangle)
        } else {
            rgba
        };
        gif_frames.push(Frame::from_parts(small, 0, 0, delay));
    }
    tracer::atomic::write_atomically(out, |w| {
        let mut encoder = GifEncoder::new_with_speed(w, 10);
        encoder.set_repeat(Repeat::Infinite).map_err(std::io::Error::other)?;
        encoder.encode_frames(gif_frames).map_err(std::io::Error::other)
    })?;
    Ok(frames.len())
}

/// An 8-bit PNG's pixels as RGBA.
fn to_rgba(png: &tracer::image_io::Png8) -> Option<RgbaImage> {
    let n = png.width as usize * png.height as usize;
    let c = png.channels as usize;
    if png.pixels.len() != n * c {
        return None;
    }
    let mut rgba = Vec::with_capacity(n * 4);
    for p in png.pixels.chunks_exact(c) {
        let px = match c {
            1 => [p[0], p[0], p[0], 255],
            2 => [p[0], p[0], p[0], p[1]],
            3 => [p[0], p[1], p[2], 255],
            4 => [p[0], p[1], p[2], p[3]],
            _ => return None,
        };
        rgba.extend_from_slice(&px);
    }
    RgbaImage::from_raw(png.width, png.height, rgba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names() {
        assert_eq!(parse_frame_png("frame0042.png"), Some(42));
        assert_eq!(parse_frame_png("frame12345.png"), Some(12345));
        assert_eq!(parse_frame_png("frame042.png"), None);
        assert_eq!(parse_frame_png("frame0042camera01.png"), None);
        assert_eq!(parse_frame_png("frame0042.exr"), None);
    }
}
