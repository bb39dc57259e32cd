//! Step 3 of the remapper (docs/design/mcc.md §5.3): initial weights. A camera pixel of camera c gets
//! α_c = 1 and every other α = 0. A background pixel P with participants S (the cameras with an
//! edge pixel in P's region; all cameras if none has, with a warning naming the region) gets
//!
//! * |S| = 1: α = 1 for that camera;
//! * otherwise, with d_i = |P − e_i(P)| and g_i = d_i / Σ_j d_j:
//!   v_i = (1 − g_i)·Π_{j≠i} g_j and α_i = v_i / Σ_j v_j.
//!
//! The product underflows long before 63 cameras (g ~ 1/63 each: 63^-62 ≈ 1e-112 in f64 is fine,
//! but the same collage in f32, or a few hundred cameras in f64, is not). Dividing every v_i by the
//! common factor Π_j g_j > 0 leaves α unchanged and gives v_i ∝ (1 − g_i)/g_i = (D − d_i)/d_i with
//! D = Σ_j d_j: no product, no underflow. A zero distance (never the case for a background pixel,
//! whose nearest edge pixels are other pixels, but the function is public) is handled exactly:
//! one camera at distance 0 takes α = 1, the limit of the formula; several share equally.

use super::grid::Layout;
use super::nearest::NearestEdges;
use super::warning::RemapWarning;
use crate::lanes::avx2_twins;
use crate::regions::Regions;
use rayon::prelude::*;

/// Step 3's weights from the distances `d` (≥ 0) of a pixel's participants, into `alpha`
/// (same length and order). They are ≥ 0, sum to 1, and α_k → 1 as d_k → 0.
pub fn interpolation_weights(d: &[f64], alpha: &mut [f64]) {
    match d.len() {
        0 => return,
        1 => {
            alpha[0] = 1.0;
            return;
        }
        _ => {}
    }
    let zeros = d.iter().filter(|&&x| x == 0.0).count();
    if zeros > 0 {
        let share = 1.0 / zeros as f64;
        for (a, &x) in alpha.iter_mut().zip(d) {
            *a = if x == 0.0 { share } else { 0.0 };
        }
        return;
    }
    let total: f64 = d.iter().sum();
    let mut sum = 0.0;
    for (a, &x) in alpha.iter_mut().zip(d) {
        // (D − d_i)/d_i, with D − d_i summed from the others' distances is the same to rounding.
        *a = (total - x).max(0.0) / x;
        sum += *a;
    }
    if sum > 0.0 && sum.is_finite() {
        alpha.iter_mut().for_each(|a| *a /= sum);
    } else {
        alpha.iter_mut().for_each(|a| *a = 1.0 / d.len() as f64);
    }
}

/// The cameras participating in each region (`participates[k][r]`: camera k has an edge pixel in
/// region r; all cameras where none has), and a warning for every region with background pixels
/// that no camera touches.
pub(crate) fn participants(
    participates: &[Vec<bool>],
    regions: &Regions,
    background: &[usize],
    cameras: usize,
) -> (Vec<Vec<usize>>, Vec<RemapWarning>) {
    let mut warnings = Vec::new();
    let lists = (0..regions.count())
        .map(|r| {
            let s: Vec<usize> = (0..cameras).filter(|&k| participates[k][r]).collect();
            if !s.is_empty() {
                return s;
            }
            if background[r] > 0 {
                warnings.push(RemapWarning::RegionWithoutCameras {
                    region: r as u32,
                    info: regions.info[r].clone(),
                    background_pixels: background[r],
                });
            }
            (0..cameras).collect()
        })
        .collect();
    (lists, warnings)
}

/// Background pixels per step of the weights' lane loop: two AVX2 vectors of f64.
const LANES: usize = 8;

/// What every row of [`initial_weights`] reads.
#[derive(Clone, Copy)]
struct Inputs<'a> {
    cam: &'a [u32],
    region: &'a [u32],
    nearest: &'a NearestEdges,
    participants: &'a [Vec<usize>],
    width: usize,
}

