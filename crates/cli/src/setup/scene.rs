//! The scene and its views (docs/design.md §3.1, §3.8, §8): the scene arguments of every command
//! that renders, the scene loaded (its warnings shown) and posed at a frame, and the cameras the
//! arguments select, numbered as the views of a collage.

use crate::args::Vec3Arg;
use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use mcc::job::View;
use std::path::{Path, PathBuf};
use tracer::camera::{CameraDesc, Projection};
use tracer::job::SceneSetup;
use tracer::scene::{CameraSelector, DEFAULT_MOTION_STEPS, Scene};

/// Camera models selectable from the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Model {
    /// Pinhole perspective (vertical field of view --fov).
    Perspective,
    /// Parallel projection (window height 2 × --ortho-half-height).
    Orthographic,
    /// Perspective with depth of field (--lens-radius, --focus-distance).
    ThinLens,
    /// Equidistant fisheye (image circle spans --fov, default 180°).
    Fisheye,
    /// Full 360° × 180° latitude–longitude panorama.
    Equirectangular,
}

/// Scene and camera choice shared by every command that renders.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    pub scene: PathBuf,
    /// Camera of the scene, by name or by number counted from 1 (`info` lists them so); repeat
    /// for several views (numbered 1, 2, … in this order). Default: the scene's first camera.
    #[arg(long = "camera", value_name = "NAME|NUMBER")]
    pub cameras: Vec<String>,
    /// Ad-hoc camera position (for scenes without cameras, e.g. OBJ), as x,y,z.
    #[arg(long, value_name = "X,Y,Z", requires = "look_at", conflicts_with = "cameras")]
    pub look_from: Option<Vec3Arg>,
    /// Ad-hoc camera target, as x,y,z.
    #[arg(long, value_name = "X,Y,Z", requires = "look_from")]
    pub look_at: Option<Vec3Arg>,
    /// Ad-hoc camera up direction.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,1,0")]
    pub up: Vec3Arg,
    /// Vertical field of view in degrees (ad-hoc cameras; the fisheye's full angle).
    #[arg(long, value_name = "DEGREES")]
    pub fov: Option<f32>,
    /// Camera model, overriding the scene camera's projection (its position is kept).
    #[arg(long, value_enum)]
    pub model: Option<Model>,
    /// Thin-lens aperture radius, in scene units.
    #[arg(long, default_value_t = 0.0)]
    pub lens_radius: f32,
    /// Thin-lens focus distance, in scene units.
    #[arg(long, default_value_t = 1.0)]
    pub focus_distance: f32,
    /// Orthographic half height, in scene units.
    #[arg(long, default_value_t = 1.0)]
    pub ortho_half_height: f32,
    /// A JSON camera list (for scenes without cameras, e.g. OBJ); its cameras are added to the
    /// scene's and can be picked with --camera.
    #[arg(long, value_name = "FILE")]
    pub cameras_file: Option<PathBuf>,
}

/// Loads the scene at `path` as `setup` says, showing its warnings on stderr unless quiet.
pub fn load_scene(path: &Path, setup: &SceneSetup, quiet: bool) -> anyhow::Result<Scene> {
    let scene = setup.load(path)?;
    if !quiet {
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
    }
    Ok(scene)
}

/// `scene` at `frame` (an animated scene posed there, cameras included; a static one as it is),
/// its geometry in motion over `shutter` (frames after the frame's start) at the default
/// motion steps; what posing found to warn about is printed unless `quiet`.
pub fn at_frame(
    setup: &SceneSetup,
    scene: Scene,
    frame: u32,
    shutter: (f32, f32),
    quiet: bool,
) -> anyhow::Result<Scene> {
    let known = scene.warnings.len();
    let posed =
        setup.at_frame_in_shutter(scene, frame, shutter, DEFAULT_MOTION_STEPS).with_context(|| {
            let (seconds, fps) = (setup.frame_seconds(frame), setup.fps);
            format!("posing the scene at frame {frame} ({seconds} s at {fps} fps)")
        })?;
    if !quiet {
        for w in posed.warnings.iter().skip(known) {
            eprintln!("warning: {w}");
        }
    }
    Ok(posed)
}

/// The cameras the arguments select, numbered in command-line order (after adding those of
/// --cameras-file to the scene's).
pub fn select_views(scene: &mut Scene, a: &SceneArgs) -> anyhow::Result<Vec<View>> {
    if let Some(file) = &a.cameras_file {
        scene.cameras.extend(tracer::scene::camera_list::load(file)?);
    }
    let scene = &*scene;
    let fov = a.fov.map(f32::to_radians);
    let mut descs = if let (Some(from), Some(at)) = (a.look_from, a.look_at) {
        let projection = Projection::Perspective { fov_y: fov.unwrap_or(45f32.to_radians()) };
        vec![CameraDesc::look_at("ad-hoc", from.0, at.0, a.up.0, projection)?]
    } else if a.cameras.is_empty() {
        vec![scene.camera(&CameraSelector::Index(0))?.clone()]
    } else {
        let mut descs = Vec::new();
        for c in &a.cameras {
            let selector = CameraSelector::parse(c);
            // Until numbering from 1, `--camera 0` meant the first camera: refuse it rather than
            // let an old script pick another camera (a camera named "0" is still found by name).
            if selector == CameraSelector::Number(0) && !scene.cameras.iter().any(|d| d.name == "0") {
                bail!(
                    "--camera 0: cameras are numbered from 1, as views are (the first camera is --camera \
                     1, or give its name); {} has {}",
                    scene.path.display(),
                    scene.describe_cameras()
                );
            }
            descs.push(scene.camera(&selector)?.clone());
        }
        descs
    };
    if let Some(model) = a.model {
        for d in &mut descs {
            let scene_fov = match d.projection {
                Projection::Perspective { fov_y } | Projection::ThinLens { fov_y, .. } => Some(fov_y),
                _ => None,
            };
            let fov_y = fov.or(scene_fov).unwrap_or(45f32.to_radians());
            d.projection = match model {
                Model::Perspective => Projection::Perspective { fov_y },
                Model::Orthographic => Projection::Orthographic { half_height: a.ortho_half_height },
                Model::ThinLens => Projection::ThinLens {
                    fov_y,
                    lens_radius: a.lens_radius,
                    focus_distance: a.focus_distance,
                },
                Model::Fisheye => Projection::Fisheye { fov: fov.unwrap_or(std::f32::consts::PI) },
                Model::Equirectangular => Projection::Equirectangular,
            };
        }
    } else if fov.is_some() && a.look_from.is_none() {
        bail!("--fov applies to ad-hoc cameras and --model; scene cameras keep their own field of view");
    }
    Ok(descs.into_iter().zip(1..).map(|(desc, id)| View { id, desc }).collect())
}
