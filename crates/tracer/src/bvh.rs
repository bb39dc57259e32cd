//! The acceleration structure: an obvhs compressed wide BVH8 (Ylitie et al. 2017) over the
//! scene's triangles, with closest-hit and occlusion (any-hit, early exit) queries. obvhs types
//! stay behind this module.
//!
//! obvhs's traps (NOTES.md) are handled here, not by callers:
//! - its node test culls boxes closer than 1e-4 in ray-parameter units whatever `tmin` says:
//!   the BVH is built in a space scaled by a power of two (exact in floating point) that maps the
//!   scene's extent to ~1024, so that cut-off is ~1e-7 of the scene whatever its scale;
//! - a −0.0 direction component makes traversal miss everything, and components below
//!   f32::EPSILON get a clamped inverse: the traversal ray's direction is sanitised (+0.0) and its
//!   inverse computed here with a much smaller clamp;
//! - `primitive_id` is a slot in `primitive_indices`: triangles are stored reordered by slot;
//! - its triangle test is not watertight: ours (`crate::triangle`) runs in the traversal, in
//!   world space on the original vertices.

use crate::ray::Ray;
use crate::scene::Mesh;
use crate::triangle::{TriangleHit, WatertightRay};
use glam::{UVec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray as BvhRay;
use obvhs::{BvhBuildParams, traverse};

/// A ray–scene intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit-direction) ray.
    pub t: f32,
    /// Index of the triangle in the scene's mesh.
    pub triangle: u32,
    /// Slot of the triangle in the BVH's own storage (for [`Bvh::triangle`]).
    pub slot: u32,
    /// Barycentric weights of the triangle's three corners at the hit.
    pub barycentrics: [f32; 3],
}

/// A bounding-volume hierarchy over a mesh's triangles.
pub struct Bvh {
    cwbvh: CwBvh,
    /// World-space corners, stored in BVH slot order.
    triangles: Vec<[Vec3A; 3]>,
    /// Slot → triangle index in the mesh.
    triangle_ids: Vec<u32>,
    /// Power-of-two scale from world space to the space the BVH was built in.
    to_bvh: f32,
}

impl Bvh {
    /// Builds the BVH over every triangle of `mesh` (obvhs medium preset).
    pub fn build(mesh: &Mesh) -> Self {
        let to_bvh = mesh.bounds().map_or(1.0, |(lo, hi)| bvh_scale(lo, hi));
        let aabbs: Vec<Aabb> = (0..mesh.triangle_count())
            .map(|t| {
                let [a, b, c] = mesh.corners(t).map(|p| Vec3A::from(p) * to_bvh);
                Aabb::new(a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let cwbvh = if aabbs.is_empty() {
            CwBvh::default()
        } else {
            obvhs::cwbvh::builder::build_cwbvh(&aabbs, BvhBuildParams::medium_build(), &mut Default::default())
        };
        let triangle_ids = cwbvh.primitive_indices.clone();
        let triangles = triangle_ids.iter().map(|&t| mesh.corners(t as usize).map(Vec3A::from)).collect();
        Self { cwbvh, triangles, triangle_ids, to_bvh }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// True when the BVH holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The world-space corners of the triangle in `slot`.
    #[inline]
    pub fn triangle(&self, slot: u32) -> &[Vec3A; 3] {
        &self.triangles[slot as usize]
    }

    /// The traversal ray in BVH space, with obvhs's direction traps defused.
    #[inline]
    fn bvh_ray(&self, ray: &Ray, t_max: f32) -> BvhRay {
        // +0.0 turns −0.0 into +0.0 (and leaves everything else alone).
        let d = Vec3A::from(ray.direction) + Vec3A::ZERO;
        let inv = |x: f32| if x.abs() < 1e-30 { 1e30f32.copysign(x) } else { 1.0 / x };
        BvhRay {
            origin: Vec3A::from(ray.origin) * self.to_bvh,
            direction: d,
            inv_direction: Vec3A::new(inv(d.x), inv(d.y), inv(d.z)),
            tmin: 0.0,
            tmax: t_max * self.to_bvh,
        }
    }

    /// The closest hit along `ray` in (0, t_max), if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        if self.triangles.is_empty() {
            return None;
        }
        let wray = WatertightRay::new(ray.origin, ray.direction);
        let mut traverse_ray = self.bvh_ray(ray, t_max);
        let mut best: Option<(u32, TriangleHit)> = None;
        let mut best_t = t_max;
        let mut state = self.cwbvh.new_traversal(traverse_ray.direction);
        let mut node;
        traverse!(self.cwbvh, node, state, node.intersect_ray(&traverse_ray, state.oct_inv4), {
            let slot = state.primitive_id;
            if let Some(h) = wray.intersect(&self.triangles[slot as usize], best_t) {
                best_t = h.t;
                best = Some((slot, h));
                traverse_ray.tmax = h.t * self.to_bvh;
            }
        });
        best.map(|(slot, h)| Hit { t: h.t, triangle: self.triangle_ids[slot as usize], slot, barycentrics: h.b })
    }

    /// True when something blocks `ray` in (0, t_max). Stops at the first blocker found.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let wray = WatertightRay::new(ray.origin, ray.direction);
        let traverse_ray = self.bvh_ray(ray, t_max);
        let mut state = self.cwbvh.new_traversal(traverse_ray.direction);
        let mut node;
        let mut blocked = false;
        'search: {
            traverse!(self.cwbvh, node, state, node.intersect_ray(&traverse_ray, state.oct_inv4), {
                if wray.intersect(&self.triangles[state.primitive_id as usize], t_max).is_some() {
                    blocked = true;
                    break 'search;
                }
            });
        }
        blocked
    }
}