/// Reusable per-task buffers: a row's background columns, per-participant distance and weight
/// lanes, and one pixel's distances and weights for the scalar path.
#[derive(Default)]
struct RowScratch {
    columns: Vec<u32>,
    d: Vec<[f64; LANES]>,
    alpha: Vec<[f64; LANES]>,
    scalar_d: Vec<f64>,
    scalar_alpha: Vec<f64>,
}

/// The distance from pixel (x, y) to pixel index `e` of an image `w` pixels wide.
#[inline(always)]
fn distance(e: u32, x: u32, y: u32, w: u32) -> f64 {
    // Row and column in f64, exactly (e < 2³² and w < 2³²: the rounded quotient never reaches the
    // next integer), so the lane loop divides in vectors rather than one integer at a time.
    let (e, w) = (e as f64, w as f64);
    let ey = (e / w).floor();
    let (dx, dy) = (e - ey * w - x as f64, ey - y as f64);
    (dx * dx + dy * dy).sqrt()
}

/// [`distance`] of a chunk's lanes, `e` and `w` already in f64: whole-array steps, which
/// vectorise.
#[inline(always)]
fn distances(e: &[f64; LANES], xs: &[f64; LANES], y: f64, w: f64) -> [f64; LANES] {
    let ey: [f64; LANES] = std::array::from_fn(|i| (e[i] / w).floor());
    let dx: [f64; LANES] = std::array::from_fn(|i| e[i] - ey[i] * w - xs[i]);
    let dy: [f64; LANES] = std::array::from_fn(|i| ey[i] - y);
    std::array::from_fn(|i| (dx[i] * dx[i] + dy[i] * dy[i]).sqrt())
}

/// One background pixel, through [`interpolation_weights`].
#[inline(always)]
fn pixel_weights(x: usize, y: usize, row: &mut [&mut [f32]], scratch: &mut RowScratch, inputs: Inputs) {
    let p = y * inputs.width + x;
    let s = &inputs.participants[inputs.region[p] as usize];
    let RowScratch { scalar_d: d, scalar_alpha: alpha, .. } = scratch;
    d.clear();
    d.extend(
        s.iter().map(|&k| distance(inputs.nearest.planes[k][p], x as u32, y as u32, inputs.width as u32)),
    );
    alpha.resize(s.len(), 0.0);
    interpolation_weights(d, alpha);
    for (&k, &a) in s.iter().zip(alpha.iter()) {
        row[k][x] = a as f32;
    }
}

/// One row of [`initial_weights`]: camera pixels 1 for their camera; background pixels in chunks
/// of [`LANES`] sharing a region, each lane [`interpolation_weights`]' operations in its order
/// (the same bits); a chunk across regions or with a zero distance goes pixel by pixel.
#[inline(always)]
fn weights_row_body(y: usize, row: &mut [&mut [f32]], scratch: &mut RowScratch, inputs: Inputs) {
    let Inputs { cam, region, nearest, participants, width } = inputs;
    let base = y * width;
    scratch.columns.clear();
    for x in 0..width {
        match cam[base + x] {
            0 => scratch.columns.push(x as u32),
            c => row[c as usize - 1][x] = 1.0,
        }
    }
    let columns = std::mem::take(&mut scratch.columns);
    for chunk in columns.chunks(LANES) {
        let r = region[base + chunk[0] as usize];
        let s = &participants[r as usize];
        if chunk.len() < LANES || s.len() < 2 || chunk.iter().any(|&x| region[base + x as usize] != r) {
            chunk.iter().for_each(|&x| pixel_weights(x as usize, y, row, scratch, inputs));
            continue;
        }
        let xs: [u32; LANES] = chunk.try_into().expect("a whole chunk");
        let xf = xs.map(|x| x as f64);
        let RowScratch { d, alpha, .. } = scratch;
        d.resize(s.len(), [0.0; LANES]);
        alpha.resize(s.len(), [0.0; LANES]);
        for (dk, &k) in d.iter_mut().zip(s) {
            let plane = &nearest.planes[k];
            // Gather first, then one loop over whole arrays: it vectorises.
            let e: [f64; LANES] = std::array::from_fn(|i| plane[base + xs[i] as usize] as f64);
            *dk = distances(&e, &xf, y as f64, width as f64);
        }
        if d.iter().any(|dk| dk.contains(&0.0)) {
            chunk.iter().for_each(|&x| pixel_weights(x as usize, y, row, scratch, inputs));
            continue;
        }
        // D = Σ d in the scalar sum's order; (D − d_k) / d_k; their sum; then the division.
        let mut total = d[0];
        for dk in &d[1..] {
            for (t, &di) in total.iter_mut().zip(dk) {
                *t += di;
            }
        }
        let mut sum = [0.0f64; LANES];
        for (ak, dk) in alpha.iter_mut().zip(d.iter()) {
            for i in 0..LANES {
                ak[i] = (total[i] - dk[i]).max(0.0) / dk[i];
                sum[i] += ak[i];
            }
        }
        let equal = 1.0 / s.len() as f64;
        for (ak, &k) in alpha.iter().zip(s) {
            let out = &mut row[k];
            for i in 0..LANES {
                let ok = sum[i] > 0.0 && sum[i].is_finite();
                out[chunk[i] as usize] = (if ok { ak[i] / sum[i] } else { equal }) as f32;
            }
        }
    }
    scratch.columns = columns;
}

