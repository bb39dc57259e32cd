//! `mcctrace animate`: render a shot through per-frame ray files (docs/design/workflow.md §6 lens
//! reader, §8 workflow) with the library's [`Animate`] job: finished frames skipped, stale ones
//! rendered again and the reason said, so a crashed run resumes and a render farm's job array
//! can split a shot by `--frames` ranges over a shared folder; `--check` renders nothing and
//! names every frame that is not finished (the farm's last step). Then the preview GIF.

use crate::args::{FrameRange, Shutter};
use crate::preview::{GIF_NAME, finished_frames, write_gif};
use crate::progress::{Bars, ShotBar};
use crate::setup::output::{summary, warn_nonfinite};
use crate::setup::quality::QualityArgs;
use crate::with_threads;
use anyhow::bail;
use clap::{Args, ValueEnum};
use mcc::job::{Animate, AnimateEvent, AnimateReport, JobProgress};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use tracer::job::SceneSetup;

/// Preview kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PreviewArg {
    /// An animated GIF of every finished frame in the output folder (preview.gif).
    Gif,
    /// No preview.
    None,
}

/// `--res` as `animate` reads it (the shared help speaks of a camera's picture).
const RES_HELP: &str = "Output resolution (default: the ray files'; with --crop N, the size after the crop)";

/// Arguments of `mcctrace animate`.
#[derive(Args, Debug)]
#[command(mut_arg("res", |a| a.help(RES_HELP)))]
pub struct AnimateArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    pub scene: PathBuf,
    /// Directory of per-frame ray files rerender-frameFFFF.mcr (or .txt), as `inbetween`,
    /// `keys` or `rerender` write them.
    #[arg(long)]
    pub lens_dir: PathBuf,
    /// Frames to render, FIRST..=LAST (both included) or one frame F (any sub-range of the
    /// shot; finished frames are skipped).
    #[arg(long, value_name = "A..=B")]
    pub frames: FrameRange,
    /// Output directory: frameFFFF.exr and frameFFFF.png per frame, and the preview.
    #[arg(long)]
    pub out: PathBuf,
    /// Frames per second: an animated scene is posed at frame / FPS seconds (and over the
    /// shutter from there, with --shutter). Also the preview's rate.
    #[arg(long, default_value_t = SceneSetup::DEFAULT_FPS)]
    pub fps: f32,
    /// Motion blur: the shutter is open from OPEN to CLOSE frames after each frame's start
    /// (0 ≤ OPEN ≤ CLOSE ≤ 1; Blender's shutter S at position START is 0..S); each eye ray's
    /// time blends the ray files of frames f and f+1, and moving geometry is interpolated
    /// between 3 motion steps over the shutter to that time.
    #[arg(long, value_name = "OPEN..CLOSE")]
    pub shutter: Option<Shutter>,
    /// Drop an N-pixel border (in the ray files' pixels) rendered with `render --overscan N`;
    /// --res is then the size of what is left.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub crop: u32,
    /// Preview of the finished frames written after rendering.
    #[arg(long, value_enum, default_value = "gif")]
    pub preview: PreviewArg,
    /// Render nothing: check every frame of --frames by the resume rule (files there and whole,
    /// the same settings and rays), name every missing, damaged or stale one and fail if there
    /// is any; else write the preview. A farm's last step.
    #[arg(long)]
    pub check: bool,
    #[command(flatten)]
    pub quality: QualityArgs,
}

/// The job `a` asks for: its settings checked, its film framed.
fn job(a: &AnimateArgs) -> anyhow::Result<Animate> {
    let q = &a.quality;
    let setup = q.scene_setup(a.fps)?;
    if !a.lens_dir.is_dir() {
        bail!("--lens-dir {}: not a directory", a.lens_dir.display());
    }
    let framing =
        Animate::framing(&a.lens_dir, a.frames.first, a.crop, q.res.map(|r| r.0))?.map_err(|rays| {
            anyhow::anyhow!("--crop {} leaves nothing of a {}x{} image", a.crop, rays.x, rays.y)
        })?;
    Ok(Animate {
        scene: a.scene.clone(),
        lens_dir: a.lens_dir.clone(),
        frames: a.frames.range(),
        out: a.out.clone(),
        setup,
        quality: q.quality(),
        shutter: a.shutter.map_or((0.0, 0.0), |s| (s.open, s.close)),
        crop: a.crop,
        framing,
    })
}

/// `animate`'s progress on the terminal: stale frames and skips said, the shot's bar (drawn once
/// the scene is loaded) over each frame's stages, a line per frame written.
struct ShotProgress {
    quiet: bool,
    /// Frames in the range asked for.
    frames: u64,
    /// Samples per pixel, for the frames' summaries.
    spp: u32,
    out: PathBuf,
    /// Frames to render, known once every frame is checked.
    todo: AtomicU64,
    bar: OnceLock<(ShotBar, Bars)>,
}

