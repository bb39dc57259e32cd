//! `mcctrace animate`: render a shot through per-frame ray files (docs/design.md §6 lens
//! reader, §8 workflow). Every frame is an independent unit of work: `--frames` takes any
//! sub-range, and a frame whose EXR and PNG are both in the output folder is skipped (both are
//! written atomically, so an existing file is complete), so a crashed run resumes and a render
//! farm's job array can split a shot by frame ranges over a shared folder.
//!
//! Motion blur (`--shutter OPEN..CLOSE`) is camera-ray blur: each eye ray gets a time in the
//! shutter interval and the lens reader interpolates the ray files of frames f and f+1 by it.
//! Animated geometry is posed once per frame, at frame / fps seconds: there is no object motion
//! blur (the BVH holds one pose per frame).

use crate::args::{FrameRange, Shutter};
use crate::preview::{GIF_NAME, finished_frames, write_gif};
use crate::progress::Bars;
use crate::setup::output::{summary, warn_nonfinite};
use crate::setup::quality::QualityArgs;
use crate::setup::scene::load_scene;
use crate::with_threads;
use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use glam::UVec2;
use mcc::job::carrier_camera;
use std::path::{Path, PathBuf};
use tracer::job::{CameraRender, RenderInfo, SceneSetup, write_render};
use tracer::lens::LensChain;

/// Preview kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PreviewArg {
    /// An animated GIF of every finished frame in the output folder (preview.gif).
    Gif,
    /// No preview.
    None,
}

/// Arguments of `mcctrace animate`.
#[derive(Args, Debug)]
pub struct AnimateArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    pub scene: PathBuf,
    /// Directory of per-frame ray files rerender-frameFFFF.mcr (or .txt), as `inbetween`,
    /// `keys` or `rerender` write them.
    #[arg(long)]
    pub lens_dir: PathBuf,
    /// Frames to render, FIRST..=LAST (any sub-range of the shot; finished frames are skipped).
    #[arg(long, value_name = "A..=B")]
    pub frames: FrameRange,
    /// Output directory: frameFFFF.exr and frameFFFF.png per frame, and the preview.
    #[arg(long)]
    pub out: PathBuf,
    /// Frames per second: an animated scene is posed at frame / FPS seconds (geometry is not
    /// blurred: it holds that pose for the whole shutter interval). Also the preview's rate.
    #[arg(long, default_value_t = SceneSetup::DEFAULT_FPS)]
    pub fps: f32,
    /// Camera motion blur: the shutter is open from OPEN to CLOSE frames after each frame's
    /// start (0 ≤ OPEN ≤ CLOSE ≤ 1); each eye ray's time blends the ray files of frames f and
    /// f+1. No object motion blur: moving geometry is sampled at the frame's time.
    #[arg(long, value_name = "OPEN..CLOSE")]
    pub shutter: Option<Shutter>,
    /// Preview of the finished frames written after rendering.
    #[arg(long, value_enum, default_value = "gif")]
    pub preview: PreviewArg,
    #[command(flatten)]
    pub quality: QualityArgs,
}

/// What the EXR header names as the camera of an animated frame.
const ANIMATED: &str = "multicamera collage (animated)";

/// The EXR of `frame` in `out` (its PNG preview is beside it).
pub fn frame_exr(out: &Path, frame: u32) -> PathBuf {
    out.join(format!("frame{frame:04}.exr"))
}

