//! One camera's smooth ray field for the seamless blend (docs/design/mcc.md §5.8): the camera's
//! edge rays extended over every other pixel by the membrane ([`super::membrane`]), in place of
//! the column's nearest edge ray, whose choice jumps across medial axes.
//!
//! Directions are interpolated in a tangent frame: the azimuthal equidistant map (the sphere's
//! logarithm) about the camera's mean edge direction, which is smooth and exact in angle near that
//! direction and singular only at its antipode, so views up to nearly a full turn wide extend
//! without the cancellation that averaging unit vectors suffers. Origins are interpolated as
//! points, and not at all when every edge ray shares one origin (pinholes).

use super::grid::{Grid, Layout};
use super::membrane::{Free, Membrane, prolong, relax};
use crate::ray_file::StoredRay;
use crate::slerp::angle_between;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::ops::Range;

/// Relative residual at which the membrane solves stop. What error is left is smooth: it bends
/// the field by far less than a pixel's step (docs/design/mcc.md §5.8).
const TOLERANCE: f64 = 1e-4;
/// Red–black sweeps of the membrane on the pixels after the interpolation from 2 × 2 blocks.
const RELAX_SWEEPS: usize = 4;
/// How far from the camera's pixels (in pixels, along rows and columns) the sweeps reach: the
/// interpolation errs near them only, and a sweep moves a change by a pixel or two.
const RELAX_REACH: usize = 8;
/// Iterations a solve may take (a handful reach [`TOLERANCE`]; docs/performance.md).
const MAX_ITERATIONS: usize = 30;

/// The azimuthal equidistant map about a unit direction.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TangentFrame {
    centre: Vec3,
    u: Vec3,
    v: Vec3,
}

impl TangentFrame {
    /// The frame about the normalised sum of `directions` (+z if they cancel out).
    pub(crate) fn around(directions: impl Iterator<Item = Vec3>) -> Self {
        let sum: DVec3 = directions.map(|d| d.as_dvec3()).sum();
        let centre = sum.try_normalize().map_or(Vec3::Z, |c| c.as_vec3());
        let (u, v) = centre.any_orthonormal_pair();
        Self { centre, u, v }
    }

    /// Tangent coordinates of unit `d`: its angle from the centre along its bearing.
    #[inline]
    pub(crate) fn log(&self, d: Vec3) -> [f32; 2] {
        let (a, b) = (d.dot(self.u), d.dot(self.v));
        let sine = (a * a + b * b).sqrt();
        if sine == 0.0 {
            // The centre itself (or its antipode, the map's one singular point: any bearing).
            return if d.dot(self.centre) >= 0.0 { [0.0, 0.0] } else { [std::f32::consts::PI, 0.0] };
        }
        let angle = angle_between(self.centre, d);
        [a / sine * angle, b / sine * angle]
    }

    /// The unit direction of tangent coordinates `t`.
    #[inline]
    pub(crate) fn exp(&self, t: [f32; 2]) -> Vec3 {
        let angle = (t[0] * t[0] + t[1] * t[1]).sqrt();
        if angle < 1e-12 {
            return self.centre;
        }
        let (sin, cos) = angle.sin_cos();
        let bearing = (self.u * t[0] + self.v * t[1]) / angle;
        (self.centre * cos + bearing * sin).normalize()
    }
}

/// A camera's field over the picture: tangent coordinates of every pixel's direction, and its
/// origin.
pub(crate) struct CameraField {
    frame: TangentFrame,
    /// Tangent coordinates (only read at other pixels than the camera's own).
    tangent: Vec<[f32; 2]>,
    /// Origins, row-major; `None` when all are `origin`.
    origins: Option<Vec<[f32; 3]>>,
    origin: Vec3,
}

impl CameraField {
    /// The field's direction at pixel `p` (not one of the camera's own).
    #[inline]
    pub(crate) fn direction(&self, p: usize) -> Vec3 {
        self.frame.exp(self.tangent[p])
    }