/// The power of two that maps the scene's largest extent into [512, 1024), clamped so that no
/// coordinate overflows (an exact scale: it changes exponents only).
fn bvh_scale(lo: Vec3, hi: Vec3) -> f32 {
    let extent = (hi - lo).max_element();
    let magnitude = lo.abs().max(hi.abs()).max_element();
    if !(extent > 0.0) || !extent.is_finite() {
        return 1.0;
    }
    let mut k = (1024.0 / extent).log2().floor() as i32;
    // Keep |coordinates| × scale well inside f32's range.
    let max_k = (1e30f32 / magnitude.max(1e-30)).log2().floor() as i32;
    k = k.min(max_k).clamp(-120, 120);
    2f32.powi(k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::MeshPart;

    fn mesh_of(tris: &[[Vec3; 3]]) -> Mesh {
        let mut m = Mesh::default();
        let positions: Vec<Vec3> = tris.iter().flatten().copied().collect();
        m.push(MeshPart { positions: &positions, normals: None, uvs: None, indices: None, material: 0 }).unwrap();
        m
    }

    /// A deterministic little generator for test inputs.
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((self.0 >> 40) as f32) / (1u64 << 24) as f32
        }
        fn vec(&mut self) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next()) * 2.0 - Vec3::ONE
        }
    }

    /// The BVH answers exactly like testing every triangle, at scene scales 1e-4 … 1e4.
    #[test]
    fn matches_brute_force_at_every_scale() {
        for scale in [1e-4f32, 1e-2, 1.0, 1e2, 1e4] {
            let mut rng = Lcg(7);
            let tris: Vec<[Vec3; 3]> = (0..300)
                .map(|_| {
                    let c = rng.vec() * 5.0;
                    [c + rng.vec() * 0.4, c + rng.vec() * 0.4, c + rng.vec() * 0.4].map(|p| p * scale)
                })
                .collect();
            let mesh = mesh_of(&tris);
            let bvh = Bvh::build(&mesh);
            for _ in 0..2000 {
                let o = rng.vec() * 6.0 * scale;
                let d = rng.vec().normalize();
                let ray = Ray::new(o, d, 0.0);
                let wray = WatertightRay::new(o, d);
                let brute = tris
                    .iter()
                    .enumerate()
                    .filter_map(|(i, t)| wray.intersect(&t.map(Vec3A::from), f32::INFINITY).map(|h| (i, h.t)))
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                let got = bvh.intersect(&ray, f32::INFINITY).map(|h| (h.triangle as usize, h.t));
                assert_eq!(got, brute, "scale {scale}");
                assert_eq!(bvh.occluded(&ray, f32::INFINITY), brute.is_some());
                if let Some((_, t)) = brute {
                    assert!(!bvh.occluded(&ray, t * 0.999));
                }
            }
        }
    }

    /// −0.0 direction components and axis-parallel rays still hit (obvhs traps).
    #[test]
    fn negative_zero_and_axis_parallel_directions_hit() {
        let mesh = mesh_of(&[[Vec3::new(-1.0, -1.0, -3.0), Vec3::new(1.0, -1.0, -3.0), Vec3::new(0.0, 1.0, -3.0)]]);
        let bvh = Bvh::build(&mesh);
        let d = Vec3::new(-0.0, -0.0, -1.0);
        let hit = bvh.intersect(&Ray::new(Vec3::ZERO, d, 0.0), f32::INFINITY).expect("−0.0 direction must hit");
        assert!((hit.t - 3.0).abs() < 1e-6);
        let tiny = Vec3::new(1e-9, -1e-9, -1.0).normalize();
        assert!(bvh.intersect(&Ray::new(Vec3::ZERO, tiny, 0.0), f32::INFINITY).is_some());
    }

    /// Hits closer than obvhs's 1e-4 node cut-off are found in a tiny scene.
    #[test]
    fn near_hits_in_tiny_scenes() {
        let s = 1e-5;
        let mesh = mesh_of(&[[Vec3::new(-1.0, -1.0, -1.0) * s, Vec3::new(1.0, -1.0, -1.0) * s, Vec3::new(0.0, 1.0, -1.0) * s]]);
        let bvh = Bvh::build(&mesh);
        let hit = bvh.intersect(&Ray::new(Vec3::ZERO, -Vec3::Z, 0.0), f32::INFINITY).unwrap();
        assert!((hit.t - s).abs() < 1e-11);
        assert!(Bvh::build(&Mesh::default()).intersect(&Ray::new(Vec3::ZERO, Vec3::Z, 0.0), 1.0).is_none());
    }
}
