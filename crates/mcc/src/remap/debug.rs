//! The remapper's debug pictures (docs/design/mcc.md §5.6): per camera an edge image and a weight
//! image, and a false-colour map of which camera dominates each pixel. They show what steps 1–4
//! decided, so a surprising rerender can be traced to an edge, a region or a weight. A map of the
//! seam ratio ([`super::seam`], docs/design/mcc.md §5.8) shows where the result tears.

use crate::error::Result;
use image::{DynamicImage, GrayImage, Luma, Rgb, RgbImage};
use std::path::{Path, PathBuf};

/// What the remapper decided, kept when [`super::RemapConfig::debug`] is set.
#[derive(Clone, Debug)]
pub struct RemapDebug {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Camera ids, ascending: camera index k is `cameras[k]`.
    pub cameras: Vec<u32>,
    /// Dense camera plane: 0 for background, k + 1 for camera index k.
    pub cam: Vec<u32>,
    /// Step 1's edge mask.
    pub edges: Vec<bool>,
    /// The final (smoothed, renormalised) weight plane of every camera index.
    pub weights: Vec<Vec<f32>>,
    /// The camera index with the largest weight per pixel.
    pub dominant: Vec<u32>,
    /// The seam ratio of the result (`None` when there was nothing to measure).
    pub seams: Option<super::SeamRatios>,
}

/// A distinct, stable colour per camera index (hues spaced by the golden angle).
pub fn camera_colour(k: usize) -> [u8; 3] {
    let h = (k as f32 * 0.618_034).fract() * 6.0;
    let (s, v) = (0.75f32, 1.0f32);
    let f = h.fract();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    let (r, g, b) = match h as u32 {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    [(r * 255.0).round() as u8, (g * 255.0).round() as u8, (b * 255.0).round() as u8]
}

impl RemapDebug {
    /// Camera index k's edge image: its edge pixels white, its other pixels grey, other cameras'
    /// pixels dark grey, background black.
    pub fn edge_image(&self, k: usize) -> GrayImage {
        let c = k as u32 + 1;
        let px = |p: usize| match (self.cam[p], self.edges[p]) {
            (0, _) => 0,
            (x, true) if x == c => 255,
            (x, false) if x == c => 128,
            _ => 48,
        };
        GrayImage::from_fn(self.width, self.height, |x, y| Luma([px((y * self.width + x) as usize)]))
    }

    /// Camera index k's weight image: α from 0 (black) to 1 (white).
    pub fn weight_image(&self, k: usize) -> GrayImage {
        let plane = &self.weights[k];
        GrayImage::from_fn(self.width, self.height, |x, y| {
            let a = plane[(y * self.width + x) as usize];
            Luma([(a.clamp(0.0, 1.0) * 255.0).round() as u8])
        })
    }

    /// Which camera dominates each pixel, in [`camera_colour`]s: full strength on camera pixels,
    /// scaled by the dominant weight on background pixels (dark where no camera clearly wins).
    pub fn dominant_image(&self) -> RgbImage {
        RgbImage::from_fn(self.width, self.height, |x, y| {
            let p = (y * self.width + x) as usize;
            let k = self.dominant[p] as usize;
            let colour = camera_colour(k);
            let strength =
                if self.cam[p] != 0 { 1.0 } else { 0.25 + 0.6 * self.weights[k][p].clamp(0.0, 1.0) };
            Rgb(colour.map(|v| (v as f32 * strength).round() as u8))
        })
    }

    /// Writes every picture into `dir` as `debug-frameFFFF-cameraCC-{edges,weights}.png`,
    /// `debug-frameFFFF-dominant.png` and `debug-frameFFFF-seams.png` (atomically); returns the
    /// paths written.
    pub fn write_pngs(&self, dir: &Path, frame: u32) -> Result<Vec<PathBuf>> {
        let mut written = Vec::new();
        let mut write = |name: String, image: DynamicImage| -> Result<()> {
            let path = dir.join(name);
            crate::png::write_png(&path, &image)?;
            written.push(path);
            Ok(())
        };
        for (k, &id) in self.cameras.iter().enumerate() {
            write(
                format!("debug-frame{frame:04}-camera{id:02}-edges.png"),
                DynamicImage::ImageLuma8(self.edge_image(k)),
            )?;
            write(
                format!("debug-frame{frame:04}-camera{id:02}-weights.png"),
                DynamicImage::ImageLuma8(self.weight_image(k)),
            )?;
        }
        write(format!("debug-frame{frame:04}-dominant.png"), DynamicImage::ImageRgb8(self.dominant_image()))?;
        if let Some(seams) = &self.seams {
            write(format!("debug-frame{frame:04}-seams.png"), DynamicImage::ImageRgb8(seams.image()))?;
        }
        Ok(written)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_are_distinct_for_the_first_cameras() {
        let colours: Vec<[u8; 3]> = (0..16).map(camera_colour).collect();
        for i in 0..16 {
            for j in 0..i {
                assert_ne!(colours[i], colours[j], "{i} {j}");
            }
        }
    }
}
