//! The acceleration structure: a wide BVH8 built by obvhs as a compressed wide BVH (Ylitie et
//! al. 2017, obvhs's medium preset) over the scene's triangles, with closest-hit and occlusion
//! (any-hit, early exit) queries. obvhs types stay behind this module.
//!
//! obvhs builds the tree; traversal is ours, on the same tree stored uncompressed
//! (`node.rs`), which is how its traps (docs/design/tracer.md §3.2) are closed and what makes a query
//! cheap:
//! - child boxes are exact f32 boxes of their triangles, tested with no 1e-4 entry cut-off,
//!   so nearby geometry in small scenes is never culled; slab order and reciprocals come from
//!   one sanitised direction (obvhs's test misses everything for a −0.0 component and clamps
//!   components below f32::EPSILON); exits are widened by 1 + 2γ₃ (Ize, "Robust BVH Ray
//!   Traversal", JCGT 2(2), 2013) so rounding never culls a box that holds a hit;
//! - children are visited nearest first from a fixed stack (no allocation per query);
//! - triangles are stored in the order obvhs's leaves reference them (slots);
//! - the triangle test is our watertight one (`crate::triangle`), in world space on the
//!   original vertices (obvhs's Möller–Trumbore test is not watertight);
//! - a ray spawned at a hit skips the triangle it leaves and the leaf-mates wholly behind it
//!   (`leaving.rs`): those tests could only miss;
//! - triangles that move within the shutter have trees of their own (`motion.rs`), one per
//!   segment between motion steps, the one at the ray's time walked after the static one; a
//!   scene without motion has none;
//! - instances (`instances.rs`) have a tree of their own over the copies, each copy walked in
//!   its mesh's space down that mesh's one tree; a scene without instances has none.

mod instances;
mod leaving;
mod motion;
mod node;
mod orient;
mod walk;

use crate::ray::Ray;
use crate::scene::{Mesh, SceneInstances, SceneMotion};
use crate::triangle::TriangleHit;
use glam::{Affine3A, Vec3};
use instances::InstanceTree;
pub use leaving::Leaving;
use leaving::SlotSides;
use motion::{MotionTrees, Moving};
use node::WideNode;
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use walk::{Fixed, QueryRay, STACK, Step, Tree, Triangles, Walk, blocks, test_all, walk};

/// A ray–scene intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit-direction) ray.
    pub t: f32,
    /// Index of the triangle in the scene's mesh.
    pub triangle: u32,
    /// Slot of the triangle in the BVH's own storage (for [`Bvh::triangle`] and
    /// [`Bvh::leaving`]).
    pub slot: u32,
    /// Barycentric weights of the triangle's three corners at the hit.
    pub barycentrics: [f32; 3],
    /// The ray's time (frames): where a moving triangle was when it was hit.
    pub time: f32,
}

/// A bounding-volume hierarchy over a mesh's triangles.
pub struct Bvh {
    /// The tree; node 0 is the root (empty when there are no triangles).
    nodes: Vec<WideNode>,
    /// World-space corners, stored in BVH slot order.
    triangles: Vec<[[f32; 3]; 3]>,
    /// Slot → triangle index in the mesh.
    triangle_ids: Vec<u32>,
    /// Triangle index in the mesh → slot.
    slot_of: Vec<u32>,
    /// Per static slot: its plane and the leaf-mates on each side (what rays leaving it skip).
    sides: Vec<SlotSides>,
    /// The triangles that move within the shutter, in slots after the static ones (a tree per
    /// segment between motion steps, each numbering all of them); `None` when nothing moves.
    motion: Option<Box<MotionTrees>>,
    /// The instances, in slots after the moving triangles; `None` when there are none.
    instances: Option<Box<InstanceTree>>,
}

/// How far past the best hit so far a closest-hit walk keeps looking, as a factor: far enough
/// that a triangle whose rounded distance equals it passes the triangle test's range check
/// (which compares unrounded, scaled distances), so ties are broken by triangle index.
const TIE_RANGE: f32 = 1.0 + 4.0 * f32::EPSILON;

