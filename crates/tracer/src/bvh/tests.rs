//! The BVH against brute force: every scale, stack overflow, skipping what a spawned ray
//! cannot hit, obvhs's traps.

use super::*;
use crate::scene::MeshPart;
use crate::test_support::Rng;
use crate::triangle::{WatertightRay, safe_reciprocal};
use glam::Vec3;

fn mesh_of(tris: &[[Vec3; 3]]) -> Mesh {
    let mut m = Mesh::default();
    let positions: Vec<Vec3> = tris.iter().flatten().copied().collect();
    m.push(MeshPart { positions: &positions, normals: None, uvs: None, indices: None, material: 0 }).unwrap();
    m
}

/// The closest hit of the ray from `o` along `d` (index, t), testing every triangle.
fn brute_closest(tris: &[[Vec3; 3]], o: Vec3, d: Vec3) -> Option<(usize, f32)> {
    let wray = WatertightRay::new(o, d, safe_reciprocal(d));
    tris.iter()
        .enumerate()
        .filter_map(|(i, t)| wray.intersect(&t.map(|p| p.to_array()), f32::INFINITY).map(|h| (i, h.t)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// The BVH answers exactly like testing every triangle, at scene scales 1e-4 … 1e4, and at
/// the extremes: on the denormal grid (1e-39) and far past the builder's range (1e20 …
/// 1e37, built rescaled by a power of two: obvhs panicked building the 1e30 scene, and the
/// triangle test returned t = NaN from 1e20 on).
#[test]
fn matches_brute_force_at_every_scale() {
    for scale in [1e-4f32, 1e-2, 1.0, 1e2, 1e4, 1e-39, 1e20, 1e30, 1e37] {
        let mut rng = Rng::new(7);
        let tris: Vec<[Vec3; 3]> = (0..300)
            .map(|_| {
                let c = rng.in_cube(1.0) * 5.0;
                [c + rng.in_cube(1.0) * 0.4, c + rng.in_cube(1.0) * 0.4, c + rng.in_cube(1.0) * 0.4]
                    .map(|p| p * scale)
            })
            .collect();
        let mesh = mesh_of(&tris);
        let bvh = Bvh::build(&mesh);
        for _ in 0..2000 {
            let o = rng.in_cube(1.0) * 6.0 * scale;
            let d = rng.in_cube(1.0).normalize();
            let ray = Ray::new(o, d, 0.0);
            let brute = brute_closest(&tris, o, d);
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
    let mut rng = Rng::new(9);
    let tris: Vec<[Vec3; 3]> = (0..2000)
        .map(|_| {
            let c = rng.in_cube(1.0) * 5.0;
            [c + rng.in_cube(1.0) * 0.3, c + rng.in_cube(1.0) * 0.3, c + rng.in_cube(1.0) * 0.3]
        })
        .collect();
    let bvh = Bvh::build(&mesh_of(&tris));
    let mut overflows = 0;
    for _ in 0..1000 {
        let ray = Ray::new(rng.in_cube(1.0) * 6.0, rng.in_cube(1.0).normalize(), 0.0);
        let q = QueryRay::new(&ray);
        let walked =
            walk::<1, true, _>(&bvh.fixed(), &q, f32::INFINITY, Leaving::NOTHING, &mut |_, _, _| Step::Miss);
        overflows += (walked.0 == Walk::Overflow) as u32;
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
        let mut rng = Rng::new(8);
        let tris: Vec<[Vec3; 3]> = (0..400)
            .map(|_| {
                let c = rng.in_cube(1.0) * 5.0;
                [c + rng.in_cube(1.0) * 0.6, c + rng.in_cube(1.0) * 0.6, c + rng.in_cube(1.0) * 0.6]
                    .map(|p| p * scale)
            })
            .collect();
        let bvh = Bvh::build(&mesh_of(&tris));
        let mut hits = 0;
        for i in 0..3000 {
            let d = [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z][i % 6];
            let o = (rng.in_cube(1.0) * 5.0 - d * 7.0) * scale;
            let ray = Ray::new(o, d, 0.0);
            let brute = brute_closest(&tris, o, d);
            let got = bvh.intersect(&ray, f32::INFINITY).map(|h| (h.triangle as usize, h.t));
            assert_eq!(got, brute, "scale {scale}, ray {ray:?}");
            hits += brute.is_some() as u32;
        }
        assert!(hits > 300, "scale {scale}: only {hits} rays hit");
    }
}

/// Skipping what a spawned ray cannot hit changes no answer. The scene has what the skip
/// relies on: closed boxes (leaf-mates behind each face), quads folded by 0, ±1e-6 and ±0.3
/// (mates on either side, or on the plane), and loose triangles. Rays are spawned from hits as
/// the integrator does it (offset origin), in random directions and grazing ones (cosines
/// 1e-2 … 0 with the plane), and get the same closest hit and occlusion with and without
/// [`Bvh::leaving`], also through the overflow fallback, but for spurious hits at the origin.
/// The skip must engage for many. (With `leaving::TANGENT` at 0, grazing rays skip real hits
/// and this test fails.)
#[test]
fn leaving_skips_nothing_a_spawned_ray_can_hit() {
    let mut rng = Rng::new(11);
    let mut tris: Vec<[Vec3; 3]> = Vec::new();
    for _ in 0..40 {
        let c = rng.in_cube(1.0) * 3.0;
        let axis = rng.in_cube(1.0).normalize();
        let rot = glam::Quat::from_axis_angle(axis, rng.unit() * 6.0);
        let h = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 0.4 + Vec3::splat(0.05);
        let corner = |i: u32| {
            let s = Vec3::new(
                [-1.0, 1.0][(i & 1) as usize],
                [-1.0, 1.0][(i >> 1 & 1) as usize],
                [-1.0, 1.0][(i >> 2) as usize],
            );
            c + rot * (s * h)
        };
        // The six faces as (corner indices) counter-clockwise seen from outside.
        for [a, b, cc, d] in
            [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
        {
            tris.push([corner(a), corner(b), corner(cc)]);
            tris.push([corner(a), corner(cc), corner(d)]);
        }
    }
    for fold in [0.0, 1e-6, -1e-6, 0.3, -0.3].repeat(12) {
        let p0 = rng.in_cube(1.0) * 3.0;
        let (p1, p2) = (p0 + rng.in_cube(1.0) * 0.6, p0 + rng.in_cube(1.0) * 0.6);
        let n = (p1 - p0).cross(p2 - p0).normalize();
        tris.push([p0, p1, p2]);
        tris.push([p0, p2, p0 + (p2 - p1) + fold * n]);
    }
    for _ in 0..60 {
        let c = rng.in_cube(1.0) * 3.0;
        tris.push([c + rng.in_cube(1.0) * 0.5, c + rng.in_cube(1.0) * 0.5, c + rng.in_cube(1.0) * 0.5]);
    }
    let bvh = Bvh::build(&mesh_of(&tris));
    let (mut spawned, mut engaged, mut spurious) = (0, 0, 0);
    for _ in 0..9000 {
        let ray = Ray::new(rng.in_cube(1.0) * 4.0, rng.in_cube(1.0).normalize(), 0.0);
        let Some(hit) = bvh.intersect(&ray, f32::INFINITY) else { continue };
        let tri = &bvh.triangle_at(hit.slot, 0.0);
        let (p, p_error) = crate::triangle::hit_point(tri, hit.barycentrics);
        let [a, b, c] = tri.map(Vec3::from_array);
        let n = (b - a).cross(c - a).normalize();
        let tangent = n.cross(rng.in_cube(1.0)).normalize();
        let side = if rng.unit() < 0.5 { 1.0 } else { -1.0 };
        let grazing = [1e-2, 2e-3, 1e-3, 5e-4, 0.0].map(|cos| (tangent + side * cos * n).normalize());
        let random = [(); 6].map(|_| rng.in_cube(1.0).normalize());
        for w in grazing.into_iter().chain(random) {
            let next = Ray::new(crate::interaction::offset_ray_origin(p, p_error, n, w), w, 0.0);
            let leaving = bvh.leaving(hit.slot, w);
            engaged += (leaving != Leaving::slot(hit.slot)) as u32;
            let all = bvh.intersect(&next, f32::INFINITY);
            assert_ne!(all.map(|h| h.slot), Some(hit.slot), "a spawned ray hit its own triangle");
            let skipping = bvh.intersect_from(&next, f32::INFINITY, leaving, |_, _| true);
            assert_eq!(bvh.closest::<1>(&next, f32::INFINITY, leaving, |_, _| true), skipping);
            if skipping != all {
                // The one difference allowed: the full query's hit is a skipped mate right at
                // the origin, a grazing ray's rounding at their shared edge (the self-hit the
                // offset exists to prevent), not a surface the ray reaches.
                let h = all.expect("skipping found a hit the full query did not");
                assert!(leaving.skips(h.slot) && h.t < 1e-4, "skipped a real hit {h:?} ({skipping:?})");
                spurious += 1;
                continue;
            }
            let t = all.map_or(4.0, |h| h.t * 0.999);
            for t_max in [t, f32::INFINITY] {
                let blocked = bvh.occluded(&next, t_max);
                assert_eq!(bvh.occluded_from(&next, t_max, leaving, |_, _| true), blocked);
                assert_eq!(bvh.any::<1>(&next, t_max, leaving, |_, _| true), blocked);
            }
            spawned += 1;
        }
    }
    assert!(spawned > 15_000, "only {spawned} spawned rays");
    assert!(spurious <= spawned / 1000, "{spurious} spurious hits");
    assert!(engaged > 4_000, "the leaf-mate skip engaged for only {engaged} of {spawned} rays");

    // And it is real: a ray aimed at a triangle it claims to leave does not see it.
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

/// Triangles at `time` with every corner moved by `motion(corner, step)`, interpolated as
/// the motion tree does (linearly between the two steps around the time).
fn moved_at(tris: &[[Vec3; 3]], steps: &[Vec<Vec3>], open: f32, close: f32, time: f32) -> Vec<[Vec3; 3]> {
    let x = ((time - open) / (close - open) * (steps.len() - 1) as f32).clamp(0.0, (steps.len() - 1) as f32);
    let k = (x as usize).min(steps.len() - 2);
    let f = x - k as f32;
    (0..tris.len())
        .map(|t| {
            std::array::from_fn(|c| {
                let (p, q) = (steps[k][3 * t + c], steps[k + 1][3 * t + c]);
                let v = p * (1.0 - f) + q * f;
                v.clamp(p.min(q), p.max(q))
            })
        })
        .collect()
}

/// The BVH with moving triangles answers every ray at its time exactly as testing every
/// triangle interpolated to that time: closest hits (triangle and t) and occlusion, for a mix
/// of static triangles and triangles that translate, rotate and deform over three and five
/// steps, through the walk and through the overflow fallback; rays leaving a moving triangle
/// never hit it again.
#[test]
fn moving_triangles_match_brute_force_at_every_time() {
    for steps_n in [2usize, 3, 5] {
        let mut rng = Rng::new(21 + steps_n as u64);
        let tris: Vec<[Vec3; 3]> = (0..400)
            .map(|_| {
                let c = rng.in_cube(1.0) * 5.0;
                [c + rng.in_cube(1.0) * 0.4, c + rng.in_cube(1.0) * 0.4, c + rng.in_cube(1.0) * 0.4]
            })
            .collect();
        let mesh = mesh_of(&tris);
        let (open, close) = (7.0f32, 7.5f32);
        // Every third triangle stays; the others slide, spin about the scene's centre or wobble.
        let steps: Vec<Vec<Vec3>> = (0..steps_n)
            .map(|k| {
                let s = k as f32 / (steps_n - 1) as f32;
                mesh.positions
                    .iter()
                    .enumerate()
                    .map(|(v, &p)| match (v / 3) % 3 {
                        0 => p,
                        1 => p + Vec3::new(1.5, -0.5, 0.25) * s,
                        _ => glam::Quat::from_rotation_y(0.8 * s) * p + Vec3::splat(0.1 * (v % 3) as f32 * s),
                    })
                    .collect()
            })
            .collect();
        let motion = SceneMotion { open, close, positions: steps.clone(), normals: vec![] };
        let moving = motion.moving_triangles(&mesh);
        assert_eq!(moving.iter().filter(|&&m| m).count(), tris.len() - tris.len().div_ceil(3));
        let bvh = Bvh::build_moving(&mesh, &motion, &moving);
        assert!(bvh.has_motion() && bvh.len() == tris.len());
        let mut hits = 0;
        for i in 0..3000 {
            let time =
                if i % 10 == 0 { [open, close, 6.0, 8.0, 7.25][i / 10 % 5] } else { open + rng.unit() * 0.5 };
            let at = moved_at(&tris, &steps, open, close, time);
            // Aimed at a random triangle where it is at that time, or anywhere.
            let o = rng.in_cube(1.0) * 6.0;
            let target = at[(rng.unit() * at.len() as f32) as usize % at.len()][0];
            let d = if i % 2 == 0 { (target - o).normalize() } else { rng.in_cube(1.0).normalize() };
            let ray = Ray::new(o, d, time);
            let brute = brute_closest(&at, o, d);
            let hit = bvh.intersect(&ray, f32::INFINITY);
            assert_eq!(hit.map(|h| (h.triangle as usize, h.t)), brute, "steps {steps_n}, time {time}");
            assert_eq!(bvh.closest::<1>(&ray, f32::INFINITY, Leaving::NOTHING, |_, _| true), hit);
            assert_eq!(bvh.occluded(&ray, f32::INFINITY), brute.is_some());
            assert_eq!(bvh.any::<1>(&ray, f32::INFINITY, Leaving::NOTHING, |_, _| true), brute.is_some());
            let Some(h) = hit else { continue };
            hits += 1;
            assert!(!bvh.occluded(&ray, h.t * 0.999));
            assert_eq!(bvh.is_moving(h.slot), moving[h.triangle as usize]);
            let corners = bvh.triangle_at(h.slot, time);
            assert_eq!(corners, at[h.triangle as usize].map(|p| p.to_array()));
            // A ray spawned from the hit, at the same time, does not meet its own triangle.
            let (p, p_error) = crate::triangle::hit_point(&corners, h.barycentrics);
            let [a, b, c] = corners.map(Vec3::from_array);
            let n = (b - a).cross(c - a).normalize();
            let w = rng.in_cube(1.0).normalize();
            let next = Ray::new(crate::interaction::offset_ray_origin(p, p_error, n, w), w, time);
            let again = bvh.intersect(&next, f32::INFINITY);
            assert_ne!(again.map(|g| g.slot), Some(h.slot), "a spawned ray hit its own triangle");
            let leaving = bvh.leaving(h.slot, w);
            assert_eq!(
                bvh.intersect_from(&next, f32::INFINITY, leaving, |_, _| true).map(|g| g.slot),
                again.map(|g| g.slot)
            );
        }
        assert!(hits > 800, "steps {steps_n}: only {hits} rays hit");
    }
}

/// A mesh whose motion moves nothing builds the static tree alone, slot for slot as
/// [`Bvh::build`] does.
#[test]
fn motion_that_moves_nothing_is_the_static_tree() {
    let mut rng = Rng::new(5);
    let tris: Vec<[Vec3; 3]> =
        (0..200).map(|_| [rng.in_cube(1.0), rng.in_cube(1.0), rng.in_cube(1.0)]).collect();
    let mesh = mesh_of(&tris);
    let motion =
        SceneMotion { open: 0.0, close: 1.0, positions: vec![mesh.positions.clone(); 3], normals: vec![] };
    let moving = motion.moving_triangles(&mesh);
    assert!(!moving.contains(&true));
    let (a, b) = (Bvh::build(&mesh), Bvh::build_moving(&mesh, &motion, &moving));
    assert!(!b.has_motion());
    assert_eq!((a.triangles, a.triangle_ids, a.slot_of), (b.triangles, b.triangle_ids, b.slot_of));
}

/// A refitted tree (the same triangles, every vertex moved) answers like a tree built afresh
/// and like testing every triangle; a mesh of other triangles is refused, nothing changed.
#[test]
fn refitted_tree_matches_brute_force() {
    let mut rng = Rng::new(31);
    let tris: Vec<[Vec3; 3]> = (0..500)
        .map(|_| {
            let c = rng.in_cube(1.0) * 5.0;
            [c + rng.in_cube(1.0) * 0.4, c + rng.in_cube(1.0) * 0.4, c + rng.in_cube(1.0) * 0.4]
        })
        .collect();
    let mut bvh = Bvh::build(&mesh_of(&tris));
    // Bent and stretched: every vertex moves, some far.
    let moved: Vec<[Vec3; 3]> = tris
        .iter()
        .map(|t| t.map(|p| glam::Quat::from_rotation_z(0.3 * p.y) * p + Vec3::new(0.0, p.x * p.x * 0.2, 0.5)))
        .collect();
    assert!(bvh.refit(&mesh_of(&moved)));
    let fresh = Bvh::build(&mesh_of(&moved));
    for _ in 0..3000 {
        let (o, d) = (rng.in_cube(1.0) * 6.0, rng.in_cube(1.0).normalize());
        let ray = Ray::new(o, d, 0.0);
        let brute = brute_closest(&moved, o, d);
        assert_eq!(bvh.intersect(&ray, f32::INFINITY).map(|h| (h.triangle as usize, h.t)), brute);
        assert_eq!(fresh.intersect(&ray, f32::INFINITY).map(|h| (h.triangle as usize, h.t)), brute);
        assert_eq!(bvh.occluded(&ray, f32::INFINITY), brute.is_some());
    }
    assert!(!bvh.refit(&mesh_of(&moved[1..])), "another triangle count");
}
