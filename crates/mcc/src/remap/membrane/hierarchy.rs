//! The multigrid hierarchy under [`super::Membrane`]: coarse levels of 2 × 2 aggregates, their
//! red–black smoother, the transfers between levels, the V-cycle and the full-multigrid start.
//!
//! The fine equations are a graph Laplacian (unit conductance between neighbouring free pixels)
//! plus a *ground* conductance to each fixed neighbour. A coarse cell sums the grounds of its
//! free children and the conductances that cross to each neighbouring cell: the Galerkin operator
//! of piecewise-constant aggregation, so every level is again a 5-point graph Laplacian with
//! ground. That operator is about twice as stiff as a rediscretised one (Braess 1995) and would
//! halve every correction, so links are scaled by ½ and grounds by ¾ (scales chosen by trial on
//! test masks; docs/design/mcc.md §5.8). Corrections prolong bilinearly (cell-centred weights 9/16,
//! 3/16, 3/16, 1/16) and residuals restrict by the exact transpose; the smoother runs red–black
//! before the coarse correction and black–red after. So the V-cycle is a symmetric positive
//! definite operator, as conjugate gradients requires of a preconditioner.
//!
//! The coarse levels also carry the problem itself (the fixed values' pull, aggregated like the
//! grounds) for a full-multigrid start: solve the coarsest level, interpolate, one V-cycle per
//! level on the way up (Brandt 1977).

use super::{PARALLEL_CELLS, Shared, for_rows};
use crate::remap::grid::Grid;
use rayon::prelude::*;

/// Coarsening stops at a level with at most this many cells, which is swept instead.
const COARSEST_CELLS: usize = 64;
/// Symmetric sweep pairs on the coarsest level per visit.
const COARSEST_SWEEPS: usize = 20;
/// Scale of the aggregated links and grounds (see the module notes).
const LINK_SCALE: f32 = 0.5;
const GROUND_SCALE: f32 = 0.75;

/// One row of a coarse level's east links, south links, grounds and activity marks.
type CellRows<'a> = (((&'a mut [f32], &'a mut [f32]), &'a mut [f32]), &'a mut [f32]);

/// A coarse level: per cell the conductance to its east and south neighbours and its diagonal
/// (their sum with the west and north links and the ground); a diagonal of 0 marks a cell
/// without free pixels.
#[derive(Default)]
pub(super) struct Coarse {
    pub grid: Grid,
    east: Vec<f32>,
    south: Vec<f32>,
    ground: Vec<f32>,
    pub diag: Vec<f32>,
}

/// The buffers of one coarse level during a solve.
#[derive(Default)]
pub(super) struct Work<const K: usize> {
    pub solution: Vec<[f32; K]>,
    pub rhs: Vec<[f32; K]>,
    residual: Vec<[f32; K]>,
    /// Rows of the finer level folded to this level's width ([`restrict`]'s scratch).
    pub folded: Vec<[f32; K]>,
}

/// Rebuilds `levels` (reusing their memory) for a mask on `grid`.
pub(super) fn build(levels: &mut Vec<Coarse>, grid: Grid, fixed: &[bool]) {
    let Grid { width, height } = grid;
    let mut count = 0;
    if width * height > COARSEST_CELLS {
        let free = |x: usize, y: usize| !fixed[y * width + x];
        let ground = |x: usize, y: usize| {
            let p = y * width + x;
            let mut g = 0.0;
            if x > 0 && fixed[p - 1] {
                g += 1.0;
            }
            if x + 1 < width && fixed[p + 1] {
                g += 1.0;
            }
            if y > 0 && fixed[p - width] {
                g += 1.0;
            }
            if y + 1 < height && fixed[p + width] {
                g += 1.0;
            }
            g
        };
        let link = |x: usize, y: usize, east: bool| {
            let q = if east { (x + 1, y) } else { (x, y + 1) };
            if free(x, y) && free(q.0, q.1) { 1.0 } else { 0.0 }
        };
        if levels.is_empty() {
            levels.push(Coarse::default());
        }
        levels[0].aggregate(grid, free, ground, link);
        count = 1;
        while levels[count - 1].grid.len() > COARSEST_CELLS {
            if levels.len() == count {
                levels.push(Coarse::default());
            }
            let (done, rest) = levels.split_at_mut(count);
            let last = &done[count - 1];
            let w = last.grid.width;
            rest[0].aggregate(
                last.grid,
                |x, y| last.diag[y * w + x] > 0.0,
                |x, y| last.ground[y * w + x],
                |x, y, east| {
                    let p = y * w + x;
                    if east { last.east[p] } else { last.south[p] }
                },
            );
            count += 1;
        }
    }
    levels.truncate(count);
}

