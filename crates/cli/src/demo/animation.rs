//! The demo's keyframe workflow on the bundled café (docs/design.md §5–8), end to end: two key
//! frames, each with its own pair of cameras and its own collage, remapped and in-betweened
//! (what `keys` does) into one ray file per frame, rendered frame by frame (`animate`), and a
//! preview GIF. Key 0 is the still demo's collage (cameras `left` and `right`, the bundled mask
//! and regions); the last key uses the scene's `wide` camera and an ad-hoc camera by the window,
//! cut by a mask generated here.

use super::cafe::{DemoCamera, DemoSettings, DemoView, render_tagged_views};
use super::masks::{CAFE_MASK, CAFE_REGIONS, resize_labels, write_second_mask};
use crate::animate::{AnimateArgs, PreviewArg, animate};
use crate::args::{FrameRange, RayFormatArg, Resolution};
use crate::collage::default_labels;
use crate::inbetween::{InbetweenOutputArgs, ModeArg, write_inbetweens};
use crate::setup::collage::remap;
use crate::setup::quality::QualityArgs;
use anyhow::{Context, bail};
use glam::Vec3;
use mcc::inbetween::Keys;
use mcc::job::{CollageFiles, RemapJob};
use std::path::PathBuf;
use std::time::Instant;
use tracer::job::SceneSetup;

/// The animated shot.
pub(crate) struct Shot {
    /// Frames in the shot (keys at the first and the last).
    pub frames: u32,
    /// Resolution of the animated frames.
    pub frame_res: Resolution,
    /// Samples per pixel of the animated frames.
    pub frame_spp: u32,
}

pub(crate) fn run(s: &DemoSettings, shot: &Shot) -> anyhow::Result<()> {
    let start = Instant::now();
    if shot.frames < 2 {
        bail!("--frames {}: the shot needs at least 2 frames (a key at each end)", shot.frames);
    }
    let scene_path = &s.scene;
    let out = &s.out;
    let views_dir = out.join("views");
    std::fs::create_dir_all(&views_dir).with_context(|| format!("creating {}", views_dir.display()))?;
    let res = s.res;
    let q = s.quality();
    let (first, last) = (0, shot.frames - 1);
    let mut pictures: Vec<(String, PathBuf)> = Vec::new();

    // 1. Key 0: `left` and `right` facing each other across the table, the bundled mask.
    let key0_views = [
        DemoView { id: 1, camera: DemoCamera::Scene("left") },
        DemoView { id: 2, camera: DemoCamera::Scene("right") },
    ];
    pictures.extend(render_tagged_views(scene_path, &key0_views, first, &views_dir, &q)?);
    let map = mcc::compose::LabelMap::Colours(default_labels());
    let collage0 = out.join(format!("key{first:04}-collage.png"));
    // The bundled label and region images are 480x270: brought to the views' size by nearest
    // neighbour, which keeps every label colour exact.
    let mask0 = out.join(format!("key{first:04}-mask.png"));
    resize_labels(CAFE_MASK, res.0, &mask0)?;
    mcc::compose::compose_files(&mask0, &map, &views_dir, first, &collage0)?;
    let regions0 = out.join(format!("key{first:04}-collage-regions.png"));
    resize_labels(CAFE_REGIONS, res.0, &regions0)?;
    pictures.push((format!("key {first} mask (red = camera 1, green = 2)"), mask0.clone()));
    pictures.push((format!("key {first} collage"), collage0.clone()));
    pictures.push((format!("key {first} regions"), regions0.clone()));

    // 2. The last key: other cameras entirely (the room from its far corner, and the couple
    //    from the window side), a generated mask, no regions.
    let key1_views = [
        DemoView { id: 1, camera: DemoCamera::Scene("wide") },
        DemoView {
            id: 2,
            camera: DemoCamera::LookAt {
                name: "window",
                from: Vec3::new(0.6, 1.45, 1.7),
                at: Vec3::new(0.1, 1.0, -0.4),
                fov_degrees: 45.0,
            },
        },
    ];
    pictures.extend(render_tagged_views(scene_path, &key1_views, last, &views_dir, &q)?);
    let mask1 = out.join(format!("key{last:04}-mask.png"));
    write_second_mask(&mask1, res.0)?;
    let collage1 = out.join(format!("key{last:04}-collage.png"));
    mcc::compose::compose_files(&mask1, &map, &views_dir, last, &collage1)?;
    pictures.push((format!("key {last} mask (red = camera 1, green = 2)"), mask1.clone()));
    pictures.push((format!("key {last} collage"), collage1.clone()));

    // 3. Remap both keys and in-between every frame (what `mcctrace keys` does).
    let key0 = CollageFiles { regions: Some(regions0), ..CollageFiles::new(&collage0, &views_dir, first) };
    let key1 = CollageFiles::new(&collage1, &views_dir, last);
    let mut remapped = Vec::new();
    for (frame, input) in [(first, key0), (last, key1)] {
        remapped.push((frame, remap(&RemapJob::new(input), s.quiet)?.output.rays));
    }
    let keys = Keys::new(remapped, Some(shot.frame_res.0))?;
    let lens_dir = out.join("lens");
    let output = InbetweenOutputArgs {
        frames: Some(FrameRange { first, last }),
        out: lens_dir.clone(),
        mode: ModeArg::Smooth,
        res: Some(shot.frame_res),
        ray_format: RayFormatArg::Binary,
        crop: 0,
        quiet: s.quiet,
    };
    let written = write_inbetweens(&keys, &output)?;
    println!("in-betweened {} frames -> {}", written.len(), lens_dir.display());

    // 4. Render every frame through its rays, then the preview.
    let frames_dir = out.join("frames");
    let animate_args = AnimateArgs {
        scene: scene_path.clone(),
        lens_dir: lens_dir.clone(),
        frames: FrameRange { first, last },
        out: frames_dir.clone(),
        fps: SceneSetup::DEFAULT_FPS,
        shutter: None,
        crop: 0,
        preview: PreviewArg::Gif,
        check: false,
        quality: QualityArgs {
            denoise: s.denoise,
            ..QualityArgs::with(shot.frame_spp, shot.frame_res, s.threads, true)
        },
    };
    let report = animate(&animate_args)?;
    println!(
        "rendered {} frames ({} already finished) at {} x {} spp -> {}",
        report.rendered.len(),
        report.skipped.len(),
        shot.frame_res,
        shot.frame_spp,
        frames_dir.display()
    );

    println!(
        "\nmcctrace demo --animation: done in {:.1} s; everything is in {}",
        start.elapsed().as_secs_f64(),
        out.display()
    );
    for (what, path) in &pictures {
        println!("  {what:<46} {}", path.display());
    }
    println!("  {:<46} {}", "in-betweened rays (one file per frame)", lens_dir.display());
    println!("  {:<46} {}", "frames (EXR + PNG)", frames_dir.display());
    if let Some(gif) = &report.preview {
        println!("  {:<46} {}", "preview", gif.display());
    }
    Ok(())
}
