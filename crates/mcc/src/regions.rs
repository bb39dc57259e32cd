//! Region images (docs/design/mcc.md §4.6): optional, at the collage's resolution; a region is the
//! set of pixels of one exact colour (not necessarily connected). Given explicitly or found beside
//! the collage as `<collage-stem>-regions.png`; without one, the whole picture is one region.
//!
//! Regions are numbered densely 0, 1, … in the raster order of their first pixel, so the numbering
//! (and every result that depends on it) is deterministic. Colours compare exactly at the image's
//! own depth (alpha included): an antialiased brush makes many one-pixel regions, which is the
//! user's to fix, not ours to guess.

use crate::error::{MccError, Result};
use image::DynamicImage;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The region of every pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Regions {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Region index per pixel, `y · width + x`.
    pub index: Vec<u32>,
    /// Per region: its colour as 16-bit RGBA (8-bit images widened ×257) and its first pixel.
    pub info: Vec<RegionInfo>,
}

/// What identifies a region to a user.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegionInfo {
    /// Colour, 16-bit RGBA (unused for a region from a layer).
    pub colour: [u16; 4],
    /// First pixel in raster order, (x, y).
    pub first: (u32, u32),
    /// The layer it came from, in a layered file (`layer "sky"`); `None` in a region image.
    pub layer: Option<String>,
}

impl std::fmt::Display for RegionInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [r, g, b, a] = self.colour;
        let (x, y) = self.first;
        if let Some(layer) = &self.layer {
            write!(f, "{layer}")?;
        } else if [r, g, b, a].iter().all(|v| v % 257 == 0) {
            write!(f, "colour #{:02x}{:02x}{:02x}", r / 257, g / 257, b / 257)?;
            if a != u16::MAX {
                write!(f, " alpha {}", a / 257)?;
            }
        } else {
            write!(f, "colour rgba16({r}, {g}, {b}, {a})")?;
        }
        write!(f, ", first pixel ({x}, {y})")
    }
}

impl Regions {
    /// One region covering a `width × height` picture.
    pub fn single(width: u32, height: u32) -> Self {
        let info = vec![RegionInfo { colour: [0, 0, 0, u16::MAX], first: (0, 0), layer: None }];
        Self { width, height, index: vec![0; width as usize * height as usize], info }
    }

    /// Number of regions.
    pub fn count(&self) -> usize {
        self.info.len()
    }

    /// The region at (x, y).
    #[inline]
    pub fn at(&self, x: u32, y: u32) -> u32 {
        self.index[y as usize * self.width as usize + x as usize]
    }

    /// Regions from an image: one per exact colour.
    pub fn from_image(image: &DynamicImage) -> Self {
        let (width, height) = (image.width(), image.height());
        let rgba = image.to_rgba16();
        let mut lookup: HashMap<[u16; 4], u32> = HashMap::new();
        let mut info = Vec::new();
        let mut index = Vec::with_capacity(width as usize * height as usize);
        let mut last: Option<([u16; 4], u32)> = None;
        for (k, p) in rgba.pixels().enumerate() {
            // Regions come in runs: reuse the previous pixel's answer while the colour repeats.
            let r = match last {
                Some((c, r)) if c == p.0 => r,
                _ => *lookup.entry(p.0).or_insert_with(|| {
                    let k = k as u32;
                    info.push(RegionInfo { colour: p.0, first: (k % width, k / width), layer: None });
                    info.len() as u32 - 1
                }),
            };
            last = Some((p.0, r));
            index.push(r);
        }
        Self { width, height, index, info }
    }

    /// Reads the region image at `path`; it must be `width × height` (the collage's size).
    pub fn load(path: &Path, width: u32, height: u32) -> Result<Self> {
        let image = crate::png::read_image(path)?;
        if (image.width(), image.height()) != (width, height) {
            return Err(MccError::SizeMismatch {
                path: path.into(),
                what: "the region image".into(),
                found: (image.width(), image.height()),
                expected_from: "the collage".into(),
                expected: (width, height),
            });
        }
        Ok(Self::from_image(&image))
    }

    /// `<collage-stem>-regions.png` beside `collage`.
    pub fn beside(collage: &Path) -> PathBuf {
        let stem = collage.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        collage.with_file_name(format!("{stem}-regions.png"))
    }

    /// The regions for `collage`: from `explicit` if given, else from the image beside the collage
    /// if there is one, else a single region. Returns the path used, if any.
    pub fn find(
        collage: &Path,
        explicit: Option<&Path>,
        width: u32,
        height: u32,
    ) -> Result<(Self, Option<PathBuf>)> {
        let path = match explicit {
            Some(p) => p.to_path_buf(),
            None => {
                let beside = Self::beside(collage);
                if !beside.is_file() {
                    return Ok((Self::single(width, height), None));
                }
                beside
            }
        };
        Ok((Self::load(&path, width, height)?, Some(path)))
    }

    /// Refuses regions whose size differs from `(width, height)`.
    pub fn check_size(&self, width: u32, height: u32) -> Result<()> {
        if (self.width, self.height) != (width, height)
            || self.index.len() != width as usize * height as usize
        {
            return Err(MccError::input(
                "region image",
                format!("is {}x{}, but the collage is {width}x{height}", self.width, self.height),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::scratch_dir;
    use image::{Rgb, RgbImage};

    #[test]
    fn one_region_per_exact_colour_in_raster_order() {
        let img = RgbImage::from_fn(4, 3, |x, y| match (x + y) % 3 {
            0 => Rgb([255, 0, 0]),
            1 => Rgb([0, 0, 255]),
            _ => Rgb([255, 0, 1]), // one unit off red: a different region
        });
        let r = Regions::from_image(&DynamicImage::ImageRgb8(img));
        assert_eq!(r.count(), 3);
        assert_eq!(&r.index[..4], &[0, 1, 2, 0]);
        assert_eq!(r.info[2].first, (2, 0));
        assert_eq!(r.info[1].to_string(), "colour #0000ff, first pixel (1, 0)");
    }

    #[test]
    fn found_beside_the_collage_or_single() {
        let dir = scratch_dir("regions");
        let collage = dir.join("cut.png");
        let (r, used) = Regions::find(&collage, None, 5, 4).unwrap();
        assert_eq!((r.count(), used), (1, None));
        assert!(r.index.iter().all(|&i| i == 0));
        let beside = Regions::beside(&collage);
        assert!(beside.ends_with("cut-regions.png"));
        let img = RgbImage::from_fn(5, 4, |x, _| if x < 2 { Rgb([1, 2, 3]) } else { Rgb([9, 9, 9]) });
        crate::png::write_png(&beside, &DynamicImage::ImageRgb8(img)).unwrap();
        let (r, used) = Regions::find(&collage, None, 5, 4).unwrap();
        assert_eq!((r.count(), used.as_deref()), (2, Some(beside.as_path())));
        let err = Regions::find(&collage, None, 6, 4).unwrap_err().to_string();
        assert!(err.contains("cut-regions.png") && err.contains("5x4") && err.contains("6x4"), "{err}");
        let err = Regions::find(&collage, Some(&dir.join("nope.png")), 5, 4).unwrap_err().to_string();
        assert!(err.contains("nope.png"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
