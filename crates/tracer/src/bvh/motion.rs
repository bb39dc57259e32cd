//! Triangles that move within the shutter (motion triangles, as Cycles': each corner stored
//! at every motion step and interpolated linearly between the two steps around the ray's time).
//!
//! They get a tree of their own, beside the static one, so that static geometry is traced as
//! without a shutter: a scene with nothing moving has no motion tree, and its queries run the
//! static walk alone. The tree is built over each triangle's box over the whole shutter (the
//! union of its boxes at the steps: a corner interpolated between two steps stays in their
//! box), so one tree answers every time; the walk interpolates the triangles it tests to the
//! ray's time. Per-step trees would each need a second walk per query, or a tree per pair of
//! steps; a tree over the shutter's boxes costs only the looser boxes of what moves fast.

use super::Triangles;
use crate::scene::{Mesh, SceneMotion};
use crate::triangle::{TriangleHit, WatertightRay};
use glam::Vec3;

/// The moving triangles: their corners at every step and the tree over their shutter boxes.
pub(super) struct MotionTree {
    /// The tree over the triangles' shutter boxes (node 0 the root).
    pub nodes: Vec<super::node::WideNode>,
    /// Corners at every step, slot-major: slot s's step k at `s * steps + k`.
    pub corners: Vec<[[f32; 3]; 3]>,
    /// Motion slot → triangle index in the mesh.
    pub triangle_ids: Vec<u32>,
    /// Steps per triangle (≥ 2).
    pub steps: usize,
    /// Ray time of the first step.
    open: f32,
    /// Steps per unit of ray time after the first: (steps − 1) / (close − open).
    rate: f32,
}

/// Where a ray's time falls between the steps: the earlier step and the fraction to the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MotionAt {
    /// The step before the time (0 ..= steps − 2).
    pub step: usize,
    /// How far towards the next step, in [0, 1].
    pub f: f32,
}

impl MotionTree {
    /// The tree over the triangles `moving` (mesh indices) of `mesh`, their corners taken from
    /// `motion`'s steps.
    pub fn build(mesh: &Mesh, motion: &SceneMotion, moving: &[u32]) -> Self {
        let steps = motion.steps();
        let step_corners =
            |t: u32, k: usize| mesh.triangles[t as usize].map(|v| motion.positions[k][v as usize].to_array());
        let aabbs: Vec<obvhs::aabb::Aabb> = moving
            .iter()
            .map(|&t| {
                let mut lo = Vec3::splat(f32::INFINITY);
                let mut hi = Vec3::splat(f32::NEG_INFINITY);
                for k in 0..steps {
                    for p in step_corners(t, k) {
                        lo = lo.min(Vec3::from_array(p));
                        hi = hi.max(Vec3::from_array(p));
                    }
                }
                obvhs::aabb::Aabb::new(lo.into(), hi.into())
            })
            .collect();
        let cwbvh = super::build_in_range(aabbs);
        let triangle_ids: Vec<u32> = cwbvh.primitive_indices.iter().map(|&i| moving[i as usize]).collect();
        let corners: Vec<[[f32; 3]; 3]> =
            triangle_ids.iter().flat_map(|&t| (0..steps).map(move |k| step_corners(t, k))).collect();
        let nodes = super::widen(&cwbvh, &corners, steps);
        let span = motion.close - motion.open;
        Self { nodes, corners, triangle_ids, steps, open: motion.open, rate: (steps - 1) as f32 / span }
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

    /// Motion slot `slot`'s corners at `at`: (1 − f)·p + f·q, which is p at f = 0 and q at
    /// f = 1 exactly, each coordinate clamped to the two steps' range, so rounding never takes
    /// it outside the box the tree holds it in.
    #[inline(always)]
    pub fn corners_at(&self, slot: usize, at: MotionAt) -> [[f32; 3]; 3] {
        let i = slot * self.steps + at.step;
        let (a, b) = (&self.corners[i], &self.corners[i + 1]);
        let g = 1.0 - at.f;
        std::array::from_fn(|c| {
            std::array::from_fn(|x| {
                let (p, q) = (a[c][x], b[c][x]);
                (p * g + q * at.f).clamp(p.min(q), p.max(q))
            })
        })
    }
}

/// The moving triangles at one time, as the walk tests them.
pub(super) struct Moving<'a> {
    pub tree: &'a MotionTree,
    pub at: MotionAt,
}

impl Triangles for Moving<'_> {
    #[inline(always)]
    fn test(&self, ray: &WatertightRay, slot: usize, t_max: f32) -> Option<TriangleHit> {
        ray.intersect(&self.tree.corners_at(slot, self.at), t_max)
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
        let tree = MotionTree {
            nodes: vec![],
            corners: vec![],
            triangle_ids: vec![],
            steps: 3,
            open: 10.0,
            rate: 4.0,
        };
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
        let tree = MotionTree {
            nodes: vec![],
            corners: vec![a, b],
            triangle_ids: vec![0],
            steps: 2,
            open: 0.0,
            rate: 1.0,
        };
        for k in 0..=64 {
            let at = tree.at(k as f32 / 64.0);
            let c = tree.corners_at(0, at);
            for v in 0..3 {
                for x in 0..3 {
                    let (lo, hi) = (a[v][x].min(b[v][x]), a[v][x].max(b[v][x]));
                    assert!(c[v][x] >= lo && c[v][x] <= hi, "{k}: {:?}", c[v]);
                }
            }
        }
        assert_eq!(tree.corners_at(0, tree.at(0.0)), a, "the first step exactly");
        assert_eq!(tree.corners_at(0, tree.at(1.0)), b, "the last step exactly");
    }
}
