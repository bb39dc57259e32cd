//! Scenes as users author them, rendered: every feature the loaders gained (textures, samplers,
//! `KHR_texture_transform`, second texture coordinates, normal maps and tangents, alpha cut-outs,
//! glass, spot/point/directional lights in glTF units, Blender's conventions, environment maps,
//! camera lists) checked against closed forms computed here by hand, never against the
//! renderer's own output.
//!
//! Every asset is written by the test into a temporary folder: glTF JSON by hand (this package
//! has no JSON crate), buffers as `.bin` files, images with the tracer's PNG/EXR writers.
//!
//! Tolerances: where a pixel's estimate is noisy, |rendered − expected| ≤ 5·σ + a small model
//! error, with σ from the render's own per-sample variance; the expected value is the closed form
//! averaged over the pixel's footprint (the film's box filter). Where every sample is exact
//! (emission seen directly, a directional light on a plane), the tolerance is float precision.
//!
//! One module per kind of feature; `assets` writes the files, `harness` renders and checks.

mod assets;
mod blender;
mod camera_lists;
mod environment;
mod geometry_extensions;
mod harness;
mod lights;
mod materials;
mod shared_instances;
mod skinning;
mod textures;
