//! Triangles a spawned ray cannot hit, skipped without a test.
//!
//! A ray spawned at a hit starts on the triangle it leaves, its origin pushed off the
//! triangle's plane to the side the ray goes (`crate::interaction`, pbrt-v4 §6.8.6). A straight
//! ray from a point of a plane meets that plane nowhere else, so the ray cannot hit the
//! triangle again at t > 0; nor, going to one side, any triangle wholly on the other side of
//! the plane (the closed half-space: touching the plane is still behind). Those tests could
//! only confirm a miss, or report a hit the offset exists to prevent. On the Cornell box they
//! were a large share of all triangle tests: the walls are not axis-aligned, so their boxes hold
//! the origins spawned on them, and a wall's two triangles, or a block's faces, share a leaf
//! (docs/performance.md, ledger: "skip leaf-mates behind"). Some walls fold towards the room by
//! a rounding, and their mates are still tested.
//!
//! Which side each leaf-mate lies on is decided when the tree is built or refitted, by
//! Shewchuk's exact orientation predicate (`orient.rs`). Which side a ray goes is decided per ray from
//! the triangle's normal, only when the answer is certain: rays within [`TANGENT`] of the
//! plane (in cosine) skip the triangle they leave alone. Leaf-mates are the only candidates,
//! so the test in the walk is a subtraction and a bit test.

use glam::{DVec3, Vec3};

/// Rays whose direction cosine with the plane's normal is within this of zero go to no side
/// certainly enough: the stored normal is within ~1e-7 rad of the exact one, the integrator's
/// offset normal (f32, of a triangle not thinner than [`THIN`]) within ~1e-4.
const TANGENT: f32 = 1e-3;

/// Triangles whose sine of the angle between two edges is below this skip no leaf-mates: their
/// normals, as the integrator computes them, are too uncertain to tell sides at [`TANGENT`].
const THIN: f64 = 1e-3;

/// The triangles one query skips: slots `first + k` for each bit k of `mask`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Leaving {
    first: u32,
    mask: u8,
}

impl Leaving {
    /// A ray that leaves no surface (an eye ray): every triangle is tested.
    pub const NOTHING: Self = Self { first: u32::MAX, mask: 0 };

    /// Skip only the triangle in `slot` (see [`super::Bvh::leaving`], which may skip more).
    #[inline]
    pub const fn slot(slot: u32) -> Self {
        Self { first: slot, mask: 1 }
    }

    /// The same triangles with their slots moved up by `base` (a mesh's tree's slots as one
    /// instance numbers them).
    #[inline]
    pub(super) fn shifted(self, base: u32) -> Self {
        Self { first: self.first.wrapping_add(base), mask: self.mask }
    }

    /// True when the query skips the triangle in `slot`.
    #[inline(always)]
    pub(super) fn skips(self, slot: u32) -> bool {
        let k = slot.wrapping_sub(self.first);
        k < 8 && (self.mask >> k) & 1 != 0
    }
}

/// One slot's plane and the leaf-mates wholly on each side of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct SlotSides {
    /// Unit normal of the triangle's front face (counter-clockwise), from f64 arithmetic.
    normal: [f32; 3],
    /// The slot's leaf's first slot.
    leaf_first: u32,
    /// Bit k: slot `leaf_first + k` lies wholly behind the plane or on it (rays going to the
    /// front skip it); the slot's own bit is set.
    behind: u8,
    /// Bit k: slot `leaf_first + k` lies wholly in front of the plane or on it.
    in_front: u8,
}

impl SlotSides {
    /// What a ray leaving this slot along `direction` skips.
    #[inline(always)]
    pub(super) fn leaving(&self, slot: u32, direction: Vec3) -> Leaving {
        let cos = direction.dot(Vec3::from_array(self.normal));
        let mask = if cos > TANGENT {
            self.behind
        } else if cos < -TANGENT {
            self.in_front
        } else {
            return Leaving::slot(slot);
        };
        Leaving { first: self.leaf_first, mask }
    }
}

