//! Step 4 of the remapper (docs/design/mcc.md §5.4): smoothing. Each camera's weight plane separately
//! and double-buffered (every output reads only the previous plane), rewriting background pixels
//! only (camera pixels keep exactly their 0/1 weights):
//!
//! a. box blur of radius 4 (9 × 9 window), dividing at the border by the number of window pixels
//!    inside the image;
//! b. the ease curve on every background weight;
//! c. box blur of radius 3 (7 × 7), same rules;
//! d. renormalise each background pixel's weights to sum to 1.
//!
//! The ease curve is Perlin's gain, the column's "ease curve with control value 0.75":
//! ease(t) = (2t)^k / 2 for t < ½ and 1 − (2 − 2t)^k / 2 otherwise, k = log₂(1 / (1 − g)).
//! With g = 0.75, k = 2: ease(t) = 2t² below ½, 1 − 2(1 − t)² above (the form of docs/design/mcc.md
//! §5.4, computed exactly); g = 0.5 is the identity.
//!
//! The blur is separable and runs in constant time per pixel whatever the radius: prefix sums
//! along each row, then a running sum down the columns kept as one running total per column (rows
//! are visited in order, so memory is read row by row). Sums are f64, so adding and removing
//! values leaves no drift worth the name; the clipped window is the product of its clipped row and
//! column extents, which is the count to divide by.

use super::grid::Grid;
use crate::lanes::avx2_twins;
use rayon::prelude::*;

/// The ease curve with control `g` ∈ (0, 1) (see the module notes).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ease {
    exponent: f32,
}

impl Ease {
    pub(crate) fn new(control: f32) -> Self {
        Self { exponent: (1.0 / (1.0 - control)).log2() }
    }

    #[inline]
    pub(crate) fn apply(self, t: f32) -> f32 {
        let pow = |x: f32| if self.exponent == 2.0 { x * x } else { x.powf(self.exponent) };
        // Both halves, then a select: branch-free, so the plane loop vectorises.
        let (low, high) = (0.5 * pow(2.0 * t), 1.0 - 0.5 * pow(2.0 - 2.0 * t));
        if t < 0.5 { low } else { high }
    }

    /// Applies the curve to a whole plane. Camera pixels hold exactly 0 or 1 after the first
    /// blur, which the curve maps to themselves, so no background test is needed.
    fn apply_plane(self, plane: &mut [f32]) {
        if self.exponent == 2.0 {
            for v in plane {
                let t = *v;
                let (low, high) = (2.0 * t * t, 1.0 - 2.0 * (1.0 - t) * (1.0 - t));
                *v = if t < 0.5 { low } else { high };
            }
        } else {
            plane.iter_mut().for_each(|v| *v = self.apply(*v));
        }
    }
}

/// Reusable buffers for one plane's smoothing.
#[derive(Default)]
pub(crate) struct Scratch {
    /// Row sums (the horizontal pass), a full plane.
    rows: Vec<f32>,
    /// The second buffer of the double-buffered plane.
    other: Vec<f32>,
    /// Running column totals.
    columns: Vec<f64>,
    /// Reciprocal window widths per column.
    inverse_x: Vec<f64>,
    /// Prefix sums of one row.
    prefix: Vec<f64>,
}

/// Rows whose prefix sums run side by side in the horizontal pass: four independent chains of
/// f64 additions instead of one keep the adder busy (each row's sum keeps its own order).
const ROWS_AT_ONCE: usize = 4;

/// The settings of step 4: the two blurs' radii and the ease between them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Smoothing {
    /// Radii of the first and the second box blur (0 skips one).
    pub radii: (usize, usize),
    /// The ease curve.
    pub ease: Ease,
}

/// One blur: planes of `grid`, from `src` into `dst` with window radius `radius`, writing only
/// where `background` is true (elsewhere `dst` gets `src`'s value).
pub(crate) struct Blur<'a> {
    pub src: &'a [f32],
    pub dst: &'a mut [f32],
    pub background: &'a [bool],
    pub grid: Grid,
    pub radius: usize,
}

/// Box blur of `blur.src` into `blur.dst`, dividing by the in-image window count.
pub(crate) fn box_blur(blur: Blur, scratch: &mut Scratch) {
    if blur.radius == 0 {
        blur.dst.copy_from_slice(blur.src);
        return;
    }
    box_blur_at_level(blur, scratch);
}

