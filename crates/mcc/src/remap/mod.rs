//! The lens remapper (docs/design/mcc.md §5): turns a decoded collage, its regions and the views' ray
//! files into one ray per pixel. Camera pixels keep their camera's ray bit for bit; background
//! pixels get a ray blended from the nearest edge pixels of every camera:
//!
//! 1. [`edges`]: edge pixels of each camera;
//! 2. [`nearest`]: exact nearest edge pixel of each camera within the pixel's region;
//! 3. [`weights`]: initial weights from the distances;
//! 4. [`smooth`]: blur, ease, blur, renormalise;
//! 5. [`burp`]: origins by weighted sum, directions by burp of slerps;
//! 6. [`debug`]: optional pictures of the above.
//!
//! That is the column's blend, [`Blend::Glassner`], the default. [`Blend::Seamless`]
//! ([`seamless`]) keeps steps 1 and 5 and every camera pixel's ray, but blends smooth per-camera
//! ray fields ([`field`], solved by [`membrane`]) with weights whose region participation fades
//! instead of switching: no tears at region boundaries or medial axes. [`seam`] measures tears
//! (the seam ratio) in either mode's output.
//!
//! Memory: a camera pixel only ever needs its own camera's ray, and e_c(P) is always a pixel of
//! camera c, so the remapper keeps a single merged plane of source rays ([`SourceRays`]: R_id(p)(p)
//! at every camera pixel) instead of every camera's file; [`SourceRays::load`] reads the files one
//! at a time. Per camera it holds one u32 plane (e_c) and one f32 weight plane (peak memory:
//! `benches/remap.rs`; docs/performance.md, ledger: "merged source-ray plane").

pub mod burp;
pub mod debug;
pub(crate) mod edges;
pub(crate) mod field;
pub(crate) mod grid;
pub(crate) mod membrane;
pub(crate) mod nearest;
pub mod seam;
pub(crate) mod seamless;
pub(crate) mod smooth;
pub mod warning;
pub mod weights;

pub use debug::RemapDebug;
pub use seam::{SeamRatios, SeamSummary};
pub use warning::RemapWarning;

use crate::collage::Collage;
use crate::error::{MccError, Result};
use crate::ray_file::{RayFile, StoredRay};
use crate::regions::Regions;
use rayon::prelude::*;
use std::borrow::Borrow;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// How background pixels blend the cameras.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Blend {
    /// The column's method (docs/design/mcc.md §5): nearest edge rays, distance weights, blurs and ease.
    #[default]
    Glassner,
    /// Smooth per-camera ray fields and fading region participation: removes the column's seams
    /// (docs/design/mcc.md §5.8). Ignores the blur radii and the ease.
    Seamless,
}

/// Remapper settings (docs/design/mcc.md §5.4); [`RemapConfig::GLASSNER`] is the default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RemapConfig {
    /// How background pixels blend the cameras.
    pub blend: Blend,
    /// Radius of the first box blur (step 4a); 0 skips it.
    pub first_blur_radius: u32,
    /// Radius of the second box blur (step 4c); 0 skips it.
    pub second_blur_radius: u32,
    /// Control value g ∈ (0, 1) of the ease curve (step 4b); 0.5 is the identity.
    pub ease_control: f32,
    /// Seamless blend: width of the region participation fade, as a fraction of the picture's
    /// shorter side.
    pub region_fade: f32,
    /// Keep the debug data (edges, weights, dominant camera, seam ratios) in the output.
    pub debug: bool,
    /// Measure the seam ratio of the result ([`RemapOutput::seams`]; always with `debug`).
    pub report: bool,
}

impl RemapConfig {
    /// The column's settings: blur radii 4 and 3, ease control 0.75.
    pub const GLASSNER: Self = Self {
        blend: Blend::Glassner,
        first_blur_radius: 4,
        second_blur_radius: 3,
        ease_control: 0.75,
        region_fade: 0.1,
        debug: false,
        report: false,
    };
    /// No smoothing at all: the raw weights of step 3 (for comparisons and tests).
    pub const UNSMOOTHED: Self =
        Self { first_blur_radius: 0, second_blur_radius: 0, ease_control: 0.5, ..Self::GLASSNER };
    /// The seamless blend: smooth ray fields, region participation fading over a tenth of the
    /// shorter side.
    pub const SEAMLESS: Self = Self { blend: Blend::Seamless, ..Self::GLASSNER };