    /// The field's origin at pixel `p`.
    #[inline]
    pub(crate) fn origin(&self, p: usize) -> Vec3 {
        self.origins.as_ref().map_or(self.origin, |o| Vec3::from_array(o[p]))
    }
}

/// The solvers the fields of one picture share (their buffers are reused camera after camera).
/// Each field is solved on the grid of 2 × 2 blocks, interpolated bilinearly and relaxed on the
/// pixels (docs/design/mcc.md §5.8).
pub(crate) struct FieldSolvers {
    grid: Grid,
    directions: Membrane<2>,
    origins: Membrane<3>,
    /// Blocks holding a pixel of the camera (the coarse membrane's fixed cells).
    fixed: Vec<bool>,
    /// Per row, the pixels the relaxing sweeps visit.
    spans: Vec<Range<usize>>,
}

impl FieldSolvers {
    /// Solvers for pictures on `grid`.
    pub(crate) fn new(grid: Grid) -> Self {
        let (directions, origins) = (Membrane::new(grid.blocks()), Membrane::new(grid.blocks()));
        Self { grid, directions, origins, fixed: Vec::new(), spans: Vec::new() }
    }

    /// The field of camera `c` of `layout` (its pixels are those with `cam[p] == c`) from the
    /// merged `sources`: the membrane of its edge rays over every pixel that is not its own. Rows
    /// run in parallel; the result does not depend on the thread count.
    pub(crate) fn field(&mut self, layout: &Layout, c: u32, sources: &[StoredRay]) -> CameraField {
        let Layout { cam, edges, .. } = *layout;
        debug_assert_eq!(layout.grid, self.grid);
        let n = cam.len();
        let edge = |p: usize| cam[p] == c && edges[p];
        let frame = TangentFrame::around((0..n).filter(|&p| edge(p)).map(|p| sources[p].direction));
        let grid = self.grid;
        let blocks = grid.blocks();
        self.fixed.clear();
        self.fixed.par_extend((0..blocks.len()).into_par_iter().map(|b| block(b, grid).any(|p| cam[p] == c)));
        relax_spans(&self.fixed, grid, &mut self.spans);
        let on = Blocks { grid, fixed: &self.fixed, spans: &self.spans };
        let own = |p: usize| cam[p] == c;
        let log = |p: usize| (cam[p] == c).then(|| frame.log(sources[p].direction));
        let tangent = block_field(&mut self.directions, on, own, edge, log);
        // Origins: one shared point (bit for bit) needs no membrane.
        let mut edge_origins = (0..n).filter(|&p| edge(p)).map(|p| sources[p].origin);
        let origin = edge_origins.next().unwrap_or(Vec3::ZERO);
        let bits = |o: Vec3| o.to_array().map(f32::to_bits);
        if edge_origins.all(|o| bits(o) == bits(origin)) {
            return CameraField { frame, tangent, origins: None, origin };
        }
        let point = |p: usize| (cam[p] == c).then(|| sources[p].origin.to_array());
        let on = Blocks { grid, fixed: &self.fixed, spans: &self.spans };
        let points = block_field(&mut self.origins, on, own, edge, point);
        CameraField { frame, tangent, origins: Some(points), origin }
    }
}

/// Per pixel row of `grid`, the pixels within [`RELAX_REACH`] (along rows and columns) of a
/// block with a pixel of the camera (`fixed`, on the grid's blocks), as one range: the extent of
/// those blocks in the nearby rows, widened by the reach.
fn relax_spans(fixed: &[bool], grid: Grid, spans: &mut Vec<Range<usize>>) {
    let (Grid { width: w, height: h }, Grid { width: cw, height: ch }) = (grid, grid.blocks());
    // Per block row, the first and last fixed block.
    let extents: Vec<Option<(usize, usize)>> = fixed
        .chunks(cw)
        .map(|row| Some((row.iter().position(|&f| f)?, row.iter().rposition(|&f| f)?)))
        .collect();
    let reach_blocks = RELAX_REACH.div_ceil(2);
    spans.clear();
    spans.extend((0..h).map(|y| {
        let cy = y / 2;
        let rows = cy.saturating_sub(reach_blocks)..(cy + reach_blocks + 1).min(ch);
        let (lo, hi) =
            extents[rows].iter().flatten().fold((usize::MAX, 0), |(lo, hi), &(a, b)| (lo.min(a), hi.max(b)));
        if lo > hi { 0..0 } else { (2 * lo).saturating_sub(RELAX_REACH)..(2 * hi + 2 + RELAX_REACH).min(w) }
    }));
}

