//! Triangles that move within the shutter (motion triangles, as Cycles': each corner stored
//! at every motion step and interpolated linearly between the two steps around the ray's time).
//!
//! They get trees of their own, beside the static one, so that static geometry is traced as
//! without a shutter: a scene with nothing moving has no motion tree, and its queries run the
//! static walk alone. There are [`SLICES`] trees per pair of consecutive steps (a segment of
//! the shutter), each over every triangle's box over its slice of the segment in time (the
//! corners interpolated at the slice's ends: a corner interpolated between them stays in their
//! box); a ray walks the one tree of the slice its time falls in, which interpolates the
//! triangles it tests to the ray's time. One tree over the whole shutter's boxes answered every
//! time too, but its boxes held a fast mover's whole path, and rays through it tested far more
//! triangles (docs/performance.md §3.3, "a motion tree per segment", "time slices").
//! Per-step trees would need two walks per query.

use super::Triangles;
use crate::scene::{Mesh, SceneMotion};
use crate::triangle::{TriangleHit, WatertightRay};
use glam::Vec3;

/// Trees per segment: slice j of [`SLICES`] holds the triangles' boxes over the fractions
/// j / SLICES … (j + 1) / SLICES of the segment (measured: docs/performance.md §3.3).
const SLICES: usize = 2;

/// The moving triangles: [`SLICES`] [`MotionTree`]s per segment between consecutive steps.
/// Motion slot `i · count + s` is slot s of tree i, which is slice i mod SLICES of segment
/// i / SLICES.
pub(super) struct MotionTrees {
    /// Tree i, over slice i mod [`SLICES`] of the segment between steps i / SLICES and the next.
    pub trees: Vec<MotionTree>,
    /// How many triangles move (each tree holds all of them).
    pub count: usize,
    /// Steps (≥ 2).
    steps: usize,
    /// Ray time of the first step.
    open: f32,
    /// Steps per unit of ray time after the first: (steps − 1) / (close − open).
    rate: f32,
}

/// The moving triangles of one segment: their corners at its two steps and the tree over
/// their boxes.
pub(super) struct MotionTree {
    /// The tree over the triangles' segment boxes (node 0 the root).
    pub nodes: Vec<super::node::WideNode>,
    /// Corners at the segment's two steps, slot-major: slot s's earlier step at `2s`.
    pub corners: Vec<[[f32; 3]; 3]>,
    /// Motion slot → triangle index in the mesh.
    pub triangle_ids: Vec<u32>,
}

/// Where a ray's time falls between the steps: the earlier step and the fraction to the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MotionAt {
    /// The step before the time (0 ..= steps − 2).
    pub step: usize,
    /// How far towards the next step, in [0, 1].
    pub f: f32,
}

impl MotionTrees {
    /// The trees over the triangles `moving` (mesh indices) of `mesh`, their corners taken from
    /// `motion`'s steps; the segments' trees are built in parallel.
    pub fn build(mesh: &Mesh, motion: &SceneMotion, moving: &[u32]) -> Self {
        use rayon::prelude::*;
        let steps = motion.steps();
        let trees = (0..(steps - 1) * SLICES)
            .into_par_iter()
            .map(|i| MotionTree::build(mesh, motion, moving, i / SLICES, i % SLICES))
            .collect();
        let span = motion.close - motion.open;
        Self { trees, count: moving.len(), steps, open: motion.open, rate: (steps - 1) as f32 / span }
    }

    /// Where `time` falls between the steps; times outside the shutter hold its ends.
    #[inline(always)]
    pub fn at(&self, time: f32) -> MotionAt {
        let x = ((time - self.open) * self.rate).clamp(0.0, (self.steps - 1) as f32);
        // NaN (a NaN time) clamps to NaN; `as usize` maps it to 0, and f = 0 then holds step 0.
        let step = (x as usize).min(self.steps - 2);
        let f = x - step as f32;
        MotionAt { step, f: if f.is_nan() { 0.0 } else { f } }
    }

