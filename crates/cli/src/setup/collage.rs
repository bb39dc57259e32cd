//! The collage inputs and remapper settings (docs/design.md §4.5, §4.6, §5) that `remap`,
//! `rerender`, `keys` and the demo share, the library's [`RemapJob`] they make, and what is said
//! about a finished remap.

use anyhow::bail;
use clap::Args;
use mcc::job::{CollageFiles, RemapJob, Remapped};
use mcc::{CollageOptions, RemapConfig, StrayHints, StrayPolicy, TagCode};
use std::path::PathBuf;

/// Collage inputs and remapper settings, shared by `remap` and `rerender`.
#[derive(Args, Debug, Clone)]
pub struct CollageInputArgs {
    /// The collage: an 8-bit RGB/RGBA image cut from the tagged views, or a layered OpenRaster
    /// (.ora) or Photoshop (.psd) file whose visible layers are named after their cameras.
    #[arg(long)]
    pub collage: Option<PathBuf>,
    /// Directory holding the views' ray files (frameFFFFcameraCC.mcr or .txt).
    #[arg(long)]
    pub rays: Option<PathBuf>,
    /// Region image, or layered file of region layers (default: the collage's "regions" layer
    /// group, else <collage-stem>-regions.png beside the collage, if present).
    #[arg(long)]
    pub regions: Option<PathBuf>,
    /// How the collage is read and remapped.
    #[command(flatten)]
    pub settings: RemapSettingsArgs,
    /// Write debug pictures (each camera's edges and weights, the dominant camera, a map of the
    /// seam ratio) here.
    #[arg(long)]
    pub debug_dir: Option<PathBuf>,
    /// Report the seam ratio of the remapped rays (p99, p99.9 and maximum over the background
    /// pixels; about 1 where the blend turns smoothly, large at a tear).
    #[arg(long)]
    pub report: bool,
}

/// Collage-reading and remapper settings, shared by `remap`, `rerender` and `keys`.
#[derive(Args, Debug, Clone)]
pub struct RemapSettingsArgs {
    /// Treat stray pixels (non-background with no usable camera id, e.g. an antialiased
    /// selection edge) as background instead of refusing the collage.
    #[arg(long)]
    pub ignore_strays: bool,
    /// Bits per channel of the camera tag.
    #[arg(long, default_value_t = TagCode::DEFAULT_BITS, value_parser = crate::args::tag_bits)]
    pub tag_bits: u8,
    /// Radius of the remapper's first box blur.
    #[arg(long, default_value_t = RemapConfig::GLASSNER.first_blur_radius)]
    pub blur1: u32,
    /// Radius of the remapper's second box blur.
    #[arg(long, default_value_t = RemapConfig::GLASSNER.second_blur_radius)]
    pub blur2: u32,
    /// Control value of the remapper's ease curve (0.5: no easing).
    #[arg(long, default_value_t = RemapConfig::GLASSNER.ease_control, value_parser = crate::args::ease)]
    pub ease: f32,
    /// Seamless blend: removes the seams of the column's blend (tears at region boundaries,
    /// jumps between separate pieces of one camera) by blending smooth extensions of each
    /// camera's edge rays; camera pixels keep their rays. Ignores --blur1, --blur2 and --ease.
    #[arg(long)]
    pub seamless: bool,
}

impl RemapSettingsArgs {
    /// How to decode a collage.
    pub fn collage_options(&self) -> anyhow::Result<CollageOptions> {
        Ok(CollageOptions {
            tag: TagCode::new(self.tag_bits)?,
            strays: if self.ignore_strays { StrayPolicy::Background } else { StrayPolicy::Refuse },
            hints: StrayHints {
                ignore: "--ignore-strays",
                tag_bits: "--tag-bits",
                tagged_views: "`render --tag`",
                layered_views: "`render --layers`",
            },
        })
    }

    /// The remapper's settings.
    pub fn config(&self) -> RemapConfig {
        let preset = if self.seamless { RemapConfig::SEAMLESS } else { RemapConfig::GLASSNER };
        RemapConfig {
            first_blur_radius: self.blur1,
            second_blur_radius: self.blur2,
            ease_control: self.ease,
            ..preset
        }
    }

    /// The job remapping `collage` (regions beside it unless given) against frame `frame`'s
    /// views in `rays_dir`.
    pub fn job(
        &self,
        collage: PathBuf,
        regions: Option<PathBuf>,
        rays_dir: PathBuf,
        frame: u32,
    ) -> anyhow::Result<RemapJob> {
        let input = CollageFiles {
            regions,
            options: self.collage_options()?,
            ..CollageFiles::new(collage, rays_dir, frame)
        };
        Ok(RemapJob { config: self.config(), ..RemapJob::new(input) })
    }
}

impl CollageInputArgs {
    /// The remap job the arguments ask for, at `frame`.
    pub fn job(&self, frame: u32) -> anyhow::Result<RemapJob> {
        let (Some(collage), Some(rays)) = (&self.collage, &self.rays) else {
            bail!("give both --collage and --rays (or --lens FILE for rerender)");
        };
        let mut job = self.settings.job(collage.clone(), self.regions.clone(), rays.clone(), frame)?;
        job.config.report = self.report;
        Ok(RemapJob { debug_dir: self.debug_dir.clone(), ..job })
    }
}

/// Runs `job`, then (unless quiet) shows its warnings, its time and its debug pictures; the
/// seam ratio when it was asked for (even when quiet).
pub fn remap(job: &RemapJob, quiet: bool) -> anyhow::Result<Remapped> {
    let start = std::time::Instant::now();
    let done = job.run()?;
    tell_remapped(job, &done, start.elapsed().as_secs_f64(), quiet);
    Ok(done)
}

/// Says what `job` made in `seconds`: (unless quiet) its warnings, its time and its debug
/// pictures; the seam ratio when it was asked for (even when quiet).
pub fn tell_remapped(job: &RemapJob, done: &Remapped, seconds: f64, quiet: bool) {
    if job.config.report {
        match &done.output.seams {
            Some(seams) => println!("{}: {seams}", job.input.collage.display()),
            None => {
                println!("{}: no seam ratio (no background pixels, or no pitch)", job.input.collage.display())
            }
        }
    }
    if !quiet {
        let collage = job.input.collage.display();
        if let Some(found) = &done.regions_found {
            eprintln!("regions: {} (found beside {collage}; --regions chooses another)", found.display());
        }
        for w in &done.output.warnings {
            eprintln!("warning: {collage}: {w}");
        }
        let rays = &done.output.rays;
        eprintln!("remapped {collage} ({}x{}) in {seconds:.2} s", rays.width, rays.height);
        if let Some(dir) = &job.debug_dir {
            eprintln!("debug pictures: {} files in {}", done.debug_pictures.len(), dir.display());
        }
    }
}