/// Makes `work` fit `levels`, reusing its memory.
pub(super) fn fit<const K: usize>(work: &mut Vec<Work<K>>, levels: &[Coarse]) {
    work.resize_with(levels.len(), Work::default);
    for (w, level) in work.iter_mut().zip(levels) {
        let n = level.diag.len();
        for buffer in [&mut w.solution, &mut w.rhs, &mut w.residual] {
            buffer.clear();
            buffer.resize(n, [0.0; K]);
        }
    }
}

impl Coarse {
    /// Becomes the level of 2 × 2 aggregates of a level on `grid` given by its `active` cells,
    /// their `ground`s and their `link`s (east or south, to the next cell).
    fn aggregate(
        &mut self,
        grid: Grid,
        active: impl Fn(usize, usize) -> bool + Sync,
        ground: impl Fn(usize, usize) -> f32 + Sync,
        link: impl Fn(usize, usize, bool) -> f32 + Sync,
    ) {
        let Grid { width, height } = grid;
        self.grid = grid.blocks();
        let Grid { width: cw, height: ch } = self.grid;
        for v in [&mut self.east, &mut self.south, &mut self.ground, &mut self.diag] {
            v.clear();
            v.resize(cw * ch, 0.0);
        }
        // Per cell (links and ground, diag = 1 marking activity), then the diagonals.
        let cells = |(cy, (((east, south), grounds), active_row)): (usize, CellRows<'_>)| {
            for cx in 0..cw {
                let (x0, y0) = (2 * cx, 2 * cy);
                let mut any = false;
                let mut g = 0.0f32;
                for (x, y) in [(x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1)] {
                    if x < width && y < height && active(x, y) {
                        any = true;
                        g += ground(x, y);
                    }
                }
                if !any {
                    continue;
                }
                active_row[cx] = 1.0;
                grounds[cx] = GROUND_SCALE * g;
                // Links that cross to the next aggregate (none past the grid's edge).
                if x0 + 2 < width {
                    let mut l = link(x0 + 1, y0, true);
                    if y0 + 1 < height {
                        l += link(x0 + 1, y0 + 1, true);
                    }
                    east[cx] = LINK_SCALE * l;
                }
                if y0 + 2 < height {
                    let mut l = link(x0, y0 + 1, false);
                    if x0 + 1 < width {
                        l += link(x0 + 1, y0 + 1, false);
                    }
                    south[cx] = LINK_SCALE * l;
                }
            }
        };
        if cw * ch >= PARALLEL_CELLS {
            let rows = self.east.par_chunks_mut(cw).zip(self.south.par_chunks_mut(cw));
            rows.zip(self.ground.par_chunks_mut(cw))
                .zip(self.diag.par_chunks_mut(cw))
                .enumerate()
                .for_each(cells);
        } else {
            let rows = self.east.chunks_mut(cw).zip(self.south.chunks_mut(cw));
            rows.zip(self.ground.chunks_mut(cw)).zip(self.diag.chunks_mut(cw)).enumerate().for_each(cells);
        }
        let (east, south, ground) = (&self.east, &self.south, &self.ground);
        for_rows(&mut self.diag, cw, |(cy, row)| {
            for (cx, d) in row.iter_mut().enumerate() {
                if *d == 0.0 {
                    continue;
                }
                let c = cy * cw + cx;
                let mut sum = ground[c] + east[c] + south[c];
                if cx > 0 {
                    sum += east[c - 1];
                }
                if cy > 0 {
                    sum += south[c - cw];
                }
                // An aggregate linked to nothing and grounded nowhere cannot move; keep it out
                // rather than divide by zero.
                *d = if sum > 0.0 { sum } else { 0.0 };
            }
        });
    }

