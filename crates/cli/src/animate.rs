//! `mcctrace animate`: render a shot through per-frame ray files (docs/design.md §6 lens
//! reader, §8 workflow). Every frame is an independent unit of work: `--frames` takes any
//! sub-range, and a frame is skipped only when it is finished by `tracer::job::check_finished`'s
//! rule (docs/farm.md: EXR and PNG there and whole, the same settings and rays in the header);
//! a stale or damaged frame is rendered again and the reason said. So a crashed run resumes and
//! a render farm's job array can split a shot by frame ranges over a shared folder; `--check`
//! renders nothing and names every frame that is not finished (the farm's last step).
//!
//! Motion blur (`--shutter OPEN..CLOSE`): each eye ray gets a time in the shutter interval; the
//! lens reader interpolates the ray files of frames f and f+1 by it (camera-ray blur), and an
//! animated scene's moving geometry is posed at the motion steps over the shutter and
//! interpolated to the ray's time (geometry blur, which needs no next frame: the animation
//! holds its last keys past its end).

use crate::args::{FrameRange, Shutter};
use crate::preview::{GIF_NAME, finished_frames, write_gif};
use crate::progress::ShotBar;
use crate::setup::output::{summary, warn_nonfinite};
use crate::setup::quality::QualityArgs;
use crate::setup::scene::load_scene;
use crate::with_threads;
use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use glam::UVec2;
use mcc::job::{FrameRays, Framing, LENS_DIR_KEY, carrier_camera};
use std::path::{Path, PathBuf};
use tracer::job::{
    CameraRender, Provenance, Quality, RenderInfo, SceneSetup, Stale, check_finished, write_render,
};
use tracer::lens::LensChain;
use tracer::scene::DEFAULT_MOTION_STEPS;

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

/// The header key recording what the camera-ray blur did to a frame (with `--shutter` only).
const RAY_BLUR_KEY: &str = "mcctrace/ray_blur";

/// What the EXR header names as the camera of an animated frame.
const ANIMATED: &str = "multicamera collage (animated)";

/// The EXR of `frame` in `out` (its PNG preview is beside it).
pub fn frame_exr(out: &Path, frame: u32) -> PathBuf {
    out.join(format!("frame{frame:04}.exr"))
}

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AnimateReport {
    /// Frames rendered by this run.
    pub rendered: Vec<u32>,
    /// Frames skipped because they were finished.
    pub skipped: Vec<u32>,
    /// Frames rendered again, and why their files were not finished (missing files aside).
    pub stale: Vec<(u32, Stale)>,
    /// The preview written, if any.
    pub preview: Option<PathBuf>,
}

/// The film and its crop: --res (the size after --crop) and the first frame's ray file's size.
fn framing(a: &AnimateArgs, first: u32) -> anyhow::Result<Framing> {
    let res = a.quality.res.map(|r| r.0);
    let rays = match res {
        // Without a crop the film is --res itself: no ray file need be read.
        Some(r) if a.crop == 0 => return Ok(Framing { film: r, border: UVec2::ZERO }),
        _ => {
            let path = mcc::names::find_rerender_rays(&a.lens_dir, first)?;
            let rays = mcc::RayFile::read(&path)?;
            UVec2::new(rays.width, rays.height)
        }
    };
    Framing::new(rays, a.crop, res)
        .ok_or_else(|| anyhow::anyhow!("--crop {} leaves nothing of a {}x{} image", a.crop, rays.x, rays.y))
}

/// The settings every frame of a run shares, and what its files are checked against.
struct Shot<'a> {
    a: &'a AnimateArgs,
    setup: SceneSetup,
    quality: Quality,
    shutter: (f32, f32),
    framing: Framing,
}

impl<'a> Shot<'a> {
    fn new(a: &'a AnimateArgs) -> anyhow::Result<Self> {
        let q = &a.quality;
        let setup = q.scene_setup(a.fps)?;
        if !a.lens_dir.is_dir() {
            bail!("--lens-dir {}: not a directory", a.lens_dir.display());
        }
        let shutter = a.shutter.map_or((0.0, 0.0), |s| (s.open, s.close));
        let framing = framing(a, a.frames.first)?;
        Ok(Self { a, setup, quality: q.quality(), shutter, framing })
    }

    fn motion_blur(&self) -> bool {
        self.shutter.1 > self.shutter.0
    }

