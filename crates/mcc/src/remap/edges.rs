//! Step 1 of the remapper (docs/design/mcc.md §5.1): a pixel p with camera c ≠ 0 is an *edge pixel of
//! c* if it lies on the outermost border of the image or if any of its 8 neighbours has another
//! camera (a background neighbour included). Background pixels are never edges.

use super::grid::Grid;
use rayon::prelude::*;

/// The edge mask of a dense camera plane (`cam[p]` = 0 for background, k + 1 for camera index k):
/// `true` at edge pixels. Rows are independent, so they run in parallel.
pub(crate) fn edge_mask(cam: &[u32], grid: Grid) -> Vec<bool> {
    let Grid { width, height } = grid;
    let mut edges = vec![false; cam.len()];
    edges.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let here = &cam[y * width..(y + 1) * width];
        // Rows above and below; on the border the pixel is an edge anyway, so any row will do.
        let above = if y > 0 { &cam[(y - 1) * width..y * width] } else { here };
        let below = if y + 1 < height { &cam[(y + 1) * width..(y + 2) * width] } else { here };
        let border_row = y == 0 || y + 1 == height;
        for (x, e) in row.iter_mut().enumerate() {
            let c = here[x];
            if c == 0 {
                continue;
            }
            if border_row || x == 0 || x + 1 == width {
                *e = true;
                continue;
            }
            let (l, r) = (x - 1, x + 1);
            *e = above[l] != c
                || above[x] != c
                || above[r] != c
                || here[l] != c
                || here[r] != c
                || below[l] != c
                || below[x] != c
                || below[r] != c;
        }
    });
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition, pixel by pixel.
    fn brute(cam: &[u32], w: usize, h: usize) -> Vec<bool> {
        (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as i64, (p / w) as i64);
                let c = cam[p];
                if c == 0 {
                    return false;
                }
                if x == 0 || y == 0 || x + 1 == w as i64 || y + 1 == h as i64 {
                    return true;
                }
                (-1..=1).any(|dy| (-1..=1).any(|dx| cam[((y + dy) * w as i64 + x + dx) as usize] != c))
            })
            .collect()
    }

    #[test]
    fn matches_the_definition() {
        let mut rng = crate::test_util::Rng::new(1);
        for _ in 0..300 {
            let (w, h) = (1 + rng.below(12) as usize, 1 + rng.below(9) as usize);
            let cams = 1 + rng.below(3);
            // Blocky content so that interiors exist.
            let cam: Vec<u32> =
                (0..w * h).map(|p| ((p % w / 3 + p / w / 3) as u32 * 7 + cams) % (cams + 1)).collect();
            assert_eq!(edge_mask(&cam, Grid::new(w, h)), brute(&cam, w, h), "{w}x{h}");
        }
    }

    #[test]
    fn the_column_figure_5_cases() {
        // 5 × 4: camera 1 fills the left 3 columns, camera 2 column 3, background column 4.
        let cam: Vec<u32> = (0..20).map(|p| [1, 1, 1, 2, 0][p % 5]).collect();
        let e = edge_mask(&cam, Grid::new(5, 4));
        assert!(e[0], "camera pixel on the border");
        assert!(!e[5 + 1], "interior camera pixel");
        assert!(e[5 + 2], "beside another camera");
        assert!(e[5 + 3], "beside background");
        assert!(!e[5 + 4], "background is never an edge");
    }
}
