//! `mcctrace render`: render a scene from one or more cameras (docs/design.md §3, §8) with the
//! library's [`RenderViews`] job, each view written as EXR + PNG, with the MCC lens writer's rays
//! and the tagger's stamp when asked; or, with `--tile I/N`, one band of each view
//! (docs/farm.md); a band, and with `--resume` a whole view, is skipped when already finished.

use crate::args::{RayFormatArg, Shutter};
use crate::progress::Bars;
use crate::setup::output::{output_paths, summary, warn_nonfinite};
use crate::setup::quality::QualityArgs;
use crate::setup::scene::{SceneArgs, at_frame, load_scene, select_views};
use crate::with_threads;
use anyhow::bail;
use clap::Args;
use mcc::job::{JobProgress, RenderViews, ViewsEvent};
use std::path::PathBuf;
use tracer::job::{Band, SceneSetup};

/// Arguments of `mcctrace render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub quality: QualityArgs,
    /// Frame number (used in output names and by lens shaders; an animated scene is posed at
    /// FRAME / --fps seconds).
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Frames per second: the scene time of frame F is F / FPS seconds.
    #[arg(long, default_value_t = SceneSetup::DEFAULT_FPS)]
    pub fps: f32,
    /// Motion blur of what moves in an animated scene: the shutter is open from OPEN to CLOSE
    /// frames after the frame's start (0 ≤ OPEN ≤ CLOSE ≤ 1; Blender's shutter S at position
    /// START is 0..S). Moving meshes are sampled at 3 motion steps over it and interpolated to
    /// each ray's time.
    #[arg(long, value_name = "OPEN..CLOSE")]
    pub shutter: Option<Shutter>,
    /// Output: an .exr file (one camera), or a directory that receives
    /// frameFFFFcameraCC.exr and .png per camera.
    #[arg(long)]
    pub out: PathBuf,
    /// MCC lens writer: also record every pixel's centre ray as frameFFFFcameraCC.mcr (or .txt).
    #[arg(long)]
    pub lens_writer: bool,
    /// MCC camera tagger: the PNG beside each EXR carries the camera number in its low bits.
    #[arg(long)]
    pub tag: bool,
    /// Bits per channel of the camera tag (camera ids 1 … 2^(3·bits) − 1).
    #[arg(long, default_value_t = mcc::TagCode::DEFAULT_BITS, value_name = "B", value_parser = crate::args::tag_bits)]
    pub tag_bits: u8,
    /// Encoding of ray files.
    #[arg(long, value_enum, default_value = "binary")]
    pub ray_format: RayFormatArg,
    /// Render an extra border of N pixels around each view (undo with `rerender --crop N`).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub overscan: u32,
    /// Number of the first view; the others follow in command-line order (for views rendered
    /// in separate runs).
    #[arg(long, default_value_t = 1, value_name = "ID")]
    pub first_id: u32,
    /// Also write the views as one OpenRaster file, a layer per camera over a black background,
    /// to cut the collage in a layered editor (Krita, GIMP, MyPaint) and remap it as it is.
    #[arg(long, value_name = "FILE.ora")]
    pub layers: Option<PathBuf>,
    /// Render only band I of N horizontal bands of each view, to NAME.tileIofN.exr beside the
    /// view's NAME.exr (no PNG); `mcctrace merge` assembles them. A band already finished with
    /// the same settings is skipped; one past the last row is empty and says so.
    #[arg(long, value_name = "I/N", value_parser = crate::args::tile,
          conflicts_with_all = ["lens_writer", "tag", "layers"])]
    pub tile: Option<Band>,
    /// Skip a view whose files are finished with the same settings (docs/farm.md: its EXR and
    /// PNG whole, the header's settings this run's; with --tag every PNG pixel tagged with its
    /// number, with --lens-writer its ray file whole); a stale one is rendered again and said so.
    /// The farm's view tasks pass it.
    #[arg(long, conflicts_with = "layers")]
    pub resume: bool,
}

pub fn run(a: RenderArgs) -> anyhow::Result<()> {
    let q = &a.quality;
    let code = mcc::TagCode::new(a.tag_bits)?;
    let setup = q.scene_setup(a.fps)?;
    let scene = load_scene(&a.scene.scene, &setup, q.quiet)?;
    // Pose an animated scene (cameras included) before picking cameras from it.
    let shutter = a.shutter.map_or((0.0, 0.0), |s| (s.open, s.close));
    let mut scene = at_frame(&setup, scene, a.frame, shutter, q.quiet)?;
    let mut views = select_views(&mut scene, &a.scene)?;
    if a.first_id == 0 {
        bail!("--first-id must be at least 1 (0 means no camera)");
    }
    for v in &mut views {
        v.id += a.first_id - 1;
    }
    if a.tag {
        for v in &views {
            code.check_id(v.id)?;
        }
    }
    if let Some(path) = &a.layers {
        mcc::layers::openraster::check_path(path)?;
    }
    let outputs = output_paths(&a.out, &views, a.frame)?;
    let quality = q.quality();
    let tracer = quality.tracer(&scene)?;
    let job = RenderViews {
        tracer: &tracer,
        scene: &a.scene.scene,
        views: &views,
        exrs: &outputs,
        resolution: q.resolution(),
        overscan: a.overscan,
        frame: a.frame,
        shutter,
        quality,
        rays: a.lens_writer.then(|| a.ray_format.into()),
        tag: a.tag.then_some(code),
        setup: Some(&setup),
        band: a.tile,
        resume: a.resume,
        layers: a.layers.as_deref(),
    };
    let progress = ViewsTerminal { quiet: q.quiet, spp: q.spp, bars: Bars::new(q.quiet) };
    with_threads(q.threads, || job.run(&progress))??;
    Ok(())
}

/// `render`'s progress on the terminal: each view's stages, skips and re-renders said, a line
/// per view written (the demos' source views print theirs on stdout instead).
pub(crate) struct ViewsTerminal {
    /// No bars or summaries (warnings and re-renders are still said).
    pub quiet: bool,
    /// Samples per pixel, for the summaries.
    pub spp: u32,
    /// The views' stages.
    pub bars: Bars,
}

impl JobProgress<ViewsEvent<'_>> for ViewsTerminal {
    fn stages(&self) -> &dyn tracer::render::Progress {
        &self.bars
    }

    fn event(&self, event: ViewsEvent) {
        match event {
            ViewsEvent::EmptyBand { view, band, rows } => {
                let name = &view.desc.name;
                eprintln!("{name}: band {band} of a {}-row image is empty: nothing to render", rows.start);
            }
            ViewsEvent::Finished { view, what, target } => {
                if !self.quiet {
                    eprintln!("{}: {what} finished in {}, skipped", view.desc.name, target.display());
                }
            }
            ViewsEvent::Stale { view, what, why } => {
                eprintln!("{}: {what}: {why}, re-rendering", view.desc.name)
            }
            ViewsEvent::Written { view, rendered, files } => {
                warn_nonfinite(&view.desc.name, rendered);
                if !self.quiet {
                    eprintln!("{}", summary(&view.desc.name, self.spp, rendered, &files.exr));
                    // The ray file is named by the view's frame and id (docs/design/mcc.md §4.3), not by --out.
                    if let Some(rays) = &files.rays {
                        eprintln!("{}: rays -> {}", view.desc.name, rays.display());
                    }
                }
            }
        }
    }
}
