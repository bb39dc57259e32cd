//! `mcctrace demo`: the main job on the bundled café scene (SPEC §8's workflow end to end):
//! render the two facing views with the lens writer and tagger, compose the bundled collage
//! mask, remap it (with its region image), rerender, and write every picture to one folder.

use crate::args::Resolution;
use crate::collage::default_labels;
use crate::output::{Png, RenderInfo, write_render};
use crate::remap::{CollageInputArgs, remap_collage};
use crate::render::{QualityArgs, SceneArgs, load_scene, prepare, render_camera, select_views, summary};
use crate::rerender::render_with_rays;
use anyhow::Context;
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tracer::lens::LensChain;

/// Arguments of `mcctrace demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Samples per pixel of every render.
    #[arg(long, default_value_t = 32)]
    spp: u32,
    /// Resolution of the views and of the final picture (the bundled mask is 480x270).
    #[arg(long, default_value = "480x270", value_name = "WxH")]
    res: Resolution,
    /// Render threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bars.
    #[arg(long, short)]
    quiet: bool,
}

/// The bundled scenes: beside the current directory (a checkout), else beside the sources.
fn scenes_dir() -> PathBuf {
    let here = Path::new("scenes");
    if here.is_dir() {
        here.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
    }
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let cafe = scenes_dir().join("cafe");
    let scene_path = cafe.join("cafe.gltf");
    let mask = cafe.join("collage-mask.png");
    let region_image = cafe.join("collage-mask-regions.png");
    let out = &a.out;
    let views_dir = out.join("views");
    std::fs::create_dir_all(&views_dir).with_context(|| format!("creating {}", views_dir.display()))?;
    let q = QualityArgs {
        spp: a.spp,
        res: Some(a.res),
        seed: 0,
        threads: a.threads,
        max_depth: tracer::integrator::IntegratorConfig::DEFAULT.max_depth,
        rr_depth: tracer::integrator::IntegratorConfig::DEFAULT.rr_depth,
        env: None,
        env_map: None,
        env_rotation: 0.0,
        env_strength: 1.0,
        spot_falloff: None,
        aovs: false,
        quiet: a.quiet,
    };
    let mut pictures: Vec<(String, PathBuf)> = Vec::new();

    // 1. The two source views, facing each other across the table: EXR, tagged PNG, rays.
    let scene_args = SceneArgs {
        scene: scene_path.clone(),
        cameras: vec!["left".into(), "right".into()],
        look_from: None,
        look_at: None,
        up: "0,1,0".parse().map_err(anyhow::Error::msg)?,
        fov: None,
        model: None,
        lens_radius: 0.0,
        focus_distance: 1.0,
        ortho_half_height: 1.0,
        cameras_file: None,
    };
    let mut scene = load_scene(&scene_path, true)?;
    let views = select_views(&mut scene, &scene_args)?;
    let tracer = prepare(&mut scene, &q)?;
    let code = mcc::TagCode::default();
    for view in &views {
        let camera = view.desc.build(a.res.0)?;
        let mut lenses = LensChain::new();
        lenses.push(Box::new(mcc::LensWriter::new(views_dir.clone(), mcc::RayFormat::Binary)));
        let rendered = render_camera(&tracer, camera.as_ref(), &view.desc.name, view.id, &mut lenses, &q, 0)?;
        let exr = views_dir.join(mcc::names::view_render_name(0, view.id));
        let info = RenderInfo {
            scene: &scene_path,
            camera: &view.desc.name,
            spp: q.spp,
            seed: 0,
            max_depth: q.max_depth,
            frame: 0,
        };
        let png = write_render(&exr, &rendered, &info, false, Png::Tagged { code, camera: view.id })?;
        println!("{}", summary(&view.desc.name, &q, &rendered, &exr));
        pictures.push((format!("view {} '{}' (tagged)", view.id, view.desc.name), png));
    }
    drop(tracer);

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
        ignore_strays: false,
        tag_bits: code.bits(),
        blur1: mcc::RemapConfig::GLASSNER.first_blur_radius,
        blur2: mcc::RemapConfig::GLASSNER.second_blur_radius,
        ease: mcc::RemapConfig::GLASSNER.ease_control,
        debug_dir: Some(debug_dir.clone()),
    };
    let remapped = remap_collage(&input, 0, a.quiet)?;
    let rays_path = out.join(mcc::names::rerender_name(0, mcc::RayFormat::Binary));
    remapped.rays.write(&rays_path, mcc::RayFormat::Binary)?;
    pictures.push(("debug maps (edges, weights, dominant camera)".into(), debug_dir));

    // 4. Rerender through the collage's rays.
    let final_exr = out.join("final.exr");
    let final_png = render_with_rays(&scene_path, remapped.rays, Some(a.res), 0, &final_exr, &q, 0)?;
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
    println!(
        "  {:<46} {}",
        "linear HDR renders",
        format!("{}/*.exr, {}", views_dir.display(), final_exr.display())
    );
    Ok(())
}
