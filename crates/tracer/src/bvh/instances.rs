//! Two levels: a tree per unique mesh in its own space (bottom), and a tree over the instances
//! placing them (top), so the triangles and their trees are stored once per mesh, whatever the
//! number of copies (docs/design/tracer.md §3.13).
//!
//! A query walks the top tree in world space; at an instance it takes the ray into the mesh's
//! space (by the instance's inverse transform, or for one that moves, its transform at the ray's
//! time inverted) without normalising the direction, so t is the world ray's parameter and a
//! hit's t and barycentrics mean what they mean in world space, and walks the mesh's tree there
//! with the same watertight test and nearest-first walk as the static tree. Instance k's slots
//! follow the slots before it (`base`): a slot names one copy's triangle, so what a spawned ray
//! skips (`leaving.rs`, decided in the mesh's space) carries over unchanged.
//!
//! A moving instance's box in the top tree holds the mesh's box at every time of the shutter:
//! the boxes at sub-steps fine enough that the rotation turns at most [`SUB_TURN`] between two,
//! widened by what a point can stray from the chord between them (φ·|S·x| for a turn φ).

use super::leaving::Leaving;
use super::node::WideNode;
use super::walk::{Fixed, QueryRay, Step, Tree, Walk, test_all, walk, walk_nodes};
use super::{Bvh, build_in_range, widen};
use crate::ray::Ray;
use crate::scene::{Mesh, Placement, RigidMotion, SceneInstances};
use crate::triangle::TriangleHit;
use glam::{Affine3A, Vec3};

/// The most a moving instance turns between two of the sub-steps its top box is built from
/// (radians).
const SUB_TURN: f32 = 0.02;

/// One placed copy of a mesh.
pub(super) struct Placed {
    /// Its mesh's tree in [`InstanceTree::meshes`].
    mesh: u32,
    /// Its first triangle in the scene's mesh.
    first: u32,
    /// Its first slot.
    base: u32,
    /// Local to world (a moving instance's at the shutter's opening).
    world: Affine3A,
    /// World to local, for an instance that does not move.
    inverse: Affine3A,
    /// Its transform over the shutter (boxed: most copies stand still).
    motion: Option<Box<RigidMotion>>,
    /// How it moves its mesh's attributes, when the scene's mesh holds that mesh once in its
    /// own space (shared) rather than this copy's triangles in world space.
    shared: Option<Box<Placement>>,
}

/// The instances: each unique mesh's tree and the tree over the copies.
pub(super) struct InstanceTree {
    /// Per unique mesh, its tree in local space (static, one level).
    meshes: Vec<Bvh>,
    /// The copies, in the order the top tree's leaves number them; `base` increases.
    placed: Vec<Placed>,
    /// The tree over the copies' world boxes.
    top: Vec<WideNode>,
    /// (first triangle, copy) sorted by first triangle.
    by_triangle: Vec<(u32, u32)>,
    /// The first slot past the last copy's.
    end: u32,
}

