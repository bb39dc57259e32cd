//! mcctrace's tracer: a BVH-accelerated unidirectional path tracer whose camera passes every eye
//! ray through a chain of lens shaders (docs/design/tracer.md §3). It knows nothing about the multicamera
//! collage; the `mcc` crate plugs in through [`lens::LensShader`].
#![warn(missing_docs)]
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    reason = "`!(x > 0.0)` is how this crate rejects NaN along with the out-of-range values"
)]

pub mod adaptive;
pub mod atomic;
pub mod bsdf;
pub mod bvh;
pub mod camera;
pub mod denoise;
pub mod error;
pub mod film;
pub mod image;
pub mod image_io;
pub mod integrator;
pub mod interaction;
pub mod job;
pub mod lens;
pub mod light;
pub mod material;
pub mod ray;
pub mod render;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod shading;
#[cfg(any(test, feature = "test-support"))]
pub mod test_support;
pub mod texture;
mod triangle;

pub use error::{Result, TracerError};