/// Above this magnitude (2^60 ≈ 1.2e18) the boxes are rescaled before obvhs builds on them.
/// Its builder works in f32 on surface areas and costs, which overflow for boxes past ~1e19;
/// the corrupted tree then made it index out of bounds (a scene 1e21 across panicked in
/// `tests/stress/`, `denormal_and_huge_coordinates_give_no_nan`).
const BUILD_RANGE: f32 = (1u64 << 60) as f32;

/// Builds the CWBVH over `aabbs`. Scenes beyond [`BUILD_RANGE`] are built on their boxes scaled
/// by 2^−k (largest coordinate brought near 2^40), and the nodes scaled back by 2^k: powers of
/// two scale exactly (each node is p + q·2^(e−127), so p·2^k and e + k), so the tree's boxes are
/// the ones it would have in world space. Scaled box corners that lose bits to the denormal
/// range are rounded outwards, so every box still holds its triangle.
fn build_in_range(mut aabbs: Vec<Aabb>) -> CwBvh {
    let largest = aabbs.iter().map(|b| b.min.abs().max(b.max.abs()).max_element()).fold(0.0f32, f32::max);
    let k = if largest > BUILD_RANGE {
        // The binary exponent of `largest` (≤ 127 for finite input), less 40.
        ((largest.to_bits() >> 23) as i32 - 127) - 40
    } else {
        0
    };
    let (down, up) = (f32::from_bits(((127 - k) as u32) << 23), f32::from_bits(((127 + k) as u32) << 23));
    if k > 0 {
        let outwards = |v: glam::Vec3A, lower: bool| {
            let scaled = v * down;
            // Exact unless it fell into the denormal range; then step outwards if it moved in.
            let fix = |s: f32, x: f32| match (lower, s * up) {
                (true, back) if back > x => s.next_down(),
                (false, back) if back < x => s.next_up(),
                _ => s,
            };
            glam::Vec3A::new(fix(scaled.x, v.x), fix(scaled.y, v.y), fix(scaled.z, v.z))
        };
        for b in &mut aabbs {
            *b = Aabb::new(outwards(b.min, true), outwards(b.max, false));
        }
    }
    // obvhs's `build_cwbvh`, step by step (the same calls, the same tree), so that the boxes
    // are freed once the binary tree holds them: a big scene's peak is this conversion's
    // (docs/performance.md, ledger: "boxes freed before the conversion").
    let config = BvhBuildParams::medium_build();
    let indices = (0..aabbs.len() as u32).collect();
    let mut bvh2 = obvhs::ploc::PlocBuilder::with_capacity(aabbs.len()).build(
        config.ploc_search_distance,
        &aabbs,
        indices,
        config.sort_precision,
        config.search_depth_threshold,
    );
    drop(aabbs);
    obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(
        &mut bvh2,
        config.reinsertion_batch_ratio,
        None,
    );
    let mut cwbvh =
        obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(&bvh2, config.max_prims_per_leaf.clamp(1, 3), true, false);
    drop(bvh2);
    if k > 0 {
        for node in &mut cwbvh.nodes {
            node.p *= up;
            for e in &mut node.e {
                // e = 0 is a zero extent (a point), which stays one. e + k cannot pass 254
                // for boxes inside the f32 range; saturating would only enlarge the boxes.
                if *e != 0 {
                    *e = (*e as i32 + k).min(254) as u8;
                }
            }
        }
        let scale_back = |b: &mut Aabb| *b = Aabb::new(b.min * up, b.max * up);
        scale_back(&mut cwbvh.total_aabb);
        cwbvh.exact_node_aabbs.iter_mut().flatten().for_each(scale_back);
    }
    cwbvh
}

impl Bvh {
    /// Builds the BVH over every triangle of `mesh` (obvhs medium preset).
    pub fn build(mesh: &Mesh) -> Self {
        Self::build_static(mesh, (0..mesh.triangle_count() as u32).collect())
    }

    /// Builds the BVH over `mesh` whose triangles `moving` (one flag per triangle) move as
    /// `motion`'s steps say: those go in the motion tree, answered at each ray's time, the rest
    /// in the static tree exactly as [`Bvh::build`] would hold them.
    pub fn build_moving(mesh: &Mesh, motion: &SceneMotion, moving: &[bool]) -> Self {
        Self::build_scene(mesh, Some((motion, moving)), None)
    }

