//! Bands merged into the image one run would have written (docs/farm.md, "Bands and resume"):
//! the pixels of every layer copied row for row (each pixel is a pure function of the seed, so
//! the result is bit for bit the single run's), the header the same apart from the seconds,
//! which add up the bands' (their rays and samples add up exactly). Missing, duplicate,
//! misplaced or mismatched bands are refused by file.

use super::COUNT_KEYS;
use super::band::{Band, IMAGE_SIZE_KEY, TILE_KEY, TILE_ROWS_KEY};
use super::output::{
    DENOISE_AUX_KEY, DENOISE_KEY, DENOISED_LAYER, DENOISER_KEY, denoise_final, is_setting_key,
};
use crate::denoise::{Guide, Quality, Settings};
use crate::error::{Result, TracerError};
use crate::image::{GrayImage, RgbImage};
use crate::image_io::{Aov, ExrImage, ExrLayer, read_exr, write_exr, write_png_srgb};
use glam::UVec2;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// What a merge wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Merged {
    /// The whole image's EXR.
    pub exr: PathBuf,
    /// Its PNG preview.
    pub png: PathBuf,
    /// How many band files went into it.
    pub bands: usize,
    /// The image's size.
    pub size: UVec2,
}

/// The band files `NAME.tileIofN.exr` of the image `out` (`NAME.exr`) in its folder, in band
/// order (every N found: a folder holding bands of two cuts is refused by [`merge_bands`]).
pub fn band_files(out: &Path) -> Result<Vec<PathBuf>> {
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let name = out.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| TracerError::io(dir, e))? {
        let entry = entry.map_err(|e| TracerError::io(dir, e))?;
        let file = entry.file_name().to_string_lossy().into_owned();
        if let Some((band, whole)) = Band::from_file_name(&file).filter(|(_, whole)| *whole == name) {
            found.push((band.count, band.index, dir.join(file), whole));
        }
    }
    found.sort();
    Ok(found.into_iter().map(|(_, _, path, _)| path).collect())
}

/// One band file read and checked against its own header.
struct Piece {
    path: PathBuf,
    band: Band,
    rows: Range<u32>,
    size: UVec2,
    image: ExrImage,
}

impl Piece {
    fn read(path: &Path) -> Result<Self> {
        let image = read_exr(path)?;
        let bad = |m: String| TracerError::image(path, m);
        let get = |key: &str| {
            image.metadata.get(key).ok_or_else(|| {
                bad(format!("no {key} in its header: not a band file (`render --tile I/N` writes them)"))
            })
        };
        let band = Band::parse(get(TILE_KEY)?).map_err(|e| bad(e.to_string()))?;
        let size = get(IMAGE_SIZE_KEY)?
            .split_once('x')
            .and_then(|(w, h)| Some(UVec2::new(w.parse().ok()?, h.parse().ok()?)))
            .ok_or_else(|| bad(format!("{IMAGE_SIZE_KEY} is not WxH")))?;
        let rows = band.rows(size.y);
        let recorded = get(TILE_ROWS_KEY)?;
        if *recorded != format!("{}..{}", rows.start, rows.end) {
            return Err(bad(format!(
                "rows {recorded}, but band {band} of a {}-row image is rows {}..{}",
                size.y, rows.start, rows.end
            )));
        }
        if (image.rgb.width, image.rgb.height) != (size.x, rows.len() as u32) {
            return Err(bad(format!(
                "{}x{} pixels, but band {band} of a {}x{} image is {}x{}",
                image.rgb.width,
                image.rgb.height,
                size.x,
                size.y,
                size.x,
                rows.len()
            )));
        }
        Ok(Self { path: path.to_path_buf(), band, rows, size, image })
    }

    /// The header's settings: every `mcctrace/…` key but the band's and the counts.
    fn settings(&self) -> BTreeMap<&str, &str> {
        let band_keys = [TILE_KEY, TILE_ROWS_KEY, IMAGE_SIZE_KEY];
        self.image
            .metadata
            .iter()
            .filter(|(k, _)| is_setting_key(k) && !band_keys.contains(&k.as_str()))
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect()
    }

    /// The count `key` of the header, as a number.
    fn count<T: std::str::FromStr>(&self, key: &str) -> Result<T> {
        self.image
            .metadata
            .get(key)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| TracerError::image(&self.path, format!("no number {key} in its header")))
    }
}

