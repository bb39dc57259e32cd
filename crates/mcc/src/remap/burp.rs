//! Step 5 of the remapper (docs/design/mcc.md §5.5): rays. A camera pixel of camera c gets exactly
//! R_c(p), bit for bit. A background pixel P gets the origin Σ_c α_c·A_c(e_c(P)) and the direction
//! by *burp* (Glassner's "bilinear uniform repeated" interpolation): order the cameras with α > 0
//! by ascending id, p_0 … p_{n−1} their directions D_c(e_c(P)); r_{n−1} = p_{n−1};
//! r_k = slerp(r_{k+1}, p_k, α_k / β_k) with β_k = Σ_{j≥k} α_j; the direction is r_0.
//! Each step is the accurate [`crate::slerp::slerp`], so nearly opposite eye rays stay exact
//! and no step yields NaN; α_k / β_k ≤ 1 because β_k ≥ α_k.

use super::grid::Layout;
use super::nearest::NearestEdges;
use crate::lanes::{avx2_twins, select, select3};
use crate::ray_file::StoredRay;
use crate::slerp::{NLERP_CHORD_SQUARED, along, arc, nlerp, slerp};
use glam::Vec3;
use rayon::prelude::*;

/// Burp of unit `directions` with `weights` (same order, ascending camera id); entries with a
/// weight ≤ 0 take no part. `None` when no weight is positive.
pub fn burp(directions: &[Vec3], weights: &[f32]) -> Option<Vec3> {
    let mut r: Option<Vec3> = None;
    let mut beta = 0.0f32;
    for (&p, &a) in directions.iter().zip(weights).rev() {
        if a.is_nan() || a <= 0.0 {
            continue;
        }
        beta += a;
        r = Some(match r {
            None => p,
            Some(r) => slerp(r, p, (a / beta).min(1.0)),
        });
    }
    r
}

/// Background pixels per step of the lane loop: AVX2's eight f32 lanes (two SSE2 registers on
/// the baseline).
const LANES: usize = 8;

/// One camera's part in a chunk of pixels: its weight and the source ray of its nearest edge
/// pixel, per lane, structure of arrays (so the lane loop reads whole vectors).
#[derive(Default)]
struct Step {
    weight: [f32; LANES],
    origin: Lanes3,
    direction: Lanes3,
}

/// A chunk's burp chains, one per lane: Σ α·origin, β = Σ α, and the direction so far (valid
/// once β > 0, i.e. once a camera has taken part).
#[derive(Default)]
struct Chains {
    origin: Lanes3,
    direction: Lanes3,
    beta: [f32; LANES],
}

/// Three lanes' worth of vectors, structure of arrays.
type Lanes3 = [[f32; LANES]; 3];

/// Lane `i` of `v`.
#[inline(always)]
fn lane(v: &Lanes3, i: usize) -> Vec3 {
    Vec3::new(v[0][i], v[1][i], v[2][i])
}

/// Writes lane `i` of `v`.
#[inline(always)]
fn set_lane(v: &mut Lanes3, i: usize, x: Vec3) {
    for (c, x) in v.iter_mut().zip(x.to_array()) {
        c[i] = x;
    }
}

