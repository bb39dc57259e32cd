//! Writing a finished render: linear EXR with metadata and optional AOVs, plus an sRGB PNG
//! preview beside it. Both are written atomically by the tracer's image I/O.

use anyhow::Context;
use std::path::{Path, PathBuf};
use tracer::image_io::{Aov, write_exr, write_png_srgb};
use tracer::render::Rendered;

/// What to record in the EXR header besides the image.
pub struct RenderInfo<'a> {
    pub scene: &'a Path,
    pub camera: &'a str,
    pub spp: u32,
    pub seed: u32,
    pub max_depth: u32,
    pub frame: u32,
}

/// Writes `rendered` to `exr` (and its PNG preview beside it, unless `png` says otherwise);
/// returns the preview's path.
pub fn write_render(
    exr: &Path,
    rendered: &Rendered,
    info: &RenderInfo<'_>,
    aovs: bool,
) -> anyhow::Result<PathBuf> {
    let images = &rendered.images;
    let metadata = [
        ("mcctrace/scene", info.scene.display().to_string()),
        ("mcctrace/camera", info.camera.to_owned()),
        ("mcctrace/spp", info.spp.to_string()),
        ("mcctrace/seed", info.seed.to_string()),
        ("mcctrace/max_depth", info.max_depth.to_string()),
        ("mcctrace/frame", info.frame.to_string()),
        ("mcctrace/seconds", format!("{:.6}", rendered.stats.seconds)),
        ("mcctrace/rays", rendered.stats.rays.to_string()),
    ];
    let layers: Vec<Aov<'_>> = if aovs {
        vec![
            Aov::Rgb { name: "albedo", image: &images.albedo },
            Aov::Rgb { name: "normal", image: &images.normal },
            Aov::Gray { name: "depth", image: &images.depth },
            Aov::Rgb { name: "variance", image: &images.variance },
        ]
    } else {
        Vec::new()
    };
    write_exr(exr, &images.image, &layers, &metadata)
        .with_context(|| format!("writing {}", exr.display()))?;
    let png = exr.with_extension("png");
    write_png_srgb(&png, &images.image).with_context(|| format!("writing {}", png.display()))?;
    Ok(png)
}
