//! The membrane: harmonic interpolation on the pixel grid (docs/design/mcc.md §5.8). Values are
//! given at *fixed* pixels; every other pixel becomes the average of its 4-neighbours inside the
//! image: Laplace's equation with Dirichlet conditions at the fixed pixels and Neumann conditions
//! at the image border, the interpolant of seamless cloning (Pérez, Gangnet & Blake 2003, "Poisson
//! image editing"; Farbman et al. 2009 call it the membrane). It is smooth away from the fixed
//! pixels and meets them continuously: no medial-axis jumps, unlike a nearest-pixel fill.
//!
//! Solved by a full-multigrid start and conjugate gradients preconditioned with one multigrid
//! V-cycle ([`hierarchy`]): the combination stays robust for arbitrary masks, where a plain
//! V-cycle's coarse grids misjudge the mask (a fictitious-domain multigrid preconditioner;
//! Trottenberg, Oosterlee & Schüller 2001, *Multigrid*, §7.8). Cost: a few passes over the
//! pixels per iteration and a few iterations, whatever the mask.
//!
//! Deterministic whatever the thread count: red–black sweeps read only the other colour, and every
//! sum over the image is a fixed-order sum of per-row sums.

mod hierarchy;

use super::grid::Grid;
pub(crate) use hierarchy::prolong;
use hierarchy::{Coarse, Work};
use rayon::prelude::*;
use std::ops::Range;

/// Grids smaller than this many cells are processed by one thread: tasks would cost more.
const PARALLEL_CELLS: usize = 1 << 14;

/// A solver for `K`-channel membranes on one grid size: its buffers (and the hierarchy's) are
/// reused from one mask to the next, so solving camera after camera allocates nothing new.
pub(crate) struct Membrane<const K: usize> {
    grid: Grid,
    fixed: Vec<bool>,
    levels: Vec<Coarse>,
    work: Vec<Work<K>>,
    /// Fine buffers: the fixed values' pull, residual, preconditioned residual, search
    /// direction, and A·direction.
    b: Vec<[f32; K]>,
    r: Vec<[f32; K]>,
    z: Vec<[f32; K]>,
    p: Vec<[f32; K]>,
    q: Vec<[f32; K]>,
}

/// How far [`Membrane::solve`] went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Solved {
    /// Conjugate-gradient iterations run after the full-multigrid start.
    pub iterations: usize,
    /// The largest over channels of the final residual norm, relative to that of the constant
    /// guess (every free pixel at the mean of the fixed values next to free ones).
    pub relative_residual: f64,
}

impl<const K: usize> Membrane<K> {
    /// A solver for membranes on `grid`.
    pub(crate) fn new(grid: Grid) -> Self {
        Self {
            grid,
            fixed: Vec::new(),
            levels: Vec::new(),
            work: Vec::new(),
            b: Vec::new(),
            r: Vec::new(),
            z: Vec::new(),
            p: Vec::new(),
            q: Vec::new(),
        }
    }