impl Chains {
    /// The next camera down, in every lane: the scalar chain's operations, a lane at a time,
    /// each decision a select (the weight ≤ 0 or NaN: no part; the first camera: its direction;
    /// later ones: the slerp's paths, all computed). The sine and cosine are libm's, one lane at
    /// a time between two vector loops, as the scalar slerp calls them: same bits.
    /// `STARTED`: some lane has begun (else no slerp is needed).
    #[inline(always)]
    fn step<const STARTED: bool>(&mut self, s: &Step) {
        let (mut u, mut near, mut chord) = (Lanes3::default(), Lanes3::default(), [0f32; LANES]);
        let (mut angle, mut sin, mut cos) = ([0f32; LANES], [0f32; LANES], [0f32; LANES]);
        // The chain's fraction α_k / β_k, β_k the sum including this camera.
        let ts: [f32; LANES] = std::array::from_fn(|i| (s.weight[i] / (self.beta[i] + s.weight[i])).min(1.0));
        if STARTED {
            for i in 0..LANES {
                let (a, b) = (lane(&self.direction, i), lane(&s.direction, i));
                let d = b - a;
                let d2 = d.length_squared();
                let (arc_u, arc_angle) = arc(a, b, d, d2, ts[i]);
                set_lane(&mut u, i, arc_u);
                set_lane(&mut near, i, nlerp(a, d, ts[i]));
                chord[i] = d2;
                angle[i] = arc_angle;
            }
            for i in 0..LANES {
                (sin[i], cos[i]) = angle[i].sin_cos();
            }
        }
        for i in 0..LANES {
            let a = s.weight[i];
            let active = a > 0.0;
            let (origin, direction) = (lane(&self.origin, i), lane(&self.direction, i));
            let (source_origin, source_direction) = (lane(&s.origin, i), lane(&s.direction, i));
            let beta = self.beta[i];
            let next = if STARTED {
                let (t, r) = (ts[i], direction);
                let wide = along(r, lane(&u, i), sin[i], cos[i]);
                let slerped = select3(chord[i] < NLERP_CHORD_SQUARED, lane(&near, i), wide);
                let slerped = select3(t == 0.0, r, select3(t == 1.0, source_direction, slerped));
                select3(beta > 0.0, slerped, source_direction)
            } else {
                source_direction
            };
            set_lane(&mut self.origin, i, select3(active, origin + a * source_origin, origin));
            set_lane(&mut self.direction, i, select3(active, next, direction));
            self.beta[i] = select(active, beta + a, beta);
        }
    }
}

/// Reusable per-task buffer: the background columns of a row.
type Columns = Vec<u32>;

/// What every row of [`remapped_rays`] reads.
#[derive(Clone, Copy)]
struct Inputs<'a> {
    cam: &'a [u32],
    sources: &'a [StoredRay],
    nearest: &'a NearestEdges,
    planes: &'a [Vec<f32>],
}

/// One row of [`remapped_rays`]: camera pixels copied, background pixels in chunks of
/// [`LANES`] (the last chunk padded with its last pixel, computed and not written).
#[inline(always)]
fn burp_row_body(y: usize, row: &mut [StoredRay], columns: &mut Columns, inputs: Inputs) {
    let Inputs { cam, sources, nearest, planes } = inputs;
    let width = row.len();
    let base = y * width;
    columns.clear();
    for (x, out) in row.iter_mut().enumerate() {
        if cam[base + x] != 0 {
            *out = sources[base + x];
        } else {
            columns.push(x as u32);
        }
    }
    for chunk in columns.chunks(LANES) {
        let pixel: [usize; LANES] = std::array::from_fn(|i| base + chunk[i.min(chunk.len() - 1)] as usize);
        let mut chains = Chains::default();
        let mut step = Step::default();
        let mut started = false;
        // Burp runs from the highest id down; origins accumulate alongside.
        for (plane, edge) in planes.iter().zip(&nearest.planes).rev() {
            let mut any = false;
            for (i, &p) in pixel.iter().enumerate() {
                let a = plane[p];
                any |= a > 0.0;
                step.weight[i] = a;
                // Every background pixel has an edge pixel of every camera (the clamp only keeps
                // a lane without one, which would have no weight either, from indexing out).
                let source = sources[(edge[p] as usize).min(sources.len() - 1)];
                set_lane(&mut step.origin, i, source.origin);
                set_lane(&mut step.direction, i, source.direction);
            }
            if !any {
                continue;
            }
            if started {
                chains.step::<true>(&step);
            } else {
                chains.step::<false>(&step);
            }
            started = true;
        }
        for (i, &x) in chunk.iter().enumerate() {
            let beta = chains.beta[i];
            row[x as usize] = if beta > 0.0 {
                StoredRay::new(lane(&chains.origin, i) / beta, lane(&chains.direction, i))
            } else {
                // Unreachable after renormalisation; still a valid ray rather than a panic.
                sources[nearest.planes[0][pixel[i]] as usize]
            };
        }
    }
}