avx2_twins! {
    /// [`box_blur_body`] at the CPU's level.
    fn box_blur_at_level | box_blur_baseline | box_blur_avx2(blur: Blur, scratch: &mut Scratch) => box_blur_body
}

/// [`box_blur`] for a radius above 0.
#[inline(always)]
fn box_blur_body(blur: Blur, scratch: &mut Scratch) {
    let Blur { src, dst, background, grid: Grid { width, height }, radius } = blur;
    let Scratch { rows, columns, inverse_x, prefix, .. } = scratch;
    rows.resize(src.len(), 0.0);
    // Horizontal: sum over [x − r, x + r] ∩ [0, w) as a difference of prefix sums (one serial
    // add per pixel, the differences independent of each other); prefix[j·(w + 1)] is 0.
    let stride = width + 1;
    prefix.resize(ROWS_AT_ONCE * stride, 0.0);
    prefix.iter_mut().step_by(stride).for_each(|p| *p = 0.0);
    for (s, h) in src.chunks(ROWS_AT_ONCE * width).zip(rows.chunks_mut(ROWS_AT_ONCE * width)) {
        let n = s.len() / width;
        if n == ROWS_AT_ONCE {
            let mut sum = [0.0f64; ROWS_AT_ONCE];
            for x in 0..width {
                for j in 0..ROWS_AT_ONCE {
                    sum[j] += s[j * width + x] as f64;
                    prefix[j * stride + x + 1] = sum[j];
                }
            }
        } else {
            for (j, s) in s.chunks_exact(width).enumerate() {
                let mut sum = 0.0f64;
                for (p, &v) in prefix[j * stride + 1..(j + 1) * stride].iter_mut().zip(s) {
                    sum += v as f64;
                    *p = sum;
                }
            }
        }
        for (j, h) in h.chunks_exact_mut(width).enumerate() {
            window_row(&prefix[j * stride..(j + 1) * stride], h, radius);
        }
    }
    // Vertical: a running total per column over rows [y − r, y + r] ∩ [0, h).
    columns.clear();
    columns.resize(width, 0.0);
    for h in rows.chunks_exact(width).take(radius.min(height)) {
        columns.iter_mut().zip(h).for_each(|(c, &v)| *c += v as f64);
    }
    // 1 / (in-image columns of the window) per x: multiplied, not divided, in the pixel loop.
    inverse_x.clear();
    inverse_x.extend(
        (0..width).map(|x| 1.0 / ((x + radius).min(width - 1) + 1 - x.saturating_sub(radius)) as f64),
    );
    for y in 0..height {
        let inverse_y = 1.0 / ((y + radius).min(height - 1) + 1 - y.saturating_sub(radius)) as f64;
        let range = y * width..(y + 1) * width;
        let add = (y + radius < height).then(|| &rows[(y + radius) * width..(y + radius + 1) * width]);
        let sub = (y >= radius).then(|| &rows[(y - radius) * width..(y - radius + 1) * width]);
        // A row the pass does not use is any row (the other one, or none): it is not read.
        let row = Row {
            out: &mut dst[range.clone()],
            keep: &src[range.clone()],
            background: &background[range],
            add: add.or(sub).unwrap_or(&[]),
            sub: sub.or(add).unwrap_or(&[]),
        };
        // One pass per row: add the row entering the window, write, remove the row leaving it.
        match (add.is_some(), sub.is_some()) {
            (true, true) => vertical_row::<true, true>(row, columns, inverse_x, inverse_y),
            (true, false) => vertical_row::<true, false>(row, columns, inverse_x, inverse_y),
            (false, true) => vertical_row::<false, true>(row, columns, inverse_x, inverse_y),
            (false, false) => vertical_row::<false, false>(row, columns, inverse_x, inverse_y),
        }
    }
}

