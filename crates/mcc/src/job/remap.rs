//! A collage remapped from files (docs/design/mcc.md §4.5, §4.6, §5): the collage read against the
//! frame's view ray files, its regions found, the rays loaded one file at a time, the remapper
//! run, and its debug pictures written.

use crate::collage::CollageOptions;
use crate::error::{MccError, Result};
use crate::layers::{CameraNames, RegionSource, open_collage};
use crate::names::{find_view_rays, view_rays_name};
use crate::ray_file::RayFormat;
use crate::remap::{RemapConfig, RemapOutput, RemapWarning, SourceRays, remap_sources};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// A collage on disk and what it was cut from.
#[derive(Clone, Debug, PartialEq)]
pub struct CollageFiles {
    /// The collage: a tagged image, or a layered file (OpenRaster, PSD: `crate::layers`).
    pub collage: PathBuf,
    /// The region image (an image or a layered file); `None` takes the collage's `regions`
    /// group, else `<collage-stem>-regions.png` beside the collage.
    pub regions: Option<PathBuf>,
    /// The directory holding the views' ray files (`frameFFFFcameraCC.{mcr|txt}`).
    pub rays_dir: PathBuf,
    /// The frame whose views to use.
    pub frame: u32,
    /// How to decode the collage.
    pub options: CollageOptions,
}

impl CollageFiles {
    /// The collage at `collage`, cut from frame `frame`'s views in `rays_dir`, with default
    /// decoding and its region image (if any) beside it.
    pub fn new(collage: impl Into<PathBuf>, rays_dir: impl Into<PathBuf>, frame: u32) -> Self {
        Self {
            collage: collage.into(),
            regions: None,
            rays_dir: rays_dir.into(),
            frame,
            options: CollageOptions::default(),
        }
    }

    /// The files a remap of this collage reads: the collage, its region image (given, or the
    /// one beside the collage if there is one) and the frame's view ray files.
    pub fn inputs(&self) -> Result<Vec<PathBuf>> {
        let regions = match &self.regions {
            Some(path) => Some(path.clone()),
            None => Some(crate::regions::Regions::beside(&self.collage)).filter(|p| p.is_file()),
        };
        let rays = find_view_rays(&self.rays_dir, self.frame)?;
        Ok(std::iter::once(self.collage.clone()).chain(regions).chain(rays.into_values()).collect())
    }

    /// Remaps the collage: finds the frame's ray files, reads the collage (by its content: a
    /// tagged image or a layered file, [`open_collage`]) against them, finds the regions, loads
    /// the rays one file at a time and remaps. Stray pixels treated as background, and notes
    /// about a layered file's layers, come back as warnings; every error names its file.
    pub fn remap(&self, config: &RemapConfig) -> Result<RemapOutput> {
        Ok(self.remap_with_regions(config)?.0)
    }

    /// [`Self::remap`], also saying where the regions came from (given, found beside the
    /// collage, the collage's own group, or none).
    pub fn remap_with_regions(&self, config: &RemapConfig) -> Result<(RemapOutput, RegionSource)> {
        config.validate()?;
        let paths = find_view_rays(&self.rays_dir, self.frame)?;
        if paths.is_empty() {
            return Err(MccError::Directory {
                path: self.rays_dir.clone(),
                message: format!(
                    "no ray files for frame {} (looked for {} and the like)",
                    self.frame,
                    view_rays_name(self.frame, 1, RayFormat::Binary)
                ),
            });
        }
        let known: BTreeSet<u32> = paths.keys().copied().collect();
        // A tagged image, or a layered file whose layers name their cameras (by id, or by the
        // names the views' EXR headers record).
        let names = CameraNames::from_views(known, &self.rays_dir, self.frame);
        let opened = open_collage(&self.collage, self.regions.as_deref(), &names, self.options)
            .map_err(|e| with_views_size(e, &paths))?;
        if opened.collage.cameras().is_empty() {
            return Err(MccError::EmptyCollage { path: self.collage.clone() });
        }
        let sources = SourceRays::load(&opened.collage, &paths)?;
        let mut output = remap_sources(&opened.collage, &opened.regions, &sources, self.frame, config)?;
        let mut first = Vec::new();
        if !opened.strays.is_empty() {
            first.push(RemapWarning::StraysIgnored(opened.strays));
        }
        first.extend(opened.notes.into_iter().map(RemapWarning::Layers));
        if !opened.collage.ids.contains(&0) {
            first.push(RemapWarning::NoBackground);
        }
        output.warnings.splice(0..0, first);
        Ok((output, opened.regions_from))
    }
}

