//! `mcctrace remap`: the lens remapper (SPEC §5): a collage and the views' ray files in, one ray
//! per pixel out.

use crate::render::RayFormatArg;
use clap::Args;
use std::path::{Path, PathBuf};

/// Collage inputs and remapper settings, shared by `remap` and `rerender`.
#[derive(Args, Debug, Clone)]
pub struct CollageInputArgs {
    /// The collage image (8-bit RGB/RGBA cut from the tagged views).
    #[arg(long)]
    pub collage: Option<PathBuf>,
    /// Directory holding the views' ray files (frameFFFFcameraCC.mcr or .txt).
    #[arg(long)]
    pub rays: Option<PathBuf>,
    /// Region image (default: <collage-stem>-regions.png beside the collage, if present).
    #[arg(long)]
    pub regions: Option<PathBuf>,
    /// How the collage is read and remapped.
    #[command(flatten)]
    pub settings: RemapSettingsArgs,
    /// Write debug pictures (each camera's edges and weights, the dominant camera) here.
    #[arg(long)]
    pub debug_dir: Option<PathBuf>,
}

/// Collage-reading and remapper settings, shared by `remap`, `rerender` and `keys`.
#[derive(Args, Debug, Clone)]
pub struct RemapSettingsArgs {
    /// Treat stray pixels (non-background with no usable camera id, e.g. an antialiased
    /// selection edge) as background instead of refusing the collage.
    #[arg(long)]
    pub ignore_strays: bool,
    /// Bits per channel of the camera tag.
    #[arg(long, default_value_t = 2)]
    pub tag_bits: u8,
    /// Radius of the remapper's first box blur.
    #[arg(long, default_value_t = mcc::RemapConfig::GLASSNER.first_blur_radius)]
    pub blur1: u32,
    /// Radius of the remapper's second box blur.
    #[arg(long, default_value_t = mcc::RemapConfig::GLASSNER.second_blur_radius)]
    pub blur2: u32,
    /// Control value of the remapper's ease curve (0.5: no easing).
    #[arg(long, default_value_t = mcc::RemapConfig::GLASSNER.ease_control)]
    pub ease: f32,
}

impl RemapSettingsArgs {
    /// Glassner's remapper settings with `tag_bits` bits per channel, strays refused.
    pub fn glassner(tag_bits: u8) -> Self {
        Self {
            ignore_strays: false,
            tag_bits,
            blur1: mcc::RemapConfig::GLASSNER.first_blur_radius,
            blur2: mcc::RemapConfig::GLASSNER.second_blur_radius,
            ease: mcc::RemapConfig::GLASSNER.ease_control,
        }
    }
}

/// Arguments of `mcctrace remap`.
#[derive(Args, Debug)]
pub struct RemapArgs {
    #[command(flatten)]
    pub input: CollageInputArgs,
    /// Frame of the views.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// The remapped ray file to write (rerender-frameFFFF.mcr by convention).
    #[arg(long)]
    pub out: PathBuf,
    /// Encoding of the ray file.
    #[arg(long, value_enum, default_value = "binary")]
    pub ray_format: RayFormatArg,
    /// No summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs the remapper on the collage inputs; prints its warnings and writes debug pictures.
pub fn remap_collage(input: &CollageInputArgs, frame: u32, quiet: bool) -> anyhow::Result<mcc::RemapOutput> {
    let (Some(collage), Some(rays)) = (&input.collage, &input.rays) else {
        anyhow::bail!("give both --collage and --rays (or --lens FILE for rerender)");
    };
    let settings = &input.settings;
    let config = mcc::RemapConfig {
        first_blur_radius: settings.blur1,
        second_blur_radius: settings.blur2,
        ease_control: settings.ease,
        debug: input.debug_dir.is_some(),
        ..mcc::RemapConfig::GLASSNER
    };
    let options = mcc::CollageOptions {
        tag: mcc::TagCode::new(settings.tag_bits)?,
        strays: if settings.ignore_strays { mcc::StrayPolicy::Background } else { mcc::StrayPolicy::Refuse },
    };
    let inputs = mcc::remap::RemapInputs {
        collage,
        regions: input.regions.as_deref(),
        rays_dir: rays,
        frame,
        collage_options: options,
    };
    let start = std::time::Instant::now();
    let output = mcc::remap::remap_files(&inputs, &config).map_err(|e| match e {
        // The remapper works on decoded data and calls it "collage"; here the file is known.
        mcc::MccError::Input { what, message } if what == "collage" => {
            anyhow::anyhow!("{}: {message}", collage.display())
        }
        other => other.into(),
    })?;
    if !quiet {
        for w in &output.warnings {
            eprintln!("warning: {}: {w}", collage.display());
        }
        eprintln!(
            "remapped {} ({}x{}) in {:.2} s",
            collage.display(),
            output.rays.width,
            output.rays.height,
            start.elapsed().as_secs_f64()
        );
    }
    if let (Some(dir), Some(debug)) = (&input.debug_dir, &output.debug) {
        std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("creating {}: {e}", dir.display()))?;
        let written = debug.write_pngs(dir, frame)?;
        if !quiet {
            eprintln!("debug pictures: {} files in {}", written.len(), dir.display());
        }
    }
    Ok(output)
}

/// Creates the parent directory of `path` if it has one.
pub fn create_parent(path: &Path) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("creating {}: {e}", dir.display()))?;
    }
    Ok(())
}

pub fn run(a: RemapArgs) -> anyhow::Result<()> {
    let output = remap_collage(&a.input, a.frame, a.quiet)?;
    create_parent(&a.out)?;
    output.rays.write(&a.out, a.ray_format.into())?;
    if !a.quiet {
        eprintln!("rays -> {}", a.out.display());
    }
    Ok(())
}
