//! The MCC demo's hand-cut collage, drawn procedurally (docs/design.md §4.5, §8): a label image
//! saying which camera each pixel of the 480 × 270 collage comes from, and a region image.
//!
//! Labels: pure red (255, 0, 0) = camera 1 (`left`, showing figure B's face), pure green
//! (0, 255, 0) = camera 2 (`right`, showing figure A's face), black = background, to be filled
//! by the remapper. Regions: white (255, 255, 255) above the table's edge, blue (0, 0, 255)
//! below it.

use super::textures::encode_png;
use std::f32::consts::TAU;

pub const WIDTH: u32 = 480;
pub const HEIGHT: u32 = 270;

pub const CAMERA_1: [u8; 3] = [255, 0, 0];
pub const CAMERA_2: [u8; 3] = [0, 255, 0];
pub const BACKGROUND: [u8; 3] = [0, 0, 0];
pub const REGION_UPPER: [u8; 3] = [255, 255, 255];
pub const REGION_LOWER: [u8; 3] = [0, 0, 255];

/// The right edge of camera 1's piece at row y (pixel centre): a wavy cut.
fn cut_1(y: f32) -> f32 {
    let t = y / HEIGHT as f32;
    150.0 + 16.0 * (TAU * (1.1 * t + 0.15)).sin() + 7.0 * (TAU * 3.3 * t).sin()
}

/// The left edge of camera 2's piece at row y.
fn cut_2(y: f32) -> f32 {
    let t = y / HEIGHT as f32;
    330.0 + 14.0 * (TAU * (0.9 * t + 0.6)).sin() + 8.0 * (TAU * 2.7 * t + 1.0).sin()
}

/// The boundary between the regions at column x: the table's edge, roughly.
fn horizon(x: f32) -> f32 {
    let t = x / WIDTH as f32;
    192.0 + 10.0 * (TAU * (1.4 * t + 0.1)).sin()
}

/// The label colour of pixel (i, j).
pub fn label(i: u32, j: u32) -> [u8; 3] {
    let (x, y) = (i as f32 + 0.5, j as f32 + 0.5);
    if x < cut_1(y) {
        CAMERA_1
    } else if x > cut_2(y) {
        CAMERA_2
    } else {
        BACKGROUND
    }
}

/// The region colour of pixel (i, j).
pub fn region(i: u32, j: u32) -> [u8; 3] {
    let (x, y) = (i as f32 + 0.5, j as f32 + 0.5);
    if y < horizon(x) { REGION_UPPER } else { REGION_LOWER }
}

fn image(f: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    (0..HEIGHT).flat_map(|j| (0..WIDTH).map(move |i| (i, j))).flat_map(|(i, j)| f(i, j)).collect()
}

/// The PNG files: (label image, region image).
pub fn collage_images() -> (Vec<u8>, Vec<u8>) {
    let labels = encode_png(WIDTH, HEIGHT, &image(label)).expect("encoding to memory cannot fail");
    let regions = encode_png(WIDTH, HEIGHT, &image(region)).expect("encoding to memory cannot fail");
    (labels, regions)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_exact_colours_with_a_background_band() {
        let mut counts = [0usize; 3];
        for j in 0..HEIGHT {
            // Every row: camera 1, then background, then camera 2.
            let row: Vec<[u8; 3]> = (0..WIDTH).map(|i| label(i, j)).collect();
            assert_eq!(row[0], CAMERA_1);
            assert_eq!(row[WIDTH as usize - 1], CAMERA_2);
            assert!(row.contains(&BACKGROUND));
            for c in row {
                counts[[CAMERA_1, BACKGROUND, CAMERA_2].iter().position(|&k| k == c).unwrap()] += 1;
            }
        }
        assert!(counts.iter().all(|&n| n > 20_000), "{counts:?}");
        for i in 0..WIDTH {
            assert_eq!(region(i, 0), REGION_UPPER);
            assert_eq!(region(i, HEIGHT - 1), REGION_LOWER);
        }
    }
}