    /// Builds the BVH over `mesh` with its triangles that `moving` flags (as
    /// [`Bvh::build_moving`]) in the motion tree, and those `instances` draw held as instances
    /// of their meshes (each mesh's triangles once, whatever the copies); the rest in the
    /// static tree exactly as [`Bvh::build`] would hold them.
    pub fn build_scene(
        mesh: &Mesh,
        moving: Option<(&SceneMotion, &[bool])>,
        instances: Option<&SceneInstances>,
    ) -> Self {
        let mut in_copy = vec![false; if instances.is_some() { mesh.triangle_count() } else { 0 }];
        for i in instances.iter().flat_map(|s| &s.instances) {
            let count = instances.map_or(0, |s| s.meshes[i.mesh as usize].triangle_count());
            in_copy[i.first as usize..i.first as usize + count].fill(true);
        }
        let (mut still, mut moved) = (Vec::new(), Vec::new());
        for t in 0..mesh.triangle_count() {
            if in_copy.get(t) == Some(&true) {
                continue;
            }
            let m = moving.is_some_and(|(_, moving)| moving[t]);
            if m { moved.push(t as u32) } else { still.push(t as u32) }
        }
        let mut bvh = Self::build_static(mesh, still);
        if let Some((motion, _)) = moving.filter(|_| !moved.is_empty()) {
            let tree = MotionTrees::build(mesh, motion, &moved);
            let first = bvh.triangles.len() as u32;
            let needed = moved.iter().max().map_or(0, |&m| m as usize + 1);
            bvh.slot_of.resize(bvh.slot_of.len().max(needed), 0);
            // A moving triangle's slot is the first segment's (the opening's).
            for (slot, &t) in tree.trees[0].triangle_ids.iter().enumerate() {
                bvh.slot_of[t as usize] = first + slot as u32;
            }
            bvh.motion = Some(Box::new(tree));
        }
        if let Some(instances) = instances.filter(|s| !s.instances.is_empty()) {
            let first = bvh.triangles.len() + bvh.motion.as_ref().map_or(0, |m| m.count * m.trees.len());
            let first = first as u32;
            bvh.instances = Some(Box::new(InstanceTree::build(instances, first)));
        }
        bvh
    }