    /// Solves for the membrane in `values` (row-major, `K` channels per pixel) whose fixed pixels
    /// are those with `fixed(p)` and hold their values; the others are overwritten. Stops when
    /// every channel's residual is `tolerance` of the constant guess's, or after
    /// `max_iterations` conjugate-gradient iterations.
    pub(crate) fn solve(
        &mut self,
        fixed: impl Fn(usize) -> bool + Sync,
        values: &mut [[f32; K]],
        tolerance: f64,
        max_iterations: usize,
    ) -> Solved {
        let Grid { width: w, height: h } = self.grid;
        let n = w * h;
        assert_eq!(values.len(), n, "a membrane solver for {w}x{h} grids");
        self.fixed.clear();
        self.fixed.par_extend((0..n).into_par_iter().map(&fixed));
        for buffer in [&mut self.b, &mut self.r, &mut self.z, &mut self.p, &mut self.q] {
            buffer.clear();
            buffer.resize(n, [0.0; K]);
        }
        // The pull of the fixed values on each free pixel, and their mean.
        let (mean, count) = self.pull(values);
        if count == 0 {
            // No free pixel touches a fixed one: nothing to interpolate from.
            return Solved { iterations: 0, relative_residual: 0.0 };
        }
        let reference = self.constant_residual(mean);
        hierarchy::build(&mut self.levels, self.grid, &self.fixed);
        hierarchy::fit(&mut self.work, &self.levels);
        // Full-multigrid start (or the constant guess on grids too small for coarse levels).
        let fixed = &self.fixed;
        if self.levels.is_empty() {
            values.par_iter_mut().enumerate().for_each(|(p, v)| {
                if !fixed[p] {
                    *v = mean;
                }
            });
        } else {
            hierarchy::aggregate_problem(&self.b, self.grid, &self.levels, &mut self.work);
            hierarchy::full_multigrid(&self.levels, &mut self.work);
            let coarse = &self.levels[0];
            let active = |c: usize| coarse.diag[c] > 0.0;
            hierarchy::prolong::<K, false>(&self.work[0].solution, active, values, self.grid, |p| !fixed[p]);
        }
        // Conjugate gradients on the fine equations.
        // The updated residual drifts from the true one in f32: when it says done, the true one
        // is computed, and the iteration restarts from it if that is not done yet.
        let mut relative = self.residual(values, &reference);
        let (mut iterations, mut restart) = (0, true);
        let mut rz = [0.0f64; K];
        while iterations < max_iterations {
            if relative <= tolerance {
                if restart {
                    break;
                }
                relative = self.residual(values, &reference);
                restart = true;
                if relative <= tolerance {
                    break;
                }
            }
            self.precondition();
            let rz_next = dots(&self.r, &self.z, w);
            let beta: [f32; K] =
                std::array::from_fn(
                    |k| if !restart && rz[k] > 0.0 { (rz_next[k] / rz[k]) as f32 } else { 0.0 },
                );
            restart = false;
            rz = rz_next;
            self.p.par_iter_mut().zip(self.z.par_iter()).for_each(|(pp, zz)| {
                for k in 0..K {
                    pp[k] = zz[k] + beta[k] * pp[k];
                }
            });
            let pq = self.apply_and_dot();
            let alpha: [f32; K] =
                std::array::from_fn(|k| if pq[k] > 0.0 { (rz[k] / pq[k]) as f32 } else { 0.0 });
            relative = self.step(values, alpha, &reference);
            iterations += 1;
        }
        Solved { iterations, relative_residual: relative }
    }

    /// b = Σ fixed neighbours' values at each free pixel (0 at fixed ones); returns the mean of
    /// those neighbours' values and how many there were.
    fn pull(&mut self, values: &[[f32; K]]) -> ([f32; K], usize) {
        let Grid { width: w, height: h } = self.grid;
        let fixed = &self.fixed;
        let rows: Vec<([f64; K], usize)> = self
            .b
            .par_chunks_mut(w)
            .enumerate()
            .map(|(y, row)| {
                let (mut sum, mut count) = ([0.0f64; K], 0usize);
                for (x, out) in row.iter_mut().enumerate() {
                    let p = y * w + x;
                    if fixed[p] {
                        continue;
                    }
                    each_neighbour(x, y, w, h, |q| {
                        if fixed[q] {
                            for k in 0..K {
                                out[k] += values[q][k];
                                sum[k] += values[q][k] as f64;
                            }
                            count += 1;
                        }
                    });
                }
                (sum, count)
            })
            .collect();
        let (sum, count) = rows
            .iter()
            .fold(([0.0f64; K], 0), |(s, c), (rs, rc)| (std::array::from_fn(|k| s[k] + rs[k]), c + rc));
        (sum.map(|s| (s / count.max(1) as f64) as f32), count)
    }

    /// The residual norms (per channel) of the constant guess `mean`: b − ground·mean.
    fn constant_residual(&self, mean: [f32; K]) -> [f64; K] {
        let Grid { width: w, height: h } = self.grid;
        let fixed = &self.fixed;
        let rows: Vec<[f64; K]> = self
            .b
            .par_chunks(w)
            .enumerate()
            .map(|(y, row)| {
                let mut s = [0.0f64; K];
                for (x, b) in row.iter().enumerate() {
                    let p = y * w + x;
                    if fixed[p] {
                        continue;
                    }
                    let ground = [
                        x > 0 && fixed[p - 1],
                        x + 1 < w && fixed[p + 1],
                        y > 0 && fixed[p - w],
                        y + 1 < h && fixed[p + w],
                    ]
                    .iter()
                    .filter(|&&f| f)
                    .count() as f32;
                    for k in 0..K {
                        let r = (b[k] - ground * mean[k]) as f64;
                        s[k] += r * r;
                    }
                }
                s
            })
            .collect();
        sum_rows(&rows).map(f64::sqrt)
    }

