//! A finished render written out (docs/design.md §3.6): linear EXR with the settings in its header
//! and optional AOV layers, and an sRGB PNG preview beside it, both atomically.

use super::Quality;
use crate::error::Result;
use crate::image_io::{Aov, write_exr as write_exr_file, write_png_srgb};
use crate::render::Rendered;
use std::path::{Path, PathBuf};

/// What the EXR header records besides the pixels.
#[derive(Clone, Copy, Debug)]
pub struct RenderInfo<'a> {
    /// The scene file.
    pub scene: &'a Path,
    /// The camera's name (or what stood for it, e.g. "multicamera collage").
    pub camera: &'a str,
    /// The frame.
    pub frame: u32,
    /// The settings rendered with (with `aovs`, the layers are written too).
    pub quality: &'a Quality,
}

/// Writes `rendered` to the EXR `path`: the beauty image, its AOV layers if the quality asked
/// for them, and `mcctrace/…` header attributes (settings and counts).
pub fn write_exr(path: &Path, rendered: &Rendered, info: &RenderInfo<'_>) -> Result<()> {
    let (images, q) = (&rendered.images, info.quality);
    let metadata = [
        ("mcctrace/scene", info.scene.display().to_string()),
        ("mcctrace/camera", info.camera.to_owned()),
        ("mcctrace/spp", q.spp.to_string()),
        ("mcctrace/seed", q.seed.to_string()),
        ("mcctrace/max_depth", q.max_depth.to_string()),
        ("mcctrace/split", q.split.to_string()),
        ("mcctrace/frame", info.frame.to_string()),
        ("mcctrace/seconds", format!("{:.6}", rendered.stats.seconds)),
        ("mcctrace/rays", rendered.stats.rays.to_string()),
        ("mcctrace/samples", rendered.stats.samples.to_string()),
    ];
    let layers: Vec<Aov<'_>> = if q.aovs {
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
    write_exr_file(path, &images.image, &layers, &metadata)
}

/// Writes `rendered` to `exr` ([`write_exr`]) and its sRGB preview beside it; returns the
/// PNG's path.
pub fn write_render(exr: &Path, rendered: &Rendered, info: &RenderInfo<'_>) -> Result<PathBuf> {
    write_exr(exr, rendered, info)?;
    let png = exr.with_extension("png");
    write_png_srgb(&png, &rendered.images.image)?;
    Ok(png)
}