    /// The static tree over the mesh triangles `ids`.
    fn build_static(mesh: &Mesh, ids: Vec<u32>) -> Self {
        let aabbs: Vec<Aabb> = ids
            .iter()
            .map(|&t| {
                let [a, b, c] = mesh.corners(t as usize).map(glam::Vec3A::from);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let cwbvh = if aabbs.is_empty() { CwBvh::default() } else { build_in_range(aabbs) };
        let triangle_ids: Vec<u32> = cwbvh.primitive_indices.iter().map(|&i| ids[i as usize]).collect();
        let triangles: Vec<[[f32; 3]; 3]> =
            triangle_ids.iter().map(|&t| mesh.corners(t as usize).map(|p| p.to_array())).collect();
        // Only as long as the largest triangle held here needs: an instance's triangles are
        // found through the instances, and the copies cost no entry.
        let mut slot_of = vec![0u32; ids.iter().max().map_or(0, |&m| m as usize + 1)];
        for (slot, &t) in triangle_ids.iter().enumerate() {
            slot_of[t as usize] = slot as u32;
        }
        let nodes = if triangles.is_empty() { Vec::new() } else { widen(&cwbvh, &triangles, 1) };
        let sides = sides_of(&nodes, &triangles);
        Self { nodes, triangles, triangle_ids, slot_of, sides, motion: None, instances: None }
    }

    /// Refits the tree to `mesh` with its vertices moved (the same triangles: a skinned or
    /// morphing scene at another frame): every triangle and box updated in place, the tree's
    /// structure kept, no new build. Cheaper than [`Bvh::build`] by far, at the price of
    /// looser boxes where the pose strays far from the one the tree was built for. False (and
    /// nothing changed) when `mesh` has other triangles or the tree has moving ones.
    pub fn refit(&mut self, mesh: &Mesh) -> bool {
        if self.motion.is_some() || self.instances.is_some() || mesh.triangle_count() != self.slot_of.len() {
            return false;
        }
        use rayon::prelude::*;
        self.triangles.par_iter_mut().zip(&self.triangle_ids).for_each(|(tri, &t)| {
            let [a, b, c] = mesh.corners(t as usize);
            *tri = [a.to_array(), b.to_array(), c.to_array()];
        });
        fit_boxes(&mut self.nodes, &self.triangles, 1);
        self.sides = sides_of(&self.nodes, &self.triangles);
        true
    }

    /// What a ray spawned at a hit on the triangle in `slot`, along `direction`, skips: that
    /// triangle, and (a static one) the triangles of its leaf wholly on the other side of its
    /// plane. A moving triangle's plane depends on the time: its ray skips only itself, which
    /// it cannot hit again at the same time.
    #[inline(always)]
    pub fn leaving(&self, slot: u32, direction: Vec3) -> Leaving {
        match self.sides.get(slot as usize) {
            Some(sides) => sides.leaving(slot, direction),
            None => match &self.instances {
                Some(instances) if instances.holds(slot) => instances.leaving(slot, direction),
                _ => Leaving::slot(slot),
            },
        }
    }

    /// Number of triangles (every copy's; a moving one once, though each segment has a slot for it).
    pub fn len(&self) -> usize {
        self.triangles.len()
            + self.motion.as_ref().map_or(0, |m| m.count)
            + self.instances.as_ref().map_or(0, |i| i.slots())
    }

    /// Number of triangles the BVH stores: an instanced mesh's once, whatever its copies.
    pub fn stored_triangles(&self) -> usize {
        self.triangles.len()
            + self.motion.as_ref().map_or(0, |m| m.count)
            + self.instances.as_ref().map_or(0, |i| i.stored_triangles())
    }

    /// Bytes the trees, their triangles and the slot tables take.
    pub fn bytes(&self) -> usize {
        let motion = self.motion.as_ref().map_or(0, |m| m.bytes());
        std::mem::size_of_val(&self.nodes[..])
            + std::mem::size_of_val(&self.triangles[..])
            + std::mem::size_of_val(&self.triangle_ids[..])
            + std::mem::size_of_val(&self.slot_of[..])
            + std::mem::size_of_val(&self.sides[..])
            + motion
            + self.instances.as_ref().map_or(0, |i| i.bytes())
    }

    /// True when the BVH holds instances.
    pub fn has_instances(&self) -> bool {
        self.instances.is_some()
    }

    /// True when the BVH holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True when some triangle moves within the shutter.
    pub fn has_motion(&self) -> bool {
        self.motion.is_some() || self.instances.as_ref().is_some_and(|i| i.has_motion())
    }

    /// The world-space corners of mesh triangle `triangle` (by its index in the mesh); a
    /// moving triangle's at the shutter's opening. Not for a shared mesh's triangle, which
    /// every copy of it draws: [`Bvh::triangle_at`] its slot.
    #[inline]
    pub fn triangle_corners_by_id(&self, triangle: u32) -> [Vec3; 3] {
        let slot = self.instances.as_ref().and_then(|i| i.slot_of(triangle));
        let slot = slot.unwrap_or_else(|| self.slot_of[triangle as usize]);
        self.triangle_at(slot, f32::NEG_INFINITY).map(Vec3::from_array)
    }

    /// The world-space corners of the triangle in `slot` at ray time `time` (frames); a static
    /// triangle's are the same at every time.
    #[inline(always)]
    pub fn triangle_at(&self, slot: u32, time: f32) -> [[f32; 3]; 3] {
        match self.triangles.get(slot as usize) {
            Some(tri) => *tri,
            None => match self.moving(slot) {
                Some((m, k, s)) => m.corners_at(k, s, time),
                None => {
                    self.instances.as_ref().and_then(|i| i.triangle_at(slot, time)).unwrap_or([[0.0; 3]; 3])
                }
            },
        }
    }

    /// The number of slots of the static tree: every slot from here on is a moving
    /// triangle's or a copy's.
    #[inline(always)]
    pub fn static_slots(&self) -> usize {
        self.triangles.len()
    }

    /// For the slot of a copy of a shared mesh (held once in the scene's mesh, in its own
    /// space), how the copy moves that mesh's attributes; `None` for any other slot.
    #[inline]
    pub fn shared_copy(&self, slot: u32) -> Option<&crate::scene::Placement> {
        self.instances.as_ref()?.shared(slot)
    }

    /// For the slot of a copy of a shared mesh, its triangle's world corners (as
    /// [`Bvh::triangle_at`] gives them) and how the copy moves the mesh's attributes.
    #[inline]
    pub fn shared_hit(&self, slot: u32) -> Option<([[f32; 3]; 3], &crate::scene::Placement)> {
        self.instances.as_ref()?.shared_hit(slot)
    }

    /// True when the triangle in `slot` moves within the shutter.
    #[inline(always)]
    pub fn is_moving(&self, slot: u32) -> bool {
        slot as usize >= self.triangles.len()
            && (self.moving(slot).is_some() || self.instances.as_ref().is_some_and(|i| i.moves(slot)))
    }

    /// For the slot of a copy that moves rigidly within the shutter, the transform taking its
    /// points at the shutter's opening to where they are at `time` (shading normals turn
    /// with it); `None` for any other slot.
    #[inline]
    pub fn rigid_motion(&self, slot: u32, time: f32) -> Option<Affine3A> {
        self.instances.as_ref()?.motion_from_open(slot, time)
    }

    /// Where ray time `time` falls between the motion steps, as (the step before it, the
    /// fraction to the next): what a moving triangle's attributes are interpolated by. (0, 0)
    /// when nothing moves.
    #[inline]
    pub fn motion_step(&self, time: f32) -> (usize, f32) {
        self.motion.as_ref().map_or((0, 0.0), |m| {
            let at = m.at(time);
            (at.step, at.f)
        })
    }

    /// The motion trees, the segment and the slot in its tree for global `slot`, if that is
    /// a moving triangle's.
    #[inline(always)]
    fn moving(&self, slot: u32) -> Option<(&MotionTrees, usize, usize)> {
        let s = (slot as usize).checked_sub(self.triangles.len())?;
        let m = self.motion.as_deref()?;
        m.slot(s).map(|(k, s)| (m, k, s))
    }

    /// The closest hit along `ray` in (0, t_max), if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        self.intersect_from(ray, t_max, Leaving::NOTHING, |_, _| true)
    }

    /// The closest hit along `ray` in (0, t_max), but for the triangles `leaving` skips
    /// ([`Bvh::leaving`]), that `accept(triangle, barycentrics)` lets through (alpha-tested
    /// surfaces: a rejected hit does not shorten the ray).
    #[inline]
    pub fn intersect_from(
        &self,
        ray: &Ray,
        t_max: f32,
        leaving: Leaving,
        accept: impl Fn(u32, [f32; 3]) -> bool,
    ) -> Option<Hit> {
        self.closest::<STACK>(ray, t_max, leaving, accept)
    }

    /// [`Bvh::intersect_with`] with a stack of `N` entries.
    #[inline(always)]
    fn closest<const N: usize>(
        &self,
        ray: &Ray,
        t_max: f32,
        leaving: Leaving,
        accept: impl Fn(u32, [f32; 3]) -> bool,
    ) -> Option<Hit> {
        if self.nodes.is_empty() && self.motion.is_none() && self.instances.is_none() {
            return None;
        }
        let q = QueryRay::new(ray);
        // The best hit so far in scalars, not an `Option<(u32, TriangleHit)>`: LLVM copied that
        // one's barycentrics with an 8-byte load across two 4-byte stores, which the CPU
        // cannot forward, so every accepted hit stalled
        // (docs/performance.md, ledger: "closest hit in scalars").
        let (mut best_slot, mut best_id) = (u32::MAX, 0);
        let (mut t, mut b0, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0);
        // Hits at exactly the same distance (coincident triangles, a ray through a shared edge)
        // go to the lowest mesh triangle, whichever the walk meets first: the answer is then
        // the tree's shape's business no more, so a refitted tree answers as a fresh one
        // (`animate` refits per frame, and a resumed shot must keep a continuous run's bits).
        // The range stays open a hair past the best hit so that a tie is still tested (the
        // triangle test's range check is on the unrounded distance).
        let mut on_hit = |slot: u32, id: u32, h: TriangleHit| {
            let better = best_slot == u32::MAX || h.t < t || (h.t == t && id < best_id);
            if better && accept(id, h.b) {
                best_slot = slot;
                best_id = id;
                t = h.t;
                [b0, b1, b2] = h.b;
                Step::Closer(h.t * TIE_RANGE)
            } else {
                Step::Miss
            }
        };
        let mut t_max = t_max;
        if !self.nodes.is_empty() {
            let tree = self.fixed();
            let (walk, t_left) = walk::<N, true, _>(&tree, &q, t_max, leaving, &mut on_hit);
            t_max = t_left;
            if walk == Walk::Overflow {
                t_max = test_all(&tree, &q, t_max, leaving, &mut on_hit).1;
            }
        }
        if let Some(tree) = self.moving_at(ray.time) {
            let (walk, t_left) = walk::<N, true, _>(&tree, &q, t_max, leaving, &mut on_hit);
            t_max = t_left;
            if walk == Walk::Overflow {
                t_max = test_all(&tree, &q, t_left, leaving, &mut on_hit).1;
            }
        }
        if let Some(instances) = &self.instances {
            instances.walk::<N, true>(ray, &q, t_max, leaving, &mut on_hit);
        }
        (best_slot != u32::MAX).then_some(Hit {
            t,
            triangle: best_id,
            slot: best_slot,
            barycentrics: [b0, b1, b2],
            time: ray.time,
        })
    }

    /// True when something blocks `ray` in (0, t_max). Stops at the first blocker found.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.occluded_from(ray, t_max, Leaving::NOTHING, |_, _| true)
    }

