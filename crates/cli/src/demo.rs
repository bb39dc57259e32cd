//! `mcctrace demo`: the main job on the bundled scene, every picture in one folder.

use crate::args::Resolution;
use crate::output::{RenderInfo, write_render};
use crate::render::{QualityArgs, SceneArgs, load_scene, prepare, render_view, select_views, summary};
use clap::Args;
use glam::UVec2;
use std::path::{Path, PathBuf};
use tracer::lens::LensChain;

/// Arguments of `mcctrace demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    spp: u32,
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
    let scene_path = scenes_dir().join("cornell/cornell.gltf");
    let scene_args = SceneArgs {
        scene: scene_path.clone(),
        cameras: vec![],
        look_from: None,
        look_at: None,
        up: "0,1,0".parse().map_err(anyhow::Error::msg)?,
        fov: None,
        model: None,
        lens_radius: 0.0,
        focus_distance: 1.0,
        ortho_half_height: 1.0,
    };
    let q = QualityArgs {
        spp: a.spp,
        res: Resolution(UVec2::new(256, 256)),
        seed: 0,
        threads: a.threads,
        max_depth: 4,
        rr_depth: tracer::integrator::IntegratorConfig::DEFAULT.rr_depth,
        env: None,
        aovs: true,
        quiet: a.quiet,
    };
    let mut scene = load_scene(&scene_path, a.quiet)?;
    let views = select_views(&scene, &scene_args)?;
    let tracer = prepare(&mut scene, &q)?;
    std::fs::create_dir_all(&a.out)?;
    for view in &views {
        let rendered = render_view(&tracer, view, &mut LensChain::new(), &q, 0)?;
        let exr = a.out.join(format!("frame0000camera{:02}.exr", view.id));
        let info = RenderInfo {
            scene: &scene_path,
            camera: &view.desc.name,
            spp: q.spp,
            seed: 0,
            max_depth: 4,
            frame: 0,
        };
        let png = write_render(&exr, &rendered, &info, true)?;
        println!("{}", summary(&view.desc.name, &q, &rendered, &exr));
        println!("preview: {}", png.display());
    }
    Ok(())
}