avx2_twins! {
    /// [`burp_row_body`] at the CPU's level: baseline x86-64 (SSE2: each step of eight lanes is
    /// two vectors) or AVX2 (each step one vector), the same bits.
    fn burp_row | burp_row_baseline | burp_row_avx2(
        y: usize,
        row: &mut [StoredRay],
        columns: &mut Columns,
        inputs: Inputs,
    ) => burp_row_body
}

/// The remapped rays of every pixel of `layout` from the merged `sources`, the `nearest` edge
/// pixels and the weight `planes`. Rows run in parallel; each pixel's result depends only on its
/// own inputs, and its lane computes the scalar chain's bits (the same as [`burp`] of its
/// directions and weights), so neither the thread count, the pixel's place in its chunk nor the
/// CPU's vector width changes a bit.
pub(crate) fn remapped_rays(
    layout: &Layout,
    sources: &[StoredRay],
    nearest: &NearestEdges,
    planes: &[Vec<f32>],
) -> Vec<StoredRay> {
    let cam = layout.cam;
    let mut rays = vec![StoredRay::default(); cam.len()];
    let inputs = Inputs { cam, sources, nearest, planes };
    rays.par_chunks_mut(layout.grid.width).enumerate().for_each_init(Columns::new, |columns, (y, row)| {
        burp_row(y, row, columns, inputs);
    });
    rays
}