    /// What the header records of the camera-ray blur of `rays`' frame: nothing without a
    /// shutter; else the two frames blended, or that there was no next frame to blend.
    fn ray_blur(&self, rays: &FrameRays) -> Vec<(&'static str, String)> {
        if !self.motion_blur() {
            return Vec::new();
        }
        let f = rays.frame;
        let what = match &rays.next {
            Some(_) => format!("frames {f} and {}", f + 1),
            None => format!(
                "none: no ray file for frame {}, so frame {f}'s rays hold over the shutter",
                f as u64 + 1
            ),
        };
        vec![(RAY_BLUR_KEY, what)]
    }

    /// The header of `frame`, its rays' hash being `digest` and its blur `extra`.
    fn info<'b>(&'b self, frame: u32, digest: &'b str, extra: &'b [(&'b str, String)]) -> RenderInfo<'b> {
        let provenance = Provenance {
            projection: None,
            environment_map: self.setup.environment_image.as_ref(),
            rays_from: Some((LENS_DIR_KEY, &self.a.lens_dir)),
            rays_digest: Some(digest),
        };
        RenderInfo {
            shutter: self.shutter,
            provenance,
            setup: Some(&self.setup),
            crop: self.a.crop,
            extra,
            ..RenderInfo::new(&self.a.scene, ANIMATED, frame, &self.quality)
        }
    }

    /// The rays `frame` goes through (those of `earlier` reused, not read again).
    fn rays(&self, frame: u32, earlier: Option<&FrameRays>) -> anyhow::Result<FrameRays> {
        FrameRays::read(&self.a.lens_dir, frame, self.motion_blur(), earlier)
            .with_context(|| format!("frame {frame}: reading its rays"))
    }

    /// Whether `frame` is finished in the output folder (`Ok`), or why not. Its rays are read
    /// (for their hash) only when its EXR is there to compare with.
    fn status(&self, frame: u32) -> anyhow::Result<Result<(), Stale>> {
        let exr = frame_exr(&self.a.out, frame);
        if !exr.is_file() {
            return Ok(Err(Stale::Missing(exr)));
        }
        let rays = self.rays(frame, None)?;
        let (digest, blur) = (rays.digest(), self.ray_blur(&rays));
        let settings = self.info(frame, &digest, &blur).settings();
        Ok(check_finished(&exr, Some(&exr.with_extension("png")), &settings, self.framing.output()))
    }
}

/// Renders the frames `a` asks for that are not finished, then the preview (with `--check`,
/// renders nothing and fails naming every frame that is not finished).
pub fn animate(a: &AnimateArgs) -> anyhow::Result<AnimateReport> {
    let q = &a.quality;
    let shot = Shot::new(a)?;
    if a.check {
        return check(&shot);
    }
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let mut report = AnimateReport::default();
    let mut todo = Vec::new();
    for frame in a.frames.range() {
        match shot.status(frame)? {
            Ok(()) => report.skipped.push(frame),
            Err(Stale::Missing(_)) if !frame_exr(&a.out, frame).exists() => todo.push(frame),
            Err(why) => {
                if !q.quiet {
                    eprintln!("frame {frame}: {why}, re-rendering");
                }
                report.stale.push((frame, why));
                todo.push(frame);
            }
        }
    }
    if !q.quiet && !report.skipped.is_empty() {
        eprintln!(
            "animate: {} of {} frames already finished in {}, skipped",
            report.skipped.len(),
            a.frames.len(),
            a.out.display()
        );
    }
    if !todo.is_empty() {
        let base = load_scene(&a.scene, &shot.setup, q.quiet)?;
        let quality = shot.quality;
        // A static scene gets one BVH for the whole run; an animated one is posed per frame.
        let still = if base.animation.is_none() { Some(quality.tracer(&base)?) } else { None };
        let framing = shot.framing;
        let camera = carrier_camera(framing.film)?;
        let bar = ShotBar::new(todo.len() as u64, q.quiet);
        let bars = bar.frame_bars();
        let mut earlier: Option<FrameRays> = None;
        // Frames the shutter asked to blur that have no next frame's rays to blend with.
        let mut sharp = Vec::new();
        let mut told: Vec<String> = Vec::new();
        for &frame in &todo {
            // Read once: hashed for the header and handed to the lens reader, which reads nothing.
            let rays = shot.rays(frame, earlier.as_ref())?;
            let (digest, blur) = (rays.digest(), shot.ray_blur(&rays));
            if shot.motion_blur() && rays.next.is_none() {
                sharp.push(frame);
            }
            let reader = mcc::LensReader::new(mcc::lens_reader::RaySource::Directory(a.lens_dir.clone()))
                .with_motion_blur(shot.motion_blur())
                .with_frame(frame, rays.current.clone(), rays.next.clone());
            let mut lenses = LensChain::new();
            lenses.push(Box::new(reader));
            let posed;
            let tracer = match &still {
                Some(t) => t,
                None => {
                    let setup = &shot.setup;
                    let scene = setup
                        .pose_in_shutter(&base, frame, shot.shutter, DEFAULT_MOTION_STEPS)
                        .with_context(|| {
                            format!("posing the scene at frame {frame} ({} s)", setup.frame_seconds(frame))
                        })?;
                    // What posing found (motion the blur cannot show) is said once per run.
                    for w in scene.warnings.iter().skip(base.warnings.len()) {
                        if !q.quiet && !told.contains(w) {
                            eprintln!("warning: {w}");
                            told.push(w.clone());
                        }
                    }
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
                shutter: shot.shutter,
                quality,
            };
            let rendered = with_threads(q.threads, || job.run(&mut lenses, &bars))?
                .with_context(|| format!("frame {frame} (rays from {})", a.lens_dir.display()))?;
            let rendered = framing.crop(rendered);
            warn_nonfinite(&name, &rendered);
            let exr = frame_exr(&a.out, frame);
            write_render(&exr, &rendered, &shot.info(frame, &digest, &blur))?;
            earlier = Some(rays);
            bar.frame_done(&summary(&name, q.spp, &rendered, &exr));
            report.rendered.push(frame);
        }
        bar.finish();
        if let Some(w) = sharp_warning(a, &sharp) {
            eprintln!("warning: {w}");
        }
    }
    report.preview = preview(a)?;
    Ok(report)
}

/// The one warning of a run whose `--shutter` found no next frame's rays for `sharp` frames
/// (typically the shot's last): their camera rays hold over the shutter, and their headers say so.
fn sharp_warning(a: &AnimateArgs, sharp: &[u32]) -> Option<String> {
    let (&first, shutter) = (sharp.first()?, a.shutter?);
    let frames = match sharp {
        [one] => format!("frame {one} has"),
        _ => {
            let listed: Vec<String> = sharp.iter().take(4).map(u32::to_string).collect();
            let more = if sharp.len() > 4 { format!(" and {} more", sharp.len() - 4) } else { String::new() };
            format!("frames {}{more} have", listed.join(", "))
        }
    };
    let next = first.saturating_add(1);
    Some(format!(
        "--shutter {}..{}: {frames} no next frame's ray file in {} (for frame {first}: {}), so the \
         camera-ray blur has nothing to blend: the camera's rays hold over the shutter, the header \
         saying {RAY_BLUR_KEY} = none (moving geometry still blurs). To blur the camera too, write \
         the next frame's rays (`keys` or `inbetween --frames …..={next}`)",
        shutter.open,
        shutter.close,
        a.lens_dir.display(),
        mcc::names::rerender_name(next, mcc::RayFormat::Binary),
    ))
}

/// `--check`: every frame of the range by the resume rule; an error naming every frame that is
/// not finished, else the preview.
fn check(shot: &Shot) -> anyhow::Result<AnimateReport> {
    let a = shot.a;
    let mut bad = Vec::new();
    let mut report = AnimateReport::default();
    for frame in a.frames.range() {
        let status = match shot.status(frame) {
            Ok(status) => status.map_err(|why| why.to_string()),
            Err(e) => Err(format!("{e:#}")),
        };
        match status {
            Ok(()) => report.skipped.push(frame),
            Err(why) => {
                eprintln!("frame {frame}: {why}");
                bad.push(frame);
            }
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
    report.preview = preview(a)?;
    Ok(report)
}

/// Writes the preview GIF `a` asks for of every finished frame in the output folder.
fn preview(a: &AnimateArgs) -> anyhow::Result<Option<PathBuf>> {
    if a.preview != PreviewArg::Gif {
        return Ok(None);
    }
    let frames = finished_frames(&a.out)?;
    if frames.is_empty() {
        return Ok(None);
    }
    let gif = a.out.join(GIF_NAME);
    let n = write_gif(&frames, a.fps, &gif)?;
    if !a.quality.quiet {
        eprintln!("preview: {n} frames -> {}", gif.display());
    }
    Ok(Some(gif))
}

pub fn run(a: AnimateArgs) -> anyhow::Result<()> {
    let report = animate(&a)?;
    if !a.quality.quiet && !a.check {
        eprintln!(
            "animate: rendered {} frame(s), skipped {} finished -> {}",
            report.rendered.len(),
            report.skipped.len(),
            a.out.display()
        );
    }
    Ok(())
}
