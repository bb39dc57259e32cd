//! The seam ratio (docs/design/mcc.md §5.8): how abruptly a remapped ray field turns at each
//! background pixel, compared with how it turns around that pixel.
//!
//! For a pixel p with a right neighbour, s_x(p) is the angle between their directions; s_y(p)
//! likewise with the lower neighbour. The *pitch* is the median of those steps between two
//! pixels of the same camera (how far apart a view's adjacent rays are). A background pixel's
//! ratio in one direction is its step divided by the median of that direction's steps over its
//! 9 × 9 neighbourhood (clipped at the image border; camera pixels' steps included), the median
//! floored at a tenth of the pitch; its *seam ratio* is the larger of its two ratios. A field
//! that turns evenly, however fast, gives about 1 everywhere; a tear is a step many times larger
//! than the steps around it. Percentiles are nearest-rank over the background pixels.

use crate::error::{MccError, Result};
use crate::ray_file::StoredRay;
use crate::slerp::angle_between;
use image::{Rgb, RgbImage};
use rayon::prelude::*;
use std::fmt;

/// Half the side of the neighbourhood whose median a step is compared with (9 × 9).
const RADIUS: usize = 4;

/// The seam ratio's figures over a picture's background pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeamSummary {
    /// Background pixels measured.
    pub pixels: usize,
    /// Median angle (radians) between adjacent pixels of the same camera.
    pub pitch: f32,
    /// 99th percentile of the seam ratio.
    pub p99: f32,
    /// 99.9th percentile.
    pub p999: f32,
    /// Maximum.
    pub max: f32,
    /// Where the maximum is, (x, y).
    pub worst: (u32, u32),
    /// The larger of the two steps (radians) at the worst pixel.
    pub worst_step: f32,
}

impl fmt::Display for SeamSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (x, y) = self.worst;
        write!(
            f,
            "seam ratio over {} background pixels: p99 {:.2}, p99.9 {:.2}, max {:.1} at ({x}, {y}) \
             (a step of {:.4} rad; pitch {:.5} rad)",
            self.pixels, self.p99, self.p999, self.max, self.worst_step, self.pitch
        )
    }
}

/// The seam ratio of every background pixel, and its summary.
#[derive(Clone, Debug)]
pub struct SeamRatios {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Per pixel, row-major: the seam ratio of a background pixel, NaN at camera pixels.
    pub ratios: Vec<f32>,
    /// The figures.
    pub summary: SeamSummary,
}

impl SeamRatios {
    /// Measures the rays of a `width`-wide picture whose background pixels are those with
    /// `camera[p] == 0` (any other value names the pixel's camera). Refuses a picture without
    /// background pixels or without two adjacent pixels of one camera (no pitch).
    pub fn measure(rays: &[StoredRay], camera: &[u32], width: usize) -> Result<Self> {
        let n = rays.len();
        if width == 0 || !n.is_multiple_of(width) || camera.len() != n {
            return Err(MccError::input("seam ratio", format!("{n} rays do not fill {width}-pixel rows")));
        }
        let height = n / width;
        // Steps to the right and lower neighbours (NaN where there is none).
        let mut sx = vec![f32::NAN; n];
        let mut sy = vec![f32::NAN; n];
        sx.par_chunks_mut(width).zip(sy.par_chunks_mut(width)).enumerate().for_each(|(y, (rx, ry))| {
            for x in 0..width {
                let p = y * width + x;
                if x + 1 < width {
                    rx[x] = angle_between(rays[p].direction, rays[p + 1].direction);
                }
                if y + 1 < height {
                    ry[x] = angle_between(rays[p].direction, rays[p + width].direction);
                }
            }
        });
        let mut same: Vec<f32> = (0..n)
            .into_par_iter()
            .flat_map_iter(|p| {
                let (x, y, c) = (p % width, p / width, camera[p]);
                let right = (c != 0 && x + 1 < width && camera[p + 1] == c).then(|| sx[p]);
                let below = (c != 0 && y + 1 < height && camera[p + width] == c).then(|| sy[p]);
                right.into_iter().chain(below)
            })
            .collect();
        if same.is_empty() {
            return Err(MccError::input(
                "seam ratio",
                "no two adjacent pixels of one camera: no pitch to compare with",
            ));
        }
        let pitch = median(&mut same);
        let floor = pitch / 10.0;
        let ratios: Vec<f32> = (0..n)
            .into_par_iter()
            .map_init(Vec::new, |window, p| {
                if camera[p] != 0 {
                    return f32::NAN;
                }
                let (x, y) = (p % width, p / width);
                let mut ratio = 0.0f32;
                for steps in [&sx, &sy] {
                    if steps[p].is_nan() {
                        continue;
                    }
                    window.clear();
                    for yy in y.saturating_sub(RADIUS)..=(y + RADIUS).min(height - 1) {
                        let row = &steps[yy * width..(yy + 1) * width];
                        let span = &row[x.saturating_sub(RADIUS)..=(x + RADIUS).min(width - 1)];
                        window.extend(span.iter().filter(|s| !s.is_nan()));
                    }
                    ratio = ratio.max(steps[p] / median(window).max(floor));
                }
                ratio
            })
            .collect();
        let mut background: Vec<(f32, usize)> =
            ratios.iter().enumerate().filter(|(_, r)| !r.is_nan()).map(|(p, &r)| (r, p)).collect();
        if background.is_empty() {
            return Err(MccError::input("seam ratio", "the picture has no background pixels to measure"));
        }
        background.par_sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let rank = |q: f64| {
            background[((q * background.len() as f64).ceil() as usize).clamp(1, background.len()) - 1].0
        };
        // The worst pixel: the largest ratio, the first in raster order among equals.
        let max = background.last().expect("non-empty").0;
        let worst = background.iter().filter(|(r, _)| *r == max).map(|&(_, p)| p).min().expect("non-empty");
        let step = |s: f32| if s.is_nan() { 0.0 } else { s };
        let summary = SeamSummary {
            pixels: background.len(),
            pitch,
            p99: rank(0.99),
            p999: rank(0.999),
            max,
            worst: ((worst % width) as u32, (worst / width) as u32),
            worst_step: step(sx[worst]).max(step(sy[worst])),
        };
        Ok(Self { width: width as u32, height: height as u32, ratios, summary })
    }

