//! A picture denoised at half its size and brought back by its albedo: the studio's refining
//! preview, where OIDN's smallest network at full size takes too long on two cores (about
//! 105 ms at 480×270 against 27 ms at 240×135; docs/performance.md §1.7).
//!
//! Each 2 × 2 block is averaged (four samples' worth of noise less), the half-size picture is
//! denoised guided by the averaged albedo and normal, and each full-size pixel takes the
//! bilinearly interpolated *shading* (denoised radiance over albedo) times its own albedo, so
//! texture detail keeps its full resolution and only the lighting is at half. Where the albedo
//! is too dark to divide by (black surfaces, the sky), the denoised radiance itself is
//! interpolated.

use super::filter::{self, Aux};
use super::{DenoiseError, Denoiser, Settings};
use crate::image::RgbImage;
use crate::render::Progress;
use glam::Vec3;

/// Albedo channels below this are not divided by: their shading would carry the noise of a
/// near-zero quotient.
const DARKEST_ALBEDO: f32 = 0.02;

/// `color` denoised at half size and brought back to full size by `aux`'s albedo (see the
/// module); without auxiliaries, the half-size result interpolated.
pub(super) fn run(
    denoiser: &Denoiser,
    color: &RgbImage,
    aux: Option<Aux<'_>>,
    settings: Settings,
    progress: &dyn Progress,
) -> Result<RgbImage, DenoiseError> {
    filter::check_sizes(color, aux)?;
    if color.pixels.is_empty() {
        return Ok(color.clone());
    }
    let half_color = halved(color);
    let albedo = aux.map(|a| (a.albedo, halved(a.albedo)));
    let denoised = match aux {
        None => filter::run(denoiser, &half_color, None, settings, progress)?,
        Some(a) => {
            let mut normal = halved(a.normal);
            // A block averaged across an edge has a shorter normal: the network expects unit ones.
            for n in &mut normal.pixels {
                *n = n.normalize_or_zero();
            }
            let (_, half_albedo) = albedo.as_ref().expect("set with aux");
            let half_aux = Aux { albedo: half_albedo, normal: &normal };
            filter::run(denoiser, &half_color, Some(half_aux), settings, progress)?
        }
    };
    Ok(doubled(&denoised, albedo.as_ref().map(|(full, half)| (*full, half)), color.width, color.height))
}

/// The mean of each 2 × 2 block (of the pixels inside the image, at an odd edge), sanitized as
/// the filter's inputs are (NaN and negative samples count as 0, infinities as the largest
/// float) so one bad sample does not spoil its block.
fn halved(image: &RgbImage) -> RgbImage {
    let (w, h) = (image.width, image.height);
    let mut out = RgbImage::new(w.div_ceil(2), h.div_ceil(2));
    let fix = |c: f32| if c.is_nan() { 0.0 } else { c.clamp(-f32::MAX, f32::MAX) };
    for y in 0..out.height {
        for x in 0..out.width {
            let mut sum = Vec3::ZERO;
            let mut n = 0.0;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (fx, fy) = (2 * x + dx, 2 * y + dy);
                if fx < w && fy < h {
                    let p = image.get(fx, fy);
                    sum += Vec3::new(fix(p.x), fix(p.y), fix(p.z)) / 4.0;
                    n += 0.25;
                }
            }
            out.set(x, y, sum / n);
        }
    }
    out
}