    /// One red–black Gauss–Seidel sweep: u = (b + Σ c·u_neighbour) / diag.
    fn sweep<const K: usize>(&self, u: &mut [[f32; K]], b: &[[f32; K]], colours: [usize; 2]) {
        let Grid { width: w, height: h } = self.grid;
        let grid = Shared(u.as_mut_ptr());
        for colour in colours {
            let row = |y: usize| {
                let mut x = (y + colour) & 1;
                while x < w {
                    let p = y * w + x;
                    let d = self.diag[p];
                    if d > 0.0 {
                        let mut s = b[p];
                        let mut add = |q: usize, c: f32| {
                            if c != 0.0 {
                                // SAFETY: q neighbours p, so it has the other colour, which no
                                // task writes during this half-sweep.
                                let v = unsafe { grid.read(q) };
                                for k in 0..K {
                                    s[k] += c * v[k];
                                }
                            }
                        };
                        if x > 0 {
                            add(p - 1, self.east[p - 1]);
                        }
                        add(p + 1, self.east[p]);
                        if y > 0 {
                            add(p - w, self.south[p - w]);
                        }
                        add(p + w, self.south[p]);
                        let inv = 1.0 / d;
                        // SAFETY: only this task writes cells of this colour in row y.
                        unsafe { grid.write(p, s.map(|v| v * inv)) };
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
    }

    /// r = b − A u.
    fn residual<const K: usize>(&self, u: &[[f32; K]], b: &[[f32; K]], r: &mut [[f32; K]]) {
        let w = self.grid.width;
        for_rows(r, w, |(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let p = y * w + x;
                let d = self.diag[p];
                if d <= 0.0 {
                    *out = [0.0; K];
                    continue;
                }
                let mut s: [f32; K] = std::array::from_fn(|k| b[p][k] - d * u[p][k]);
                let mut add = |q: usize, c: f32| {
                    if c != 0.0 {
                        for k in 0..K {
                            s[k] += c * u[q][k];
                        }
                    }
                };
                if x > 0 {
                    add(p - 1, self.east[p - 1]);
                }
                add(p + 1, self.east[p]);
                if y > 0 {
                    add(p - w, self.south[p - w]);
                }
                add(p + w, self.south[p]);
                *out = s;
            }
        });
    }
}

/// A symmetric V-cycle on `levels[0]`: improves `here.solution` (any start) towards
/// A u = `here.rhs`; the deeper levels' buffers are overwritten.
pub(super) fn cycle<const K: usize>(levels: &[Coarse], here: &mut Work<K>, rest: &mut [Work<K>]) {
    let level = &levels[0];
    let Work { solution: u, rhs: b, residual: r, .. } = here;
    let Some((next, deeper)) = rest.split_first_mut() else {
        for _ in 0..COARSEST_SWEEPS {
            level.sweep(u, b, [0, 1]);
            level.sweep(u, b, [1, 0]);
        }
        return;
    };
    level.sweep(u, b, [0, 1]);
    level.residual(u, b, r);
    restrict(r, level.grid, &levels[1], &mut next.rhs, &mut next.folded);
    next.solution.iter_mut().for_each(|v| *v = [0.0; K]);
    cycle(&levels[1..], next, deeper);
    prolong::<K, true>(&next.solution, |_| true, u, level.grid, |p| level.diag[p] > 0.0);
    level.sweep(u, b, [1, 0]);
}

/// The full-multigrid start from the coarse problems (`work[l].rhs` holds level l's problem,
/// as [`aggregate_problem`] left it): solves the coarsest level, then interpolates each solution
/// to the next finer level and runs one V-cycle there. The finest coarse level's solution is in
/// `work[0].solution`.
pub(super) fn full_multigrid<const K: usize>(levels: &[Coarse], work: &mut [Work<K>]) {
    let last = levels.len() - 1;
    work[last].solution.iter_mut().for_each(|v| *v = [0.0; K]);
    cycle(&levels[last..], &mut work[last], &mut []);
    for l in (0..last).rev() {
        let (here, coarser) = work.split_at_mut(l + 1);
        let here = &mut here[l];
        let level = &levels[l];
        here.solution.iter_mut().for_each(|v| *v = [0.0; K]);
        let next = &levels[l + 1];
        let active = |c: usize| next.diag[c] > 0.0;
        prolong::<K, false>(&coarser[0].solution, active, &mut here.solution, level.grid, |p| {
            level.diag[p] > 0.0
        });
        cycle(&levels[l..], here, coarser);
    }
}

/// Aggregates the fine problem `b` on `grid` (each free pixel's pull of its fixed neighbours)
/// down the levels into `work[l].rhs`, scaled like the grounds so that a constant stays a
/// solution.
pub(super) fn aggregate_problem<const K: usize>(
    b: &[[f32; K]],
    grid: Grid,
    levels: &[Coarse],
    work: &mut [Work<K>],
) {
    for (l, level) in levels.iter().enumerate() {
        let (done, rest) = work.split_at_mut(l);
        let (src, Grid { width: w, height: h }) = match l {
            0 => (b, grid),
            _ => (&done[l - 1].rhs[..], levels[l - 1].grid),
        };
        let cw = level.grid.width;
        for_rows(&mut rest[0].rhs, cw, |(cy, row)| {
            for (cx, o) in row.iter_mut().enumerate() {
                let mut s = [0.0f32; K];
                if level.diag[cy * cw + cx] > 0.0 {
                    for y in 2 * cy..(2 * cy + 2).min(h) {
                        for x in 2 * cx..(2 * cx + 2).min(w) {
                            let v = src[y * w + x];
                            for k in 0..K {
                                s[k] += v[k];
                            }
                        }
                    }
                }
                *o = s.map(|v| GROUND_SCALE * v);
            }
        });
    }
}

/// The prolongation's weight of fine index `x` (of a level `coarse_len` cells wide after
/// coarsening) on coarse index `c`: ¾ on its own aggregate, ¼ on the next one towards its side
/// (its own again at the edge).
#[inline]
fn weight(x: usize, c: usize, coarse_len: usize) -> f32 {
    let own = x / 2;
    let other = if x & 1 == 1 { (own + 1).min(coarse_len - 1) } else { own.saturating_sub(1) };
    0.75 * (own == c) as u32 as f32 + 0.25 * (other == c) as u32 as f32
}

/// The coarse rhs: the transpose of [`prolong`] (adding) applied to the residual `r` on `grid`.
/// Separable: every fine row is folded to coarse width into `folded` (kept between calls, so the
/// iterations allocate nothing), then the (up to four) folded rows of a coarse row are weighed.
pub(super) fn restrict<const K: usize>(
    r: &[[f32; K]],
    grid: Grid,
    coarse: &Coarse,
    out: &mut [[f32; K]],
    folded: &mut Vec<[f32; K]>,
) {
    let Grid { width: w, height: h } = grid;
    let Grid { width: cw, height: ch } = coarse.grid;
    folded.resize(cw * h, [0.0; K]);
    for_rows(&mut folded[..cw * h], cw, |(y, frow)| {
        let row = &r[y * w..(y + 1) * w];
        for (cx, f) in frow.iter_mut().enumerate() {
            let x0 = 2 * cx;
            if cx > 0 && x0 + 2 < w && cx + 1 < cw {
                let (a, b, c, d) = (row[x0 - 1], row[x0], row[x0 + 1], row[x0 + 2]);
                *f = std::array::from_fn(|k| 0.75 * (b[k] + c[k]) + 0.25 * (a[k] + d[k]));
            } else {
                let mut s = [0.0f32; K];
                for (x, v) in row.iter().enumerate().take((x0 + 3).min(w)).skip(x0.saturating_sub(1)) {
                    let wx = weight(x, cx, cw);
                    for k in 0..K {
                        s[k] += wx * v[k];
                    }
                }
                *f = s;
            }
        }
    });
    let folded = &folded[..cw * h];
    for_rows(out, cw, |(cy, orow)| {
        orow.iter_mut().for_each(|o| *o = [0.0; K]);
        for y in (2 * cy).saturating_sub(1)..(2 * cy + 3).min(h) {
            let wy = weight(y, cy, ch);
            if wy == 0.0 {
                continue;
            }
            for (o, f) in orow.iter_mut().zip(&folded[y * cw..(y + 1) * cw]) {
                for k in 0..K {
                    o[k] += wy * f[k];
                }
            }
        }
        for (cx, o) in orow.iter_mut().enumerate() {
            if coarse.diag[cy * cw + cx] <= 0.0 {
                *o = [0.0; K];
            }
        }
    });
}

/// Bilinear prolongation of the coarse values `e` (on the 2 × 2 blocks of `grid`) into `u` (on
/// `grid`) at every fine cell where `free(p)`. Adding (`ADD`), the correction is added with the
/// full weights (inactive cells hold 0, so corrections fade towards fixed pixels); otherwise `u`
/// becomes the interpolation over the `active` cells only (weights renormalised: an inactive
/// cell has no value).
pub(crate) fn prolong<const K: usize, const ADD: bool>(
    e: &[[f32; K]],
    active: impl Fn(usize) -> bool + Sync,
    u: &mut [[f32; K]],
    grid: Grid,
    free: impl Fn(usize) -> bool + Sync,
) {
    let (Grid { width: w, height: _ }, Grid { width: cw, height: ch }) = (grid, grid.blocks());
    debug_assert_eq!(u.len(), grid.len());
    debug_assert_eq!(e.len(), grid.blocks().len());
    for_rows(u, w, |(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            if !free(y * w + x) {
                continue;
            }
            let mut s = [0.0f32; K];
            let mut total = 0.0f32;
            for (c, wt) in stencil(x, y, cw, ch) {
                if active(c) {
                    total += wt;
                    for k in 0..K {
                        s[k] += wt * e[c][k];
                    }
                }
            }
            if ADD {
                for k in 0..K {
                    out[k] += s[k];
                }
            } else if total > 0.0 {
                *out = s.map(|v| v / total);
            }
        }
    });
}

/// The four coarse cells under fine cell (x, y) and their bilinear weights (cell-centred: its
/// own cell, the horizontal and vertical neighbours towards it, the diagonal one; clamped at the
/// border).
#[inline]
fn stencil(x: usize, y: usize, cw: usize, ch: usize) -> [(usize, f32); 4] {
    let (cx, cy) = (x / 2, y / 2);
    let ox = if x & 1 == 1 { (cx + 1).min(cw - 1) } else { cx.saturating_sub(1) };
    let oy = if y & 1 == 1 { (cy + 1).min(ch - 1) } else { cy.saturating_sub(1) };
    [(cy * cw + cx, 0.5625), (cy * cw + ox, 0.1875), (oy * cw + cx, 0.1875), (oy * cw + ox, 0.0625)]
}