    /// The tree that answers a ray at `at`: its slice of its segment.
    #[inline(always)]
    pub fn tree_at(&self, at: MotionAt) -> usize {
        // f · SLICES is exact for a power of two; a fraction on a boundary is in both slices.
        at.step * SLICES + ((at.f * SLICES as f32) as usize).min(SLICES - 1)
    }

    /// Motion slot `slot`'s tree and its slot there, if it is one.
    #[inline(always)]
    pub fn slot(&self, slot: usize) -> Option<(usize, usize)> {
        let k = slot / self.count.max(1);
        (k < self.trees.len()).then(|| (k, slot - k * self.count))
    }

    /// Tree `i`'s slot `slot`'s corners at `time`: where its segment's triangle is at a time
    /// within the segment, its nearer end at a time outside it.
    #[inline(always)]
    pub fn corners_at(&self, i: usize, slot: usize, time: f32) -> [[f32; 3]; 3] {
        let (at, k) = (self.at(time), i / SLICES);
        let f = if at.step == k {
            at.f
        } else if at.step < k {
            0.0
        } else {
            1.0
        };
        self.trees[i].corners_at(slot, f)
    }

    /// Bytes the trees and their corners take.
    pub fn bytes(&self) -> usize {
        self.trees
            .iter()
            .map(|m| {
                std::mem::size_of_val(&m.nodes[..])
                    + std::mem::size_of_val(&m.corners[..])
                    + std::mem::size_of_val(&m.triangle_ids[..])
            })
            .sum()
    }
}

impl MotionTree {
    /// The tree over the triangles `moving` (mesh indices) of `mesh` between `motion`'s steps
    /// `k` and `k + 1`, over slice `j` of that segment: each triangle's box holds its corners
    /// interpolated at the slice's two ends (a linear path between them stays in it), widened
    /// by 2^−20 of the coordinates' magnitude, far more than the few ulps by which the rounded
    /// interpolation of [`MotionTree::corners_at`] within the slice can stray from them.
    fn build(mesh: &Mesh, motion: &SceneMotion, moving: &[u32], k: usize, j: usize) -> Self {
        let step_corners =
            |t: u32, k: usize| mesh.triangles[t as usize].map(|v| motion.positions[k][v as usize].to_array());
        let (f0, f1) = (j as f32 / SLICES as f32, (j + 1) as f32 / SLICES as f32);
        let slice_box = |t: u32| {
            let ends = Self {
                nodes: vec![],
                corners: vec![step_corners(t, k), step_corners(t, k + 1)],
                triangle_ids: vec![],
            };
            let (a, b) = (ends.corners_at(0, f0), ends.corners_at(0, f1));
            let mut lo = Vec3::splat(f32::INFINITY);
            let mut hi = Vec3::splat(f32::NEG_INFINITY);
            for c in 0..3 {
                let (p, q) = (Vec3::from_array(ends.corners[0][c]), Vec3::from_array(ends.corners[1][c]));
                let margin = p.abs().max(q.abs()) * (1.0 / (1 << 20) as f32) + Vec3::splat(f32::MIN_POSITIVE);
                let (u, v) = (Vec3::from_array(a[c]), Vec3::from_array(b[c]));
                lo = lo.min(u.min(v) - margin);
                hi = hi.max(u.max(v) + margin);
            }
            (lo, hi)
        };
        let boxes: Vec<(Vec3, Vec3)> = moving.iter().map(|&t| slice_box(t)).collect();
        let aabbs = boxes.iter().map(|&(lo, hi)| obvhs::aabb::Aabb::new(lo.into(), hi.into())).collect();
        let cwbvh = super::build_in_range(aabbs);
        let order = &cwbvh.primitive_indices;
        let triangle_ids: Vec<u32> = order.iter().map(|&i| moving[i as usize]).collect();
        let corners: Vec<[[f32; 3]; 3]> =
            triangle_ids.iter().flat_map(|&t| [step_corners(t, k), step_corners(t, k + 1)]).collect();
        // The leaves' boxes are the slice boxes: two corner sets per slot, one at each extreme.
        let extremes: Vec<[[f32; 3]; 3]> = order
            .iter()
            .flat_map(|&i| {
                let (lo, hi) = boxes[i as usize];
                [[lo.to_array(); 3], [hi.to_array(); 3]]
            })
            .collect();
        let nodes = super::widen(&cwbvh, &extremes, 2);
        Self { nodes, corners, triangle_ids }
    }

