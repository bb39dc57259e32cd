//! The bundled café for the demos (docs/design/workflow.md §8): where its files are, the demos' render
//! settings, and its source views rendered with the lens writer and the tagger (EXR, tagged PNG
//! and rays under the view names of docs/design/mcc.md §4.3).

use crate::args::Resolution;
use crate::progress::Bars;
use crate::setup::output::{summary, warn_nonfinite};
use crate::setup::scene::load_scene;
use crate::with_threads;
use glam::Vec3;
use mcc::job::{JobProgress, RenderViews, View, ViewsEvent};
use std::path::{Path, PathBuf};
use tracer::camera::{CameraDesc, Projection};
use tracer::job::{Quality, SceneSetup};
use tracer::scene::CameraSelector;

/// What both demos are told: where to write, and how to render the source views.
pub(crate) struct DemoSettings {
    /// The café's scene file.
    pub scene: PathBuf,
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
    /// Denoise the final rerender and the animation's frames (not the source views) at this
    /// quality.
    pub denoise: Option<tracer::denoise::Quality>,
}

impl DemoSettings {
    /// The quality settings of the source views.
    pub fn quality(&self) -> Quality {
        Quality { spp: self.spp, ..Quality::DEFAULT }
    }
}

/// Where the café lies in a checkout, and under an installation's `share/mcctrace/`.
const CAFE: &str = "scenes/cafe/cafe.gltf";

/// The café's scene file: `given` (`demo --scene`), else [`CAFE`] under the current directory or
/// one of its parents (a checkout), else beside the executable or one of its parents (a
/// checkout's `target/release/`), directly or in `share/mcctrace/` (an installation). Never a
/// path fixed at build time: an installed binary has no source tree.
pub(crate) fn find_cafe(given: Option<&Path>) -> anyhow::Result<PathBuf> {
    if let Some(path) = given {
        anyhow::ensure!(path.is_file(), "--scene {}: not a file", path.display());
        return Ok(path.to_path_buf());
    }
    let mut roots: Vec<PathBuf> = Vec::new();
    if let Ok(dir) = std::env::current_dir() {
        roots.extend(dir.ancestors().map(Path::to_path_buf));
    }
    if let Some(dir) = std::env::current_exe().ok().as_deref().and_then(Path::parent) {
        roots.extend(dir.ancestors().map(Path::to_path_buf));
    }
    find_cafe_under(&roots).ok_or_else(|| {
        anyhow::anyhow!(
            "the café scene ({CAFE}) is under neither the current directory, the executable's folder, \
             nor their parents (or their share/mcctrace/): give it with --scene FILE"
        )
    })
}

/// The first of `roots` holding [`CAFE`] directly or in `share/mcctrace/`.
fn find_cafe_under(roots: &[PathBuf]) -> Option<PathBuf> {
    roots
        .iter()
        .flat_map(|root| [root.join(CAFE), root.join("share/mcctrace").join(CAFE)])
        .find(|p| p.is_file())
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

/// The demo's source views' progress: their stages' bars, a summary on stdout per view.
struct DemoViews {
    spp: u32,
    bars: Bars,
}

impl JobProgress<ViewsEvent<'_>> for DemoViews {
    fn stages(&self) -> &dyn tracer::render::Progress {
        &self.bars
    }

    fn event(&self, event: ViewsEvent) {
        // Neither banded nor resumed: every view is rendered.
        if let ViewsEvent::Written { view, rendered, files } = event {
            warn_nonfinite(&view.desc.name, rendered);
            println!("{}", summary(&view.desc.name, self.spp, rendered, &files.exr));
        }
    }
}

/// Renders `views` of the café at `frame` into `views_dir` with the lens writer and tagger;
/// returns (caption, tagged PNG) per view.
pub(crate) fn render_tagged_views(
    scene_path: &Path,
    views: &[DemoView],
    frame: u32,
    views_dir: &Path,
    s: &DemoSettings,
) -> anyhow::Result<Vec<(String, PathBuf)>> {
    let scene = load_scene(scene_path, &SceneSetup::default(), s.quiet)?;
    let quality = s.quality();
    let tracer = quality.tracer(&scene)?;
    let mut chosen = Vec::new();
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
        chosen.push(View { id: view.id, desc });
    }
    let exrs: Vec<PathBuf> =
        chosen.iter().map(|v| views_dir.join(mcc::names::view_render_name(frame, v.id))).collect();
    let job = RenderViews {
        tracer: &tracer,
        scene: scene_path,
        views: &chosen,
        exrs: &exrs,
        resolution: s.res.0,
        overscan: 0,
        frame,
        shutter: (0.0, 0.0),
        quality,
        rays: Some(mcc::RayFormat::Binary),
        tag: Some(mcc::TagCode::default()),
        setup: None,
        band: None,
        resume: false,
        layers: None,
    };
    let progress = DemoViews { spp: quality.spp, bars: Bars::new(s.quiet) };
    let written = with_threads(s.threads, || job.run(&progress))??;
    Ok(chosen
        .iter()
        .zip(written)
        .filter_map(|(view, files)| {
            let caption = format!("frame {frame} view {} '{}' (tagged)", view.id, view.desc.name);
            files.png.map(|png| (caption, png))
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The café is found under a checkout's root or an installation's share/mcctrace/, from any
    /// folder below them; nowhere else.
    #[test]
    fn finds_the_cafe_relative_to_where_it_is_run() {
        let base = std::env::temp_dir().join(format!("mcctrace-find-cafe-{}", std::process::id()));
        let (checkout, install) = (base.join("checkout"), base.join("usr"));
        for root in [checkout.clone(), install.join("share/mcctrace")] {
            std::fs::create_dir_all(root.join("scenes/cafe")).unwrap();
            std::fs::write(root.join(CAFE), "{}").unwrap();
        }
        let below = checkout.join("target/release");
        let ancestors = |d: &Path| d.ancestors().map(Path::to_path_buf).collect::<Vec<_>>();
        assert_eq!(find_cafe_under(&ancestors(&below)), Some(checkout.join(CAFE)));
        assert_eq!(
            find_cafe_under(&ancestors(&install.join("bin"))),
            Some(install.join("share/mcctrace").join(CAFE))
        );
        assert_eq!(find_cafe_under(&[base.join("elsewhere")]), None);
        let given = checkout.join(CAFE);
        assert_eq!(find_cafe(Some(&given)).unwrap(), given);
        assert!(find_cafe(Some(&base.join("none.gltf"))).unwrap_err().to_string().contains("--scene"));
        std::fs::remove_dir_all(&base).unwrap();
    }
}
