//! `mcctrace demo`: the main job on the bundled café scene (docs/design.md §8's workflow end to
//! end): render the two facing views with the lens writer and tagger, compose the bundled collage
//! mask, remap it (with its region image), rerender, and write every picture to one folder.

use crate::args::Resolution;
use crate::collage::default_labels;
use crate::output::{Png, RenderInfo, write_render};
use crate::remap::{CollageInputArgs, RemapSettingsArgs, remap_collage};
use crate::render::{QualityArgs, load_scene, prepare, render_camera, summary};
use crate::rerender::render_with_rays;
use anyhow::Context;
use clap::Args;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tracer::camera::{CameraDesc, Projection};
use tracer::lens::LensChain;
use tracer::scene::CameraSelector;

/// Arguments of `mcctrace demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder (default out/demo, or out/demo-animation with --animation).
    #[arg(long)]
    pub(crate) out: Option<PathBuf>,
    /// Samples per pixel of every render (default 32; with --animation: of the key frames'
    /// source views, default 8).
    #[arg(long)]
    pub(crate) spp: Option<u32>,
    /// Resolution of the views and of the final picture (default 480x270, the bundled mask's;
    /// with --animation: of the key frames' source views, default 240x135).
    #[arg(long, value_name = "WxH")]
    pub(crate) res: Option<Resolution>,
    /// Render threads (default: all cores).
    #[arg(long)]
    pub(crate) threads: Option<usize>,
    /// No progress bars.
    #[arg(long, short)]
    pub(crate) quiet: bool,
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
    #[arg(long, default_value_t = 8)]
    pub(crate) frame_spp: u32,
}

/// The bundled scenes: beside the current directory (a checkout), else beside the sources.
pub(crate) fn scenes_dir() -> PathBuf {
    let here = Path::new("scenes");
    if here.is_dir() {
        here.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
    }
}

/// The quality settings of the demo's renders.
pub(crate) fn quality(spp: u32, res: Resolution, threads: Option<usize>, quiet: bool) -> QualityArgs {
    QualityArgs {
        spp,
        res: Some(res),
        seed: 0,
        threads,
        max_depth: tracer::integrator::IntegratorConfig::DEFAULT.max_depth,
        rr_depth: tracer::integrator::IntegratorConfig::DEFAULT.rr_depth,
        split: tracer::integrator::IntegratorConfig::DEFAULT.split,
        env: None,
        env_map: None,
        env_rotation: 0.0,
        env_strength: 1.0,
        spot_falloff: None,
        aovs: false,
        adaptive: false,
        quiet,
    }
}