/// The pixels of block `b` of `grid` (an index on its blocks).
fn block(b: usize, grid: Grid) -> impl Iterator<Item = usize> {
    let (Grid { width: w, height: h }, cw) = (grid, grid.blocks().width);
    let (x0, y0) = (2 * (b % cw), 2 * (b / cw));
    (y0..(y0 + 2).min(h)).flat_map(move |y| (x0..(x0 + 2).min(w)).map(move |x| y * w + x))
}

/// Ridge on the gradient of [`centre_value`]'s plane: where the camera's pixels near a block lie
/// on one line, the gradient across it is unknown and taken as 0 (the mean along the line).
const RIDGE: f64 = 1e-3;

/// The field at the centre of block `b` of `grid`, from the camera's
/// pixels (`value` is `Some` at them): their mean when the block is all the camera's, else the
/// least-squares plane through those of the 4 × 4 pixels around the block, at its centre. A
/// coarse cell's value stands for its centre: the mean of a partial block's pixels would
/// misplace the camera's border by up to a pixel, and the membrane with it (docs/design/mcc.md §5.8).
fn centre_value<const K: usize>(
    b: usize,
    grid: Grid,
    value: &impl Fn(usize) -> Option<[f32; K]>,
) -> [f32; K] {
    let (Grid { width: w, height: h }, cw) = (grid, grid.blocks().width);
    let (x0, y0) = (2 * (b % cw), 2 * (b / cw));
    let (mut sum, mut count) = ([0.0f32; K], 0);
    for v in block(b, grid).filter_map(value) {
        (0..K).for_each(|k| sum[k] += v[k]);
        count += 1;
    }
    if count == 4 {
        return sum.map(|s| s * 0.25);
    }
    // Normal equations of v ≈ a + g_x·dx + g_y·dy, (dx, dy) from the block's centre.
    let (mut m, mut rhs) = ([[0.0f64; 3]; 3], [[0.0f64; 3]; K]);
    for y in y0.saturating_sub(1)..(y0 + 3).min(h) {
        for x in x0.saturating_sub(1)..(x0 + 3).min(w) {
            let Some(v) = value(y * w + x) else { continue };
            let basis = [1.0, x as f64 - x0 as f64 - 0.5, y as f64 - y0 as f64 - 0.5];
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += basis[i] * basis[j];
                }
                for k in 0..K {
                    rhs[k][i] += basis[i] * v[k] as f64;
                }
            }
        }
    }
    m[1][1] += RIDGE;
    m[2][2] += RIDGE;
    // Cramer's rule for the constant term a.
    let det3 = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let det = det3(m);
    if det.abs() < 1e-12 {
        return [0.0; K];
    }
    std::array::from_fn(|k| {
        let mut a = m;
        (0..3).for_each(|i| a[i][0] = rhs[k][i]);
        (det3(a) / det) as f32
    })
}