avx2_twins! {
    /// [`weights_row_body`] at the CPU's level.
    fn weights_row | weights_row_baseline | weights_row_avx2(
        y: usize,
        row: &mut [&mut [f32]],
        scratch: &mut RowScratch,
        inputs: Inputs,
    ) => weights_row_body
}

/// The initial weight planes (one per camera of `layout`, f32) from the `nearest` edge pixels
/// and each region's `participants` (`region`: the region of every pixel): rows in parallel,
/// every plane's row written by the task that owns the row.
pub(crate) fn initial_weights(
    layout: &Layout,
    region: &[u32],
    nearest: &NearestEdges,
    participants: &[Vec<usize>],
) -> Vec<Vec<f32>> {
    let Layout { grid, cam, cameras, .. } = *layout;
    let mut planes: Vec<Vec<f32>> = (0..cameras).map(|_| vec![0f32; cam.len()]).collect();
    let rows = grid.rows_mut(&mut planes);
    let inputs = Inputs { cam, region, nearest, participants, width: grid.width };
    rows.into_par_iter().enumerate().for_each_init(RowScratch::default, |scratch, (y, mut row)| {
        weights_row(y, &mut row, scratch, inputs);
    });
    planes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::weights_by_product;

    /// The lanes against [`interpolation_weights`] pixel by pixel, bit for bit: random regions
    /// (chunks across regions), one to six participants, and nearest pixels at distance 0.
    #[test]
    fn lanes_give_the_scalar_weights_bits() {
        use crate::remap::nearest::NearestEdges;
        let mut rng = crate::test_util::Rng::new(31);
        for _ in 0..60 {
            let (w, h, cameras) =
                (1 + rng.below(45) as usize, 1 + rng.below(7) as usize, 1 + rng.below(6) as usize);
            let n = w * h;
            let cam: Vec<u32> =
                (0..n).map(|_| if rng.below(4) == 0 { 1 + rng.below(cameras as u32) } else { 0 }).collect();
            let regions = 1 + rng.below(3) as usize;
            let region: Vec<u32> = (0..n)
                .map(|p| ((p % w) / 11 + rng.below(2) as usize * (p / w)) as u32 % regions as u32)
                .collect();
            let participants: Vec<Vec<usize>> = (0..regions)
                .map(|_| {
                    let s: Vec<usize> = (0..cameras).filter(|_| rng.below(3) != 0).collect();
                    if s.is_empty() { vec![0] } else { s }
                })
                .collect();
            // Some nearest pixels are the pixel itself: distance 0.
            let planes = (0..cameras)
                .map(|_| {
                    (0..n).map(|p| if rng.below(50) == 0 { p as u32 } else { rng.below(n as u32) }).collect()
                })
                .collect();
            let nearest = NearestEdges { planes, participates: Vec::new() };
            let grid = crate::remap::grid::Grid::new(w, h);
            let edges = crate::remap::edges::edge_mask(&cam, grid);
            let layout = Layout { grid, cam: &cam, edges: &edges, cameras };
            let got = initial_weights(&layout, &region, &nearest, &participants);
            for p in 0..n {
                let mut want = vec![0f32; cameras];
                if cam[p] != 0 {
                    want[cam[p] as usize - 1] = 1.0;
                } else {
                    let s = &participants[region[p] as usize];
                    let d: Vec<f64> = s
                        .iter()
                        .map(|&k| distance(nearest.planes[k][p], (p % w) as u32, (p / w) as u32, w as u32))
                        .collect();
                    let mut alpha = vec![0.0; s.len()];
                    interpolation_weights(&d, &mut alpha);
                    s.iter().zip(&alpha).for_each(|(&k, &a)| want[k] = a as f32);
                }
                for k in 0..cameras {
                    assert_eq!(got[k][p].to_bits(), want[k].to_bits(), "{w}x{h}, camera {k}, pixel {p}");
                }
            }
        }
    }

    #[test]
    fn distance_in_floats_equals_integer_division() {
        let mut rng = crate::test_util::Rng::new(32);
        for i in 0..100_000u32 {
            let w = 1 + rng.below(if i % 2 == 0 { 8000 } else { u32::MAX });
            let e = match i % 3 {
                0 => rng.below(u32::MAX),
                1 => (rng.below(u32::MAX / w) * w).wrapping_sub(1),
                _ => u32::MAX - rng.below(w),
            };
            let (x, y) = (rng.below(9000), rng.below(9000));
            let (dx, dy) = ((e % w) as f64 - x as f64, (e / w) as f64 - y as f64);
            assert_eq!(distance(e, x, y, w).to_bits(), (dx * dx + dy * dy).sqrt().to_bits(), "e {e}, w {w}");
        }
    }

    #[test]
    fn equals_the_literal_formula() {
        let mut rng = crate::test_util::Rng::new(8);
        for _ in 0..1000 {
            let n = 2 + rng.below(7) as usize;
            let d: Vec<f64> = (0..n).map(|_| 1.0 + rng.unit() as f64 * 100.0).collect();
            let mut a = vec![0.0; n];
            interpolation_weights(&d, &mut a);
            for (x, y) in a.iter().zip(weights_by_product(&d)) {
                assert!((x - y).abs() < 1e-12, "{a:?}");
            }
        }
    }

    #[test]
    fn interpolates_sums_to_one_and_never_nan() {
        // α_k → 1 as d_k → 0.
        let mut a = [0.0; 3];
        let mut last = 0.0;
        for dk in [10.0, 1.0, 0.1, 1e-3, 1e-6, 1e-9] {
            interpolation_weights(&[dk, 5.0, 7.0], &mut a);
            assert!(a[0] > last);
            last = a[0];
        }
        assert!(last > 1.0 - 1e-8);
        interpolation_weights(&[0.0, 5.0, 7.0], &mut a);
        assert_eq!(a, [1.0, 0.0, 0.0]);
        interpolation_weights(&[0.0, 0.0, 7.0], &mut a);
        assert_eq!(a, [0.5, 0.5, 0.0]);
        let mut one = [0.0];
        interpolation_weights(&[3.0], &mut one);
        assert_eq!(one, [1.0]);
        // 63 cameras (the literal product underflows to 0/0 for many more): finite, sums to 1.
        for n in [63usize, 511, 5000] {
            let d: Vec<f64> = (0..n).map(|i| 1.0 + (i * 7919 % 1000) as f64).collect();
            let mut a = vec![0.0; n];
            interpolation_weights(&d, &mut a);
            assert!(a.iter().all(|x| x.is_finite() && *x >= 0.0));
            assert!((a.iter().sum::<f64>() - 1.0).abs() < 1e-9);
            // Nearer cameras weigh more.
            let nearest = (0..n).min_by(|&i, &j| d[i].total_cmp(&d[j])).unwrap();
            assert!(a.iter().all(|&x| x <= a[nearest]));
        }
        assert!(
            weights_by_product(&(0..5000).map(|i| 1.0 + i as f64).collect::<Vec<_>>())
                .iter()
                .any(|x| x.is_nan())
        );
    }
}
