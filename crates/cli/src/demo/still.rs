//! The demo's main job on the bundled café (docs/design.md §8's workflow end to end): render
//! the two facing views with the lens writer and tagger, compose the bundled collage mask, remap
//! it (with its region image), rerender, and write every picture to one folder.

use super::cafe::{DemoCamera, DemoSettings, DemoView, render_tagged_views};
use super::masks::{CAFE_MASK, CAFE_REGIONS, resize_labels};
use crate::collage::default_labels;
use crate::rerender::render_through;
use crate::setup::collage::remap;
use anyhow::Context;
use mcc::job::{CollageFiles, RemapJob, Rerender};
use std::path::PathBuf;
use std::time::Instant;
use tracer::job::{Quality, SceneSetup};

pub(crate) fn run(s: &DemoSettings) -> anyhow::Result<()> {
    let start = Instant::now();
    let scene_path = &s.scene;
    let out = &s.out;
    let views_dir = out.join("views");
    std::fs::create_dir_all(&views_dir).with_context(|| format!("creating {}", views_dir.display()))?;
    let mut pictures: Vec<(String, PathBuf)> = Vec::new();

    // 1. The two source views, facing each other across the table: EXR, tagged PNG, rays.
    let views = [
        DemoView { id: 1, camera: DemoCamera::Scene("left") },
        DemoView { id: 2, camera: DemoCamera::Scene("right") },
    ];
    pictures.extend(render_tagged_views(scene_path, &views, 0, &views_dir, s)?);

    // 2. The collage, cut from the tagged views by the bundled label mask (red = camera 1,
    //    green = camera 2, black = the background the remapper blends), brought to the views'
    //    size by nearest neighbour (no new colours), as is its region image.
    let collage = out.join("collage.png");
    let map = mcc::compose::LabelMap::Colours(default_labels());
    let mask = out.join("collage-mask.png");
    resize_labels(CAFE_MASK, s.res.0, &mask)?;
    mcc::compose::compose_files(&mask, &map, &views_dir, 0, &collage)?;
    pictures.push(("collage mask (red = camera 1, green = 2, black = blend)".into(), mask.clone()));
    pictures.push(("collage".into(), collage.clone()));
    let regions = out.join("collage-regions.png");
    resize_labels(CAFE_REGIONS, s.res.0, &regions)?;
    pictures.push(("regions".into(), regions.clone()));

    // 3. Remap (with debug pictures) and save the rays.
    let debug_dir = out.join("debug");
    let input = CollageFiles { regions: Some(regions), ..CollageFiles::new(&collage, &views_dir, 0) };
    let remapped = remap(&RemapJob { debug_dir: Some(debug_dir.clone()), ..RemapJob::new(input) }, s.quiet)?;
    let rays_path = out.join(mcc::names::rerender_name(0, mcc::RayFormat::Binary));
    remapped.write_rays(&rays_path, mcc::RayFormat::Binary)?;
    pictures.push(("debug maps (edges, weights, dominant camera)".into(), debug_dir));

    // 4. Rerender through the collage's rays.
    let final_exr = out.join("final.exr");
    let job = Rerender {
        resolution: Some(s.res.0),
        quality: Quality { denoise: s.denoise, ..s.quality() },
        ..Rerender::new(remapped.output.rays, 0)
    };
    let final_png = render_through(scene_path, &SceneSetup::default(), &job, s.threads, s.quiet, &final_exr)?;
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