    /// r = Σ in-image neighbours − n·u at free pixels (0 at fixed ones); returns the largest
    /// channel's norm relative to `reference`.
    fn residual(&mut self, u: &[[f32; K]], reference: &[f64; K]) -> f64 {
        let squares = apply(&self.fixed, u, &mut self.r, self.grid, |_, au| {
            let r = au.map(|v| -v);
            (r, r.map(|v| v as f64 * v as f64))
        });
        relative(&squares, reference)
    }

    /// z = one symmetric V-cycle on A z = r from z = 0.
    fn precondition(&mut self) {
        let grid = self.grid;
        self.sweep([0, 1], true);
        if self.levels.is_empty() {
            self.sweep([1, 0], false);
            return;
        }
        // q = r − A z (q is free until the next `apply_and_dot`), restricted.
        let r = &self.r;
        apply(&self.fixed, &self.z, &mut self.q, grid, |p, az| {
            (std::array::from_fn(|k| r[p][k] - az[k]), [0.0; K])
        });
        let (first, rest) = self.work.split_first_mut().expect("a coarse level");
        hierarchy::restrict(&self.q, grid, &self.levels[0], &mut first.rhs, &mut first.folded);
        first.solution.iter_mut().for_each(|v| *v = [0.0; K]);
        hierarchy::cycle(&self.levels, first, rest);
        let fixed = &self.fixed;
        hierarchy::prolong::<K, true>(&first.solution, |_| true, &mut self.z, grid, |p| !fixed[p]);
        self.sweep([1, 0], false);
    }

    /// One red–black Gauss–Seidel sweep of A z = r (colours in the given order; fixed pixels hold
    /// 0): z = (r + Σ in-image neighbours) / their count. With `from_zero`, z starts at 0, so the
    /// first colour's cells become r / count without reading anything.
    fn sweep(&mut self, colours: [usize; 2], from_zero: bool) {
        if from_zero {
            let Grid { width: w, height: h } = self.grid;
            let (fixed, r) = (&self.fixed, &self.r);
            for_rows(&mut self.z, w, |(y, row)| {
                for (x, out) in row.iter_mut().enumerate() {
                    let p = y * w + x;
                    *out = if !fixed[p] && (x + y) & 1 == colours[0] {
                        let inv = 1.0 / neighbour_count(x, y, w, h);
                        r[p].map(|v| v * inv)
                    } else {
                        [0.0; K]
                    };
                }
            });
        } else {
            self.half_sweep(colours[0]);
        }
        self.half_sweep(colours[1]);
    }

    /// The cells of one colour: z = (r + Σ in-image neighbours) / their count.
    fn half_sweep(&mut self, colour: usize) {
        let fixed = &self.fixed;
        let w = self.grid.width;
        half_sweep(
            &mut self.z,
            Some(&self.r),
            Free { fixed: |p| fixed[p], span: |_| 0..w },
            colour,
            self.grid,
        );
    }

    /// q = A p at free pixels (0 at fixed ones; p holds 0 there); returns p·q per channel.
    fn apply_and_dot(&mut self) -> [f64; K] {
        let p = &self.p;
        apply(&self.fixed, p, &mut self.q, self.grid, |i, ap| {
            (ap, std::array::from_fn(|k| p[i][k] as f64 * ap[k] as f64))
        })
    }

    /// u += α p, r −= α q at free pixels; returns the new residual relative to `reference`.
    fn step(&mut self, u: &mut [[f32; K]], alpha: [f32; K], reference: &[f64; K]) -> f64 {
        let w = self.grid.width;
        let (fixed, p, q) = (&self.fixed, &self.p, &self.q);
        let rows: Vec<[f64; K]> = u
            .par_chunks_mut(w)
            .zip(self.r.par_chunks_mut(w))
            .enumerate()
            .map(|(y, (u_row, r_row))| {
                let mut s = [0.0f64; K];
                for (x, (uu, rr)) in u_row.iter_mut().zip(r_row.iter_mut()).enumerate() {
                    let i = y * w + x;
                    if fixed[i] {
                        continue;
                    }
                    for k in 0..K {
                        uu[k] += alpha[k] * p[i][k];
                        rr[k] -= alpha[k] * q[i][k];
                        s[k] += rr[k] as f64 * rr[k] as f64;
                    }
                }
                s
            })
            .collect();
        relative(&sum_rows(&rows), reference)
    }
}

