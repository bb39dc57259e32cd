//! Writing a finished render: linear EXR with metadata and optional AOVs, plus an sRGB PNG
//! preview beside it. Both are written atomically by the tracer's image I/O.

use anyhow::Context;
use std::path::{Path, PathBuf};
use tracer::image::RgbImage;
use tracer::image_io::{Aov, linear_to_srgb8, write_exr, write_png_rgb8, write_png_srgb};
use tracer::render::Rendered;

/// What the PNG beside the EXR shows.
#[derive(Clone, Copy, Debug)]
pub enum Png {
    /// The sRGB preview.
    Preview,
    /// The sRGB preview with the view's camera number in the low bits (docs/design.md §4.4, the
    /// tagger).
    Tagged {
        /// The tag code.
        code: mcc::TagCode,
        /// The camera number.
        camera: u32,
    },
}

/// What to record in the EXR header besides the image.
pub struct RenderInfo<'a> {
    pub scene: &'a Path,
    pub camera: &'a str,
    pub spp: u32,
    pub seed: u32,
    pub max_depth: u32,
    pub split: u32,
    pub frame: u32,
}

/// Writes `rendered` to `exr` and a PNG beside it; returns the PNG's path.
pub fn write_render(
    exr: &Path,
    rendered: &Rendered,
    info: &RenderInfo<'_>,
    aovs: bool,
    png: Png,
) -> anyhow::Result<PathBuf> {
    let images = &rendered.images;
    let metadata = [
        ("mcctrace/scene", info.scene.display().to_string()),
        ("mcctrace/camera", info.camera.to_owned()),
        ("mcctrace/spp", info.spp.to_string()),
        ("mcctrace/seed", info.seed.to_string()),
        ("mcctrace/max_depth", info.max_depth.to_string()),
        ("mcctrace/split", info.split.to_string()),
        ("mcctrace/frame", info.frame.to_string()),
        ("mcctrace/seconds", format!("{:.6}", rendered.stats.seconds)),
        ("mcctrace/rays", rendered.stats.rays.to_string()),
        ("mcctrace/samples", rendered.stats.samples.to_string()),
    ];
    let layers: Vec<Aov<'_>> = if aovs {
        vec![
            Aov::Rgb { name: "albedo", image: &images.albedo },
            Aov::Rgb { name: "normal", image: &images.normal },
            Aov::Gray { name: "depth", image: &images.depth },
            Aov::Rgb { name: "variance", image: &images.variance },
            Aov::Gray { name: "samples", image: &images.samples },
        ]
    } else {
        Vec::new()
    };
    write_exr(exr, &images.image, &layers, &metadata)?;
    let png_path = exr.with_extension("png");
    write_png(&png_path, &images.image, png)?;
    Ok(png_path)
}

/// Writes `image` as an 8-bit sRGB PNG, tagged or not.
pub fn write_png(path: &Path, image: &RgbImage, png: Png) -> anyhow::Result<()> {
    match png {
        Png::Preview => write_png_srgb(path, image)?,
        Png::Tagged { code, camera } => {
            let bytes: Vec<u8> =
                image.pixels.iter().flat_map(|p| p.to_array().map(linear_to_srgb8)).collect();
            let mut rgb = mcc::image::RgbImage::from_raw(image.width, image.height, bytes)
                .context("image size does not match its pixels")?;
            code.tag_rgb(&mut rgb, camera)?;
            write_png_rgb8(path, image.width, image.height, rgb.as_raw())?;
        }
    }
    Ok(())
}