/// The sides of every slot, given the leaves as (first slot, count) and the triangles in slot
/// order. Slots are independent of each other: they are computed in parallel (a refit does
/// this every frame), each by the same arithmetic whatever the thread.
pub(super) fn slot_sides(leaves: &[(u32, u32)], triangles: &[[[f32; 3]; 3]]) -> Vec<SlotSides> {
    use rayon::prelude::*;
    // A slot in no leaf (there is none in a tree obvhs built) skips only itself.
    let mut leaf_of: Vec<Option<(u32, u32)>> = vec![None; triangles.len()];
    for &(first, count) in leaves {
        // Masks hold eight slots; obvhs's leaves hold at most three triangles.
        let end = (first + count).min(first + 8);
        for s in first..end {
            leaf_of[s as usize] = Some((first, end));
        }
    }
    leaf_of.par_iter().enumerate().map(|(s, &leaf)| side_of(s as u32, leaf, triangles)).collect()
}

/// Slot `s`'s sides, its leaf being slots `first..end`. Plain loops and comparisons: closures
/// and array maps were not inlined in the workspace's incremental release builds, and a refit
/// runs this for every slot every frame.
fn side_of(s: u32, leaf: Option<(u32, u32)>, triangles: &[[[f32; 3]; 3]]) -> SlotSides {
    let Some((first, end)) = leaf else {
        return SlotSides { normal: [0.0; 3], leaf_first: s, behind: 1, in_front: 1 };
    };
    let tri = &triangles[s as usize];
    let own = 1u8 << (s - first);
    let mut side = SlotSides { normal: [0.0; 3], leaf_first: first, behind: own, in_front: own };
    // A thin triangle's normal cannot tell sides: it skips only itself.
    let Some(normal) = normal_of(tri) else { return side };
    side.normal = normal;
    let same = |p: &[f32; 3], q: &[f32; 3]| p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
    for m in first..end {
        if m == s {
            continue;
        }
        let (mut behind, mut in_front) = (true, true);
        for v in &triangles[m as usize] {
            // orient3d > 0: below the plane, seen so that the corners run counter-clockwise
            // from above; that is, behind the front face. A shared corner lies on the plane
            // exactly, and saying so directly spares the predicate its slowest, exact path.
            if same(v, &tri[0]) || same(v, &tri[1]) || same(v, &tri[2]) {
                continue;
            }
            let o = super::orient::orient3d(tri[0], tri[1], tri[2], *v);
            behind &= o >= 0.0;
            in_front &= o <= 0.0;
        }
        if behind {
            side.behind |= 1 << (m - first);
        }
        if in_front {
            side.in_front |= 1 << (m - first);
        }
    }
    side
}