/// Assembles the band files `bands` (any order) into `out` (an .exr) and its PNG beside it, as
/// one run without `--tile` would have written them. Refused, naming the file: a file that is
/// not a whole band (unreadable, no band header, rows or size not its band's), bands of another
/// cut, image size or setting than the first, a band given twice, and a missing non-empty band
/// (named as the first band is named, `NAME.tileIofN.exr`, or after `out`).
pub fn merge_bands(bands: &[PathBuf], out: &Path) -> Result<Merged> {
    if bands.is_empty() {
        return Err(TracerError::Settings(format!(
            "no band files for {}: give them, or render them beside it with --tile I/N",
            out.display()
        )));
    }
    let read: Vec<Piece> = bands.iter().map(|p| Piece::read(p)).collect::<Result<_>>()?;
    let first = &read[0];
    let reference = first.settings();
    let mut pieces: BTreeMap<u32, &Piece> = BTreeMap::new();
    for piece in &read {
        let bad = |m: String| TracerError::image(&piece.path, m);
        if (piece.band.count, piece.size) != (first.band.count, first.size) {
            return Err(bad(format!(
                "band {} of a {}x{} image, but {} is band {} of a {}x{} image",
                piece.band,
                piece.size.x,
                piece.size.y,
                first.path.display(),
                first.band,
                first.size.x,
                first.size.y
            )));
        }
        let settings = piece.settings();
        let mut keys: Vec<&str> = settings.keys().chain(reference.keys()).copied().collect();
        keys.sort_unstable();
        keys.dedup();
        let differ: Vec<String> = keys
            .into_iter()
            .filter(|k| settings.get(k) != reference.get(k))
            .map(|k| {
                let (mine, theirs) =
                    (settings.get(k).unwrap_or(&"(none)"), reference.get(k).unwrap_or(&"(none)"));
                format!("{} {mine} ≠ {theirs}", k.trim_start_matches("mcctrace/"))
            })
            .collect();
        if !differ.is_empty() {
            return Err(bad(format!(
                "rendered with other settings than {}: {}",
                first.path.display(),
                differ.join(", ")
            )));
        }
        let layers = |p: &Piece| p.image.layers.keys().cloned().collect::<Vec<_>>();
        if layers(piece) != layers(first) {
            return Err(bad(format!(
                "layers {:?}, but {} has {:?}",
                layers(piece),
                first.path.display(),
                layers(first)
            )));
        }
        if let Some(other) = pieces.insert(piece.band.index, piece) {
            return Err(bad(format!("band {} is given twice: also {}", piece.band, other.path.display())));
        }
    }
    // A missing band is named as the given bands are: NAME.tileIofN.exr beside the first.
    let name = first.path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let whole =
        Band::from_file_name(&name).map_or_else(|| out.to_path_buf(), |(_, w)| first.path.with_file_name(w));
    for index in 1..=first.band.count {
        let band = Band { index, count: first.band.count };
        if !pieces.contains_key(&index) && !band.rows(first.size.y).is_empty() {
            let rows = band.rows(first.size.y);
            return Err(TracerError::image(
                band.path(&whole),
                format!(
                    "band {band} (rows {}..{}) is missing: render it with --tile {band}",
                    rows.start, rows.end
                ),
            ));
        }
    }
    write_merged(&pieces, first, out)
}

