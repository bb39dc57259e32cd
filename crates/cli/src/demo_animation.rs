//! `mcctrace demo --animation`: the column's keyframe workflow (docs/design.md §5–8) on the bundled
//! café, end to end: two key frames, each with its own pair of cameras and its own collage,
//! remapped and in-betweened (`keys`) into one ray file per frame, rendered frame by frame
//! (`animate`), and a preview GIF. Key 0 is the plain demo's collage (cameras `left` and `right`,
//! the bundled mask and regions); the last key uses the scene's `wide` camera and an ad-hoc camera
//! by the window, cut by a mask generated here.

use crate::animate::{AnimateArgs, PreviewArg, animate};
use crate::args::{FrameRange, Resolution};
use crate::collage::default_labels;
use crate::demo::{DemoArgs, DemoCamera, DemoView, quality, render_tagged_views, scenes_dir};
use crate::inbetween::{InbetweenOutputArgs, ModeArg, write_inbetweens};
use crate::keys::{KeysArgs, remap_keys};
use crate::remap::RemapSettingsArgs;
use crate::render::RayFormatArg;
use anyhow::{Context, bail};
use glam::{UVec2, Vec3};
use mcc::inbetween::Keys;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Writes the last key's label mask at `size`: camera 1 (red) on the left, camera 2 (green) on
/// the right, each edge a gentle wave, and a black band between them for the remapper to blend.
fn write_second_mask(path: &Path, size: UVec2) -> anyhow::Result<()> {
    let (w, h) = (size.x as usize, size.y as usize);
    let mut rgb = vec![0u8; w * h * 3];
    for y in 0..h {
        let fy = y as f32 / h as f32;
        // Edges at about 40 % and 62 % of the width, waving by 3 % of it.
        let left_edge = w as f32 * (0.40 + 0.03 * (fy * 9.0).sin());
        let right_edge = w as f32 * (0.62 + 0.03 * (fy * 7.0 + 1.0).cos());
        for x in 0..w {
            let fx = x as f32 + 0.5;
            let px = &mut rgb[(y * w + x) * 3..][..3];
            if fx < left_edge {
                px.copy_from_slice(&[255, 0, 0]);
            } else if fx > right_edge {
                px.copy_from_slice(&[0, 255, 0]);
            }
        }
    }
    tracer::image_io::write_png_rgb8(path, size.x, size.y, &rgb)?;
    Ok(())
}

/// Writes the 8-bit label image `src` at `size` into `dst`, by nearest neighbour (every output
/// pixel copies the input pixel under its centre, so no new colours appear).
fn resize_labels(src: &Path, size: UVec2, dst: &Path) -> anyhow::Result<()> {
    let png = tracer::image_io::read_png8(src)?;
    let c = png.channels as usize;
    if c < 3 {
        bail!("{}: expected an RGB or RGBA label image", src.display());
    }
    let (w, h) = (size.x as usize, size.y as usize);
    let mut rgb = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        let sy = ((y as u64 * 2 + 1) * png.height as u64 / (2 * h as u64)) as usize;
        for x in 0..w {
            let sx = ((x as u64 * 2 + 1) * png.width as u64 / (2 * w as u64)) as usize;
            let at = (sy * png.width as usize + sx) * c;
            rgb.extend_from_slice(&png.pixels[at..at + 3]);
        }
    }
    tracer::image_io::write_png_rgb8(dst, size.x, size.y, &rgb)?;
    Ok(())
}

pub fn run(a: DemoArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    if a.frames < 2 {
        bail!("--frames {}: the shot needs at least 2 frames (a key at each end)", a.frames);
    }
    let out = a.out.clone().unwrap_or_else(|| PathBuf::from("out/demo-animation"));
    let cafe = scenes_dir().join("cafe");
    let scene_path = cafe.join("cafe.gltf");
    let views_dir = out.join("views");
    std::fs::create_dir_all(&views_dir).with_context(|| format!("creating {}", views_dir.display()))?;
    let res = a.res.unwrap_or(Resolution(UVec2::new(240, 135)));
    let q = quality(a.spp.unwrap_or(8), res, a.threads, a.quiet);
    let code = mcc::TagCode::default();
    let (first, last) = (0, a.frames - 1);
    let mut pictures: Vec<(String, PathBuf)> = Vec::new();

    // 1. Key 0: `left` and `right` facing each other across the table, the bundled mask.
    let key0_views = [
        DemoView { id: 1, camera: DemoCamera::Scene("left") },
        DemoView { id: 2, camera: DemoCamera::Scene("right") },
    ];
    pictures.extend(render_tagged_views(&scene_path, &key0_views, first, &views_dir, &q, code)?);
    let map = mcc::compose::LabelMap::Colours(default_labels());
    let collage0 = out.join(format!("key{first:04}-collage.png"));
    // The bundled label and region images are 480x270: brought to the views' size by nearest
    // neighbour, which keeps every label colour exact.
    let mask0 = out.join(format!("key{first:04}-mask.png"));
    resize_labels(&cafe.join("collage-mask.png"), res.0, &mask0)?;
    mcc::compose::compose_files(&mask0, &map, &views_dir, first, &collage0)?;
    let regions0 = out.join(format!("key{first:04}-collage-regions.png"));
    resize_labels(&cafe.join("collage-mask-regions.png"), res.0, &regions0)?;
    pictures.push((format!("key {first} collage"), collage0.clone()));

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
    pictures.extend(render_tagged_views(&scene_path, &key1_views, last, &views_dir, &q, code)?);
    let mask1 = out.join(format!("key{last:04}-mask.png"));
    write_second_mask(&mask1, res.0)?;
    let collage1 = out.join(format!("key{last:04}-collage.png"));
    mcc::compose::compose_files(&mask1, &map, &views_dir, last, &collage1)?;
    pictures.push((format!("key {last} collage"), collage1.clone()));

    // 3. Remap both keys and in-between every frame (what `mcctrace keys` does).
    let lens_dir = out.join("lens");
    let output = InbetweenOutputArgs {
        frames: Some(FrameRange { first, last }),
        out: lens_dir.clone(),
        mode: ModeArg::Smooth,
        res: Some(a.frame_res),
        ray_format: RayFormatArg::Binary,
        quiet: a.quiet,
    };
    let keys_args = KeysArgs {
        keys: vec![
            format!("{first}={},{}", collage0.display(), regions0.display())
                .parse()
                .map_err(anyhow::Error::msg)?,
            format!("{last}={}", collage1.display()).parse().map_err(anyhow::Error::msg)?,
        ],
        rays: views_dir.clone(),
        settings: RemapSettingsArgs::glassner(code.bits()),
        output,
    };
    let keys = Keys::new(remap_keys(&keys_args)?, Some(a.frame_res.0))?;
    let written = write_inbetweens(&keys, &keys_args.output)?;
    println!("in-betweened {} frames -> {}", written.len(), lens_dir.display());

    // 4. Render every frame through its rays, then the preview.
    let frames_dir = out.join("frames");
    let animate_args = AnimateArgs {
        scene: scene_path.clone(),
        lens_dir: lens_dir.clone(),
        frames: FrameRange { first, last },
        out: frames_dir.clone(),
        fps: crate::scene_time::DEFAULT_FPS,
        shutter: None,
        preview: PreviewArg::Gif,
        quality: quality(a.frame_spp, a.frame_res, a.threads, true),
    };
    let report = animate(&animate_args)?;
    println!(
        "rendered {} frames ({} already finished) at {} x {} spp -> {}",
        report.rendered.len(),
        report.skipped.len(),
        a.frame_res,
        a.frame_spp,
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