/// One row of the horizontal pass: window sums from the row's prefix sums (`prefix[0]` = 0).
#[inline(always)]
fn window_row(prefix: &[f64], h: &mut [f32], radius: usize) {
    let width = h.len();
    // Clipped windows at both ends; in between, one subtraction of two shifted slices.
    let window = |x: usize| (prefix[(x + radius + 1).min(width)] - prefix[x.saturating_sub(radius)]) as f32;
    let (left, right) = (radius.min(width), width.saturating_sub(radius).max(radius.min(width)));
    for x in (0..left).chain(right..width) {
        h[x] = window(x);
    }
    if right > left {
        let (hi, lo) = (&prefix[left + radius + 1..=right + radius], &prefix[left - radius..right - radius]);
        for ((out, &a), &b) in h[left..right].iter_mut().zip(hi).zip(lo) {
            *out = (a - b) as f32;
        }
    }
}

/// One output row of the vertical pass, what it writes from, and the rows of horizontal sums
/// entering (`add`) and leaving (`sub`) the window.
struct Row<'a> {
    out: &'a mut [f32],
    keep: &'a [f32],
    background: &'a [bool],
    add: &'a [f32],
    sub: &'a [f32],
}

/// The vertical pass at one row: per column, the total plus the entering row (`ADD`), the
/// blurred value where background, the total minus the leaving row (`SUB`) — the order of the
/// three separate passes this fuses, so the same bits.
#[inline(always)]
fn vertical_row<const ADD: bool, const SUB: bool>(
    row: Row,
    columns: &mut [f64],
    inverse_x: &[f64],
    inverse_y: f64,
) {
    let Row { out, keep, background, add, sub } = row;
    let width = out.len();
    let (out, keep, background, inverse_x) =
        (&mut out[..width], &keep[..width], &background[..width], &inverse_x[..width]);
    let columns = &mut columns[..width];
    let (add, sub) = (&add[..if ADD { width } else { 0 }], &sub[..if SUB { width } else { 0 }]);
    for x in 0..width {
        let mut c = columns[x];
        if ADD {
            c += add[x] as f64;
        }
        let blurred = (c * inverse_x[x] * inverse_y) as f32;
        out[x] = if background[x] { blurred } else { keep[x] };
        if SUB {
            c -= sub[x] as f64;
        }
        columns[x] = c;
    }
}

/// Steps 4a–c on one plane of `grid`: blur, ease, blur; the plane is both input and final
/// output, and only its `background` pixels change.
pub(crate) fn smooth_plane(
    plane: &mut [f32],
    background: &[bool],
    grid: Grid,
    smoothing: Smoothing,
    scratch: &mut Scratch,
) {
    let Smoothing { radii, ease } = smoothing;
    let mut other = std::mem::take(&mut scratch.other);
    other.resize(plane.len(), 0.0);
    box_blur(Blur { src: plane, dst: &mut other, background, grid, radius: radii.0 }, scratch);
    ease.apply_plane(&mut other);
    box_blur(Blur { src: &other, dst: plane, background, grid, radius: radii.1 }, scratch);
    scratch.other = other;
}

