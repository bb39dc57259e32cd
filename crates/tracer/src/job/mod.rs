//! Render jobs (docs/design.md §3, §8): the workflow every rendering command and the studio
//! share, callable without any argument parser. A scene file is loaded, overridden and posed
//! ([`SceneSetup`]), prepared at some [`Quality`], seen through one camera and its lens chain
//! ([`CameraRender`]), and written as EXR + PNG ([`write_render`]). A finished output is told
//! from a stale one by its header ([`check_finished`]); an image rendered in bands ([`Band`]) is
//! assembled by [`merge_bands`] (docs/farm.md). Progress and cancellation go through
//! [`crate::render::Progress`]; nothing here prints.

mod band;
mod camera_render;
mod merge;
mod output;
mod quality;
mod resume;
mod scene_setup;

pub use band::{Band, IMAGE_SIZE_KEY, TILE_KEY, TILE_ROWS_KEY};
pub use camera_render::CameraRender;
pub use merge::{Merged, band_files, merge_bands};
pub use output::{
    COUNT_KEYS, DENOISE_AUX_KEY, DENOISE_KEY, DENOISED_LAYER, DENOISER_KEY, Provenance, RenderInfo,
    denoise_final, describe_projection, is_setting_key, write_exr, write_render,
};
pub use quality::Quality;
pub use resume::{Companion, Stale, check_finished, check_finished_with, compare_settings};
pub use scene_setup::{EnvironmentImage, SceneSetup};
