//! `mcctrace rerender`: the lens reader (docs/design.md §6, §8): remap a collage (or take a ready
//! ray file) and render the scene with one ray per pixel from it, at any output resolution.

use crate::args::Resolution;
use crate::output::{Png, RenderInfo, write_render};
use crate::remap::{CollageInputArgs, create_parent, remap_collage};
use crate::render::{QualityArgs, RayFormatArg, load_scene, prepare, render_camera, summary};
use anyhow::{Context, bail};
use clap::Args;
use glam::{UVec2, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tracer::camera::{CameraDesc, Projection};
use tracer::film::FilmImages;
use tracer::lens::LensChain;
use tracer::render::Rendered;

/// Arguments of `mcctrace rerender`.
#[derive(Args, Debug)]
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
    #[arg(long, default_value_t = crate::scene_time::DEFAULT_FPS)]
    pub fps: f32,
    /// Drop an N-pixel border (in collage pixels) rendered with `render --overscan N`.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub crop: u32,
    /// Output image (.exr; a PNG preview goes beside it). The remapped rays are saved beside it
    /// too, as rerender-frameFFFF.mcr.
    #[arg(long)]
    pub out: PathBuf,
    /// Encoding of the saved ray file.
    #[arg(long, value_enum, default_value = "binary")]
    pub ray_format: RayFormatArg,
    #[command(flatten)]
    pub quality: QualityArgs,
}

/// Crops `n` pixels from every side of the render's images.
fn crop(r: &mut Rendered, n: u32) -> anyhow::Result<()> {
    let img = &r.images.image;
    if 2 * n >= img.width || 2 * n >= img.height {
        bail!("--crop {n} leaves nothing of a {}x{} image", img.width, img.height);
    }
    let (w, h) = (img.width - 2 * n, img.height - 2 * n);
    let i = &r.images;
    let cut = |x: &tracer::image::RgbImage| x.crop(n, n, w, h).expect("checked above");
    r.images = FilmImages {
        image: cut(&i.image),
        variance: cut(&i.variance),
        samples: i.samples.crop(n, n, w, h).expect("checked above"),
        albedo: cut(&i.albedo),
        normal: cut(&i.normal),
        depth: i.depth.crop(n, n, w, h).expect("checked above"),
    };
    Ok(())
}

/// Renders `scene_path` (posed at `frame` / `fps` seconds if animated) through the rays of
/// `rays` into `out` (shared with the demo).
#[allow(clippy::too_many_arguments)]
pub fn render_with_rays(
    scene_path: &Path,
    rays: mcc::RayFile,
    res: Option<Resolution>,
    crop_border: u32,
    out: &Path,
    q: &QualityArgs,
    frame: u32,
    fps: f32,
) -> anyhow::Result<PathBuf> {
    let (w, h) = (rays.width, rays.height);
    let res = res.map_or(UVec2::new(w, h), |r| r.0);
    // The crop is given in collage pixels; scale it to the output. Checked before the scene is
    // loaded and rendered: a bad value fails at once and leaves nothing behind.
    let crop_out = (crop_border as f64 * res.x as f64 / w as f64).round() as u32;
    if crop_out > 0 && (2 * crop_out as u64 >= res.x as u64 || 2 * crop_out as u64 >= res.y as u64) {
        bail!("--crop {crop_border} leaves nothing of a {}x{} image", res.x, res.y);
    }
    let scene = load_scene(scene_path, q.quiet)?;
    let mut scene = crate::scene_time::at_frame(scene, frame, fps)?;
    let tracer = prepare(&mut scene, q)?;
    // The lens reader replaces every ray; the camera only carries the film size.
    let carrier = CameraDesc::look_at(
        "lens reader",
        Vec3::ZERO,
        -Vec3::Z,
        Vec3::Y,
        Projection::Perspective { fov_y: 1.0 },
    )?
    .build(res)?;
    let mut lenses = LensChain::new();
    lenses.push(Box::new(mcc::LensReader::new(mcc::lens_reader::RaySource::Rays(Arc::new(rays)))));
    let mut rendered = render_camera(&tracer, carrier.as_ref(), "rerender", 0, &mut lenses, q, frame)?;
    if crop_out > 0 {
        crop(&mut rendered, crop_out)?;
    }
    let info = RenderInfo {
        scene: scene_path,
        camera: "multicamera collage",
        spp: q.spp,
        seed: q.seed,
        max_depth: q.max_depth,
        split: q.split,
        frame,
    };
    let png = write_render(out, &rendered, &info, q.aovs, Png::Preview)?;
    if !q.quiet {
        eprintln!("{}", summary("rerender", q, &rendered, out));
    }
    Ok(png)
}

pub fn run(a: RerenderArgs) -> anyhow::Result<()> {
    let q = &a.quality;
    if !a.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!("--out {}: give an .exr file", a.out.display());
    }
    create_parent(&a.out)?;
    let Some(path) = &a.lens else {
        let output = remap_collage(&a.input, a.frame, q.quiet)?;
        // The remapped rays are saved only once the render has succeeded: a run that fails
        // (a bad --crop, --spp, scene …) leaves no output behind (docs/design.md §8).
        render_with_rays(&a.scene, output.rays.clone(), q.res, a.crop, &a.out, q, a.frame, a.fps)?;
        let dir = a.out.parent().map(Path::to_path_buf).unwrap_or_default();
        let saved = dir.join(mcc::names::rerender_name(a.frame, a.ray_format.into()));
        output.rays.write(&saved, a.ray_format.into()).with_context(|| "saving the remapped rays")?;
        if !q.quiet {
            eprintln!("rays -> {}", saved.display());
        }
        return Ok(());
    };
    let rays = mcc::RayFile::read(path)?;
    render_with_rays(&a.scene, rays, q.res, a.crop, &a.out, q, a.frame, a.fps)?;
    Ok(())
}