/// The unit front normal (f64 arithmetic, rounded once), if the triangle is thick enough
/// ([`THIN`]) to tell sides by it.
fn normal_of(tri: &[[f32; 3]; 3]) -> Option<[f32; 3]> {
    let v = |p: [f32; 3]| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
    let a = v(tri[0]);
    let (e1, e2) = (v(tri[1]) - a, v(tri[2]) - a);
    let n = e1.cross(e2);
    let len = n.length();
    (len.is_finite() && len > 0.0 && len >= THIN * e1.length() * e2.length()).then(|| {
        let u = n / len;
        [u.x as f32, u.y as f32, u.z as f32]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn coord(p: [f32; 3]) -> robust::Coord3D<f32> {
        robust::Coord3D { x: p[0], y: p[1], z: p[2] }
    }

    /// The predicate's sign convention as used above: a point on the front side of a
    /// counter-clockwise triangle is "in front", one behind is "behind", one on it both.
    #[test]
    fn sides_follow_the_front_face() {
        let a = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; // front: +z
        let above = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let below = [[0.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 1.0, -1.0]];
        let fold_down = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, -0.5]]; // shares an edge
        let coplanar = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        let straddling = [[0.0, 0.0, -1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let tris = [a, above, below, fold_down, coplanar, straddling];
        let sides = slot_sides(&[(0, 6)], &tris);
        assert_eq!(sides[0].normal, [0.0, 0.0, 1.0]);
        assert_eq!(sides[0].behind, 0b01_1101, "itself, below, the downward fold, the coplanar one");
        assert_eq!(sides[0].in_front, 0b01_0011, "itself, above, the coplanar one");
        let up = Vec3::new(0.0, 0.6, 0.8);
        assert_eq!(sides[0].leaving(0, up), Leaving { first: 0, mask: 0b01_1101 });
        assert_eq!(sides[0].leaving(0, -up), Leaving { first: 0, mask: 0b01_0011 });
        let grazing = Vec3::new(1.0, 0.0, 1e-4).normalize();
        assert_eq!(sides[0].leaving(0, grazing), Leaving::slot(0), "too close to the plane to tell");
        assert!(sides[0].leaving(0, up).skips(3) && !sides[0].leaving(0, up).skips(5));
        assert!(!Leaving::NOTHING.skips(0) && !Leaving::NOTHING.skips(u32::MAX - 1));
    }

    /// Leaves of triangles sharing corners (a fan, some coplanar, some folded) get the sides the
    /// predicate gives when asked about every corner, shared ones included.
    #[test]
    fn shared_corners_are_on_the_plane_as_the_predicate_says() {
        let mut rng = crate::test_support::Rng::new(0x2545_f491);
        let mut next = move || rng.unit() * 2.0 - 1.0;
        for round in 0..500 {
            // A fan around a centre: rim points on a tilted plane, some lifted off it.
            let centre = [next(), next(), next()];
            let rim: Vec<[f32; 3]> = (0..4)
                .map(|k| {
                    let lift = if round % 3 == 0 || k % 2 == 0 { 0.0 } else { next() };
                    [centre[0] + next(), centre[1] + next(), centre[2] + lift]
                })
                .collect();
            let tris: Vec<[[f32; 3]; 3]> = (0..3).map(|k| [centre, rim[k], rim[k + 1]]).collect();
            let sides = slot_sides(&[(0, 3)], &tris);
            for s in 0..3 {
                let Some(normal) = normal_of(&tris[s]) else { continue };
                let (mut behind, mut in_front) = (1u8 << s, 1u8 << s);
                for m in (0..3).filter(|&m| m != s) {
                    let t = &tris[s];
                    let o =
                        tris[m].map(|v| robust::orient3d(coord(t[0]), coord(t[1]), coord(t[2]), coord(v)));
                    behind |= u8::from(o.iter().all(|&o| o >= 0.0)) << m;
                    in_front |= u8::from(o.iter().all(|&o| o <= 0.0)) << m;
                }
                let want = SlotSides { normal, leaf_first: 0, behind, in_front };
                assert_eq!(sides[s], want, "round {round}, slot {s}");
            }
        }
    }

    /// A sliver's normal is not trusted: it skips only itself.
    #[test]
    fn thin_triangles_skip_only_themselves() {
        let sliver = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1e-5, 0.0]];
        let below = [[0.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 1.0, -1.0]];
        let sides = slot_sides(
            &[(4, 2)],
            &[[[0.0; 3]; 3], [[0.0; 3]; 3], [[0.0; 3]; 3], [[0.0; 3]; 3], sliver, below],
        );
        assert_eq!(sides[4].leaving(4, Vec3::Z), Leaving::slot(4));
        assert_eq!(sides[5].leaving(5, -Vec3::Z), Leaving { first: 4, mask: 0b11 }, "the sliver lies above");
        assert_eq!(sides[0].leaving(0, Vec3::Z), Leaving::slot(0), "a slot in no leaf");
    }
}
