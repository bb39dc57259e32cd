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

    /// The `width × height` region whose top-left corner is (`x`, `y`); `None` if it does not
    /// fit inside the image.
    pub fn crop(&self, x: u32, y: u32, width: u32, height: u32) -> Option<Self> {
        crop(&self.pixels, self.width, self.height, x, y, width, height).map(|pixels| Self {
            width,
            height,
            pixels,
        })
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

impl GrayImage {
    /// The `width × height` region whose top-left corner is (`x`, `y`), if it fits.
    pub fn crop(&self, x: u32, y: u32, width: u32, height: u32) -> Option<Self> {
        crop(&self.pixels, self.width, self.height, x, y, width, height).map(|pixels| Self {
            width,
            height,
            pixels,
        })
    }
}

fn crop<T: Copy>(pixels: &[T], w: u32, h: u32, x: u32, y: u32, cw: u32, ch: u32) -> Option<Vec<T>> {
    if x.checked_add(cw)? > w || y.checked_add(ch)? > h {
        return None;
    }
    let mut out = Vec::with_capacity(cw as usize * ch as usize);
    for row in y..y + ch {
        let start = (row * w + x) as usize;
        out.extend_from_slice(&pixels[start..start + cw as usize]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crop_takes_the_region() {
        let img = GrayImage { width: 4, height: 3, pixels: (0..12).map(|v| v as f32).collect() };
        let c = img.crop(1, 1, 2, 2).unwrap();
        assert_eq!(c.pixels, vec![5.0, 6.0, 9.0, 10.0]);
        assert!(img.crop(3, 0, 2, 1).is_none());
        assert!(img.crop(0, 0, 4, 3).is_some());
    }
}