    /// Refuses an ease control outside (0, 1) and a region fade outside (0, 1].
    pub fn validate(&self) -> Result<()> {
        let g = self.ease_control;
        if !(g.is_finite() && g > 0.0 && g < 1.0) {
            return Err(MccError::Settings(format!("ease control {g} must be strictly between 0 and 1")));
        }
        let f = self.region_fade;
        if !(f.is_finite() && f > 0.0 && f <= 1.0) {
            return Err(MccError::Settings(format!(
                "region fade {f} must be above 0 and at most 1 (a fraction of the shorter side)"
            )));
        }
        Ok(())
    }
}

impl Default for RemapConfig {
    fn default() -> Self {
        Self::GLASSNER
    }
}

/// The remapper's result.
#[derive(Clone, Debug)]
pub struct RemapOutput {
    /// One ray per pixel (camera id 0, marked computed).
    pub rays: RayFile,
    /// Warnings, in the order found.
    pub warnings: Vec<RemapWarning>,
    /// Debug data, when asked for.
    pub debug: Option<RemapDebug>,
    /// The seam ratio of the rays, when asked for ([`RemapConfig::report`] or `debug`).
    pub seams: Option<SeamSummary>,
}

/// The source ray of every camera pixel: R_id(p)(p), merged into one plane (background slots are
/// unused). All the remapper needs from the views' ray files.
#[derive(Clone, Debug)]
pub struct SourceRays {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The rays, row-major.
    pub rays: Vec<StoredRay>,
    /// Cameras whose pixels have been filled.
    pub cameras: BTreeSet<u32>,
}

impl SourceRays {
    fn empty(collage: &Collage) -> Self {
        let rays = vec![StoredRay::default(); collage.ids.len()];
        Self { width: collage.width, height: collage.height, rays, cameras: BTreeSet::new() }
    }

    /// Refuses camera `id`'s ray file (`name` says which) unless it has the collage's size.
    fn check_size(collage: &Collage, id: u32, file: &RayFile, name: &Path) -> Result<()> {
        if (file.width, file.height) != (collage.width, collage.height) {
            return Err(MccError::SizeMismatch {
                path: name.into(),
                what: format!("camera {id}'s ray file"),
                found: (file.width, file.height),
                expected_from: "the collage".into(),
                expected: (collage.width, collage.height),
            });
        }
        Ok(())
    }

    /// Copies camera `id`'s rays at its collage pixels; `name` says which file they came from.
    fn fill(&mut self, collage: &Collage, id: u32, file: &RayFile, name: &Path) -> Result<()> {
        Self::check_size(collage, id, file, name)?;
        for ((out, &c), ray) in self.rays.iter_mut().zip(&collage.ids).zip(&file.rays) {
            if c == id {
                *out = *ray;
            }
        }
        self.cameras.insert(id);
        Ok(())
    }

    /// Gathers from ray files already in memory (camera id → file, owned or borrowed): one
    /// parallel pass, each pixel written once.
    pub fn gather<F: Borrow<RayFile>>(collage: &Collage, files: &BTreeMap<u32, F>) -> Result<Self> {
        let cameras = collage.cameras();
        let mut used: Vec<(u32, &RayFile)> = Vec::with_capacity(cameras.len());
        for &id in &cameras {
            let file = files.get(&id).ok_or_else(|| missing(id))?.borrow();
            Self::check_size(collage, id, file, Path::new(&format!("<camera {id} rays>")))?;
            used.push((id, file));
        }
        let mut rays = Vec::new();
        // Ids come in runs: each task keeps the index of the last camera it looked up.
        (0..collage.ids.len())
            .into_par_iter()
            .map_init(
                || 0usize,
                |k, p| match collage.ids[p] {
                    0 => StoredRay::default(),
                    id => {
                        if used[*k].0 != id {
                            *k = used.binary_search_by_key(&id, |u| u.0).expect("a camera of the collage");
                        }
                        used[*k].1.rays[p]
                    }
                },
            )
            .collect_into_vec(&mut rays);
        Ok(Self { width: collage.width, height: collage.height, rays, cameras })
    }

    /// Loads the ray files of the collage's cameras (camera id → path), one at a time, so that
    /// only one view's rays are ever in memory beside the merged plane.
    pub fn load(collage: &Collage, paths: &BTreeMap<u32, PathBuf>) -> Result<Self> {
        let mut sources = Self::empty(collage);
        for id in collage.cameras() {
            let path = paths.get(&id).ok_or_else(|| missing(id))?;
            let file = RayFile::read(path)?;
            sources.fill(collage, id, &file, path)?;
        }
        Ok(sources)
    }
}