/// The fine operator at every free pixel: `out[p]` and a contribution to the returned sum are
/// `f(p, (A x)(p))`, with A x = n·x − Σ in-image neighbours (x holds the fixed values, or 0, at
/// fixed pixels); `out` is 0 at fixed pixels. Sums are per row, added in row order.
fn apply<const K: usize>(
    fixed: &[bool],
    x: &[[f32; K]],
    out: &mut [[f32; K]],
    grid: Grid,
    f: impl Fn(usize, [f32; K]) -> ([f32; K], [f64; K]) + Sync,
) -> [f64; K] {
    let Grid { width: w, height: h } = grid;
    let rows: Vec<[f64; K]> = out
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            let mut s = [0.0f64; K];
            for (i, o) in row.iter_mut().enumerate() {
                let p = y * w + i;
                if fixed[p] {
                    *o = [0.0; K];
                    continue;
                }
                let (sum, n) = neighbour_sum(x, i, y, w, h);
                let (v, c) = f(p, std::array::from_fn(|k| n * x[p][k] - sum[k]));
                *o = v;
                for k in 0..K {
                    s[k] += c[k];
                }
            }
            s
        })
        .collect();
    sum_rows(&rows)
}

/// The cells a sweep may change: in each row y the pixels of `span(y)`, except those with
/// `fixed(p)`.
pub(crate) struct Free<F, S> {
    pub fixed: F,
    pub span: S,
}

/// `sweeps` red–black Gauss–Seidel sweeps of the membrane itself on `values` (on `grid`): each
/// `free` pixel becomes the mean of its neighbours; the others hold their values. Smooths what
/// an interpolation from a coarser grid left near the fixed pixels.
pub(crate) fn relax<const K: usize>(
    values: &mut [[f32; K]],
    free: Free<impl Fn(usize) -> bool + Sync, impl Fn(usize) -> Range<usize> + Sync>,
    grid: Grid,
    sweeps: usize,
) {
    for _ in 0..sweeps {
        for colour in [0, 1] {
            half_sweep(values, None, Free { fixed: &free.fixed, span: &free.span }, colour, grid);
        }
    }
}

/// The `free` cells of one colour: u = (rhs + Σ in-image neighbours) / their count (rhs 0 when
/// `None`). Rows run in parallel on large grids; each reads only the other colour.
fn half_sweep<const K: usize>(
    u: &mut [[f32; K]],
    rhs: Option<&[[f32; K]]>,
    free: Free<impl Fn(usize) -> bool + Sync, impl Fn(usize) -> Range<usize> + Sync>,
    colour: usize,
    grid: Grid,
) {
    let Free { fixed, span } = free;
    let Grid { width: w, height: h } = grid;
    let grid = Shared(u.as_mut_ptr());
    let row = |y: usize| {
        let Range { start, end } = span(y);
        let mut x = start + ((start + y + colour) & 1);
        while x < end {
            let p = y * w + x;
            if !fixed(p) {
                // SAFETY: (x, y) has this half-sweep's colour, its neighbours the other one.
                let (sum, n) = unsafe { grid.neighbours(x, y, w, h) };
                let inv = 1.0 / n;
                let b = rhs.map_or([0.0; K], |r| r[p]);
                let v: [f32; K] = std::array::from_fn(|k| (b[k] + sum[k]) * inv);
                // SAFETY: only this task writes cells of this colour in row y.
                unsafe { grid.write(p, v) };
            }
            x += 2;
        }
    };
    if w * h >= PARALLEL_CELLS {
        (0..h).into_par_iter().for_each(row);
    } else {
        (0..h).for_each(row);
    }
}

/// Runs `rows` over the rows of `out` (`width` cells each), in parallel when it is large.
fn for_rows<T: Send>(out: &mut [T], width: usize, rows: impl Fn((usize, &mut [T])) + Sync + Send) {
    if out.len() >= PARALLEL_CELLS {
        out.par_chunks_mut(width).enumerate().for_each(rows);
    } else {
        out.chunks_mut(width).enumerate().for_each(rows);
    }
}

/// Per-channel dot products, summed row by row in a fixed order.
fn dots<const K: usize>(a: &[[f32; K]], b: &[[f32; K]], width: usize) -> [f64; K] {
    let rows: Vec<[f64; K]> = a
        .par_chunks(width)
        .zip(b.par_chunks(width))
        .map(|(ra, rb)| {
            let mut s = [0.0f64; K];
            for (x, y) in ra.iter().zip(rb) {
                for k in 0..K {
                    s[k] += x[k] as f64 * y[k] as f64;
                }
            }
            s
        })
        .collect();
    sum_rows(&rows)
}