/// `half` brought to `w × h`: per channel, the bilinear interpolation of the half-size shading
/// (`half / half_albedo`) times the full-size albedo where both albedos are bright enough, else
/// of the half-size radiance itself. Finite and non-negative for finite input.
fn doubled(half: &RgbImage, albedo: Option<(&RgbImage, &RgbImage)>, w: u32, h: u32) -> RgbImage {
    let mut out = RgbImage::new(w, h);
    let (hw, hh) = (half.width as i64, half.height as i64);
    let at = |x: i64, y: i64| (x.clamp(0, hw - 1) as u32, y.clamp(0, hh - 1) as u32);
    for y in 0..h {
        // The full-size pixel's centre in half-size pixel coordinates.
        let fy = (y as f32 + 0.5) / 2.0 - 0.5;
        let (y0, ty) = (fy.floor() as i64, fy - fy.floor());
        for x in 0..w {
            let fx = (x as f32 + 0.5) / 2.0 - 0.5;
            let (x0, tx) = (fx.floor() as i64, fx - fx.floor());
            let taps = [
                (at(x0, y0), (1.0 - tx) * (1.0 - ty)),
                (at(x0 + 1, y0), tx * (1.0 - ty)),
                (at(x0, y0 + 1), (1.0 - tx) * ty),
                (at(x0 + 1, y0 + 1), tx * ty),
            ];
            let mut radiance = Vec3::ZERO;
            for &((hx, hy), wgt) in &taps {
                radiance += half.get(hx, hy) * wgt;
            }
            let mut pixel = radiance;
            if let Some((full_albedo, half_albedo)) = albedo {
                let own = full_albedo.get(x, y);
                for c in 0..3 {
                    if own[c] < DARKEST_ALBEDO {
                        continue;
                    }
                    // The shading of the taps whose albedo can be divided by, renormalised.
                    let (mut shading, mut weight) = (0.0, 0.0);
                    for &((hx, hy), wgt) in &taps {
                        let a = half_albedo.get(hx, hy)[c];
                        if a >= DARKEST_ALBEDO {
                            shading += half.get(hx, hy)[c] / a * wgt;
                            weight += wgt;
                        }
                    }
                    if weight > 0.0 {
                        pixel[c] = shading / weight * own[c].min(1.0);
                    }
                }
            }
            out.set(x, y, if pixel.is_finite() { pixel.max(Vec3::ZERO) } else { radiance });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: u32, h: u32, f: impl Fn(u32, u32) -> Vec3) -> RgbImage {
        let mut i = RgbImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                i.set(x, y, f(x, y));
            }
        }
        i
    }

    /// Halving averages each block, including a ragged last row and column, and a NaN counts
    /// as 0 rather than spoiling its block.
    #[test]
    fn halving_averages_blocks() {
        let i = image(5, 3, |x, y| Vec3::splat((x + 10 * y) as f32));
        let h = halved(&i);
        assert_eq!((h.width, h.height), (3, 2));
        assert_eq!(h.get(0, 0), Vec3::splat((0.0 + 1.0 + 10.0 + 11.0) / 4.0));
        assert_eq!(h.get(2, 0), Vec3::splat((4.0 + 14.0) / 2.0));
        assert_eq!(h.get(2, 1), Vec3::splat(24.0));
        let mut bad = i.clone();
        bad.set(0, 0, Vec3::NAN);
        assert_eq!(halved(&bad).get(0, 0), Vec3::splat((1.0 + 10.0 + 11.0) / 4.0));
    }

    /// A picture that is its albedo times smooth lighting comes back from its own half-size
    /// version with the albedo's full-resolution detail (a one-pixel checker): the error is
    /// that of interpolating the lighting alone, far below plain interpolation's.
    #[test]
    fn doubling_keeps_the_albedos_detail() {
        let (w, h) = (32, 24);
        let albedo =
            image(w, h, |x, y| if (x + y) % 2 == 0 { Vec3::new(0.9, 0.5, 0.1) } else { Vec3::splat(0.1) });
        let light = |x: u32, y: u32| 1.0 + x as f32 / w as f32 + 0.5 * y as f32 / h as f32;
        let color = image(w, h, |x, y| albedo.get(x, y) * light(x, y));
        let (half_color, half_albedo) = (halved(&color), halved(&albedo));
        let guided = doubled(&half_color, Some((&albedo, &half_albedo)), w, h);
        let plain = doubled(&half_color, None, w, h);
        let err = |i: &RgbImage| {
            i.pixels
                .iter()
                .zip(&color.pixels)
                .map(|(a, b)| ((*a - *b) / (*b + 0.01)).abs().max_element())
                .fold(0.0, f32::max)
        };
        assert!(err(&guided) < 0.05, "guided: largest relative error {}", err(&guided));
        assert!(err(&plain) > 0.5, "plain interpolation should lose the checker: {}", err(&plain));
    }

    /// Where the albedo is black (the sky, a black surface) the radiance is interpolated, and
    /// the result is finite and non-negative.
    #[test]
    fn a_black_albedo_falls_back_on_the_radiance() {
        let (w, h) = (8, 6);
        let albedo = image(w, h, |x, _| if x < 4 { Vec3::ZERO } else { Vec3::splat(0.5) });
        let color = image(w, h, |x, _| if x < 4 { Vec3::new(2.0, 3.0, 4.0) } else { Vec3::splat(0.25) });
        let out = doubled(&halved(&color), Some((&albedo, &halved(&albedo))), w, h);
        assert!(out.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0));
        assert_eq!(out.get(0, 3), Vec3::new(2.0, 3.0, 4.0));
        assert!((out.get(7, 3) - Vec3::splat(0.25)).abs().max_element() < 1e-6, "{}", out.get(7, 3));
    }
}
