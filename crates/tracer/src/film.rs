//! The film (SPEC §3, "Film"): box-filtered pixels — each sample counts fully in the pixel its
//! film position falls in, so a pixel's value is the plain mean of its samples. Alongside the
//! mean, each pixel keeps the sum of squares for the per-sample variance (the statistical
//! golden tests and the variance AOV need it) and the first-hit AOVs.
//!
//! A sample that is dropped (by the camera or a lens shader) or non-finite counts as black; the
//! non-finite ones are also counted so tests can assert there are none.

use crate::image::{GrayImage, RgbImage};
use crate::integrator::FirstHit;
use glam::{DVec3, Vec3};

/// Accumulates one pixel's samples.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelAccumulator {
    sum: DVec3,
    sum_sq: DVec3,
    albedo: Vec3,
    normal: Vec3,
    depth: f32,
    /// Samples whose value was NaN or infinite (recorded as black).
    pub nonfinite: u32,
    /// Samples the camera or a lens shader dropped (recorded as black).
    pub dropped: u32,
}

impl PixelAccumulator {
    /// Adds a sample's radiance.
    #[inline]
    pub fn add(&mut self, radiance: Vec3) {
        if !radiance.is_finite() {
            self.nonfinite += 1;
            return;
        }
        let v = radiance.as_dvec3();
        self.sum += v;
        self.sum_sq += v * v;
    }

    /// Adds a sample's first-hit record (AOVs average over the pixel's samples too).
    #[inline]
    pub fn add_first_hit(&mut self, first: &FirstHit) {
        self.albedo += first.albedo;
        self.normal += first.normal;
        self.depth += if first.depth.is_finite() { first.depth } else { 0.0 };
    }

    /// Records a dropped sample.
    #[inline]
    pub fn drop_sample(&mut self) {
        self.dropped += 1;
    }
}

/// A whole film of accumulated pixels and the images made from them.
pub struct Film {
    width: u32,
    height: u32,
    spp: u32,
    pixels: Vec<PixelAccumulator>,
}

/// The images a render produces.
#[derive(Clone, Debug)]
pub struct FilmImages {
    /// The mean radiance per pixel.
    pub image: RgbImage,
    /// Unbiased per-sample variance per pixel and channel (divide by spp for the variance of
    /// the pixel's mean).
    pub variance: RgbImage,
    /// Mean first-hit base colour.
    pub albedo: RgbImage,
    /// Mean first-hit shading normal (world space, not renormalised).
    pub normal: RgbImage,
    /// Mean first-hit distance (0 where nothing was hit).
    pub depth: GrayImage,
}

impl Film {
    /// An empty film; `pixels` must hold width × height accumulators in row-major order.
    pub fn new(width: u32, height: u32, spp: u32, pixels: Vec<PixelAccumulator>) -> Self {
        debug_assert_eq!(pixels.len(), width as usize * height as usize);
        Self { width, height, spp, pixels }
    }

    /// Total non-finite samples.
    pub fn nonfinite_samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.nonfinite as u64).sum()
    }

    /// Total dropped samples.
    pub fn dropped_samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.dropped as u64).sum()
    }

    /// The mean, variance and AOV images.
    pub fn images(&self) -> FilmImages {
        let n = self.spp as f64;
        let map_rgb = |f: &dyn Fn(&PixelAccumulator) -> Vec3| RgbImage {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(f).collect(),
        };
        let image = map_rgb(&|p| (p.sum / n).as_vec3());
        let variance = map_rgb(&|p| {
            if self.spp < 2 {
                return Vec3::ZERO;
            }
            let mean = p.sum / n;
            ((p.sum_sq - mean * p.sum) / (n - 1.0)).max(DVec3::ZERO).as_vec3()
        });
        let inv = 1.0 / self.spp as f32;
        let albedo = map_rgb(&|p| p.albedo * inv);
        let normal = map_rgb(&|p| p.normal * inv);
        let depth = GrayImage {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(|p| p.depth * inv).collect(),
        };
        FilmImages { image, variance, albedo, normal, depth }
    }
}