/// A camera of a demo view: one of the scene's, or an ad-hoc look-at camera.
pub(crate) enum DemoCamera {
    /// The scene camera of this name.
    Scene(&'static str),
    /// Eye, target (+y up) and vertical field of view in degrees.
    LookAt { name: &'static str, from: Vec3, at: Vec3, fov_degrees: f32 },
}

/// A source view of the demo: its camera and its number.
pub(crate) struct DemoView {
    pub id: u32,
    pub camera: DemoCamera,
}

/// Renders `views` of the scene at `frame` into `views_dir` with the lens writer and tagger
/// (EXR, tagged PNG and rays under docs/design.md §4.3 names); returns (caption, tagged PNG) per
/// view.
pub(crate) fn render_tagged_views(
    scene_path: &Path,
    views: &[DemoView],
    frame: u32,
    views_dir: &Path,
    q: &QualityArgs,
    code: mcc::TagCode,
) -> anyhow::Result<Vec<(String, PathBuf)>> {
    let mut scene = load_scene(scene_path, true)?;
    let tracer = prepare(&mut scene, q)?;
    let mut pictures = Vec::new();
    for view in views {
        let desc = match &view.camera {
            DemoCamera::Scene(name) => scene.camera(&CameraSelector::Name((*name).into()))?.clone(),
            DemoCamera::LookAt { name, from, at, fov_degrees } => CameraDesc::look_at(
                name,
                *from,
                *at,
                Vec3::Y,
                Projection::Perspective { fov_y: fov_degrees.to_radians() },
            )?,
        };
        let camera = desc.build(q.resolution())?;
        let mut lenses = LensChain::new();
        lenses.push(Box::new(mcc::LensWriter::new(views_dir.to_path_buf(), mcc::RayFormat::Binary)));
        let rendered = render_camera(&tracer, camera.as_ref(), &desc.name, view.id, &mut lenses, q, frame)?;
        let exr = views_dir.join(mcc::names::view_render_name(frame, view.id));
        let info = RenderInfo {
            scene: scene_path,
            camera: &desc.name,
            spp: q.spp,
            seed: q.seed,
            max_depth: q.max_depth,
            split: q.split,
            frame,
        };
        let png = write_render(&exr, &rendered, &info, false, Png::Tagged { code, camera: view.id })?;
        println!("{}", summary(&desc.name, q, &rendered, &exr));
        pictures.push((format!("frame {frame} view {} '{}' (tagged)", view.id, desc.name), png));
    }
    Ok(pictures)
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    if a.animation {
        return crate::demo_animation::run(a);
    }
    let start = Instant::now();
    let cafe = scenes_dir().join("cafe");
    let scene_path = cafe.join("cafe.gltf");
    let mask = cafe.join("collage-mask.png");
    let region_image = cafe.join("collage-mask-regions.png");
    let out = &a.out.clone().unwrap_or_else(|| PathBuf::from("out/demo"));
    let views_dir = out.join("views");
    std::fs::create_dir_all(&views_dir).with_context(|| format!("creating {}", views_dir.display()))?;
    let res = a.res.unwrap_or(Resolution(glam::UVec2::new(480, 270)));
    let q = quality(a.spp.unwrap_or(32), res, a.threads, a.quiet);
    let mut pictures: Vec<(String, PathBuf)> = Vec::new();

    // 1. The two source views, facing each other across the table: EXR, tagged PNG, rays.
    let code = mcc::TagCode::default();
    let views = vec![
        DemoView { id: 1, camera: DemoCamera::Scene("left") },
        DemoView { id: 2, camera: DemoCamera::Scene("right") },
    ];
    pictures.extend(render_tagged_views(&scene_path, &views, 0, &views_dir, &q, code)?);

    // 2. The collage, cut from the tagged views by the bundled label mask (red = camera 1,
    //    green = camera 2, black = the background the remapper blends).
    let collage = out.join("collage.png");
    let map = mcc::compose::LabelMap::Colours(default_labels());
    mcc::compose::compose_files(&mask, &map, &views_dir, 0, &collage)?;
    pictures.push(("collage".into(), collage.clone()));
    let regions = out.join("collage-regions.png");
    std::fs::copy(&region_image, &regions).with_context(|| format!("copying {}", region_image.display()))?;
    pictures.push(("regions".into(), regions.clone()));

    // 3. Remap (with debug pictures) and save the rays.
    let debug_dir = out.join("debug");
    let input = CollageInputArgs {
        collage: Some(collage.clone()),
        rays: Some(views_dir.clone()),
        regions: Some(regions),
        settings: RemapSettingsArgs::glassner(code.bits()),
        debug_dir: Some(debug_dir.clone()),
    };
    let remapped = remap_collage(&input, 0, a.quiet)?;
    let rays_path = out.join(mcc::names::rerender_name(0, mcc::RayFormat::Binary));
    remapped.rays.write(&rays_path, mcc::RayFormat::Binary)?;
    pictures.push(("debug maps (edges, weights, dominant camera)".into(), debug_dir));

    // 4. Rerender through the collage's rays.
    let final_exr = out.join("final.exr");
    let final_png = render_with_rays(&scene_path, remapped.rays, Some(res), 0, &final_exr, &q, 0, 24.0)?;
    pictures.push(("final rerender".into(), final_png));

    println!(
        "\nmcctrace demo: done in {:.1} s; everything is in {}",
        start.elapsed().as_secs_f64(),
        out.display()
    );
    for (what, path) in &pictures {
        println!("  {what:<46} {}", path.display());
    }
    println!("  {:<46} {}", "remapped rays", rays_path.display());
    println!("  {:<46} {}/*.exr, {}", "linear HDR renders", views_dir.display(), final_exr.display());
    Ok(())
}