impl InstanceTree {
    /// The tree over `instances`, their slots numbered from `first_slot`.
    pub(super) fn build(instances: &SceneInstances, first_slot: u32) -> Self {
        let meshes: Vec<Bvh> = instances
            .meshes
            .iter()
            .map(|m| {
                let mesh = Mesh {
                    positions: m.positions.clone(),
                    triangles: m.triangles.clone(),
                    material_ids: vec![0; m.triangles.len()],
                    ..Mesh::default()
                };
                Bvh::build(&mesh)
            })
            .collect();
        let local_boxes: Vec<(Vec3, Vec3)> = meshes.iter().map(local_box).collect();
        let world_boxes: Vec<(Vec3, Vec3)> = instances
            .instances
            .iter()
            .map(|i| match &i.motion {
                None => transformed_box(local_boxes[i.mesh as usize], &i.world),
                Some(m) => swept_box(local_boxes[i.mesh as usize], m),
            })
            .collect();
        let aabbs =
            world_boxes.iter().map(|&(lo, hi)| obvhs::aabb::Aabb::new(lo.into(), hi.into())).collect();
        let cwbvh = build_in_range(aabbs);
        // A box as the three corners `widen` fits a leaf's box to.
        let as_corners: Vec<[[f32; 3]; 3]> = cwbvh
            .primitive_indices
            .iter()
            .map(|&k| {
                let (lo, hi) = world_boxes[k as usize];
                [lo.to_array(), hi.to_array(), hi.to_array()]
            })
            .collect();
        let top = widen(&cwbvh, &as_corners, 1);
        let mut base = first_slot;
        let placed: Vec<Placed> = cwbvh
            .primitive_indices
            .iter()
            .map(|&k| {
                let i = &instances.instances[k as usize];
                let p = Placed {
                    mesh: i.mesh,
                    first: i.first,
                    base,
                    world: i.world,
                    inverse: i.world.inverse(),
                    motion: i.motion.clone().map(Box::new),
                    shared: instances.meshes[i.mesh as usize]
                        .shared
                        .then(|| Box::new(Placement::new(&i.world))),
                };
                base += meshes[i.mesh as usize].len() as u32;
                p
            })
            .collect();
        // A shared mesh's copies all name one range: no triangle number tells them apart.
        let mut by_triangle: Vec<(u32, u32)> = placed
            .iter()
            .enumerate()
            .filter(|(_, p)| p.shared.is_none())
            .map(|(k, p)| (p.first, k as u32))
            .collect();
        by_triangle.sort_unstable();
        Self { meshes, placed, top, by_triangle, end: base }
    }

    /// How many triangles the trees store (each unique mesh's once).
    pub(super) fn stored_triangles(&self) -> usize {
        self.meshes.iter().map(Bvh::len).sum()
    }

    /// Bytes the trees and their triangles take.
    pub(super) fn bytes(&self) -> usize {
        self.meshes.iter().map(Bvh::bytes).sum::<usize>()
            + self.placed.len() * std::mem::size_of::<Placed>()
            + self.placed.iter().filter_map(|p| p.motion.as_deref()).map(RigidMotion::bytes).sum::<usize>()
            + self.placed.iter().filter(|p| p.shared.is_some()).count() * std::mem::size_of::<Placement>()
            + std::mem::size_of_val(&self.top[..])
            + std::mem::size_of_val(&self.by_triangle[..])
    }

    /// How many slots the copies number (one per triangle per copy).
    pub(super) fn slots(&self) -> usize {
        (self.end - self.placed.first().map_or(self.end, |p| p.base)) as usize
    }

    /// True when some copy moves within the shutter.
    pub(super) fn has_motion(&self) -> bool {
        self.placed.iter().any(|p| p.motion.is_some())
    }

    /// The copy whose slots hold `slot`, and the slot in its mesh's tree.
    #[inline]
    fn copy_of_slot(&self, slot: u32) -> Option<(&Placed, u32)> {
        if slot >= self.end {
            return None;
        }
        let k = self.placed.partition_point(|p| p.base <= slot).checked_sub(1)?;
        let p = &self.placed[k];
        Some((p, slot - p.base))
    }

    /// The copy drawing the scene's triangle `triangle`, and the triangle in its mesh.
    #[inline]
    fn copy_of_triangle(&self, triangle: u32) -> Option<(&Placed, u32)> {
        let k = self.by_triangle.partition_point(|&(first, _)| first <= triangle).checked_sub(1)?;
        let p = &self.placed[self.by_triangle[k].1 as usize];
        let local = triangle - p.first;
        (local < self.meshes[p.mesh as usize].len() as u32).then_some((p, local))
    }

    /// How the copy whose slots hold `slot` moves its mesh's attributes, when its mesh is
    /// shared.
    #[inline]
    pub(super) fn shared(&self, slot: u32) -> Option<&Placement> {
        self.copy_of_slot(slot)?.0.shared.as_deref()
    }

