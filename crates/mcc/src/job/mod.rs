//! MCC jobs (docs/design.md §4–6, §8): the file-level workflows the commands, the demo and the
//! studio share, callable without any argument parser. Each is a plain struct of settings with
//! defaults; running it returns what it made (and writes files only where it says so).
//!
//! - [`ViewRender`]: a view rendered to EXR + PNG, with the lens writer's rays and the
//!   tagger's stamp when asked (`render`, the demo's source views);
//! - [`RenderViews`]: a scene's [`View`]s rendered in turn, finished ones skipped, gathered into
//!   one layered file when asked (`render`, the demos);
//! - [`RemapJob`]: a collage remapped from its files ([`CollageFiles`]), debug pictures written
//!   (`remap`, `rerender`, `keys`);
//! - [`Rerender`]: the scene rendered through a collage's rays, from memory or a lens file
//!   (`rerender`);
//! - [`Animate`]: a shot rendered frame by frame through per-frame ray files, finished frames
//!   skipped (`animate`, the animation demo);
//! - [`KeyFrames`]: key collages remapped and in-betweened ([`Inbetween`]) into one ray file
//!   per frame, skipped when finished (`keys`, the animation demo);
//! - [`KeysRecord`]: what the ray files of `keys` were made from, to tell them finished.
//!
//! A job that runs long reports through a [`JobProgress`] sink: its renders' stages, and events
//! of its own that the caller words (the command line) or ignores ([`Silent`]).
//!
//! In-memory callers remap with [`crate::remap::remap`] directly and hand the rays to
//! [`Rerender`]; progress and cancellation go through [`tracer::render::Progress`].

mod animate;
mod keys;
mod keys_record;
mod progress;
mod remap;
mod rerender;
mod view;
mod views;

pub use animate::{Animate, AnimateEvent, AnimateProgress, AnimateReport, RAY_BLUR_KEY, frame_exr};
pub use keys::{Inbetween, Key, KeyFrames, KeysEvent, KeysProgress};
pub use keys_record::{KeysRecord, RECORD_NAME, file_sha256};
pub use progress::{JobProgress, Silent};
pub use remap::{CollageFiles, RemapJob, Remapped};
pub use rerender::{
    COLLAGE_KEY, FrameRays, Framing, LENS_DIR_KEY, LENS_FILE_KEY, Rerender, carrier_camera, lens_dir_digest,
    stretch_warning,
};
pub use view::{ViewFiles, ViewRender};
pub use views::{RenderViews, View, ViewsEvent, ViewsProgress};
