//! `mcctrace demo`: the whole workflow on the bundled café (docs/design/workflow.md §8), every picture
//! written to one folder. [`still`] is the main job (two views, a collage, a remap, the
//! rerender); [`animation`] the keyframe workflow (two key collages in-betweened into a shot);
//! both render the café's views as [`cafe`] does and cut label images as [`masks`] does.

mod animation;
mod cafe;
mod masks;
mod still;

use crate::args::Resolution;
use cafe::DemoSettings;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `mcctrace demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// The café scene (default: scenes/cafe/cafe.gltf under the current directory or the
    /// executable's folder, or one of their parents, or their share/mcctrace/).
    #[arg(long, value_name = "FILE")]
    pub(crate) scene: Option<PathBuf>,
    /// Output folder (default out/demo, or out/demo-animation with --animation).
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Samples per pixel of every render (default 32; with --animation: of the key frames'
    /// source views, default 8).
    #[arg(long, value_parser = crate::args::spp)]
    pub(crate) spp: Option<u32>,
    /// Resolution of the views and of the final picture, any size (default 480x270, the bundled
    /// mask's, which is scaled to it;
    /// with --animation: of the key frames' source views, default 240x135).
    #[arg(long, value_name = "WxH")]
    pub(crate) res: Option<Resolution>,
    /// Render threads (default: all cores).
    #[arg(long)]
    pub(crate) threads: Option<usize>,
    /// No progress bars.
    #[arg(long, short)]
    pub(crate) quiet: bool,
    /// Denoise the final rerender (and `--animation`'s frames) with Intel Open Image Denoise at
    /// QUALITY (high, the default; balanced; fast); the source views stay raw, as the collage
    /// is painted from them.
    #[arg(long, value_name = "QUALITY", num_args = 0..=1, require_equals = true,
        default_missing_value = tracer::denoise::Quality::DEFAULT.name(), value_parser = crate::args::denoise_quality)]
    pub(crate) denoise: Option<tracer::denoise::Quality>,
    /// The keyframe workflow instead: two key collages with different cameras, in-betweened
    /// into a short shot, rendered with `animate`, and a preview GIF.
    #[arg(long)]
    pub(crate) animation: bool,
    /// With --animation: frames in the shot (keys at the first and the last).
    #[arg(long, default_value_t = 48, value_name = "N")]
    pub(crate) frames: u32,
    /// With --animation: resolution of the animated frames.
    #[arg(long, default_value = "160x90", value_name = "WxH")]
    pub(crate) frame_res: Resolution,
    /// With --animation: samples per pixel of the animated frames.
    #[arg(long, default_value_t = 8, value_parser = crate::args::spp)]
    pub(crate) frame_spp: u32,
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    let (out, spp, res) =
        if a.animation { ("out/demo-animation", 8, (240, 135)) } else { ("out/demo", 32, (480, 270)) };
    if a.denoise.is_some() {
        // Said before the source views render, not after.
        tracer::denoise::Denoiser::shared().map_err(|e| anyhow::anyhow!("--denoise: {e}"))?;
    }
    let settings = DemoSettings {
        scene: cafe::find_cafe(a.scene.as_deref())?,
        out: a.out.unwrap_or_else(|| PathBuf::from(out)),
        spp: a.spp.unwrap_or(spp),
        res: a.res.unwrap_or(Resolution(glam::UVec2::new(res.0, res.1))),
        threads: a.threads,
        quiet: a.quiet,
        denoise: a.denoise,
    };
    if a.animation {
        let shot = animation::Shot { frames: a.frames, frame_res: a.frame_res, frame_spp: a.frame_spp };
        animation::run(&settings, &shot)
    } else {
        still::run(&settings)
    }
}