/// A field solved on 2 × 2 blocks: blocks with a pixel of the camera (`fixed`) hold the field at
/// their centre ([`centre_value`], from the camera's own `value`s), the membrane fills the other
/// blocks, and the pixels that are not the camera's get the bilinear interpolation of the blocks,
/// relaxed by a few sweeps of the membrane on the pixels (which settle the step from the
/// camera's edge). `value` is `Some` exactly where `own`. Only blocks with an edge pixel of the camera (`edge`) need a value: any block
/// that a free block or a free pixel's interpolation touches has one (edges are 8-connected).
fn block_field<const K: usize>(
    membrane: &mut Membrane<K>,
    on: Blocks,
    own: impl Fn(usize) -> bool + Sync,
    edge: impl Fn(usize) -> bool + Sync,
    value: impl Fn(usize) -> Option<[f32; K]> + Sync,
) -> Vec<[f32; K]> {
    let Blocks { grid, fixed, spans } = on;
    let mut coarse: Vec<[f32; K]> = (0..grid.blocks().len())
        .into_par_iter()
        .map(|b| if fixed[b] && block(b, grid).any(&edge) { centre_value(b, grid, &value) } else { [0.0; K] })
        .collect();
    membrane.solve(|b| fixed[b], &mut coarse, TOLERANCE, MAX_ITERATIONS);
    let mut fine: Vec<[f32; K]> = (0..grid.len())
        .into_par_iter()
        .map(|p| if edge(p) { value(p).unwrap_or([0.0; K]) } else { [0.0; K] })
        .collect();
    prolong::<K, false>(&coarse, |_| true, &mut fine, grid, |p| !own(p));
    relax(&mut fine, Free { fixed: own, span: |y: usize| spans[y].clone() }, grid, RELAX_SWEEPS);
    fine
}