fn missing(id: u32) -> MccError {
    MccError::input(format!("camera {id}"), "the collage uses this camera but no ray file was given for it")
}

/// Remaps a collage with the views' ray files in memory (camera id → file, owned or borrowed).
/// See [`remap_sources`].
pub fn remap<F: Borrow<RayFile>>(
    collage: &Collage,
    regions: &Regions,
    files: &BTreeMap<u32, F>,
    frame: u32,
    config: &RemapConfig,
) -> Result<RemapOutput> {
    remap_sources(collage, regions, &SourceRays::gather(collage, files)?, frame, config)
}

/// Remaps a collage (docs/design/mcc.md §5): the returned rays are frame `frame`'s rerender rays.
pub fn remap_sources(
    collage: &Collage,
    regions: &Regions,
    sources: &SourceRays,
    frame: u32,
    config: &RemapConfig,
) -> Result<RemapOutput> {
    config.validate()?;
    let (width, height) = (collage.width as usize, collage.height as usize);
    regions.check_size(collage.width, collage.height)?;
    if (sources.width, sources.height) != (collage.width, collage.height)
        || sources.rays.len() != collage.ids.len()
    {
        return Err(MccError::input(
            "source rays",
            format!("are {}x{}, but the collage is {width}x{height}", sources.width, sources.height),
        ));
    }
    let cameras: Vec<u32> = collage.cameras().into_iter().collect();
    if cameras.is_empty() {
        return Err(MccError::input("collage", "has no camera pixels: there is nothing to remap from"));
    }
    if let Some(&id) = cameras.iter().find(|id| !sources.cameras.contains(id)) {
        return Err(missing(id));
    }
    // Dense camera indices (0 background, k + 1 camera k); ids come in runs, so cache the last.
    let mut last = (0u32, 0u32);
    let cam: Vec<u32> = collage
        .ids
        .iter()
        .map(|&id| {
            if id != last.0 {
                last = (id, if id == 0 { 0 } else { cameras.binary_search(&id).map_or(0, |k| k as u32 + 1) });
            }
            last.1
        })
        .collect();
    let grid = grid::Grid::new(width, height);
    let edges = edges::edge_mask(&cam, grid);
    let layout = grid::Layout { grid, cam: &cam, edges: &edges, cameras: cameras.len() };
    let (rays, planes, warnings) = match config.blend {
        Blend::Glassner => {
            let boxes = nearest::RegionBoxes::new(&layout, &regions.index, regions.count());
            let nearest = nearest::nearest_edges(&layout, &regions.index, &boxes);
            let (participants, warnings) =
                weights::participants(&nearest.participates, regions, &boxes.background, cameras.len());
            let mut planes = weights::initial_weights(&layout, &regions.index, &nearest, &participants);
            let background: Vec<bool> = cam.iter().map(|&c| c == 0).collect();
            let smoothing = smooth::Smoothing {
                radii: (config.first_blur_radius as usize, config.second_blur_radius as usize),
                ease: smooth::Ease::new(config.ease_control),
            };
            smooth::smooth(&mut planes, &background, grid, smoothing);
            drop(background);
            let rays = burp::remapped_rays(&layout, &sources.rays, &nearest, &planes);
            (rays, planes, warnings)
        }
        Blend::Seamless => {
            let blend = seamless::seamless(&layout, &sources.rays, regions, config.region_fade);
            (blend.rays, blend.weights, blend.warnings)
        }
    };
    let dominant = config.debug.then(|| burp::dominant(&cam, &planes));
    // Nothing to measure without background pixels or a pitch: no figures, not an error.
    let ratios =
        (config.debug || config.report).then(|| SeamRatios::measure(&rays, &cam, width).ok()).flatten();
    let seams = ratios.as_ref().map(|r| r.summary);
    let debug = dominant.map(|dominant| RemapDebug {
        width: collage.width,
        height: collage.height,
        cameras: cameras.clone(),
        cam,
        edges,
        weights: planes,
        dominant,
        seams: ratios,
    });
    let mut rays = RayFile::new(collage.width, collage.height, frame, 0, rays)?;
    rays.computed = true;
    Ok(RemapOutput { rays, warnings, debug, seams })
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // the tests index pixels on purpose
mod tests;
