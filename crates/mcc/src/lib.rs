//! The multicamera collage (MCC, docs/design.md §4–6): ray files and their names, the camera tag
//! code, collage and region decoding, the lens remapper, and the lens writer and reader that plug
//! into the tracer as [`tracer::lens::LensShader`]s. Library code reports every problem as an
//! [`MccError`] that names the file and what is wrong with it; it never prints.
#![warn(missing_docs)]

pub mod collage;
pub mod compose;
pub mod error;
pub mod inbetween;
pub mod job;
mod lanes;
pub mod layers;
pub mod lens_reader;
pub mod lens_writer;
pub mod names;
pub mod png;
pub mod ray_file;
pub mod regions;
pub mod remap;
pub mod slerp;
pub mod stray;
pub mod tag;

// The crate's test helpers; the workspace's tests reach them (the oracles) through the
// `test-support` feature, which `mcctrace` never builds. Test-only API: its small helpers carry
// no doc lines of their own.
#[cfg(any(test, feature = "test-support"))]
#[allow(missing_docs)]
pub mod test_util;

/// The `image` crate this one's API uses (tagging, composing, debug pictures), re-exported so
/// callers name the same types.
pub use image;

pub use collage::{Collage, CollageOptions};
pub use error::{MccError, Result};
pub use inbetween::{InbetweenMode, Keys};
pub use lens_reader::LensReader;
pub use lens_writer::LensWriter;
pub use ray_file::{RayFile, RayFormat, StoredRay};
pub use regions::Regions;
pub use remap::{RemapConfig, RemapOutput, remap};
pub use stray::{StrayHints, StrayPolicy, StrayReport};
pub use tag::TagCode;