/// A stray-pixel error `e` told what the views' size says: strays in a collage of another size
/// than the views (`paths`, by id) come from resampling it, which is what the report then says.
fn with_views_size(e: MccError, paths: &std::collections::BTreeMap<u32, PathBuf>) -> MccError {
    let MccError::StrayPixels { path, mut report } = e else { return e };
    let collage = image::image_dimensions(&path).ok();
    let views = paths.values().next().and_then(|p| crate::RayFile::read(p).ok()).map(|r| (r.width, r.height));
    if let (Some(collage), Some(views)) = (collage, views)
        && collage != views
    {
        report.resized = Some((collage, views));
    }
    MccError::StrayPixels { path, report }
}

/// A collage remapped from its files, with the debug pictures written to a folder.
#[derive(Clone, Debug, PartialEq)]
pub struct RemapJob {
    /// The collage and its views.
    pub input: CollageFiles,
    /// The remapper's settings (Glassner's by default).
    pub config: RemapConfig,
    /// Where the debug pictures go (created if missing); `None`: no pictures.
    pub debug_dir: Option<PathBuf>,
}

/// What a [`RemapJob`] made.
#[derive(Clone, Debug)]
pub struct Remapped {
    /// The rays, warnings and (with debug pictures) the debug data.
    pub output: RemapOutput,
    /// The debug pictures written, if any.
    pub debug_pictures: Vec<PathBuf>,
    /// The region image found beside the collage and used, when none was given (a file the
    /// caller did not name changes the remap: say so).
    pub regions_found: Option<PathBuf>,
}

impl RemapJob {
    /// Remaps `input` with Glassner's settings and no debug pictures.
    pub fn new(input: CollageFiles) -> Self {
        Self { input, config: RemapConfig::GLASSNER, debug_dir: None }
    }

    /// Remaps, then writes the debug pictures (`debug-frameFFFF-…png`) if asked.
    pub fn run(&self) -> Result<Remapped> {
        let config = RemapConfig { debug: self.config.debug || self.debug_dir.is_some(), ..self.config };
        let (output, regions_from) = self.input.remap_with_regions(&config)?;
        let regions_found = match regions_from {
            RegionSource::File(path) if self.input.regions.is_none() => Some(path),
            _ => None,
        };
        let mut debug_pictures = Vec::new();
        if let (Some(dir), Some(debug)) = (&self.debug_dir, &output.debug) {
            std::fs::create_dir_all(dir).map_err(|e| MccError::io(dir, e))?;
            debug_pictures = debug.write_pngs(dir, self.input.frame)?;
        }
        Ok(Remapped { output, debug_pictures, regions_found })
    }
}

