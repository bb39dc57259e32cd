//! In-memory images the tracer produces and reads: linear float RGB, row-major, top row first.

use glam::Vec3;

/// A linear-RGB float image, row-major from the top-left corner.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` pixels, row by row from the top.
    pub pixels: Vec<Vec3>,
}

impl RgbImage {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![Vec3::ZERO; width as usize * height as usize] }
    }

    /// The pixel at column `x`, row `y`.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Sets the pixel at column `x`, row `y`.
    #[inline]
    pub fn set(&mut self, x: u32, y: u32, v: Vec3) {
        self.pixels[y as usize * self.width as usize + x as usize] = v;
    }

    /// Mean of all pixels.
    pub fn mean(&self) -> Vec3 {
        let sum: glam::DVec3 = self.pixels.iter().map(|p| p.as_dvec3()).sum();
        (sum / self.pixels.len().max(1) as f64).as_vec3()
    }
}

/// A single-channel float image (depth and the like), row-major from the top-left corner.
#[derive(Clone, Debug, PartialEq)]
pub struct GrayImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` values, row by row from the top.
    pub pixels: Vec<f32>,
}