impl ShotProgress {
    fn new(job: &Animate, quiet: bool) -> Self {
        let frames = (job.frames.end() - job.frames.start()) as u64 + 1;
        let (spp, out) = (job.quality.spp, job.out.clone());
        Self { quiet, frames, spp, out, todo: AtomicU64::new(0), bar: OnceLock::new() }
    }

    fn bar(&self) -> &(ShotBar, Bars) {
        self.bar.get_or_init(|| {
            let bar = ShotBar::new(self.todo.load(Ordering::Relaxed), self.quiet);
            let bars = bar.frame_bars();
            (bar, bars)
        })
    }
}

impl JobProgress<AnimateEvent<'_>> for ShotProgress {
    fn stages(&self) -> &dyn tracer::render::Progress {
        &self.bar().1
    }

    fn event(&self, event: AnimateEvent) {
        match event {
            AnimateEvent::Stale { frame, why } => {
                if !self.quiet {
                    eprintln!("frame {frame}: {why}, re-rendering");
                }
            }
            AnimateEvent::Planned { skipped, todo } => {
                self.todo.store(todo.len() as u64, Ordering::Relaxed);
                if !self.quiet && !skipped.is_empty() {
                    eprintln!(
                        "animate: {} of {} frames already finished in {}, skipped",
                        skipped.len(),
                        self.frames,
                        self.out.display()
                    );
                }
            }
            AnimateEvent::Warned { warning } => {
                if !self.quiet {
                    eprintln!("warning: {warning}");
                }
            }
            AnimateEvent::Loaded { warnings } => {
                if !self.quiet {
                    for w in warnings {
                        eprintln!("warning: {w}");
                    }
                }
                self.bar();
            }
            AnimateEvent::Written { name, rendered, exr, .. } => {
                warn_nonfinite(name, rendered);
                self.bar().0.frame_done(&summary(name, self.spp, rendered, exr));
            }
        }
    }
}

/// Renders the frames of `job` that are not finished on `threads` threads, showing progress
/// unless `quiet`; warns (even when quiet) of frames the shutter could not blur, `shutter`
/// being the flag as given.
pub(crate) fn render_shot(
    job: &Animate,
    threads: Option<usize>,
    quiet: bool,
    shutter: Option<Shutter>,
) -> anyhow::Result<AnimateReport> {
    let progress = ShotProgress::new(job, quiet);
    let report = with_threads(threads, || job.run(&progress))??;
    if let Some((bar, _)) = progress.bar.get() {
        bar.finish();
    }
    let flag = shutter.map(|s| format!("--shutter {}..{}", s.open, s.close));
    if let Some(w) = flag.and_then(|flag| job.sharp_warning(&report.sharp, &flag)) {
        eprintln!("warning: {w}");
    }
    Ok(report)
}

/// `--check`: every frame of the range by the resume rule; an error naming every frame that is
/// not finished, else the preview.
fn check(a: &AnimateArgs, job: &Animate) -> anyhow::Result<()> {
    let mut bad = Vec::new();
    for frame in a.frames.range() {
        let status = match job.status(frame) {
            Ok(status) => status.map_err(|why| why.to_string()),
            Err(e) => Err(format!("{:#}", anyhow::Error::from(e))),
        };
        if let Err(why) = status {
            eprintln!("frame {frame}: {why}");
            bad.push(frame);
        }
    }
    if !bad.is_empty() {
        bail!(
            "{} of {} frames in {} are not finished: {}",
            bad.len(),
            a.frames.len(),
            a.out.display(),
            bad.iter().map(u32::to_string).collect::<Vec<_>>().join(", ")
        );
    }
    if !a.quality.quiet {
        eprintln!("animate --check: all {} frames finished in {}", a.frames.len(), a.out.display());
    }
    preview(a.preview, &a.out, a.fps, a.quality.quiet)?;
    Ok(())
}

/// Writes the preview GIF `kind` asks for of every finished frame in `out`, at `fps`.
pub(crate) fn preview(
    kind: PreviewArg,
    out: &Path,
    fps: f32,
    quiet: bool,
) -> anyhow::Result<Option<PathBuf>> {
    if kind != PreviewArg::Gif {
        return Ok(None);
    }
    let frames = finished_frames(out)?;
    if frames.is_empty() {
        return Ok(None);
    }
    let gif = out.join(GIF_NAME);
    let n = write_gif(&frames, fps, &gif)?;
    if !quiet {
        eprintln!("preview: {n} frames -> {}", gif.display());
    }
    Ok(Some(gif))
}

/// Renders the frames `a` asks for that are not finished, then the preview (with `--check`,
/// renders nothing and fails naming every frame that is not finished).
pub fn run(a: AnimateArgs) -> anyhow::Result<()> {
    let job = job(&a)?;
    if a.check {
        return check(&a, &job);
    }
    let q = &a.quality;
    let report = render_shot(&job, q.threads, q.quiet, a.shutter)?;
    preview(a.preview, &a.out, a.fps, q.quiet)?;
    if !q.quiet {
        eprintln!(
            "animate: rendered {} frame(s), skipped {} finished -> {}",
            report.rendered.len(),
            report.skipped.len(),
            a.out.display()
        );
    }
    Ok(())
}
