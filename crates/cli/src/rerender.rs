//! `mcctrace rerender`: the lens reader (docs/design/workflow.md §6, §8): remap a collage (or take a
//! ready ray file) and render the scene with one ray per pixel from it, at any output
//! resolution; with `--tile I/N`, one band of it (docs/farm.md), skipped when already finished.

use crate::args::{RayFormatArg, Shutter};
use crate::progress::Bars;
use crate::setup::collage::{CollageInputArgs, remap};
use crate::setup::output::{create_parent, summary, warn_nonfinite};
use crate::setup::quality::QualityArgs;
use crate::setup::scene::{at_frame, load_scene};
use crate::with_threads;
use anyhow::{Context, bail};
use clap::Args;
use mcc::job::Rerender;
use std::path::{Path, PathBuf};
use tracer::job::{Band, SceneSetup, Stale};

/// Arguments of `mcctrace rerender`.
#[derive(Args, Debug)]
#[command(mut_arg("res", |a| a.help(RES_HELP)))]
pub struct RerenderArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    pub scene: PathBuf,
    #[command(flatten)]
    pub input: CollageInputArgs,
    /// A ready ray file (from `mcctrace remap` or the in-betweener) instead of --collage/--rays.
    #[arg(long, conflicts_with_all = ["collage", "rays", "regions"])]
    pub lens: Option<PathBuf>,
    /// Frame (selects the views' ray files and names the outputs; an animated scene is posed at
    /// FRAME / --fps seconds).
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Frames per second: the scene time of frame F is F / FPS seconds.
    #[arg(long, default_value_t = SceneSetup::DEFAULT_FPS)]
    pub fps: f32,
    /// Motion blur of what moves in an animated scene, as `render --shutter`: the shutter is
    /// open from OPEN to CLOSE frames after the frame's start (0 ≤ OPEN ≤ CLOSE ≤ 1); moving
    /// meshes are sampled at 3 motion steps over it and interpolated to each ray's time.
    #[arg(long, value_name = "OPEN..CLOSE")]
    pub shutter: Option<Shutter>,
    /// Drop an N-pixel border (in collage pixels) rendered with `render --overscan N`; --res is
    /// then the size of what is left.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub crop: u32,
    /// Output image NAME.exr; a PNG preview goes beside it as NAME.png, and the remapped rays
    /// (unless --lens) as NAME.mcr (or NAME.txt), named after it so that no other file is
    /// replaced (`--out lens/rerender-frame0005.exr` puts them where `animate` looks).
    #[arg(long)]
    pub out: PathBuf,
    /// Encoding of the saved ray file.
    #[arg(long, value_enum, default_value = "binary")]
    pub ray_format: RayFormatArg,
    /// Render only band I of N horizontal bands of the output, to NAME.tileIofN.exr beside
    /// --out NAME.exr (no PNG); `mcctrace merge` assembles them. A band already finished with
    /// the same settings is skipped; one past the last row is empty and says so.
    #[arg(long, value_name = "I/N", value_parser = crate::args::tile)]
    pub tile: Option<Band>,
    #[command(flatten)]
    pub quality: QualityArgs,
}

/// `--res` as `rerender` reads it (the shared help speaks of a camera's picture).
const RES_HELP: &str = "Output resolution (default: the collage's, or the --lens file's; with --crop N, the size after the crop)";

/// Renders `scene` (set up and posed at the job's frame as `setup` says) through the job's rays
/// into `out` and its PNG beside it, whose path it returns (a band: into its band file, whose
/// path it returns; shared with the demo), on `threads` threads, quietly or not.
pub fn render_through(
    scene: &Path,
    setup: &SceneSetup,
    job: &Rerender,
    threads: Option<usize>,
    quiet: bool,
    out: &Path,
) -> anyhow::Result<PathBuf> {
    // Checked before the scene is loaded and rendered: a bad value fails at once and leaves
    // nothing behind.
    if job.framing().is_none() {
        let size = job.rays_size();
        bail!("--crop {} leaves nothing of a {}x{} image", job.crop, size.x, size.y);
    }
    let loaded = load_scene(scene, setup, quiet)?;
    let posed = at_frame(setup, loaded, job.frame, job.shutter, quiet)?;
    let tracer = job.quality.tracer(&posed)?;
    let rendered = with_threads(threads, || job.run(&tracer, &Bars::new(quiet)))??;
    warn_nonfinite("rerender", &rendered);
    let written = job.write(out, &rendered, scene)?;
    if !quiet {
        eprintln!("{}", summary("rerender", job.quality.spp, &rendered, &job.target(out)));
    }
    Ok(written)
}

/// Where `rerender --out OUT` saves the remapped rays: OUT with the ray format's extension.
pub fn rays_path(out: &Path, format: mcc::RayFormat) -> PathBuf {
    out.with_extension(format.extension())
}

pub fn run(a: RerenderArgs) -> anyhow::Result<()> {
    let q = &a.quality;
    if !a.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!("--out {}: give an .exr file", a.out.display());
    }
    create_parent(&a.out)?;
    let (job, remapped) = match &a.lens {
        Some(path) => (Rerender::from_lens_file(path, a.frame)?, None),
        None => {
            let remapped = remap(&a.input.job(a.frame)?, q.quiet)?;
            let job = Rerender::new(remapped.output.rays.clone(), a.frame);
            let collage = a.input.collage.clone().expect("the remap had a collage");
            (Rerender { rays_from: Some((mcc::job::COLLAGE_KEY, collage)), ..job }, Some(remapped))
        }
    };
    let job = Rerender {
        resolution: q.res.map(|r| r.0),
        crop: a.crop,
        shutter: a.shutter.map_or((0.0, 0.0), |s| (s.open, s.close)),
        quality: q.quality(),
        environment_map: q.scene_setup(a.fps)?.environment_image,
        setup: Some(q.scene_setup(a.fps)?),
        band: a.tile,
        ..job
    };
    if let Some(band) = a.tile {
        match job.rows() {
            Some(rows) if rows.is_empty() => {
                eprintln!("rerender: band {band} of a {}-row image is empty: nothing to render", rows.start);
                return Ok(());
            }
            _ => {}
        }
        match job.check(&a.out, &a.scene) {
            Ok(()) => {
                if !q.quiet {
                    eprintln!("rerender: band {band} finished in {}, skipped", job.target(&a.out).display());
                }
                return Ok(());
            }
            Err(Stale::Missing(_)) => {}
            Err(why) => eprintln!("rerender: band {band}: {why}, re-rendering"),
        }
    }
    if let (Some(res), Some(w)) = (q.res, job.stretch_warning()) {
        eprintln!("warning: --res {res}: {w}");
    }
    render_through(&a.scene, &q.scene_setup(a.fps)?, &job, q.threads, q.quiet, &a.out)?;
    // The remapped rays are saved only once the render has succeeded: a run that fails (a bad
    // --crop, --spp, scene …) leaves no output behind (docs/design/workflow.md §8).
    if let Some(remapped) = remapped {
        // Named after --out, as the PNG is: a fixed name beside it (rerender-frameFFFF.mcr)
        // replaced whatever lay there, e.g. a `remap --seamless` file of that name.
        let saved = rays_path(&a.out, a.ray_format.into());
        remapped.write_rays(&saved, a.ray_format.into()).with_context(|| "saving the remapped rays")?;
        if !q.quiet {
            eprintln!("rays -> {}", saved.display());
        }
    }
    Ok(())
}
