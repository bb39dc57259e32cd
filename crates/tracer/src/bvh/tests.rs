//! The BVH against brute force: every scale, stack overflow, skipping the triangle a ray
//! leaves, obvhs's traps.

use super::*;
use crate::scene::MeshPart;
use crate::triangle::safe_reciprocal;
use glam::Vec3;

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

/// The BVH answers exactly like testing every triangle, at scene scales 1e-4 … 1e4, and at
/// the extremes: on the denormal grid (1e-39) and far past the builder's range (1e20 …
/// 1e37, built rescaled by a power of two: obvhs panicked building the 1e30 scene, and the
/// triangle test returned t = NaN from 1e20 on).
#[test]
fn matches_brute_force_at_every_scale() {
    for scale in [1e-4f32, 1e-2, 1.0, 1e2, 1e4, 1e-39, 1e20, 1e30, 1e37] {
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
            let wray = WatertightRay::new(o, d, safe_reciprocal(d));
            let brute = tris
                .iter()
                .enumerate()
                .filter_map(|(i, t)| {
                    wray.intersect(&t.map(|p| p.to_array()), f32::INFINITY).map(|h| (i, h.t))
                })
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

/// With a stack too small for the tree, the walk reports the overflow instead of losing
/// nodes, and both queries fall back to testing every triangle: the same answers.
#[test]
fn stack_overflow_falls_back_to_every_triangle() {
    let mut rng = Lcg(9);
    let tris: Vec<[Vec3; 3]> = (0..2000)
        .map(|_| {
            let c = rng.vec() * 5.0;
            [c + rng.vec() * 0.3, c + rng.vec() * 0.3, c + rng.vec() * 0.3]
        })
        .collect();
    let bvh = Bvh::build(&mesh_of(&tris));
    let mut overflows = 0;
    for _ in 0..1000 {
        let ray = Ray::new(rng.vec() * 6.0, rng.vec().normalize(), 0.0);
        let q = QueryRay::new(&ray);
        overflows += (bvh.walk::<1, true>(&q, f32::INFINITY, Leaving::NOTHING, &mut |_, _| Step::Miss).0
            == Walk::Overflow) as u32;
        let full = bvh.intersect(&ray, f32::INFINITY);
        assert_eq!(bvh.closest::<1>(&ray, f32::INFINITY, Leaving::NOTHING, |_, _| true), full);
        let t = full.map_or(f32::INFINITY, |h| h.t * 0.999);
        assert_eq!(bvh.any::<1>(&ray, t, Leaving::NOTHING, |_, _| true), bvh.occluded(&ray, t));
        assert_eq!(bvh.any::<1>(&ray, f32::INFINITY, Leaving::NOTHING, |_, _| true), full.is_some());
    }
    assert!(overflows > 500, "only {overflows} walks overflowed a one-entry stack");
}

/// Axis-parallel rays (reciprocal components clamped to ±1e30) answer like testing every
/// triangle in scenes up to 1e30 across: a node slab computed as q·(extent·1/d) + … turned
/// 0·∞ into NaN once extent/d overflowed (node quanta past ~3e8, i.e. scenes past ~1e11)
/// and lost whole subtrees.
#[test]
fn axis_parallel_rays_match_brute_force_in_huge_scenes() {
    for scale in [1.0f32, 1e6, 1e11, 1e15, 1e20, 1e30] {
        let mut rng = Lcg(8);
        let tris: Vec<[Vec3; 3]> = (0..400)
            .map(|_| {
                let c = rng.vec() * 5.0;
                [c + rng.vec() * 0.6, c + rng.vec() * 0.6, c + rng.vec() * 0.6].map(|p| p * scale)
            })
            .collect();
        let bvh = Bvh::build(&mesh_of(&tris));
        let mut hits = 0;
        for i in 0..3000 {
            let d = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z][i % 6];
            let o = (rng.vec() * 5.0 - d * 7.0) * scale;
            let ray = Ray::new(o, d, 0.0);
            let wray = WatertightRay::new(o, d, safe_reciprocal(d));
            let brute = tris
                .iter()
                .enumerate()
                .filter_map(|(i, t)| {
                    wray.intersect(&t.map(|p| p.to_array()), f32::INFINITY).map(|h| (i, h.t))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let got = bvh.intersect(&ray, f32::INFINITY).map(|h| (h.triangle as usize, h.t));
            assert_eq!(got, brute, "scale {scale}, ray {ray:?}");
            hits += brute.is_some() as u32;
        }
        assert!(hits > 300, "scale {scale}: only {hits} rays hit");
    }
}

/// Skipping the triangle a spawned ray leaves changes no answer: rays spawned from hits
/// (origin offset as the integrator does it, directions to both sides) get the same closest
/// hit and occlusion with and without [`Leaving`], also through the overflow fallback.
/// And the skip is real: a ray aimed at a triangle it claims to leave does not see it.
#[test]
fn leaving_skips_only_the_triangle_left() {
    let mut rng = Lcg(11);
    let tris: Vec<[Vec3; 3]> = (0..300)
        .map(|_| {
            let c = rng.vec() * 3.0;
            [c + rng.vec(), c + rng.vec(), c + rng.vec()]
        })
        .collect();
    let bvh = Bvh::build(&mesh_of(&tris));
    let mut spawned = 0;
    for _ in 0..2000 {
        let ray = Ray::new(rng.vec() * 3.0, rng.vec().normalize(), 0.0);
        let Some(hit) = bvh.intersect(&ray, f32::INFINITY) else { continue };
        let tri = bvh.triangle(hit.slot);
        let (p, p_error) = crate::triangle::hit_point(tri, hit.barycentrics);
        let [a, b, c] = tri.map(Vec3::from_array);
        let n = (b - a).cross(c - a).normalize();
        let leaving = Leaving::slot(hit.slot);
        for _ in 0..8 {
            let w = rng.vec().normalize();
            let next = Ray::new(crate::interaction::offset_ray_origin(p, p_error, n, w), w, 0.0);
            let all = bvh.intersect(&next, f32::INFINITY);
            assert_ne!(all.map(|h| h.slot), Some(hit.slot), "a spawned ray hit its own triangle");
            assert_eq!(bvh.intersect_from(&next, f32::INFINITY, leaving, |_, _| true), all);
            assert_eq!(bvh.closest::<1>(&next, f32::INFINITY, leaving, |_, _| true), all);
            let t = all.map_or(4.0, |h| h.t * 0.999);
            for t_max in [t, f32::INFINITY] {
                let blocked = bvh.occluded(&next, t_max);
                assert_eq!(bvh.occluded_from(&next, t_max, leaving, |_, _| true), blocked);
                assert_eq!(bvh.any::<1>(&next, t_max, leaving, |_, _| true), blocked);
            }
            spawned += 1;
        }
    }
    assert!(spawned > 8000, "only {spawned} spawned rays");

    let one =
        mesh_of(&[[Vec3::new(-1.0, -1.0, -3.0), Vec3::new(1.0, -1.0, -3.0), Vec3::new(0.0, 1.0, -3.0)]]);
    let bvh = Bvh::build(&one);
    let ray = Ray::new(Vec3::ZERO, -Vec3::Z, 0.0);
    assert!(bvh.intersect(&ray, f32::INFINITY).is_some() && bvh.occluded(&ray, f32::INFINITY));
    assert_eq!(bvh.intersect_from(&ray, f32::INFINITY, Leaving::slot(0), |_, _| true), None);
    assert!(!bvh.occluded_from(&ray, f32::INFINITY, Leaving::slot(0), |_, _| true));
}

/// −0.0 direction components and axis-parallel rays still hit (obvhs traps).
#[test]
fn negative_zero_and_axis_parallel_directions_hit() {
    let mesh =
        mesh_of(&[[Vec3::new(-1.0, -1.0, -3.0), Vec3::new(1.0, -1.0, -3.0), Vec3::new(0.0, 1.0, -3.0)]]);
    let bvh = Bvh::build(&mesh);
    let d = Vec3::new(-0.0, -0.0, -1.0);
    let hit = bvh.intersect(&Ray::new(Vec3::ZERO, d, 0.0), f32::INFINITY).expect("−0.0 direction must hit");
    assert!((hit.t - 3.0).abs() < 1e-6);
    let tiny = Vec3::new(1e-9, -1e-9, -1.0).normalize();
    assert!(bvh.intersect(&Ray::new(Vec3::ZERO, tiny, 0.0), f32::INFINITY).is_some());
}

/// Hits closer than obvhs's own 1e-4 node cut-off are found in a tiny scene.
#[test]
fn near_hits_in_tiny_scenes() {
    let s = 1e-5;
    let mesh = mesh_of(&[[
        Vec3::new(-1.0, -1.0, -1.0) * s,
        Vec3::new(1.0, -1.0, -1.0) * s,
        Vec3::new(0.0, 1.0, -1.0) * s,
    ]]);
    let bvh = Bvh::build(&mesh);
    let hit = bvh.intersect(&Ray::new(Vec3::ZERO, -Vec3::Z, 0.0), f32::INFINITY).unwrap();
    assert!((hit.t - s).abs() < 1e-11);
    assert!(Bvh::build(&Mesh::default()).intersect(&Ray::new(Vec3::ZERO, Vec3::Z, 0.0), 1.0).is_none());
}
