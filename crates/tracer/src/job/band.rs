//! Bands of an image (docs/farm.md, "Bands and resume"): `--tile I/N` renders the I-th of N
//! horizontal bands, written as a file of its own beside the whole image's name, which
//! `merge` assembles into the image one run would have written.

use crate::error::{Result, TracerError};
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Header key: which band of how many (`I/N`).
pub const TILE_KEY: &str = "mcctrace/tile";
/// Header key: the image rows the band holds (`START..END`, output pixels, top row 0).
pub const TILE_ROWS_KEY: &str = "mcctrace/tile_rows";
/// Header key: the whole image's size (`WxH`).
pub const IMAGE_SIZE_KEY: &str = "mcctrace/image_size";

/// Band `index` of `count` horizontal bands (1-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Band {
    /// Which band, 1 ..= `count`.
    pub index: u32,
    /// How many bands the image is cut into (at least 1).
    pub count: u32,
}

impl Band {
    /// Band `index` of `count`; refused unless 1 ≤ `index` ≤ `count`.
    pub fn new(index: u32, count: u32) -> Result<Self> {
        if count == 0 || index == 0 || index > count {
            return Err(TracerError::Settings(format!(
                "tile {index}/{count}: must be I/N with 1 ≤ I ≤ N (the first of 4 bands is 1/4)"
            )));
        }
        Ok(Self { index, count })
    }

    /// Parses `I/N`.
    pub fn parse(text: &str) -> Result<Self> {
        let bad = || TracerError::Settings(format!("tile {text:?}: expected I/N, e.g. 2/8"));
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        Self::new(i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?)
    }

    /// The rows of an image `height` rows tall this band holds: the first `height % count`
    /// bands take one row more than the rest, so bands differ by at most a row; with more bands
    /// than rows, the bands past the last row are empty.
    pub fn rows(&self, height: u32) -> Range<u32> {
        let (base, extra) = (height / self.count, height % self.count);
        let k = self.index - 1;
        let start = k * base + k.min(extra);
        start..start + base + u32::from(k < extra)
    }

    /// The band's file for the whole image `exr`: `NAME.tileIofN.exr` beside `NAME.exr`.
    pub fn path(&self, exr: &Path) -> PathBuf {
        let stem = exr.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        exr.with_file_name(format!("{stem}.tile{}of{}.exr", self.index, self.count))
    }

    /// The band a file name `NAME.tileIofN.exr` names, with the whole image's file name
    /// (`NAME.exr`); `None` for any other name.
    pub fn from_file_name(name: &str) -> Option<(Self, String)> {
        let rest = name.strip_suffix(".exr")?;
        let (stem, tile) = rest.rsplit_once(".tile")?;
        let (i, n) = tile.split_once("of")?;
        let band = Self::new(i.parse().ok()?, n.parse().ok()?).ok()?;
        (format!("{stem}.tile{i}of{n}.exr") == band.path(Path::new(&format!("{stem}.exr"))).to_string_lossy())
            .then(|| (band, format!("{stem}.exr")))
    }

    /// The header attributes recording this band of an image of `width` × `height`.
    pub fn header(&self, width: u32, height: u32) -> [(&'static str, String); 3] {
        let rows = self.rows(height);
        [
            (TILE_KEY, self.to_string()),
            (TILE_ROWS_KEY, format!("{}..{}", rows.start, rows.end)),
            (IMAGE_SIZE_KEY, format!("{width}x{height}")),
        ]
    }
}

impl fmt::Display for Band {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bands cover every row once, in order, differ by at most a row, and with more bands
    /// than rows the ones past the image are empty.
    #[test]
    fn bands_cover_the_rows_once() {
        for height in [1, 2, 5, 36, 37] {
            for count in [1, 2, 3, 7, 36, 40] {
                let rows: Vec<Range<u32>> =
                    (1..=count).map(|i| Band::new(i, count).unwrap().rows(height)).collect();
                assert_eq!(rows[0].start, 0);
                assert_eq!(rows.last().unwrap().end, height);
                assert!(rows.windows(2).all(|w| w[0].end == w[1].start));
                let lens: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
                let (lo, hi) = (lens.iter().min().unwrap(), lens.iter().max().unwrap());
                assert!(hi - lo <= 1, "{height} rows in {count} bands: {lens:?}");
                let empty = lens.iter().position(|&l| l == 0).unwrap_or(lens.len());
                assert!(lens[empty..].iter().all(|&l| l == 0), "empty bands only past the image");
            }
        }
        assert_eq!(Band::new(3, 4).unwrap().rows(10), 6..8);
    }

    #[test]
    fn parses_names_and_refuses_nonsense() {
        assert_eq!(Band::parse("2/8").unwrap(), Band { index: 2, count: 8 });
        for bad in ["0/4", "5/4", "1/0", "2", "a/b", "-1/3"] {
            assert!(Band::parse(bad).unwrap_err().to_string().contains("tile"), "{bad}");
        }
        let band = Band::new(2, 8).unwrap();
        let path = band.path(Path::new("out/final.exr"));
        assert_eq!(path, Path::new("out/final.tile2of8.exr"));
        assert_eq!(Band::from_file_name("final.tile2of8.exr"), Some((band, "final.exr".to_owned())));
        assert_eq!(Band::from_file_name("final.tile02of8.exr"), None);
        assert_eq!(Band::from_file_name("final.tile9of8.exr"), None);
        assert_eq!(Band::from_file_name("final.exr"), None);
    }
}