/// Step 4 on all planes: a–c per camera (cameras in parallel), then d per pixel (rows in
/// parallel). Weights summing to 1 keep a maximum ≥ 1/C through the first blur, so the eased sum
/// is ≥ 2/C² > 0; should it still vanish (f32 underflow needs ~2^60 cameras) the pixel gets equal
/// weights rather than a division by zero.
pub(crate) fn smooth(planes: &mut [Vec<f32>], background: &[bool], grid: Grid, smoothing: Smoothing) {
    let width = grid.width;
    // As many groups of cameras as threads, one scratch each: fresh scratch planes per camera
    // would pay the page faults of their first touch every time.
    let per_group = planes.len().div_ceil(rayon::current_num_threads().clamp(1, planes.len().max(1))).max(1);
    planes.par_chunks_mut(per_group).for_each(|group| {
        let mut scratch = Scratch::default();
        for plane in group {
            smooth_plane(plane, background, grid, smoothing, &mut scratch);
        }
    });
    let rows = grid.rows_mut(planes);
    rows.into_par_iter().enumerate().for_each(|(y, mut row)| {
        for x in 0..width {
            if !background[y * width + x] {
                continue;
            }
            let sum: f64 = row.iter().map(|plane| plane[x] as f64).sum();
            if sum > 0.0 && sum.is_finite() {
                let inverse = 1.0 / sum;
                row.iter_mut().for_each(|plane| plane[x] = (plane[x] as f64 * inverse) as f32);
            } else {
                let equal = 1.0 / row.len() as f32;
                row.iter_mut().for_each(|plane| plane[x] = equal);
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::Rng;

    /// The blur as first written (three passes per row, one prefix chain at a time): the fused,
    /// interleaved blur must give its bits.
    fn reference_blur(
        src: &[f32],
        background: &[bool],
        width: usize,
        height: usize,
        radius: usize,
    ) -> Vec<f32> {
        let mut dst = vec![0.0; src.len()];
        let (mut rows, mut columns) = (vec![0.0f32; src.len()], Vec::new());
        let (mut inverse_x, mut prefix) = (Vec::new(), vec![0.0f64; width + 1]);
        for (s, h) in src.chunks_exact(width).zip(rows.chunks_exact_mut(width)) {
            let mut sum = 0.0f64;
            for (p, &v) in prefix[1..].iter_mut().zip(s) {
                sum += v as f64;
                *p = sum;
            }
            // Clipped windows at both ends; in between, one subtraction of two shifted slices.
            let window =
                |x: usize| (prefix[(x + radius + 1).min(width)] - prefix[x.saturating_sub(radius)]) as f32;
            let (left, right) = (radius.min(width), width.saturating_sub(radius).max(radius.min(width)));
            for x in (0..left).chain(right..width) {
                h[x] = window(x);
            }
            if right > left {
                let (hi, lo) =
                    (&prefix[left + radius + 1..=right + radius], &prefix[left - radius..right - radius]);
                for ((out, &a), &b) in h[left..right].iter_mut().zip(hi).zip(lo) {
                    *out = (a - b) as f32;
                }
            }
        }
        columns.resize(width, 0.0f64);
        for h in rows.chunks_exact(width).take(radius.min(height)) {
            columns.iter_mut().zip(h).for_each(|(c, &v)| *c += v as f64);
        }
        inverse_x.extend(
            (0..width).map(|x| 1.0 / ((x + radius).min(width - 1) + 1 - x.saturating_sub(radius)) as f64),
        );
        for y in 0..height {
            if y + radius < height {
                let add = &rows[(y + radius) * width..(y + radius + 1) * width];
                columns.iter_mut().zip(add).for_each(|(c, &v)| *c += v as f64);
            }
            let inverse_y = 1.0 / ((y + radius).min(height - 1) + 1 - y.saturating_sub(radius)) as f64;
            let range = y * width..(y + 1) * width;
            let (out, keep, bg) = (&mut dst[range.clone()], &src[range.clone()], &background[range]);
            for (((out, &keep), &bg), (&sum, &inverse)) in
                out.iter_mut().zip(keep).zip(bg).zip(columns.iter().zip(&inverse_x))
            {
                let blurred = (sum * inverse * inverse_y) as f32;
                *out = if bg { blurred } else { keep };
            }
            if y >= radius {
                let sub = &rows[(y - radius) * width..(y - radius + 1) * width];
                columns.iter_mut().zip(sub).for_each(|(c, &v)| *c -= v as f64);
            }
        }
        dst
    }

    /// The definition: average over the clipped window, background pixels only.
    fn brute_blur(src: &[f32], bg: &[bool], w: usize, h: usize, r: usize) -> Vec<f32> {
        (0..w * h)
            .map(|p| {
                if !bg[p] {
                    return src[p];
                }
                let (x, y) = (p % w, p / w);
                let (mut sum, mut n) = (0.0f64, 0);
                for yy in y.saturating_sub(r)..=(y + r).min(h - 1) {
                    for xx in x.saturating_sub(r)..=(x + r).min(w - 1) {
                        sum += src[yy * w + xx] as f64;
                        n += 1;
                    }
                }
                (sum / n as f64) as f32
            })
            .collect()
    }

    fn random_plane(rng: &mut Rng, w: usize, h: usize) -> (Vec<f32>, Vec<bool>) {
        let bg: Vec<bool> = (0..w * h).map(|_| rng.below(3) != 0).collect();
        let plane = bg.iter().map(|&b| if b { rng.unit() } else { rng.below(2) as f32 }).collect();
        (plane, bg)
    }

    #[test]
    fn blur_gives_the_first_blurs_bits() {
        let mut rng = Rng::new(5);
        let mut scratch = Scratch::default();
        for _ in 0..300 {
            let (w, h) = (1 + rng.below(40) as usize, 1 + rng.below(23) as usize);
            let r = 1 + rng.below(6) as usize;
            let (plane, bg) = random_plane(&mut rng, w, h);
            let mut got = vec![0.0; w * h];
            box_blur(
                Blur { src: &plane, dst: &mut got, background: &bg, grid: Grid::new(w, h), radius: r },
                &mut scratch,
            );
            let want = reference_blur(&plane, &bg, w, h, r);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "{w}x{h} r={r}");
        }
    }

    #[test]
    fn blur_equals_the_window_average() {
        let mut rng = Rng::new(4);
        let mut scratch = Scratch::default();
        for _ in 0..300 {
            let (w, h) = (1 + rng.below(25) as usize, 1 + rng.below(20) as usize);
            let r = rng.below(6) as usize;
            let (plane, bg) = random_plane(&mut rng, w, h);
            let mut got = vec![0.0; w * h];
            box_blur(
                Blur { src: &plane, dst: &mut got, background: &bg, grid: Grid::new(w, h), radius: r },
                &mut scratch,
            );
            let want = brute_blur(&plane, &bg, w, h, r);
            for p in 0..w * h {
                assert!((got[p] - want[p]).abs() < 1e-6, "{w}x{h} r={r} p={p}: {} vs {}", got[p], want[p]);
                if !bg[p] {
                    assert_eq!(got[p].to_bits(), plane[p].to_bits(), "camera pixels keep their weight");
                }
            }
        }
    }

    #[test]
    fn ease_is_the_spec_curve() {
        let ease = Ease::new(0.75);
        for k in 0..=100 {
            let t = k as f32 / 100.0;
            let want = if t < 0.5 { 2.0 * t * t } else { 1.0 - 2.0 * (1.0 - t) * (1.0 - t) };
            assert_eq!(ease.apply(t), want);
        }
        let identity = Ease::new(0.5);
        for t in [0.0, 0.1, 0.5, 0.9, 1.0] {
            assert!((identity.apply(t) - t).abs() < 1e-6);
        }
        // Other controls stay monotone and fix 0, ½, 1.
        let soft = Ease::new(0.6);
        assert_eq!((soft.apply(0.0), soft.apply(0.5), soft.apply(1.0)), (0.0, 0.5, 1.0));
    }

    #[test]
    fn smoothing_steps_equal_direct_implementations() {
        let mut rng = Rng::new(9);
        for _ in 0..50 {
            let (w, h, cams) =
                (1 + rng.below(30) as usize, 1 + rng.below(20) as usize, 1 + rng.below(4) as usize);
            // Weight planes that sum to one per pixel, camera pixels one-hot.
            let mut planes = vec![vec![0f32; w * h]; cams];
            let bg: Vec<bool> = (0..w * h).map(|_| rng.below(3) != 0).collect();
            for p in 0..w * h {
                if bg[p] {
                    let raw: Vec<f32> = (0..cams).map(|_| rng.unit() + 1e-3).collect();
                    let s: f32 = raw.iter().sum();
                    (0..cams).for_each(|k| planes[k][p] = raw[k] / s);
                } else {
                    planes[rng.below(cams as u32) as usize][p] = 1.0;
                }
            }
            let ease = Ease::new(0.75);
            let want: Vec<Vec<f32>> = planes
                .iter()
                .map(|pl| {
                    let a = brute_blur(pl, &bg, w, h, 4);
                    let b: Vec<f32> =
                        a.iter().zip(&bg).map(|(&v, &b)| if b { ease.apply(v) } else { v }).collect();
                    brute_blur(&b, &bg, w, h, 3)
                })
                .collect();
            let mut got = planes.clone();
            smooth(&mut got, &bg, Grid::new(w, h), Smoothing { radii: (4, 3), ease });
            for p in 0..w * h {
                let sum: f64 = want.iter().map(|pl| pl[p] as f64).sum();
                for k in 0..cams {
                    let expect = if bg[p] { (want[k][p] as f64 / sum) as f32 } else { planes[k][p] };
                    assert!((got[k][p] - expect).abs() < 1e-5, "{w}x{h} k={k} p={p}");
                }
                if bg[p] {
                    let total: f32 = got.iter().map(|pl| pl[p]).sum();
                    assert!((total - 1.0).abs() < 1e-5);
                }
            }
        }
    }
}
