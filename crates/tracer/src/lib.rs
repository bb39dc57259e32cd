//! mcctrace's tracer: a BVH-accelerated unidirectional path tracer whose camera passes every eye
//! ray through a chain of lens shaders (SPEC §3). It knows nothing about the multicamera collage;
//! the `mcc` crate plugs in through [`lens::LensShader`].
#![warn(missing_docs)]

pub mod atomic;
pub mod camera;
pub mod compare;
pub mod error;
pub mod image;
pub mod image_io;
pub mod lens;
pub mod material;
pub mod ray;
pub mod sampling;
pub mod scene;

pub use error::{Result, TracerError};