    /// For the slot of a copy of a shared mesh, its triangle's world corners and how the copy
    /// moves the mesh's attributes, found with one search (a shared copy stands still).
    #[inline]
    pub(super) fn shared_hit(&self, slot: u32) -> Option<([[f32; 3]; 3], &Placement)> {
        let (p, local) = self.copy_of_slot(slot)?;
        let place = p.shared.as_deref()?;
        let tri = self.meshes[p.mesh as usize].triangle_at(local, 0.0);
        Some((tri.map(|c| p.world.transform_point3(Vec3::from_array(c)).to_array()), place))
    }

    /// True when `slot` is a copy's, and that copy moves.
    #[inline]
    pub(super) fn moves(&self, slot: u32) -> bool {
        self.copy_of_slot(slot).is_some_and(|(p, _)| p.motion.is_some())
    }

    /// True when `slot` is a copy's.
    #[inline]
    pub(super) fn holds(&self, slot: u32) -> bool {
        self.copy_of_slot(slot).is_some()
    }

    /// The world-space corners of the triangle in `slot` at ray time `time`: the local ones
    /// moved by the copy's transform (a still copy's by the very transform the scene's mesh
    /// was flattened with, so the same bits).
    #[inline]
    pub(super) fn triangle_at(&self, slot: u32, time: f32) -> Option<[[f32; 3]; 3]> {
        let (p, local) = self.copy_of_slot(slot)?;
        let m = p.motion.as_ref().map_or(p.world, |m| m.at(time));
        let tri = self.meshes[p.mesh as usize].triangle_at(local, time);
        Some(tri.map(|c| m.transform_point3(Vec3::from_array(c)).to_array()))
    }

    /// The slot of the scene's triangle `triangle`, if a copy draws it.
    #[inline]
    pub(super) fn slot_of(&self, triangle: u32) -> Option<u32> {
        let (p, local) = self.copy_of_triangle(triangle)?;
        Some(p.base + self.meshes[p.mesh as usize].slot_of[local as usize])
    }

    /// The transform taking the world-space points of a moving copy's `slot` at the shutter's
    /// opening to where they are at `time`; `None` for a slot that is not a moving copy's.
    #[inline]
    pub(super) fn motion_from_open(&self, slot: u32, time: f32) -> Option<Affine3A> {
        let (p, _) = self.copy_of_slot(slot)?;
        let m = p.motion.as_ref()?;
        Some(m.at(time) * p.inverse)
    }

    /// What a ray leaving the triangle in `slot` along `direction` skips: in a still copy, what
    /// it skips in the copy's mesh (sides decided in local space, where the direction is
    /// taken); in a moving one, only the triangle.
    #[inline]
    pub(super) fn leaving(&self, slot: u32, direction: Vec3) -> Leaving {
        match self.copy_of_slot(slot) {
            Some((p, local)) if p.motion.is_none() => {
                let d = p.inverse.transform_vector3(direction).normalize_or_zero();
                self.meshes[p.mesh as usize].leaving(local, d).shifted(p.base)
            }
            _ => Leaving::slot(slot),
        }
    }

    /// Walks the copies the ray meets within (0, t_max), each in its own space, handing hits
    /// to `on_hit` (slots and triangles numbered as the scene's). Returns true when `on_hit`
    /// stopped the walk, and the final t_max.
    #[inline(always)]
    pub(super) fn walk<const N: usize, const NEAREST_FIRST: bool>(
        &self,
        ray: &Ray,
        q: &QueryRay,
        t_max: f32,
        leaving: Leaving,
        on_hit: &mut impl FnMut(u32, u32, TriangleHit) -> Step,
    ) -> (bool, f32) {
        let mut visit = |first: u32, count: u32, t_max: &mut f32| {
            (first..first + count).any(|k| self.visit::<N, NEAREST_FIRST>(k, ray, t_max, leaving, on_hit))
        };
        let (walked, mut t_max) = walk_nodes::<N, NEAREST_FIRST>(&self.top, &q.node, t_max, &mut visit);
        match walked {
            Walk::Done => (false, t_max),
            Walk::Stopped => (true, t_max),
            Walk::Overflow => {
                let stopped = (0..self.placed.len() as u32).any(|k| visit(k, 1, &mut t_max));
                (stopped, t_max)
            }
        }
    }