/// Writes the checked `pieces` (by band index) as one image to `out` and its PNG.
fn write_merged(pieces: &BTreeMap<u32, &Piece>, first: &Piece, out: &Path) -> Result<Merged> {
    let size = first.size;
    let width = size.x as usize;
    let mut rgb = RgbImage::new(size.x, size.y);
    let mut layers: BTreeMap<String, ExrLayer> = first
        .image
        .layers
        .iter()
        .map(|(name, layer)| {
            let whole = match layer {
                ExrLayer::Rgb(_) => ExrLayer::Rgb(RgbImage::new(size.x, size.y)),
                ExrLayer::Gray(_) => ExrLayer::Gray(GrayImage {
                    width: size.x,
                    height: size.y,
                    pixels: vec![0.0; width * size.y as usize],
                }),
            };
            (name.clone(), whole)
        })
        .collect();
    let (mut seconds, mut rays, mut samples) = (0.0f64, 0u64, 0u64);
    for piece in pieces.values() {
        let at = piece.rows.start as usize * width..piece.rows.end as usize * width;
        rgb.pixels[at.clone()].copy_from_slice(&piece.image.rgb.pixels);
        for (name, layer) in &mut layers {
            match (layer, &piece.image.layers[name]) {
                (ExrLayer::Rgb(whole), ExrLayer::Rgb(part)) => {
                    whole.pixels[at.clone()].copy_from_slice(&part.pixels)
                }
                (ExrLayer::Gray(whole), ExrLayer::Gray(part)) => {
                    whole.pixels[at.clone()].copy_from_slice(&part.pixels)
                }
                _ => {
                    return Err(TracerError::image(
                        &piece.path,
                        format!("layer {name} is of another kind than in the first band"),
                    ));
                }
            }
        }
        seconds += piece.count::<f64>(COUNT_KEYS[0])?;
        rays += piece.count::<u64>(COUNT_KEYS[1])?;
        samples += piece.count::<u64>(COUNT_KEYS[2])?;
    }
    let mut metadata: Vec<(&str, String)> =
        first.settings().into_iter().map(|(k, v)| (k, v.to_owned())).collect();
    metadata.extend(COUNT_KEYS.into_iter().zip([
        format!("{seconds:.6}"),
        rays.to_string(),
        samples.to_string(),
    ]));
    // Bands rendered with `--denoise` carry albedo and normal, not a denoised picture: the
    // whole image is denoised here, once, so no band edge shows as a seam.
    let denoised = if let Some(settings) = denoise_settings(&first.path, &first.image.metadata)? {
        let aux = |name: &str| match layers.get(name) {
            Some(ExrLayer::Rgb(image)) => Ok(image),
            _ => Err(TracerError::image(
                &first.path,
                format!(
                    "rendered with --denoise but has no RGB layer {name} to denoise the merged image with"
                ),
            )),
        };
        let (image, denoiser) = denoise_final(&rgb, aux("albedo")?, aux("normal")?, settings)?;
        metadata.push((DENOISER_KEY, denoiser));
        Some(image)
    } else {
        None
    };
    // Without `--aovs`, the bands' albedo and normal were only for the denoiser: the merged file
    // holds the layers the single run would have written.
    let aux_only =
        denoised.is_some() && first.image.metadata.get("mcctrace/aovs").is_some_and(|v| v == "false");
    let mut aovs: Vec<Aov<'_>> = layers
        .iter()
        .filter(|_| !aux_only)
        .map(|(name, layer)| match layer {
            ExrLayer::Rgb(image) => Aov::Rgb { name, image },
            ExrLayer::Gray(image) => Aov::Gray { name, image },
        })
        .collect();
    if let Some(image) = &denoised {
        aovs.push(Aov::Rgb { name: DENOISED_LAYER, image });
    }
    write_exr(out, &rgb, &aovs, &metadata)?;
    let png = out.with_extension("png");
    write_png_srgb(&png, denoised.as_ref().unwrap_or(&rgb))?;
    Ok(Merged { exr: out.to_path_buf(), png, bands: pieces.len(), size })
}

/// How bands whose header is `metadata` (of file `path`) are denoised once merged, as their
/// header records it (`None`: not denoised); bands from before the quality was recorded say
/// `true`, which was high quality with prefiltered auxiliaries.
fn denoise_settings(path: &Path, metadata: &BTreeMap<String, String>) -> Result<Option<Settings>> {
    let Some(quality) = metadata.get(DENOISE_KEY) else { return Ok(None) };
    if quality == "true" {
        return Ok(Some(Settings { quality: Quality::High, guide: Guide::Prefiltered }));
    }
    let bad = |key: &str, value: &str| {
        TracerError::image(path, format!("header {key} is {value:?}, which this mcctrace does not know"))
    };
    let quality = Quality::from_name(quality).ok_or_else(|| bad(DENOISE_KEY, quality))?;
    let guide = metadata.get(DENOISE_AUX_KEY).map_or("", String::as_str);
    let guide = Guide::from_name(guide).ok_or_else(|| bad(DENOISE_AUX_KEY, guide))?;
    Ok(Some(Settings { quality, guide }))
}