    /// The debug map: camera pixels grey, background from black (ratio ≤ 1) through blue (3),
    /// yellow (6) and red (20) to white (100 and more), on a log scale.
    pub fn image(&self) -> RgbImage {
        RgbImage::from_fn(self.width, self.height, |x, y| {
            let r = self.ratios[(y * self.width + x) as usize];
            Rgb(if r.is_nan() { [72, 72, 72] } else { colour(r) })
        })
    }
}

/// The median of `values` (the upper one of an even count); reorders them.
fn median(values: &mut [f32]) -> f32 {
    let mid = values.len() / 2;
    *values.select_nth_unstable_by(mid, f32::total_cmp).1
}

/// The debug map's colour of a ratio.
fn colour(ratio: f32) -> [u8; 3] {
    const STOPS: [(f32, [f32; 3]); 5] = [
        (1.0, [0.0, 0.0, 0.0]),
        (3.0, [30.0, 90.0, 255.0]),
        (6.0, [255.0, 210.0, 0.0]),
        (20.0, [255.0, 0.0, 0.0]),
        (100.0, [255.0, 255.0, 255.0]),
    ];
    let l = ratio.max(1.0).ln();
    for pair in STOPS.windows(2) {
        let ((a, ca), (b, cb)) = (pair[0], pair[1]);
        if l <= b.ln() {
            let t = (l - a.ln()) / (b.ln() - a.ln());
            return std::array::from_fn(|k| (ca[k] + t * (cb[k] - ca[k])).round() as u8);
        }
    }
    [255, 255, 255]
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// A pinhole's rays through pixel centres of a `w × h` picture (vertical field of view `fov`).
    fn pinhole(w: usize, h: usize, fov: f32) -> Vec<StoredRay> {
        let t = (fov / 2.0).tan();
        (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 + 0.5, (p / w) as f32 + 0.5);
                let d = Vec3::new(
                    (2.0 * x / w as f32 - 1.0) * t * w as f32 / h as f32,
                    (1.0 - 2.0 * y / h as f32) * t,
                    -1.0,
                );
                StoredRay::new(Vec3::ZERO, d.normalize())
            })
            .collect()
    }

    #[test]
    fn a_pinhole_field_has_no_seams() {
        // A border of camera pixels (for the pitch), the rest background: all one smooth view.
        let (w, h) = (160, 90);
        let rays = pinhole(w, h, 1.0);
        let camera: Vec<u32> = (0..w * h)
            .map(|p| (p % w < 10 || p % w >= w - 10 || p / w < 10 || p / w >= h - 10) as u32)
            .collect();
        let s = SeamRatios::measure(&rays, &camera, w).unwrap().summary;
        assert_eq!(s.pixels, (w - 20) * (h - 20));
        // Adjacent pinhole rays differ by 2·tan(fov/2)/h at the centre, by cos² of the angle off
        // the axis less elsewhere; the camera pixels (the border) lie between centre and corner.
        let (centre, t) = (2.0 * 0.5f32.tan() / h as f32, 0.5f32.tan());
        let corner = centre / (1.0 + t * t * (1.0 + (w * w) as f32 / (h * h) as f32));
        assert!(s.pitch < centre && s.pitch > corner, "{s}: between {corner} and {centre}");
        assert!(s.max < 1.1 && s.p99 < 1.05, "{s}");
    }

    #[test]
    fn a_field_turning_evenly_through_half_a_turn_has_ratio_one() {
        // Left to right the direction turns by π in equal steps (nearly opposite at the ends);
        // down the columns it tilts evenly too. Every step equals its neighbours': ratio 1.
        let (w, h) = (200, 60);
        let rays: Vec<StoredRay> = (0..w * h)
            .map(|p| {
                let (a, b) = (std::f32::consts::PI * (p % w) as f32 / (w - 1) as f32, 0.004 * (p / w) as f32);
                StoredRay::new(Vec3::ZERO, Vec3::new(a.cos() * b.cos(), b.sin(), a.sin() * b.cos()))
            })
            .collect();
        let camera: Vec<u32> = (0..w * h)
            .map(|p| {
                if p % w == 0 {
                    1
                } else if p % w == w - 1 {
                    2
                } else {
                    0
                }
            })
            .collect();
        let s = SeamRatios::measure(&rays, &camera, w).unwrap();
        for (p, r) in s.ratios.iter().enumerate() {
            if camera[p] == 0 {
                assert!((r - 1.0).abs() < 2e-3, "pixel ({}, {}): {r}", p % w, p / w);
            }
        }
        assert!((s.summary.max - 1.0).abs() < 2e-3, "{}", s.summary);
    }

    #[test]
    fn a_tear_stands_out_by_its_size() {
        // A pinhole field with a tear: below row 40 every ray is tilted up by 0.25 rad.
        let (w, h) = (120, 80);
        let mut rays = pinhole(w, h, 1.0);
        for r in rays.iter_mut().skip(40 * w) {
            r.direction = glam::Quat::from_rotation_x(20.0 / h as f32).mul_vec3(r.direction);
        }
        let camera: Vec<u32> = (0..w * h).map(|p| (p % w < 5) as u32).collect();
        let s = SeamRatios::measure(&rays, &camera, w).unwrap();
        // The pixels of row 39 step across the tear; the steps around them are the pinhole's.
        let d = |x: usize, y: usize| rays[y * w + x].direction;
        let want = angle_between(d(60, 39), d(60, 40)) / angle_between(d(60, 38), d(60, 39));
        let on_tear = s.ratios[39 * w + 60];
        assert!(want > 15.0 && (on_tear - want).abs() < 0.02 * want, "{on_tear} vs {want}");
        // Only the row on the tear stands out (and the camera's steps do not count).
        for (p, &r) in s.ratios.iter().enumerate() {
            if camera[p] == 0 {
                assert_eq!(r > 5.0, p / w == 39, "pixel ({}, {}): {r}", p % w, p / w);
                assert!(!(1.1..=5.0).contains(&r), "pixel ({}, {}): {r}", p % w, p / w);
            }
        }
        assert_eq!(s.summary.worst.1, 39);
        assert!(s.summary.max > 15.0, "{}", s.summary);
        // The map shows it: black where smooth, white-hot on the tear, grey on the camera.
        let map = s.image();
        assert_eq!(map.get_pixel(60, 20).0, [0, 0, 0]);
        assert_eq!(map.get_pixel(2, 20).0, [72, 72, 72]);
        assert!(map.get_pixel(60, 39).0[0] == 255);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let rays = pinhole(4, 3, 1.0);
        assert!(SeamRatios::measure(&rays, &[0; 12], 4).unwrap_err().to_string().contains("pitch"));
        assert!(SeamRatios::measure(&rays, &[1; 12], 4).unwrap_err().to_string().contains("no background"));
        assert!(SeamRatios::measure(&rays, &[0; 12], 5).is_err());
    }
}
