//! Quality settings of a render (docs/design/tracer.md §3.3, §3.5): how many samples, which seed, how deep
//! the paths go, and what the film records.

use crate::error::Result;
use crate::integrator::{IntegratorConfig, PathTracer};
use crate::render::RenderSettings;
use crate::scene::Scene;

/// How well to render. [`Quality::DEFAULT`]: 64 samples per pixel, seed 0, the integrator's
/// default depths, no splitting, no AOVs, uniform sampling, no denoising.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Quality {
    /// Samples per pixel (with `adaptive`, the average).
    pub spp: u32,
    /// Seed of the sample sequence: the same seed gives the same image bit for bit.
    pub seed: u32,
    /// Maximum scattering vertices per path.
    pub max_depth: u32,
    /// Russian roulette starts after this many scattering vertices.
    pub rr_depth: u32,
    /// Paths continued from each camera ray's first hit.
    pub split: u32,
    /// Record albedo, normal, depth, variance and sample-count layers.
    pub aovs: bool,
    /// Spread the samples adaptively (`crate::adaptive`).
    pub adaptive: bool,
    /// Denoise the finished picture at this OIDN quality (`crate::denoise`): the film then
    /// records albedo and normal whether or not `aovs` asks to write them.
    pub denoise: Option<crate::denoise::Quality>,
}

impl Quality {
    /// The command line's defaults.
    pub const DEFAULT: Self = Self {
        spp: 64,
        seed: 0,
        max_depth: IntegratorConfig::DEFAULT.max_depth,
        rr_depth: IntegratorConfig::DEFAULT.rr_depth,
        split: IntegratorConfig::DEFAULT.split,
        aovs: false,
        adaptive: false,
        denoise: None,
    };

    /// The same settings at `spp` samples per pixel.
    pub const fn with_spp(self, spp: u32) -> Self {
        Self { spp, ..self }
    }

    /// The path tracer's configuration.
    pub fn integrator_config(&self) -> IntegratorConfig {
        IntegratorConfig::DEFAULT
            .with_max_depth(self.max_depth)
            .with_rr_depth(self.rr_depth)
            .with_split(self.split)
    }

    /// `scene` prepared for tracing (BVH, lights) at these settings.
    pub fn tracer(&self, scene: &Scene) -> Result<PathTracer> {
        PathTracer::new(scene, self.integrator_config())
    }

    /// The render loop's settings for camera `camera_id` at `frame`, the shutter open from
    /// `shutter.0` to `shutter.1` frames after the frame's start.
    pub fn settings(&self, frame: u32, camera_id: u32, shutter: (f32, f32)) -> RenderSettings {
        RenderSettings {
            spp: self.spp,
            seed: self.seed,
            frame,
            camera_id,
            shutter,
            aovs: self.aovs || self.denoise.is_some(),
            adaptive: self.adaptive,
            rows: None,
        }
    }
}

impl Default for Quality {
    fn default() -> Self {
        Self::DEFAULT
    }
}