/// The sum of per-row sums, in row order.
fn sum_rows<const K: usize>(rows: &[[f64; K]]) -> [f64; K] {
    rows.iter().fold([0.0; K], |acc, s| std::array::from_fn(|k| acc[k] + s[k]))
}

/// The largest over channels of √(squares) / reference (0 where the reference is 0).
fn relative<const K: usize>(squares: &[f64; K], reference: &[f64; K]) -> f64 {
    (0..K)
        .map(|k| if reference[k] > 0.0 { squares[k].sqrt() / reference[k] } else { 0.0 })
        .fold(0.0, f64::max)
}

/// How many 4-neighbours (x, y) has inside a `w × h` grid.
#[inline]
fn neighbour_count(x: usize, y: usize, w: usize, h: usize) -> f32 {
    ((x > 0) as u32 + (x + 1 < w) as u32 + (y > 0) as u32 + (y + 1 < h) as u32) as f32
}

/// The sum of the in-image 4-neighbours of (x, y) and their count.
#[inline(always)]
fn neighbour_sum<const K: usize>(v: &[[f32; K]], x: usize, y: usize, w: usize, h: usize) -> ([f32; K], f32) {
    neighbour_sum_by(|q| v[q], x, y, w, h)
}

/// [`neighbour_sum`] of the values `read` gives.
#[inline(always)]
fn neighbour_sum_by<const K: usize>(
    read: impl Fn(usize) -> [f32; K],
    x: usize,
    y: usize,
    w: usize,
    h: usize,
) -> ([f32; K], f32) {
    let p = y * w + x;
    if x > 0 && x + 1 < w && y > 0 && y + 1 < h {
        // Inside: the same sum in the same order as below, without the tests.
        let (l, r, u, d) = (read(p - 1), read(p + 1), read(p - w), read(p + w));
        return (std::array::from_fn(|k| ((l[k] + r[k]) + u[k]) + d[k]), 4.0);
    }
    let mut sum = [0.0f32; K];
    let mut n = 0.0f32;
    each_neighbour(x, y, w, h, |q| {
        let v = read(q);
        for k in 0..K {
            sum[k] += v[k];
        }
        n += 1.0;
    });
    (sum, n)
}

/// Calls `f` with the index of every in-image 4-neighbour of (x, y): left, right, up, down.
#[inline(always)]
fn each_neighbour(x: usize, y: usize, w: usize, h: usize, mut f: impl FnMut(usize)) {
    let p = y * w + x;
    if x > 0 {
        f(p - 1);
    }
    if x + 1 < w {
        f(p + 1);
    }
    if y > 0 {
        f(p - w);
    }
    if y + 1 < h {
        f(p + w);
    }
}

/// A grid shared by the tasks of one red–black half-sweep: each task writes only cells of the
/// half-sweep's colour in its own row and reads only cells of the other colour.
struct Shared<T>(*mut T);
// SAFETY: see the type's doc; every access goes through the unsafe methods below.
unsafe impl<T: Send> Sync for Shared<T> {}
unsafe impl<T: Send> Send for Shared<T> {}

impl<T: Copy> Shared<T> {
    /// Reads cell `p`. Caller: no task writes `p` during this half-sweep.
    #[inline]
    unsafe fn read(&self, p: usize) -> T {
        // SAFETY: `p` is a cell of the grid the pointer spans (the caller's index), and no task
        // writes it during this half-sweep (the caller's guarantee), so the read races nothing.
        unsafe { self.0.add(p).read() }
    }

    /// Writes cell `p`. Caller: no other task reads or writes `p` during this half-sweep.
    #[inline]
    unsafe fn write(&self, p: usize, v: T) {
        // SAFETY: `p` is a cell of the grid the pointer spans (the caller's index), and no other
        // task reads or writes it during this half-sweep (the caller's guarantee).
        unsafe { self.0.add(p).write(v) }
    }
}

impl<const K: usize> Shared<[f32; K]> {
    /// The sum of the in-image 4-neighbours of (x, y) and their count. Caller: as for `read`.
    #[inline]
    unsafe fn neighbours(&self, x: usize, y: usize, w: usize, h: usize) -> ([f32; K], f32) {
        // SAFETY: the caller's guarantee covers every neighbour.
        neighbour_sum_by(|q| unsafe { self.read(q) }, x, y, w, h)
    }
}

#[cfg(test)]
mod tests;