/// A camera's blocks on a picture's `grid`: which hold a pixel of the camera (`fixed`, one per
/// block) and, per pixel row, the pixels the relaxing sweeps visit (`spans`).
#[derive(Clone, Copy)]
struct Blocks<'a> {
    grid: Grid,
    fixed: &'a [bool],
    spans: &'a [Range<usize>],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::Rng;

    #[test]
    fn tangent_coordinates_round_trip_and_keep_angles() {
        let mut rng = Rng::new(12);
        for _ in 0..200 {
            let frame = TangentFrame::around([rng.direction()].into_iter());
            for _ in 0..20 {
                let d = rng.direction();
                let t = frame.log(d);
                // The coordinates' length is the angle from the centre.
                let angle = (t[0] * t[0] + t[1] * t[1]).sqrt();
                assert!((angle - angle_between(frame.centre, d)).abs() < 1e-6);
                // Away from the antipode the map inverts.
                if angle < 3.0 {
                    assert!(angle_between(frame.exp(t), d) < 2e-6, "{d} {t:?}");
                }
            }
        }
        let frame = TangentFrame::around([Vec3::X, Vec3::Y].into_iter());
        assert!((frame.centre - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-7);
        assert_eq!(frame.exp([0.0, 0.0]), frame.centre);
        assert_eq!(frame.log(frame.centre), [0.0, 0.0]);
        assert!(frame.exp(frame.log(-frame.centre)).is_finite());
        // Cancelling directions still give a frame.
        assert_eq!(TangentFrame::around([Vec3::X, -Vec3::X].into_iter()).centre, Vec3::Z);
    }

    #[test]
    fn a_ring_of_a_pinhole_fills_with_nearly_its_own_view() {
        // A ring of camera 1 around a background hole: the membrane of the ring's rays is close
        // to the pinhole's own rays in the hole (its tangent coordinates are nearly harmonic), and
        // a shared origin stays bit for bit.
        let (w, h) = (64, 48);
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let sources: Vec<StoredRay> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 + 0.5 - w as f32 / 2.0, (p / w) as f32 + 0.5 - h as f32 / 2.0);
                StoredRay::new(eye, Vec3::new(x * 0.01, -y * 0.01, -1.0).normalize())
            })
            .collect();
        let cam: Vec<u32> = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 - 32.0, (p / w) as f32 - 24.0);
                (x * x + y * y > 100.0) as u32
            })
            .collect();
        let grid = Grid::new(w, h);
        let edges = crate::remap::edges::edge_mask(&cam, grid);
        let layout = Layout { grid, cam: &cam, edges: &edges, cameras: 1 };
        let field = FieldSolvers::new(grid).field(&layout, 1, &sources);
        assert!(field.origins.is_none() && field.origin(0) == eye);
        let mut worst = 0.0f32;
        for p in (0..w * h).filter(|&p| cam[p] == 0) {
            worst = worst.max(angle_between(field.direction(p), sources[p].direction));
        }
        // A tenth of a pixel's step (0.01 rad).
        assert!(worst < 1e-3, "{worst}");
    }

    #[test]
    fn the_block_solve_stays_near_the_membrane_on_the_pixels() {
        // Two discs and a ring of camera 1 (medial axes between and inside them) with a curved
        // field of directions and of origins: the block solve against the membrane solved on
        // the pixels themselves (the definition, docs/design/mcc.md §5.8). The blocks put the
        // camera's border up to half a pixel off, which bends a curved field smoothly far from
        // it: within one pitch in angle and one origins' step, not the tenth the ring allows.
        let (w, h) = (160, 120);
        let at = |p: usize| ((p % w) as f32 - w as f32 / 2.0, (p / w) as f32 - h as f32 / 2.0);
        let sources: Vec<StoredRay> = (0..w * h)
            .map(|p| {
                let (x, y) = at(p);
                let (sx, sy) = (x * 0.01, y * 0.01);
                let direction = Vec3::new(sx + 0.3 * sx * sx, -sy + 0.2 * sx * sy, -1.0).normalize();
                StoredRay::new(Vec3::new(x * 0.02, y * 0.02 + 0.001 * x * x * 0.02, 1.0), direction)
            })
            .collect();
        let inside = |x: f32, y: f32, cx: f32, cy: f32, r: f32| (x - cx).powi(2) + (y - cy).powi(2) <= r * r;
        let cam: Vec<u32> = (0..w * h)
            .map(|p| {
                let (x, y) = at(p);
                let ring = inside(x, y, 40.0, 10.0, 25.0) && !inside(x, y, 40.0, 10.0, 12.5);
                (inside(x, y, -55.0, -20.0, 17.0) || inside(x, y, -25.0, 30.0, 13.0) || ring) as u32
            })
            .collect();
        let grid = Grid::new(w, h);
        let edges = crate::remap::edges::edge_mask(&cam, grid);
        let layout = Layout { grid, cam: &cam, edges: &edges, cameras: 1 };
        let field = FieldSolvers::new(grid).field(&layout, 1, &sources);
        let own = |p: usize| cam[p] == 1;
        let fine = |value: &dyn Fn(usize) -> Vec<f32>, k: usize| -> Vec<Vec<f32>> {
            (0..k)
                .map(|ch| {
                    let mut u: Vec<[f32; 1]> =
                        (0..w * h).map(|p| [if own(p) { value(p)[ch] } else { 0.0 }]).collect();
                    let solved = Membrane::<1>::new(Grid::new(w, h)).solve(own, &mut u, 1e-5, 60);
                    assert!(solved.relative_residual <= 1e-5, "{solved:?}");
                    u.iter().map(|v| v[0]).collect()
                })
                .collect()
        };
        let tangent = fine(&|p| field.frame.log(sources[p].direction).to_vec(), 2);
        let points = fine(&|p| sources[p].origin.to_array().to_vec(), 3);
        let (mut angle, mut distance) = (0.0f32, 0.0f32);
        for p in (0..w * h).filter(|&p| !own(p)) {
            let want = field.frame.exp([tangent[0][p], tangent[1][p]]);
            angle = angle.max(angle_between(field.direction(p), want));
            let want = Vec3::new(points[0][p], points[1][p], points[2][p]);
            distance = distance.max((field.origin(p) - want).length());
        }
        // Pitch 0.01 rad, origins' step 0.02 (measured: 8.7e-3 rad, 0.019; docs/performance.md,
        // ledger: "membrane on 2 × 2 blocks").
        assert!(angle < 1e-2 && distance < 2e-2, "{angle} rad, {distance}");
    }
}
