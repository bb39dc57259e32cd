//! Sampling and quality arguments (docs/design/tracer.md §3.3, §3.5), shared by every command that
//! renders, and the library settings they make: a [`Quality`] and a [`SceneSetup`].

use crate::args::{Resolution, SkyArg, Vec3Arg};
use anyhow::bail;
use clap::{Args, ValueEnum};
use glam::UVec2;
use std::path::PathBuf;
use tracer::job::{EnvironmentImage, Quality, SceneSetup};
use tracer::scene::{GltfReading, SpotFalloff};

/// Sampling and quality settings shared by every command that renders.
#[derive(Args, Debug, Clone)]
pub struct QualityArgs {
    /// Samples per pixel (1 … 65536; with --split N, 1 … 65536 / N).
    #[arg(long, default_value_t = Quality::DEFAULT.spp, value_parser = crate::args::spp)]
    pub spp: u32,
    /// Output resolution (default 640x360).
    #[arg(long, value_name = "WxH")]
    pub res: Option<Resolution>,
    /// Seed of the sample sequence: the same seed gives the same image bit for bit.
    #[arg(long, default_value_t = Quality::DEFAULT.seed)]
    pub seed: u32,
    /// Render threads (default: all cores). The image does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Maximum scattering vertices per path (the Cornell reference uses 4).
    #[arg(long, default_value_t = Quality::DEFAULT.max_depth)]
    pub max_depth: u32,
    /// Russian roulette starts after this many scattering vertices.
    #[arg(long, default_value_t = Quality::DEFAULT.rr_depth)]
    pub rr_depth: u32,
    /// Paths continued from each camera ray's first hit (first-vertex splitting): each of the
    /// --spp samples traces N indirect paths. Pays where indirect light makes the noise (the
    /// Cornell box: 2 reaches the same error ≈ 1.1-1.16x sooner); costs where the noise is in
    /// what the camera sees (textures, depth of field, small lights: the café ≈ 1.2x slower).
    #[arg(long, default_value_t = Quality::DEFAULT.split, value_name = "N",
          value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub split: u32,
    /// Environment radiance (constant colour) as r,g,b, replacing the scene's.
    #[arg(long, value_name = "R,G,B")]
    pub env: Option<Vec3Arg>,
    /// An equirectangular environment image (EXR; PNG/JPEG read as sRGB), importance-sampled.
    #[arg(long, value_name = "FILE")]
    pub env_map: Option<PathBuf>,
    /// Rotation of the environment image about +Y, in degrees.
    #[arg(long, default_value_t = 0.0, value_name = "DEGREES")]
    pub env_rotation: f32,
    /// Radiance multiplier of the environment image.
    #[arg(long, default_value_t = 1.0)]
    pub env_strength: f32,
    /// A uniform sky lighting the scene from every direction, importance-sampled like an
    /// environment image: `grey` (Blender's default world, 0.0509), a radiance, or R,G,B. For
    /// models that carry no light.
    #[arg(long, value_name = "grey|RADIANCE|R,G,B", conflicts_with_all = ["env", "env_map"])]
    pub sky: Option<SkyArg>,
    /// Exposure in stops: the picture × 2^EV (every light scaled alike), for scenes in real-world
    /// units (a sun of 2–3 W/m² renders near black) or too bright ones; recorded in the EXR header.
    #[arg(long, value_name = "EV", default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// How to read a glTF file where Blender's importer and the specification differ, overriding
    /// the loader's choice (Blender's for files Blender wrote, the specification's otherwise):
    /// docs/cycles.md lists the differences. Spot falloff (unless --spot-falloff is given) and
    /// KHR_materials_volume's absorption and thin walls follow it.
    #[arg(long, value_enum)]
    pub gltf_reading: Option<ReadingArg>,
    /// Spot-light falloff, overriding the reading's (Blender's for Blender-made files).
    #[arg(long, value_enum)]
    pub spot_falloff: Option<FalloffArg>,
    /// Also write albedo, normal, depth, per-sample variance and sample-count layers into the
    /// EXR.
    #[arg(long)]
    pub aovs: bool,
    /// Adaptive sampling: --spp becomes the average per pixel; a quarter of it goes to every
    /// pixel, the rest where the noise relative to the pixel's brightness is highest.
    #[arg(long)]
    pub adaptive: bool,
    /// Denoise the picture with Intel Open Image Denoise (guided by albedo and normal, rendered
    /// for it) at QUALITY: high (the default, as Cycles' finals), balanced, or fast (about 1.6 s
    /// for 1920×1080 on 2 cores against high's 8, with 1.2–1.5× its error). The PNG shows it, the EXR keeps the raw beauty and adds the layer `denoised`. Bands (--tile)
    /// are denoised whole by `merge`. Needs the library (README, "Denoising").
    #[arg(long, value_name = "QUALITY", num_args = 0..=1, require_equals = true,
        default_missing_value = tracer::denoise::Quality::DEFAULT.name(), value_parser = crate::args::denoise_quality)]
    pub denoise: Option<tracer::denoise::Quality>,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Readings of a glTF file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ReadingArg {
    /// As Blender's importer reads it (what Cycles renders).
    Blender,
    /// As the glTF specification reads it.
    Spec,
}

