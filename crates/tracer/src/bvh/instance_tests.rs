//! The two-level BVH against brute force (every triangle of every copy, transformed), still
//! and in rigid motion at random times; what a spawned ray skips in a copy; memory per copy.

use super::*;
use crate::scene::{Instance, InstanceMesh, MeshPart, RigidMotion, SceneInstances};
use crate::test_support::Rng;
use crate::triangle::{WatertightRay, safe_reciprocal};
use glam::Quat;

/// A small blob of random triangles around the origin.
fn blob(rng: &mut Rng, n: usize) -> InstanceMesh {
    let mut mesh = InstanceMesh::default();
    for k in 0..n as u32 {
        let c = rng.in_cube(1.0) * 0.8;
        mesh.positions.extend([
            c + rng.in_cube(1.0) * 0.3,
            c + rng.in_cube(1.0) * 0.3,
            c + rng.in_cube(1.0) * 0.3,
        ]);
        mesh.triangles.push([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    mesh
}

/// A random placement: any rotation, scale 0.5 … 2 per axis (some mirrored), within 8 of the
/// origin.
fn placement(rng: &mut Rng, mirror: bool) -> Affine3A {
    let axis = (rng.in_cube(1.0) + Vec3::splat(1e-3)).normalize();
    let scale = Vec3::new(0.5 + 1.5 * rng.unit(), 0.5 + 1.5 * rng.unit(), 0.5 + 1.5 * rng.unit());
    let scale = if mirror { scale * Vec3::new(-1.0, 1.0, 1.0) } else { scale };
    Affine3A::from_scale_rotation_translation(
        scale,
        Quat::from_axis_angle(axis, 6.0 * rng.unit()),
        rng.in_cube(1.0) * 8.0,
    )
}

/// A scene: `copies` instances of two blobs (every third mirrored, re-wound as the loader
/// re-winds), a few loose triangles, and the flattened mesh the scene would carry. `moving`:
/// every other copy turns up to 130° per step over three steps in time 0 … 1.
fn scene(copies: usize, moving: bool) -> (Mesh, SceneInstances) {
    let mut rng = Rng::new(0x51ce);
    let mut instances =
        SceneInstances { meshes: vec![blob(&mut rng, 40), blob(&mut rng, 25)], ..SceneInstances::default() };
    let mirrored: Vec<InstanceMesh> = instances
        .meshes
        .iter()
        .map(|m| InstanceMesh {
            positions: m.positions.clone(),
            triangles: m.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
            shared: false,
        })
        .collect();
    instances.meshes.extend(mirrored);
    let mut mesh = Mesh::default();
    let loose: Vec<Vec3> = (0..30).map(|_| rng.in_cube(1.0) * 9.0).collect();
    mesh.push(MeshPart { positions: &loose, normals: None, uvs: None, indices: None, material: 0 }).unwrap();
    for k in 0..copies {
        let mirror = k % 3 == 2;
        let m = (k % 2) as u32 + if mirror { 2 } else { 0 };
        let world = placement(&mut rng, mirror);
        let motion = (moving && k % 2 == 0).then(|| {
            let axis = rng.in_cube(1.0).normalize();
            let steps: Vec<Affine3A> = (0..3)
                .map(|s| {
                    let turn = Quat::from_axis_angle(axis, s as f32 * (1.0 + 1.3 * rng.unit()));
                    Affine3A::from_translation(rng.in_cube(1.0) * s as f32)
                        * Affine3A::from_quat(turn)
                        * world
                })
                .collect();
            RigidMotion::from_steps(0.0, 1.0, &steps).unwrap()
        });
        let local = &instances.meshes[m as usize];
        let first = mesh.triangle_count() as u32;
        let positions: Vec<Vec3> = local.positions.iter().map(|&p| world.transform_point3(p)).collect();
        let indices: Vec<u32> = local.triangles.iter().flatten().copied().collect();
        let part = MeshPart {
            positions: &positions,
            normals: None,
            uvs: None,
            indices: Some(&indices),
            material: 0,
        };
        mesh.push(part).unwrap();
        let world = motion.as_ref().map_or(world, |m| m.at(0.0));
        instances.instances.push(Instance { mesh: m, first, world, motion });
    }
    instances.validate(&mesh).unwrap();
    (mesh, instances)
}

/// Every triangle of the scene at `time` in world space, by the scene's triangle index.
fn world_triangles(mesh: &Mesh, instances: &SceneInstances, time: f32) -> Vec<[Vec3; 3]> {
    let mut tris: Vec<[Vec3; 3]> = (0..mesh.triangle_count()).map(|t| mesh.corners(t)).collect();
    for i in &instances.instances {
        let m = i.motion.as_ref().map_or(i.world, |m| m.at(time));
        let local = &instances.meshes[i.mesh as usize];
        for t in 0..local.triangle_count() {
            tris[i.first as usize + t] = local.corners(t).map(|p| m.transform_point3(p));
        }
    }
    tris
}

fn brute_closest(tris: &[[Vec3; 3]], o: Vec3, d: Vec3) -> Option<(u32, f32)> {
    let wray = WatertightRay::new(o, d, safe_reciprocal(d));
    tris.iter()
        .enumerate()
        .filter_map(|(i, t)| wray.intersect(&t.map(|p| p.to_array()), f32::INFINITY).map(|h| (i as u32, h.t)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// The BVH's answers against brute force for rays at random times: the same triangle at the
/// same distance (to the rounding of the ray taken into a copy's space), or, where two
/// triangles are that close along the ray, either.
fn check_against_brute_force(moving: bool) {
    let (mesh, instances) = scene(60, moving);
    let bvh = Bvh::build_scene(&mesh, None, Some(&instances));
    assert_eq!(bvh.len(), mesh.triangle_count());
    assert_eq!(bvh.has_motion(), moving);
    let mut rng = Rng::new(77);
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..4000 {
        let time = if moving { rng.unit() } else { 0.0 };
        let tris = world_triangles(&mesh, &instances, time);
        // Half the rays at a random triangle's centre where it is at the ray's time: moving
        // copies are hit all along their arcs, far from where the steps have them.
        let o = rng.in_cube(1.0) * 12.0;
        let d = if rng.unit() < 0.5 {
            let t = &tris[((rng.unit() * tris.len() as f32) as usize).min(tris.len() - 1)];
            ((t[0] + t[1] + t[2]) / 3.0 - o).normalize()
        } else {
            rng.in_cube(1.0).normalize()
        };
        let ray = Ray::new(o, d, time);
        let want = brute_closest(&tris, o, d);
        let got = bvh.intersect(&ray, f32::INFINITY);
        match (got, want) {
            (Some(h), Some((id, t))) => {
                // The rounding of the ray taken into a copy's space moves the hit by a few ulps
                // of the coordinates, along the ray by that over the cosine of incidence.
                let [a, b, c] = tris[id as usize];
                let cos = (b - a).cross(c - a).normalize().dot(d).abs().max(1e-3);
                let tol = 4e-6 * (o.length() + t + 10.0) / cos;
                let close = |u: f32| (u - t).abs() <= tol;
                assert!(
                    close(h.t),
                    "time {time}: t {} against {t} (triangle {} against {id}, cos {cos})",
                    h.t,
                    h.triangle
                );
                if h.triangle != id {
                    let other = brute_closest(&[tris[h.triangle as usize]], o, d).map(|x| x.1);
                    assert!(other.is_some_and(close), "time {time}");
                }
                // Where the hit is, at the ray's time.
                let at = bvh.triangle_at(h.slot, time).map(Vec3::from_array);
                let p = at[0] * h.barycentrics[0] + at[1] * h.barycentrics[1] + at[2] * h.barycentrics[2];
                assert!(
                    p.distance(ray.at(h.t)) <= 1e-3 * (1.0 + h.t),
                    "time {time}: {p} against {}",
                    ray.at(h.t)
                );
                assert!(bvh.occluded(&ray, f32::INFINITY));
                assert!(!bvh.occluded(&ray, t - 2.0 * tol), "time {time}");
                hits += 1;
            }
            (None, None) => {
                assert!(!bvh.occluded(&ray, f32::INFINITY));
                misses += 1;
            }
            (got, want) => panic!("time {time}: {got:?} against brute force {want:?}"),
        }
    }
    assert!(hits > 400 && misses > 400, "{hits} hits, {misses} misses");
}

#[test]
fn instances_match_brute_force() {
    check_against_brute_force(false);
}

#[test]
fn moving_instances_match_brute_force_at_random_times() {
    check_against_brute_force(true);
}

/// A ray spawned at a hit on a copy skips that copy's triangle (and only its slots): the next
/// hit along it, from the hit point exactly, is never the triangle it left.
#[test]
fn spawned_rays_skip_the_copy_they_leave() {
    let (mesh, instances) = scene(60, false);
    let bvh = Bvh::build_scene(&mesh, None, Some(&instances));
    let mut rng = Rng::new(3);
    let mut checked = 0;
    for _ in 0..3000 {
        let ray = Ray::new(rng.in_cube(1.0) * 12.0, rng.in_cube(1.0).normalize(), 0.0);
        let Some(h) = bvh.intersect(&ray, f32::INFINITY) else { continue };
        let d = rng.in_cube(1.0).normalize();
        let leaving = bvh.leaving(h.slot, d);
        assert!(leaving.skips(h.slot));
        let next = bvh.intersect_from(&Ray::new(ray.at(h.t), d, 0.0), f32::INFINITY, leaving, |_, _| true);
        assert!(next.is_none_or(|n| n.slot != h.slot));
        // Its neighbours in other copies are still there to hit.
        if let Some(n) = next {
            assert!(!leaving.skips(n.slot) || n.slot == h.slot);
        }
        checked += 1;
    }
    assert!(checked > 500);
}

/// Memory grows with the unique meshes, not the copies: a hundred copies store the triangles
/// of one, and cost only their places (a few hundred bytes each); flattened they cost the
/// whole mesh each.
#[test]
fn memory_grows_with_the_meshes_not_the_copies() {
    let (mesh1, one) = scene(1, false);
    let (mesh100, hundred) = scene(100, false);
    let (b1, b100) =
        (Bvh::build_scene(&mesh1, None, Some(&one)), Bvh::build_scene(&mesh100, None, Some(&hundred)));
    // Both build every unique mesh (two blobs, each also mirrored).
    assert_eq!(b1.stored_triangles(), 30 / 3 + 130);
    assert_eq!(b100.stored_triangles(), b1.stored_triangles(), "the copies add no triangle");
    assert_eq!(b100.len(), mesh100.triangle_count());
    let per_copy = (b100.bytes() - b1.bytes()) / 99;
    let flat = Bvh::build(&mesh100);
    let flat_per_copy = (flat.bytes() - Bvh::build(&mesh1).bytes()) / 99;
    assert!(per_copy < 400, "{per_copy} bytes per copy");
    assert!(flat_per_copy > 10 * per_copy, "flattened: {flat_per_copy} bytes per copy, instanced {per_copy}");
}

/// A copy 10 from the axis it turns about, from 45° to 135° within one pair of steps: halfway it
/// stands above both steps' boxes, where the top tree must still find it (its box is swept
/// along the arc, not the union of the steps').
#[test]
fn a_turning_copy_is_found_all_along_its_arc() {
    let mut rng = Rng::new(5);
    // The mesh lies 10 from its own origin, which the rotation turns about (a translation
    // would be interpolated linearly, along the chord, as Cycles interpolates it).
    let mut local = blob(&mut rng, 10);
    local.positions.iter_mut().for_each(|p| *p += Vec3::X * 10.0);
    let step = |deg: f32| Affine3A::from_rotation_z(deg.to_radians());
    let motion = RigidMotion::from_steps(0.0, 1.0, &[step(45.0), step(135.0)]).unwrap();
    let mut mesh = Mesh::default();
    let positions: Vec<Vec3> = local.positions.iter().map(|&p| step(45.0).transform_point3(p)).collect();
    let indices: Vec<u32> = local.triangles.iter().flatten().copied().collect();
    let part =
        MeshPart { positions: &positions, normals: None, uvs: None, indices: Some(&indices), material: 0 };
    mesh.push(part).unwrap();
    let instance = Instance { mesh: 0, first: 0, world: step(45.0), motion: Some(motion) };
    let instances = SceneInstances { meshes: vec![local], instances: vec![instance], shared_from: None };
    let bvh = Bvh::build_scene(&mesh, None, Some(&instances));
    let mut above = 0;
    for k in 0..400 {
        let time = k as f32 / 399.0;
        let tris = world_triangles(&mesh, &instances, time);
        let t = &tris[k % tris.len()];
        let target = (t[0] + t[1] + t[2]) / 3.0;
        let o = Vec3::new(0.0, 0.0, 20.0) + rng.in_cube(1.0);
        let ray = Ray::new(o, (target - o).normalize(), time);
        let want = brute_closest(&tris, o, ray.direction);
        let got = bvh.intersect(&ray, f32::INFINITY);
        assert_eq!(got.is_some(), want.is_some(), "time {time}: {got:?} against {want:?}");
        above += (target.y > 9.0 && want.is_some()) as u32;
    }
    assert!(above > 50, "{above} hits above the steps' boxes");
}