    /// True when a hit that `accept(triangle, barycentrics)` lets through blocks `ray` in
    /// (0, t_max), but for the triangles `leaving` skips ([`Bvh::leaving`]).
    #[inline]
    pub fn occluded_from(
        &self,
        ray: &Ray,
        t_max: f32,
        leaving: Leaving,
        accept: impl Fn(u32, [f32; 3]) -> bool,
    ) -> bool {
        self.any::<STACK>(ray, t_max, leaving, accept)
    }

    /// [`Bvh::occluded_from`] with a stack of `N` entries.
    #[inline(always)]
    fn any<const N: usize>(
        &self,
        ray: &Ray,
        t_max: f32,
        leaving: Leaving,
        accept: impl Fn(u32, [f32; 3]) -> bool,
    ) -> bool {
        if self.nodes.is_empty() && self.motion.is_none() && self.instances.is_none() {
            return false;
        }
        let q = QueryRay::new(ray);
        let mut on_hit =
            |_: u32, id: u32, h: TriangleHit| if accept(id, h.b) { Step::Stop } else { Step::Miss };
        if !self.nodes.is_empty() && blocks::<N, _>(&self.fixed(), &q, t_max, leaving, &mut on_hit) {
            return true;
        }
        if self.moving_at(ray.time).is_some_and(|tree| blocks::<N, _>(&tree, &q, t_max, leaving, &mut on_hit))
        {
            return true;
        }
        self.instances.as_ref().is_some_and(|i| i.walk::<N, false>(ray, &q, t_max, leaving, &mut on_hit).0)
    }

