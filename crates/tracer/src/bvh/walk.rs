//! The walk down one tree: the query's ray, the triangles as a walk tests them, the fixed
//! stack, nearest-first order, and the fallback when the stack overflows.

use super::Leaving;
use super::node::{NodeRay, WideNode};
use crate::ray::Ray;
use crate::triangle::{TriangleHit, WatertightRay};
use glam::Vec3;
use std::mem::MaybeUninit;

/// A tree's triangles as its walk tests them: static corners, or moving ones at a time.
pub(super) trait Triangles {
    /// The hit of `ray` on the triangle in (this tree's) `slot` within (0, t_max).
    fn test(&self, ray: &WatertightRay, slot: usize, t_max: f32) -> Option<TriangleHit>;
    /// How many triangles.
    fn len(&self) -> usize;
}

/// One tree as a walk sees it: its nodes, its triangles, the global slot of its first
/// triangle and each slot's mesh triangle.
pub(super) struct Tree<'a, T> {
    pub nodes: &'a [WideNode],
    pub tris: T,
    pub first: u32,
    pub ids: &'a [u32],
}

/// Triangles that do not move.
pub(super) struct Fixed<'a>(pub &'a [[[f32; 3]; 3]]);

impl Triangles for Fixed<'_> {
    #[inline(always)]
    fn test(&self, ray: &WatertightRay, slot: usize, t_max: f32) -> Option<TriangleHit> {
        ray.intersect(&self.0[slot], t_max)
    }

    fn len(&self) -> usize {
        self.0.len()
    }
}

/// Everything a query needs about its ray, computed once.
pub(super) struct QueryRay {
    pub node: NodeRay,
    pub triangle: WatertightRay,
}

impl QueryRay {
    /// The query of `ray`.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        Self::along(ray.origin, ray.direction)
    }

    /// The query of the ray from `origin` along `direction` (of any length: an instance's
    /// local ray keeps the world ray's parameter t).
    #[inline(always)]
    pub fn along(origin: Vec3, direction: Vec3) -> Self {
        // +0.0 turns −0.0 into +0.0 (and leaves everything else alone), so the slab order
        // and the reciprocals agree.
        let d = direction + Vec3::ZERO;
        let node = NodeRay::new(origin, d);
        Self { triangle: WatertightRay::new(origin, d, node.inv_dir), node }
    }
}

/// What a triangle hit means to the query.
pub(super) enum Step {
    /// Not accepted: the hit does not count.
    Miss,
    /// Hit at this distance: only nearer hits matter from now on.
    Closer(f32),
    /// Hit, and that is all the query wanted.
    Stop,
}

/// How a walk ended.
#[derive(PartialEq)]
pub(super) enum Walk {
    /// Every node in range was visited.
    Done,
    /// A triangle test said stop.
    Stopped,
    /// The fixed stack was too small for this tree (never for trees obvhs builds in practice;
    /// the query then falls back to testing every triangle).
    Overflow,
}

/// Entries of the traversal stack: each level of the tree adds at most seven, so this holds
/// trees 36 levels deep (an 8-wide tree over 2^32 triangles needs about 11).
pub(super) const STACK: usize = 256;

/// Whether a hit that `on_hit` stops at blocks the ray in one tree (its walk, or on overflow
/// every triangle).
#[inline(always)]
pub(super) fn blocks<const N: usize, T: Triangles>(
    tree: &Tree<'_, T>,
    q: &QueryRay,
    t_max: f32,
    leaving: Leaving,
    on_hit: &mut impl FnMut(u32, u32, TriangleHit) -> Step,
) -> bool {
    match walk::<N, false, _>(tree, q, t_max, leaving, on_hit).0 {
        Walk::Done => false,
        Walk::Stopped => true,
        Walk::Overflow => test_all(tree, q, t_max, leaving, on_hit).0 == Walk::Stopped,
    }
}

/// Tests every triangle of a tree, in slot order (the fallback when a walk overflows its
/// stack). Returns how it ended and the final t_max.
#[cold]
pub(super) fn test_all<T: Triangles>(
    tree: &Tree<'_, T>,
    q: &QueryRay,
    mut t_max: f32,
    leaving: Leaving,
    on_hit: &mut impl FnMut(u32, u32, TriangleHit) -> Step,
) -> (Walk, f32) {
    let (tris, first) = (&tree.tris, tree.first);
    for (slot, &id) in tree.ids.iter().enumerate().take(tris.len()) {
        if leaving.skips(first + slot as u32) {
            continue;
        }
        if let Some(h) = tris.test(&q.triangle, slot, t_max) {
            match on_hit(first + slot as u32, id, h) {
                Step::Miss => {}
                Step::Closer(t) => t_max = t,
                Step::Stop => return (Walk::Stopped, t_max),
            }
        }
    }
    (Walk::Done, t_max)
}