/// The camera index with the largest weight at every pixel (ties to the smallest id; a camera
/// pixel's own camera).
pub(crate) fn dominant(cam: &[u32], planes: &[Vec<f32>]) -> Vec<u32> {
    (0..cam.len())
        .into_par_iter()
        .map(|p| {
            if cam[p] != 0 {
                return cam[p] - 1;
            }
            let mut best = 0;
            for k in 1..planes.len() {
                if planes[k][p] > planes[best][p] {
                    best = k;
                }
            }
            best as u32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slerp::angle_between;
    use crate::test_util::Rng;

    #[test]
    fn two_cameras_is_slerp() {
        let mut rng = Rng::new(6);
        for _ in 0..500 {
            let (a, b) = (rng.direction(), rng.direction());
            let w = rng.unit();
            let got = burp(&[a, b], &[w, 1.0 - w]).unwrap();
            // r_1 = b, r_0 = slerp(b, a, α_0 / (α_0 + α_1)).
            let want = slerp(b, a, w / (w + (1.0 - w)));
            assert!((got - want).length() < 1e-6);
        }
        assert_eq!(burp(&[Vec3::X, Vec3::Y], &[0.0, 1.0]), Some(Vec3::Y));
        assert_eq!(burp(&[Vec3::X, Vec3::Y], &[1.0, 0.0]), Some(Vec3::X));
        assert_eq!(burp(&[Vec3::X], &[0.0]), None);
    }

    #[test]
    fn always_unit_even_for_nearly_opposite_directions() {
        let mut rng = Rng::new(7);
        for n in 1..40 {
            let base = rng.direction();
            let dirs: Vec<Vec3> = (0..n)
                .map(|k| {
                    // Alternate nearly-opposite and random directions.
                    let jitter = rng.direction() * 1e-6;
                    if k % 3 == 0 {
                        (-base + jitter).normalize()
                    } else if k % 3 == 1 {
                        base
                    } else {
                        rng.direction()
                    }
                })
                .collect();
            let weights: Vec<f32> = (0..n).map(|_| rng.unit()).collect();
            let sum: f32 = weights.iter().sum();
            let weights: Vec<f32> = weights.iter().map(|w| w / sum).collect();
            let d = burp(&dirs, &weights).unwrap();
            assert!(d.is_finite() && (d.length() - 1.0).abs() < 1e-6, "{n}: {d}");
        }
        // Exactly opposite pair with equal weights: a quarter turn on the documented circle.
        let d = burp(&[Vec3::Z, -Vec3::Z], &[0.5, 0.5]).unwrap();
        assert!((angle_between(d, Vec3::Z) - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    }

    /// The lanes against the scalar chain (origins summed, directions by [`burp`]), bit for bit:
    /// random weights with zeros, NaNs, negatives and dominant ones, sources equal, nearly and
    /// exactly opposite, rows whose background is not a multiple of the lane count.
    #[test]
    fn lanes_give_the_scalar_chains_bits() {
        use crate::remap::nearest::NONE;
        let mut rng = Rng::new(12);
        let (w, h, cameras) = (37usize, 9usize, 4usize);
        let n = w * h;
        let cam: Vec<u32> =
            (0..n).map(|_| if rng.unit() < 0.3 { 1 + rng.below(cameras as u32) } else { 0 }).collect();
        let mut sources: Vec<StoredRay> =
            (0..n).map(|_| StoredRay::new(rng.direction() * 3.0, rng.direction())).collect();
        // A few sources equal, nearly opposite and exactly opposite to the first.
        let first = sources[0].direction;
        sources[1].direction = first;
        sources[2].direction = -first;
        sources[3].direction = (-first + Vec3::new(1e-6, 0.0, 0.0)).normalize();
        sources[4].direction = (first + Vec3::new(1e-3, 0.0, 0.0)).normalize();
        let edges: Vec<Vec<u32>> = (0..cameras)
            .map(|_| {
                (0..n)
                    .map(|p| match (cam[p], rng.below(3)) {
                        (0, 0) => rng.below(5),
                        (0, _) => rng.below(n as u32),
                        _ => NONE,
                    })
                    .collect()
            })
            .collect();
        let planes: Vec<Vec<f32>> = (0..cameras)
            .map(|_| {
                (0..n)
                    .map(|_| match rng.below(8) {
                        0 => 0.0,
                        1 => f32::NAN,
                        2 => -0.25,
                        3 => 1.0,
                        4 => 1e-30,
                        _ => rng.unit(),
                    })
                    .collect()
            })
            .collect();
        let nearest = NearestEdges { planes: edges, participates: Vec::new() };
        let bits = |r: &StoredRay| bytemuck::cast::<_, [u32; 6]>(*r);
        let grid = crate::remap::grid::Grid::new(w, h);
        let edges = crate::remap::edges::edge_mask(&cam, grid);
        let layout = Layout { grid, cam: &cam, edges: &edges, cameras };
        let rays = remapped_rays(&layout, &sources, &nearest, &planes);
        let mut baseline = vec![StoredRay::default(); n];
        let mut columns = Columns::new();
        for (y, row) in baseline.chunks_mut(w).enumerate() {
            let inputs = Inputs { cam: &cam, sources: &sources, nearest: &nearest, planes: &planes };
            burp_row_baseline(y, row, &mut columns, inputs);
        }
        let mut chains = 0;
        for p in 0..n {
            let want = if cam[p] != 0 {
                sources[p]
            } else {
                let (mut origin, mut beta) = (Vec3::ZERO, 0.0f32);
                let (mut directions, mut weights) = (Vec::new(), Vec::new());
                for k in (0..cameras).rev() {
                    let a = planes[k][p];
                    let source = sources[nearest.planes[k][p] as usize];
                    if a > 0.0 {
                        origin += a * source.origin;
                        beta += a;
                    }
                    directions.insert(0, source.direction);
                    weights.insert(0, a);
                }
                match burp(&directions, &weights) {
                    Some(d) => {
                        chains += 1;
                        StoredRay::new(origin / beta, d)
                    }
                    None => sources[nearest.planes[0][p] as usize],
                }
            };
            assert_eq!(bits(&rays[p]), bits(&want), "pixel {p}");
            assert_eq!(bits(&baseline[p]), bits(&want), "pixel {p}, baseline");
        }
        assert!(chains > n / 2, "{chains} chains");
    }

    #[test]
    fn equal_directions_stay_put_and_weights_pull() {
        let d = burp(&[Vec3::X; 5], &[0.2; 5]).unwrap();
        assert_eq!(d, Vec3::X);
        // A dominant weight pulls the result close to its direction: the last step covers 98 % of
        // the quarter turn from the (Y, Z) midpoint to X.
        let d = burp(&[Vec3::X, Vec3::Y, Vec3::Z], &[0.98, 0.01, 0.01]).unwrap();
        assert!((angle_between(d, Vec3::X) - 0.02 * std::f32::consts::FRAC_PI_2).abs() < 1e-5);
        assert!((d.y - d.z).abs() < 1e-6);
    }
}