/// Spot-light falloff shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FalloffArg {
    /// Blender Cycles' smoothstep falloff.
    Blender,
    /// The glTF specification's recommended falloff.
    Gltf,
}

impl QualityArgs {
    /// The resolution asked for, or the default 640x360.
    pub fn resolution(&self) -> UVec2 {
        self.res.map_or(UVec2::new(640, 360), |r| r.0)
    }

    /// The library's quality settings; says (unless quiet) when --adaptive cannot split.
    pub fn quality(&self) -> Quality {
        if self.adaptive && tracer::adaptive::pilot_spp(self.spp).is_none() && !self.quiet {
            eprintln!(
                "note: --adaptive needs --spp {} or more to split; {} samples go to every pixel",
                tracer::adaptive::PILOT_SHARE,
                self.spp
            );
        }
        Quality {
            spp: self.spp,
            seed: self.seed,
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            split: self.split,
            aovs: self.aovs,
            adaptive: self.adaptive,
            denoise: self.denoise,
        }
    }

    /// How the scene is loaded and posed: the environment and falloff overrides, and `fps`
    /// (--fps, refused unless a positive number). With --denoise, the denoiser is started here,
    /// so a missing library is said before anything renders.
    pub fn scene_setup(&self, fps: f32) -> anyhow::Result<SceneSetup> {
        if self.denoise.is_some() {
            tracer::denoise::Denoiser::shared().map_err(|e| anyhow::anyhow!("--denoise: {e}"))?;
        }
        if !(fps.is_finite() && fps > 0.0) {
            bail!("--fps {fps}: the frame rate must be a positive number of frames per second");
        }
        // Each sample's split branches take sample indices of their own: the renderer's limit
        // is 65536 / N, said here with both flags named.
        let most = tracer::sampler::MAX_SAMPLES_PER_PIXEL / self.split;
        if self.spp > most {
            bail!(
                "--spp {} with --split {}: {} samples per pixel: must be 1 ..= {most} with {} paths split from \
                 each first hit",
                self.spp,
                self.split,
                self.spp,
                self.split
            );
        }
        let max = SceneSetup::MAX_EXPOSURE;
        if !(self.exposure.is_finite() && self.exposure.abs() <= max) {
            bail!("--exposure {}: must be a number of stops between -{max} and {max}", self.exposure);
        }
        Ok(SceneSetup {
            fps,
            sky: self.sky.map(|s| s.0),
            exposure: self.exposure,
            environment: self.env.map(|v| v.0),
            environment_image: self.env_map.as_ref().map(|path| EnvironmentImage {
                path: path.clone(),
                rotation: self.env_rotation.to_radians(),
                strength: self.env_strength,
            }),
            reading: self.gltf_reading.map(|r| match r {
                ReadingArg::Blender => GltfReading::Blender,
                ReadingArg::Spec => GltfReading::Spec,
            }),
            spot_falloff: self.spot_falloff.map(|f| match f {
                FalloffArg::Blender => SpotFalloff::Blender,
                FalloffArg::Gltf => SpotFalloff::Gltf,
            }),
        })
    }
}