/// Visits every node whose box the ray enters within (0, t_max), nearest first with
/// `NEAREST_FIRST` (closest-hit queries, where a near hit culls the far boxes) and in slot
/// order without (occlusion, where any hit ends the walk, so sorting buys nothing:
/// docs/performance.md, ledger: "unsorted occlusion walk"),
/// tests the triangles of their leaves (but those the ray is `leaving` skips) and hands
/// each hit to `on_hit(slot, triangle, hit)` (slots numbered from the tree's `first`, its
/// `ids` giving the mesh triangle), whose answer may shorten the ray or end the walk.
/// Returns how the walk ended and the final t_max.
#[inline(always)]
pub(super) fn walk<const N: usize, const NEAREST_FIRST: bool, T: Triangles>(
    tree: &Tree<'_, T>,
    q: &QueryRay,
    t_max: f32,
    leaving: Leaving,
    on_hit: &mut impl FnMut(u32, u32, TriangleHit) -> Step,
) -> (Walk, f32) {
    let Tree { nodes, tris, first: first_slot, ids } = tree;
    let first_slot = *first_slot;
    walk_nodes::<N, NEAREST_FIRST>(nodes, &q.node, t_max, &mut |first, count, t_max: &mut f32| {
        for slot in first..first + count {
            if leaving.skips(first_slot + slot) {
                continue;
            }
            let Some(h) = tris.test(&q.triangle, slot as usize, *t_max) else {
                continue;
            };
            match on_hit(first_slot + slot, ids[slot as usize], h) {
                Step::Miss => {}
                Step::Closer(t) => *t_max = t,
                Step::Stop => return true,
            }
        }
        false
    })
}

/// The walk over `nodes` alone: every node whose box the ray enters within (0, t_max), in the
/// order [`walk`] says, handing each leaf child (its first slot and count) to `leaf`, which may
/// shorten the ray (through its `&mut t_max`) or end the walk (true). A tree of triangles
/// tests them there; the tree over instances walks each instance's own tree.
#[inline(always)]
pub(super) fn walk_nodes<const N: usize, const NEAREST_FIRST: bool>(
    nodes: &[WideNode],
    ray: &NodeRay,
    mut t_max: f32,
    leaf: &mut impl FnMut(u32, u32, &mut f32) -> bool,
) -> (Walk, f32) {
    let mut stack = [MaybeUninit::<(u32, f32)>::uninit(); N];
    let mut len = 0usize;
    let mut node = &nodes[0];
    loop {
        let (mask, t_near) = node.intersect(ray, t_max);
        let mut leaves = mask & node.leaves as u32;
        while leaves != 0 {
            let c = leaves.trailing_zeros() as usize;
            leaves &= leaves - 1;
            if leaf(node.index[c], node.count[c] as u32, &mut t_max) {
                return (Walk::Stopped, t_max);
            }
        }
        // Inner children go on the stack farthest first, so the nearest comes off next (or,
        // unsorted, in reverse slot order).
        let mut inner = mask & node.inner as u32;
        let mut order = [(0u32, 0.0f32); 8];
        let mut n = 0;
        while inner != 0 {
            let c = inner.trailing_zeros() as usize;
            inner &= inner - 1;
            let entry = (node.index[c], t_near[c]);
            let mut i = n;
            while NEAREST_FIRST && i > 0 && order[i - 1].1 < entry.1 {
                order[i] = order[i - 1];
                i -= 1;
            }
            order[i] = entry;
            n += 1;
        }
        if n > 0 {
            // Descend into the nearest child now; the others wait on the stack.
            for &entry in &order[..n - 1] {
                let Some(slot) = stack.get_mut(len) else { return (Walk::Overflow, t_max) };
                slot.write(entry);
                len += 1;
            }
            if order[n - 1].1 <= t_max {
                node = &nodes[order[n - 1].0 as usize];
                continue;
            }
        }
        // The nearest node still in range (a hit found since it was pushed may be nearer).
        loop {
            if len == 0 {
                return (Walk::Done, t_max);
            }
            len -= 1;
            // SAFETY: every entry below `len` was written by the push above.
            let (index, t) = unsafe { stack[len].assume_init() };
            if t <= t_max {
                node = &nodes[index as usize];
                break;
            }
        }
    }
}
