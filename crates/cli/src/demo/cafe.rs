//! The bundled café for the demos (docs/design.md §8): where its files are, the demos' render
//! settings, and its source views rendered with the lens writer and the tagger (EXR, tagged PNG
//! and rays under the view names of docs/design.md §4.3).

use crate::args::Resolution;
use crate::progress::Bars;
use crate::setup::output::{summary, warn_nonfinite};
use crate::setup::quality::QualityArgs;
use crate::setup::scene::load_scene;
use crate::with_threads;
use glam::Vec3;
use mcc::job::ViewRender;
use std::path::{Path, PathBuf};
use tracer::camera::{CameraDesc, Projection};
use tracer::job::{CameraRender, SceneSetup};
use tracer::scene::CameraSelector;

/// What both demos are told: where to write, and how to render the source views.
pub(crate) struct DemoSettings {
    /// The output folder.
    pub out: PathBuf,
    /// Samples per pixel of the source views (and of the still demo's rerender).
    pub spp: u32,
    /// Resolution of the source views (and of the still demo's rerender).
    pub res: Resolution,
    /// Render threads (default: all cores).
    pub threads: Option<usize>,
    /// No progress bars.
    pub quiet: bool,
}

impl DemoSettings {
    /// The quality settings of the source views.
    pub fn quality(&self) -> QualityArgs {
        QualityArgs::with(self.spp, self.res, self.threads, self.quiet)
    }
}

/// The café's folder: beside the current directory (a checkout), else beside the sources.
pub(crate) fn cafe_dir() -> PathBuf {
    let here = Path::new("scenes");
    let scenes = if here.is_dir() {
        here.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
    };
    scenes.join("cafe")
}

/// The café's scene file.
pub(crate) fn cafe_scene() -> PathBuf {
    cafe_dir().join("cafe.gltf")
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

/// Renders `views` of the café at `frame` into `views_dir` with the lens writer and tagger;
/// returns (caption, tagged PNG) per view.
pub(crate) fn render_tagged_views(
    views: &[DemoView],
    frame: u32,
    views_dir: &Path,
    q: &QualityArgs,
) -> anyhow::Result<Vec<(String, PathBuf)>> {
    let scene_path = cafe_scene();
    let scene = load_scene(&scene_path, &SceneSetup::default(), q.quiet)?;
    let quality = q.quality();
    let tracer = quality.tracer(&scene)?;
    let bars = Bars::new(q.quiet);
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
        let exr = views_dir.join(mcc::names::view_render_name(frame, view.id));
        let job = ViewRender {
            render: CameraRender {
                tracer: &tracer,
                camera: camera.as_ref(),
                name: &desc.name,
                camera_id: view.id,
                frame,
                shutter: (0.0, 0.0),
                quality,
            },
            scene: &scene_path,
            exr: &exr,
            rays: Some(mcc::RayFormat::Binary),
            tag: Some(mcc::TagCode::default()),
        };
        let (rendered, files) = with_threads(q.threads, || job.run(&bars))??;
        warn_nonfinite(&desc.name, &rendered);
        println!("{}", summary(&desc.name, q.spp, &rendered, &exr));
        pictures.push((format!("frame {frame} view {} '{}' (tagged)", view.id, desc.name), files.png));
    }
    Ok(pictures)
}
