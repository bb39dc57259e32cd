//! The film (docs/design/tracer.md §3.6): box-filtered pixels — each sample counts fully in the pixel its
//! film position falls in, so a pixel's value is the plain mean of its samples. Alongside the
//! mean, each pixel keeps the sum of squares for the per-sample variance (the statistical
//! golden tests and the variance AOV need it) and the first-hit AOVs.
//!
//! A sample that is dropped (by the camera or a lens shader) or non-finite counts as black; the
//! non-finite ones are also counted so tests can assert there are none. Each pixel counts its
//! own samples: with adaptive sampling (`crate::adaptive`) pixels take different numbers.

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
    /// Samples taken (every kind: finite, non-finite and dropped).
    samples: u32,
    /// Samples whose value was NaN or infinite (recorded as black).
    pub nonfinite: u32,
    /// Samples the camera or a lens shader dropped (recorded as black).
    pub dropped: u32,
}

impl PixelAccumulator {
    /// Adds a sample's radiance.
    #[inline]
    pub fn add(&mut self, radiance: Vec3) {
        self.samples += 1;
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
        self.samples += 1;
        self.dropped += 1;
    }

    /// The mean of the samples so far (black before the first).
    pub fn mean(&self) -> DVec3 {
        self.sum / self.samples.max(1) as f64
    }

    /// The unbiased per-sample variance of the samples so far (zero below two samples).
    pub fn variance(&self) -> DVec3 {
        if self.samples < 2 {
            return DVec3::ZERO;
        }
        let n = self.samples as f64;
        ((self.sum_sq - self.sum / n * self.sum) / (n - 1.0)).max(DVec3::ZERO)
    }
}

/// A whole film of accumulated pixels and the images made from them.
pub struct Film {
    width: u32,
    height: u32,
    pixels: Vec<PixelAccumulator>,
}

/// The images a render produces.
#[derive(Clone, Debug)]
pub struct FilmImages {
    /// The mean radiance per pixel.
    pub image: RgbImage,
    /// Unbiased per-sample variance per pixel and channel (divide by the pixel's sample count
    /// for the variance of its mean).
    pub variance: RgbImage,
    /// Samples each pixel took (the same everywhere unless sampling was adaptive).
    pub samples: GrayImage,
    /// Mean first-hit base colour.
    pub albedo: RgbImage,
    /// Mean first-hit shading normal (world space, not renormalised).
    pub normal: RgbImage,
    /// Mean first-hit distance (0 where nothing was hit).
    pub depth: GrayImage,
}

impl FilmImages {
    /// Every image without a border of `n` pixels on each side (undoing a camera's overscan);
    /// `None` when the border leaves no pixel.
    pub fn without_border(&self, n: u32) -> Option<Self> {
        self.without_margins(n, n)
    }

    /// Every image without `nx` columns on the left and right and `ny` rows at the top and
    /// bottom (a border scaled to an output of another aspect); `None` when nothing is left.
    pub fn without_margins(&self, nx: u32, ny: u32) -> Option<Self> {
        let (w, h) = (self.image.width, self.image.height);
        if 2 * nx as u64 >= w as u64 || 2 * ny as u64 >= h as u64 {
            return None;
        }
        let (cw, ch) = (w - 2 * nx, h - 2 * ny);
        let rgb = |x: &RgbImage| x.crop(nx, ny, cw, ch);
        let gray = |x: &GrayImage| x.crop(nx, ny, cw, ch);
        Some(Self {
            image: rgb(&self.image)?,
            variance: rgb(&self.variance)?,
            samples: gray(&self.samples)?,
            albedo: rgb(&self.albedo)?,
            normal: rgb(&self.normal)?,
            depth: gray(&self.depth)?,
        })
    }
}

impl Film {
    /// An empty film; `pixels` must hold width × height accumulators in row-major order.
    pub fn new(width: u32, height: u32, pixels: Vec<PixelAccumulator>) -> Self {
        debug_assert_eq!(pixels.len(), width as usize * height as usize);
        Self { width, height, pixels }
    }

    /// Total samples taken.
    pub fn samples(&self) -> u64 {
        self.pixels.iter().map(|p| p.samples as u64).sum()
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
        let map_rgb = |f: &dyn Fn(&PixelAccumulator) -> Vec3| RgbImage {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(f).collect(),
        };
        let map_gray = |f: &dyn Fn(&PixelAccumulator) -> f32| GrayImage {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(f).collect(),
        };
        let image = map_rgb(&|p| p.mean().as_vec3());
        let variance = map_rgb(&|p| p.variance().as_vec3());
        let inv = |p: &PixelAccumulator| 1.0 / p.samples.max(1) as f32;
        let albedo = map_rgb(&|p| p.albedo * inv(p));
        let normal = map_rgb(&|p| p.normal * inv(p));
        let depth = map_gray(&|p| p.depth * inv(p));
        let samples = map_gray(&|p| p.samples as f32);
        FilmImages { image, variance, samples, albedo, normal, depth }
    }
}