impl Remapped {
    /// Writes the remapped rays to `path` in `format` (its folder created if missing),
    /// atomically.
    pub fn write_rays(&self, path: &Path, format: RayFormat) -> Result<()> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| MccError::io(dir, e))?;
        }
        self.output.rays.write(path, format)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray_file::{RayFile, StoredRay};
    use crate::test_util::{scratch_dir, view};

    fn bits(r: &StoredRay) -> [u32; 6] {
        bytemuck::cast(*r)
    }

    /// Writes views 1 and 2 of frame 7 at 20 × 12 into `dir` and a collage cut from them
    /// (camera 1 on the left, camera 2 on the right, one stray pixel at (8, 0) unless `clean`).
    fn cut(dir: &Path, clean: bool) -> PathBuf {
        let (w, h) = (20, 12);
        let code = crate::TagCode::default();
        for id in [1, 2] {
            let path = dir.join(view_rays_name(7, id, RayFormat::Binary));
            view(id, w, h).write(&path, RayFormat::Binary).unwrap();
        }
        let img = image::RgbImage::from_fn(w, h, |x, y| {
            image::Rgb(match x {
                0..4 => code.encode([10, 20, 30], 1).unwrap(),
                15.. => code.encode([0, 0, 0], 2).unwrap(),
                _ if y == 0 && x == 8 && !clean => [100, 100, 100],
                _ => [0, 0, 0],
            })
        });
        let path = dir.join("cut.png");
        crate::png::write_png(&path, &image::DynamicImage::ImageRgb8(img)).unwrap();
        path
    }

    #[test]
    fn remaps_from_files_and_writes_debug_pictures() {
        let dir = scratch_dir("remap-files");
        let mut input = CollageFiles::new(cut(&dir, false), &dir, 7);
        let err = input.remap(&RemapConfig::GLASSNER).unwrap_err().to_string();
        assert!(err.contains("cut.png") && err.contains("(8, 0)"), "{err}");
        input.options.strays = crate::StrayPolicy::Background;
        let job = RemapJob { debug_dir: Some(dir.join("debug")), ..RemapJob::new(input.clone()) };
        let done = job.run().unwrap();
        assert!(matches!(&done.output.warnings[..], [RemapWarning::StraysIgnored(r)] if r.count == 1));
        assert_eq!(bits(done.output.rays.get(0, 0)), bits(view(1, 20, 12).get(0, 0)));
        assert_eq!(done.debug_pictures.len(), 6);
        assert!(dir.join("debug/debug-frame0007-seams.png").is_file());
        assert_eq!(done.regions_found, None);
        assert!(done.debug_pictures.iter().all(|p| p.is_file()));
        assert!(dir.join("debug/debug-frame0007-camera02-weights.png").is_file());
        let saved = dir.join("out/rerender-frame0007.mcr");
        done.write_rays(&saved, RayFormat::Binary).unwrap();
        assert_eq!(RayFile::read(&saved).unwrap().rays, done.output.rays.rays);
        let err = CollageFiles { frame: 8, ..input }.remap(&RemapConfig::GLASSNER).unwrap_err().to_string();
        assert!(err.contains("no ray files for frame 8"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A region image beside the collage is used and named; a given one is not "found".
    #[test]
    fn names_the_region_image_found_beside_the_collage() {
        let dir = scratch_dir("remap-found-regions");
        let collage = cut(&dir, true);
        let beside = dir.join("cut-regions.png");
        let halves = image::RgbImage::from_fn(20, 12, |_, y| {
            image::Rgb(if y < 6 { [255, 0, 0] } else { [0, 0, 255] })
        });
        crate::png::write_png(&beside, &image::DynamicImage::ImageRgb8(halves)).unwrap();
        let input = CollageFiles::new(&collage, &dir, 7);
        assert_eq!(RemapJob::new(input.clone()).run().unwrap().regions_found, Some(beside.clone()));
        let given = CollageFiles { regions: Some(beside), ..input };
        assert_eq!(RemapJob::new(given).run().unwrap().regions_found, None);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_collage_without_camera_pixels_is_refused_by_name() {
        let dir = scratch_dir("remap-empty");
        cut(&dir, true);
        let black = dir.join("black.png");
        crate::png::write_png(&black, &image::DynamicImage::ImageRgb8(image::RgbImage::new(20, 12))).unwrap();
        let err = CollageFiles::new(&black, &dir, 7).remap(&RemapConfig::GLASSNER).unwrap_err();
        assert!(matches!(&err, MccError::EmptyCollage { path } if *path == black), "{err}");
        assert_eq!(
            err.to_string(),
            format!("{}: has no camera pixels: there is nothing to remap from", black.display())
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