    /// Copy `k`'s part of a walk: the ray in the copy's space, down its mesh's tree.
    #[inline(always)]
    fn visit<const N: usize, const NEAREST_FIRST: bool>(
        &self,
        k: u32,
        ray: &Ray,
        t_max: &mut f32,
        leaving: Leaving,
        on_hit: &mut impl FnMut(u32, u32, TriangleHit) -> Step,
    ) -> bool {
        let p = &self.placed[k as usize];
        let mesh = &self.meshes[p.mesh as usize];
        let inverse = match &p.motion {
            None => p.inverse,
            Some(m) => m.at(ray.time).inverse(),
        };
        let q =
            QueryRay::along(inverse.transform_point3(ray.origin), inverse.transform_vector3(ray.direction));
        let tree =
            Tree { nodes: &mesh.nodes, tris: Fixed(&mesh.triangles), first: p.base, ids: &mesh.triangle_ids };
        let mut mapped = |slot: u32, id: u32, h: TriangleHit| on_hit(slot, p.first + id, h);
        let (walked, t) = walk::<N, NEAREST_FIRST, _>(&tree, &q, *t_max, leaving, &mut mapped);
        *t_max = t;
        match walked {
            Walk::Done => false,
            Walk::Stopped => true,
            Walk::Overflow => {
                let (walked, t) = test_all(&tree, &q, *t_max, leaving, &mut mapped);
                *t_max = t;
                walked == Walk::Stopped
            }
        }
    }
}

/// The box of a mesh's tree (its triangles' corners).
fn local_box(mesh: &Bvh) -> (Vec3, Vec3) {
    let corners = mesh.triangles.iter().flatten().map(|&c| Vec3::from_array(c));
    corners.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

/// The world box of local box `b` placed by `m`, widened for the rounding of the transform
/// (and of the ray's into local space) by a relative 2^−16 of the box's size and place.
fn transformed_box((lo, hi): (Vec3, Vec3), m: &Affine3A) -> (Vec3, Vec3) {
    let (mut wlo, mut whi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for c in 0..8 {
        let corner = Vec3::select(glam::BVec3::new(c & 1 != 0, c & 2 != 0, c & 4 != 0), hi, lo);
        let p = m.transform_point3(corner);
        (wlo, whi) = (wlo.min(p), whi.max(p));
    }
    let pad = ((whi - wlo).max_element() + wlo.abs().max(whi.abs()).max_element()) * (1.0 / 65536.0);
    (wlo - Vec3::splat(pad), whi + Vec3::splat(pad))
}

/// The world box local box `b` sweeps while moving as `m` over the whole shutter: the boxes at
/// sub-steps at most [`SUB_TURN`] apart in rotation, each widened by what a point strays
/// from the chord between two sub-steps (at most φ/2·max|S·x|; widened by twice that).
fn swept_box(b: (Vec3, Vec3), m: &RigidMotion) -> (Vec3, Vec3) {
    // |S·x| for x in the box: the scale is linear between steps, so largest at one.
    let reach = b.0.abs().max(b.1.abs()).length() * m.largest_scale();
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let steps = m.steps();
    for k in 0..steps - 1 {
        // The rotation turns twice the quaternions' angle.
        let turn = 2.0 * m.arc_angle(k);
        let subs = ((turn / SUB_TURN).ceil() as usize).clamp(1, 4096);
        let (t0, t1) = (m.step_time(k), m.step_time(k + 1));
        for s in 0..=subs {
            let time = t0 + (t1 - t0) * s as f32 / subs as f32;
            let at = m.at(time);
            let stray = Vec3::splat(turn / subs as f32 * reach);
            let (blo, bhi) = transformed_box(b, &at);
            (lo, hi) = (lo.min(blo - stray), hi.max(bhi + stray));
        }
    }
    (lo, hi)
}