    /// The static tree, for a walk.
    #[inline(always)]
    fn fixed(&self) -> Tree<'_, Fixed<'_>> {
        Tree { nodes: &self.nodes, tris: Fixed(&self.triangles), first: 0, ids: &self.triangle_ids }
    }

    /// The motion tree of the segment slice ray time `time` falls in, for a walk, if any.
    #[inline(always)]
    fn moving_at(&self, time: f32) -> Option<Tree<'_, Moving<'_>>> {
        let m = self.motion.as_deref()?;
        let at = m.at(time);
        let i = m.tree_at(at);
        let tree = &m.trees[i];
        let first = (self.triangles.len() + i * m.count) as u32;
        Some(Tree { nodes: &tree.nodes, tris: Moving { tree, f: at.f }, first, ids: &tree.triangle_ids })
    }
}

/// The obvhs tree with exact child boxes: node i here is obvhs's node i; a leaf child's box
/// is the box of its triangles, an inner child's the union of its children's. `triangles`
/// holds `stride` corner sets per slot (a moving triangle's at every step, whose box is the
/// union of all).
fn widen(cwbvh: &CwBvh, triangles: &[[[f32; 3]; 3]], stride: usize) -> Vec<WideNode> {
    let mut nodes = vec![WideNode::EMPTY; cwbvh.nodes.len()];
    for (src, wide) in cwbvh.nodes.iter().zip(&mut nodes) {
        for c in 0..8 {
            if src.is_child_empty(c) {
                continue;
            }
            if src.is_leaf(c) {
                let (first, count) = src.child_primitives(c);
                wide.index[c] = first;
                wide.count[c] = count as u8;
                wide.leaves |= 1 << c;
            } else {
                wide.index[c] = src.child_node_index(c);
                wide.inner |= 1 << c;
            }
        }
    }
    fit_boxes(&mut nodes, triangles, stride);
    nodes
}

