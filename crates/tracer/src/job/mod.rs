//! Render jobs (docs/design.md §3, §8): the workflow every rendering command and the studio
//! share, callable without any argument parser. A scene file is loaded, overridden and posed
//! ([`SceneSetup`]), prepared at some [`Quality`], seen through one camera and its lens chain
//! ([`CameraRender`]), and written as EXR + PNG ([`write_render`]). Progress and cancellation
//! go through [`crate::render::Progress`]; nothing here prints.

mod camera_render;
mod output;
mod quality;
mod scene_setup;

pub use camera_render::CameraRender;
pub use output::{RenderInfo, write_exr, write_render};
pub use quality::Quality;
pub use scene_setup::{EnvironmentImage, SceneSetup};
