//! MCC jobs (docs/design.md §4–6, §8): the file-level workflows the commands, the demo and the
//! studio share, callable without any argument parser. Each is a plain struct of settings with
//! defaults; running it returns what it made (and writes files only where it says so).
//!
//! - [`ViewRender`]: a view rendered to EXR + PNG, with the lens writer's rays and the
//!   tagger's stamp when asked (`render`, the demo's source views);
//! - [`RemapJob`]: a collage remapped from its files ([`CollageFiles`]), debug pictures written
//!   (`remap`, `rerender`, `keys`);
//! - [`Rerender`]: the scene rendered through a collage's rays, from memory or a lens file
//!   (`rerender`).
//!
//! In-memory callers remap with [`crate::remap::remap`] directly and hand the rays to
//! [`Rerender`]; progress and cancellation go through [`tracer::render::Progress`].

mod remap;
mod rerender;
mod view;

pub use remap::{CollageFiles, RemapJob, Remapped};
pub use rerender::{
    COLLAGE_KEY, Framing, LENS_DIR_KEY, LENS_FILE_KEY, Rerender, carrier_camera, lens_dir_digest,
    stretch_warning,
};
pub use view::{ViewFiles, ViewRender};