/// Sets every child box of `nodes` (whose structure is set) from `triangles` (`stride` corner
/// sets per slot): what building does once and refitting does per frame.
///
/// obvhs numbers every inner node after its parent, so one pass from the last node to the root
/// sees each child's box before its parent needs it; a tree numbered otherwise is visited in
/// an order found by a walk from the root. Boxes are SIMD min/max folds over the corners in
/// slot order, with no per-node allocation (docs/performance.md, ledger: "refit: exact sides
/// in integers").
fn fit_boxes(nodes: &mut [WideNode], triangles: &[[[f32; 3]; 3]], stride: usize) {
    use glam::Vec3A;
    if nodes.is_empty() {
        return;
    }
    let children_after = nodes
        .iter()
        .enumerate()
        .all(|(i, n)| (0..8).filter(|&c| n.inner >> c & 1 != 0).all(|c| n.index[c] as usize > i));
    let order: Vec<usize> = if children_after {
        (0..nodes.len()).rev().collect()
    } else {
        // Parents before children (depth-first from the root), reversed.
        let (mut order, mut pending) = (Vec::with_capacity(nodes.len()), vec![0usize]);
        while let Some(i) = pending.pop() {
            order.push(i);
            let n = &nodes[i];
            pending.extend((0..8).filter(|&c| n.inner >> c & 1 != 0).map(|c| n.index[c] as usize));
        }
        order.reverse();
        order
    };
    let empty = (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY));
    let mut bounds = vec![empty; nodes.len()];
    for i in order {
        let wide = &mut nodes[i];
        let mut total = empty;
        for c in 0..8 {
            let (lo, hi) = if wide.leaves >> c & 1 != 0 {
                let (first, count) = (wide.index[c] as usize, wide.count[c] as usize);
                let (mut lo, mut hi) = empty;
                for tri in &triangles[first * stride..(first + count) * stride] {
                    for p in tri {
                        let p = Vec3A::new(p[0], p[1], p[2]);
                        (lo, hi) = (lo.min(p), hi.max(p));
                    }
                }
                (lo, hi)
            } else if wide.inner >> c & 1 != 0 {
                bounds[wide.index[c] as usize]
            } else {
                continue;
            };
            // A child with no corner keeps the empty box, which no ray enters.
            wide.set_box(c, lo.into(), hi.into());
            total = (total.0.min(lo), total.1.max(hi));
        }
        bounds[i] = total;
    }
}

/// Every slot's sides (`leaving.rs`), from the leaves of `nodes`.
fn sides_of(nodes: &[WideNode], triangles: &[[[f32; 3]; 3]]) -> Vec<SlotSides> {
    let leaves: Vec<(u32, u32)> = nodes
        .iter()
        .flat_map(|n| (0..8).filter(|&c| n.leaves >> c & 1 != 0).map(|c| (n.index[c], n.count[c] as u32)))
        .collect();
    leaving::slot_sides(&leaves, triangles)
}

#[cfg(test)]
mod instance_tests;
#[cfg(test)]
mod tests;