/// Whether `frame` is finished in `out`: its EXR and PNG are both there (each written
/// atomically; the PNG is written last).
pub fn is_finished(out: &Path, frame: u32) -> bool {
    let exr = frame_exr(out, frame);
    exr.is_file() && exr.with_extension("png").is_file()
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AnimateReport {
    /// Frames rendered by this run.
    pub rendered: Vec<u32>,
    /// Frames skipped because they were finished.
    pub skipped: Vec<u32>,
    /// The preview written, if any.
    pub preview: Option<PathBuf>,
}

/// The film size: --res, or the first frame's ray file's.
fn film_size(a: &AnimateArgs, first: u32) -> anyhow::Result<UVec2> {
    if let Some(r) = a.quality.res {
        return Ok(r.0);
    }
    let path = mcc::names::find_rerender_rays(&a.lens_dir, first)?;
    let rays = mcc::RayFile::read(&path)?;
    Ok(UVec2::new(rays.width, rays.height))
}

/// Renders the frames `a` asks for that are not finished, then the preview.
pub fn animate(a: &AnimateArgs) -> anyhow::Result<AnimateReport> {
    let q = &a.quality;
    let setup = q.scene_setup(a.fps)?;
    if !a.lens_dir.is_dir() {
        bail!("--lens-dir {}: not a directory", a.lens_dir.display());
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let mut report = AnimateReport::default();
    let (todo, skipped): (Vec<u32>, Vec<u32>) = a.frames.range().partition(|&f| !is_finished(&a.out, f));
    report.skipped = skipped;
    if !q.quiet && !report.skipped.is_empty() {
        eprintln!(
            "animate: {} of {} frames already finished in {}, skipped",
            report.skipped.len(),
            a.frames.len(),
            a.out.display()
        );
    }
    if let Some(&first) = todo.first() {
        let shutter = a.shutter.map_or((0.0, 0.0), |s| (s.open, s.close));
        let quality = q.quality();
        let base = load_scene(&a.scene, &setup, q.quiet)?;
        // A static scene gets one BVH for the whole run; an animated one is posed per frame.
        let still = if base.animation.is_none() { Some(quality.tracer(&base)?) } else { None };
        let camera = carrier_camera(film_size(a, first)?)?;
        let reader = mcc::LensReader::new(mcc::lens_reader::RaySource::Directory(a.lens_dir.clone()))
            .with_motion_blur(shutter.1 > shutter.0);
        let mut lenses = LensChain::new();
        lenses.push(Box::new(reader));
        let bars = Bars::new(q.quiet);
        for &frame in &todo {
            let posed;
            let tracer = match &still {
                Some(t) => t,
                None => {
                    let scene = setup.pose(&base, frame).with_context(|| {
                        format!("posing the scene at frame {frame} ({} s)", setup.frame_seconds(frame))
                    })?;
                    posed = quality.tracer(&scene)?;
                    &posed
                }
            };
            let name = format!("frame {frame}");
            let job = CameraRender {
                tracer,
                camera: camera.as_ref(),
                name: &name,
                camera_id: 0,
                frame,
                shutter,
                quality,
            };
            let rendered = with_threads(q.threads, || job.run(&mut lenses, &bars))?
                .with_context(|| format!("frame {frame} (rays from {})", a.lens_dir.display()))?;
            warn_nonfinite(&name, &rendered);
            let exr = frame_exr(&a.out, frame);
            let info = RenderInfo { scene: &a.scene, camera: ANIMATED, frame, quality: &quality };
            write_render(&exr, &rendered, &info)?;
            if !q.quiet {
                eprintln!("{}", summary(&name, q.spp, &rendered, &exr));
            }
            report.rendered.push(frame);
        }
    }
    if a.preview == PreviewArg::Gif {
        let frames = finished_frames(&a.out)?;
        if !frames.is_empty() {
            let gif = a.out.join(GIF_NAME);
            let n = write_gif(&frames, a.fps, &gif)?;
            if !q.quiet {
                eprintln!("preview: {n} frames -> {}", gif.display());
            }
            report.preview = Some(gif);
        }
    }
    Ok(report)
}

pub fn run(a: AnimateArgs) -> anyhow::Result<()> {
    let report = animate(&a)?;
    if !a.quality.quiet {
        eprintln!(
            "animate: rendered {} frame(s), skipped {} finished -> {}",
            report.rendered.len(),
            report.skipped.len(),
            a.out.display()
        );
    }
    Ok(())
}