    /// Slot `slot`'s corners a fraction `f` from the earlier step to the later: (1 − f)·p +
    /// f·q, which is p at f = 0 and q at f = 1 exactly, each coordinate clamped to the two
    /// steps' range, so rounding never takes it outside the box the tree holds it in.
    #[inline(always)]
    pub fn corners_at(&self, slot: usize, f: f32) -> [[f32; 3]; 3] {
        let (a, b) = (&self.corners[2 * slot], &self.corners[2 * slot + 1]);
        let g = 1.0 - f;
        std::array::from_fn(|c| {
            std::array::from_fn(|x| {
                let (p, q) = (a[c][x], b[c][x]);
                (p * g + q * f).clamp(p.min(q), p.max(q))
            })
        })
    }
}

/// The moving triangles of one segment at a fraction `f` through it, as the walk tests them.
pub(super) struct Moving<'a> {
    pub tree: &'a MotionTree,
    pub f: f32,
}

impl Triangles for Moving<'_> {
    #[inline(always)]
    fn test(&self, ray: &WatertightRay, slot: usize, t_max: f32) -> Option<TriangleHit> {
        ray.intersect(&self.tree.corners_at(slot, self.f), t_max)
    }

    fn len(&self) -> usize {
        self.tree.triangle_ids.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_map_to_steps_and_fractions() {
        let tree = MotionTrees { trees: vec![], count: 0, steps: 3, open: 10.0, rate: 4.0 };
        assert_eq!(tree.at(10.0), MotionAt { step: 0, f: 0.0 });
        assert_eq!(tree.at(10.125), MotionAt { step: 0, f: 0.5 });
        assert_eq!(tree.at(10.25), MotionAt { step: 1, f: 0.0 });
        assert_eq!(tree.at(10.5), MotionAt { step: 1, f: 1.0 }, "the closing time is the last step");
        assert_eq!(tree.at(11.0), MotionAt { step: 1, f: 1.0 }, "after the shutter: held");
        assert_eq!(tree.at(9.0), MotionAt { step: 0, f: 0.0 }, "before it: held");
        assert_eq!(tree.at(f32::NAN), MotionAt { step: 0, f: 0.0 });
    }

    #[test]
    fn interpolated_corners_stay_between_the_steps() {
        let a = [[1e8f32, -1.0, 0.3], [0.0, 0.0, 0.0], [1.0, 2.0, 3.0]];
        let b = [[-1.0f32, 1e8, 0.1], [0.0, 1.0, 0.0], [1.0, 2.0, 3.0]];
        let tree = MotionTree { nodes: vec![], corners: vec![a, b], triangle_ids: vec![0] };
        for k in 0..=64 {
            let c = tree.corners_at(0, k as f32 / 64.0);
            for v in 0..3 {
                for x in 0..3 {
                    let (lo, hi) = (a[v][x].min(b[v][x]), a[v][x].max(b[v][x]));
                    assert!(c[v][x] >= lo && c[v][x] <= hi, "{k}: {:?}", c[v]);
                }
            }
        }
        assert_eq!(tree.corners_at(0, 0.0), a, "the first step exactly");
        assert_eq!(tree.corners_at(0, 1.0), b, "the last step exactly");
    }
}
