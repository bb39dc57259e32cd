//! The demo's keyframe workflow on the bundled café (docs/design.md §5–8), end to end: two key
//! frames, each with its own pair of cameras and its own collage, remapped and in-betweened
//! (what `keys` does) into one ray file per frame, rendered frame by frame (`animate`), and a
//! preview GIF. Key 0 is the still demo's collage (cameras `left` and `right`, the bundled mask
//! and regions); the last key uses the scene's `wide` camera and an ad-hoc camera by the window,
//! cut by a mask generated here.

use super::cafe::{DemoCamera, DemoSettings, DemoView, render_tagged_views};
use super::masks::{CAFE_MASK, CAFE_REGIONS, resize_labels, write_second_mask};
use crate::animate::{PreviewArg, preview, render_shot};
use crate::args::Resolution;
use crate::collage::default_labels;
use crate::keys::KeysTerminal;
use anyhow::{Context, bail};
use glam::Vec3;
use mcc::job::{Animate, Inbetween, Key, KeyFrames};
use mcc::{CollageOptions, InbetweenMode, RayFormat, RemapConfig};
use std::path::PathBuf;
use std::time::Instant;
use tracer::job::{Quality, SceneSetup};

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
    let (first, last) = (0, shot.frames - 1);
    let mut pictures: Vec<(String, PathBuf)> = Vec::new();

    // 1. Key 0: `left` and `right` facing each other across the table, the bundled mask.
    let key0_views = [
        DemoView { id: 1, camera: DemoCamera::Scene("left") },
        DemoView { id: 2, camera: DemoCamera::Scene("right") },
    ];
    pictures.extend(render_tagged_views(scene_path, &key0_views, first, &views_dir, s)?);
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
    pictures.extend(render_tagged_views(scene_path, &key1_views, last, &views_dir, s)?);
    let mask1 = out.join(format!("key{last:04}-mask.png"));
    write_second_mask(&mask1, res.0)?;
    let collage1 = out.join(format!("key{last:04}-collage.png"));
    mcc::compose::compose_files(&mask1, &map, &views_dir, last, &collage1)?;
    pictures.push((format!("key {last} mask (red = camera 1, green = 2)"), mask1.clone()));
    pictures.push((format!("key {last} collage"), collage1.clone()));

    // 3. Remap both keys and in-between every frame (what `mcctrace keys` does).
    let lens_dir = out.join("lens");
    let output = Inbetween {
        frames: Some(first..=last),
        out: lens_dir.clone(),
        mode: InbetweenMode::Smooth,
        res: Some(shot.frame_res.0),
        format: RayFormat::Binary,
        crop: 0,
    };
    let key = |frame, collage: &PathBuf, regions| Key {
        frame,
        collage: collage.clone(),
        regions,
        given: String::new(),
    };
    let keys = KeyFrames {
        keys: vec![key(first, &collage0, Some(regions0)), key(last, &collage1, None)],
        rays: views_dir.clone(),
        options: CollageOptions::default(),
        config: RemapConfig::GLASSNER,
        output: output.clone(),
    };
    let written = keys.make(&KeysTerminal::new(output, s.quiet))?;
    println!("in-betweened {} frames -> {}", written.len(), lens_dir.display());

    // 4. Render every frame through its rays, then the preview.
    let frames_dir = out.join("frames");
    let framing = Animate::framing(&lens_dir, first, 0, Some(shot.frame_res.0))?
        .map_err(|_| anyhow::anyhow!("the frames' rays are empty"))?;
    let job = Animate {
        scene: scene_path.clone(),
        lens_dir: lens_dir.clone(),
        frames: first..=last,
        out: frames_dir.clone(),
        setup: SceneSetup::default(),
        quality: Quality { spp: shot.frame_spp, denoise: s.denoise, ..Quality::DEFAULT },
        shutter: (0.0, 0.0),
        crop: 0,
        framing,
    };
    let report = render_shot(&job, s.threads, true, None)?;
    let gif = preview(PreviewArg::Gif, &frames_dir, SceneSetup::DEFAULT_FPS, true)?;
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
    if let Some(gif) = &gif {
        println!("  {:<46} {}", "preview", gif.display());
    }
    Ok(())
}
