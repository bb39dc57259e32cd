//! `mcctrace render`: render a scene from one or more cameras (docs/design.md §3, §8), each view
//! written as EXR + PNG, with the MCC lens writer's rays and the tagger's stamp when asked; or,
//! with `--tile I/N`, one band of each view (docs/farm.md); a band, and with `--resume` a whole
//! view, is skipped when already finished.

use crate::args::{RayFormatArg, Shutter};
use crate::progress::Bars;
use crate::setup::output::{output_paths, summary, warn_nonfinite};
use crate::setup::quality::QualityArgs;
use crate::setup::scene::{SceneArgs, at_frame, load_scene, select_views};
use crate::with_threads;
use anyhow::bail;
use clap::Args;
use mcc::job::ViewRender;
use std::path::PathBuf;
use tracer::job::{Band, CameraRender, Provenance, SceneSetup, Stale};

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
    let mut layers = Vec::new();
    let quality = q.quality();
    let tracer = quality.tracer(&scene)?;
    let bars = Bars::new(q.quiet);
    for (view, exr) in views.iter().zip(&outputs) {
        let camera = view.camera(q.resolution(), a.overscan)?;
        let job = ViewRender {
            render: CameraRender {
                tracer: &tracer,
                camera: camera.as_ref(),
                name: &view.desc.name,
                camera_id: view.id,
                frame: a.frame,
                shutter,
                quality,
            },
            scene: &a.scene.scene,
            exr,
            rays: a.lens_writer.then(|| a.ray_format.into()),
            tag: a.tag.then_some(code),
            provenance: Provenance {
                projection: Some(view.desc.projection),
                environment_map: setup.environment_image.as_ref(),
                rays_from: None,
                rays_digest: None,
            },
            setup: Some(&setup),
            band: a.tile,
        };
        let name = &view.desc.name;
        let what = match a.tile {
            Some(band) => {
                let rows = job.rows().expect("a band has rows");
                if rows.is_empty() {
                    eprintln!(
                        "{name}: band {band} of a {}-row image is empty: nothing to render",
                        rows.start
                    );
                    continue;
                }
                Some(format!("band {band}"))
            }
            None => a.resume.then(|| "view".to_owned()),
        };
        if let Some(what) = what {
            match job.check() {
                Ok(()) => {
                    if !q.quiet {
                        eprintln!("{name}: {what} finished in {}, skipped", job.target().display());
                    }
                    continue;
                }
                // Not rendered yet: nothing to say.
                Err(Stale::Missing(path)) if path == job.target() => {}
                Err(why) => eprintln!("{name}: {what}: {why}, re-rendering"),
            }
        }
        let (rendered, files) = with_threads(q.threads, || job.run(&bars))??;
        warn_nonfinite(&view.desc.name, &rendered);
        if !q.quiet {
            eprintln!("{}", summary(&view.desc.name, q.spp, &rendered, &files.exr));
            // The ray file is named by the view's frame and id (docs/design.md §4.3), not by --out.
            if let Some(rays) = &files.rays {
                eprintln!("{}: rays -> {}", view.desc.name, rays.display());
            }
        }
        if a.layers.is_some() {
            layers.push((view.id, &view.desc.name, mcc::layers::openraster::srgb8(&rendered.images.image)));
        }
    }
    if let Some(path) = &a.layers {
        let views: Vec<_> = layers
            .iter()
            .map(|(id, name, image)| mcc::layers::openraster::ViewLayer { id: *id, name, image })
            .collect();
        mcc::layers::openraster::write(path, &views)?;
    }
    Ok(())
}
