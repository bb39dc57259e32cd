//! Numerical robustness of the tracer core (docs/design/tracer.md §3.4; docs/testing.md §4): the ray–surface arithmetic
//! must not depend on where the scene is or how big it is.
//!
//! (a) Scale and offset: the Cornell box with every vertex and the camera scaled by 10^k,
//!     k ∈ {−4, −2, 0, 2, 4}, or translated by 10^4 along every axis, is the same scene (radiance
//!     is scale-free), so each must render the same image as the unscaled box — checked with the
//!     statistical two-estimate test (`StatTest::between`, independent seeds). Reference: the
//!     unscaled render, itself proven against Mitsuba in `cornell_reference.rs`.
//! (b) Self-intersection: rays spawned from hit points on tiny (1e-4) and huge (1e4) triangles at
//!     random orientations, up to 1e4 from the origin, in random and grazing directions on both
//!     sides, never hit their own triangle again; shadow rays between points on two triangles
//!     (`spawn_ray_to`) are blocked by neither end. Reference: geometry (a ray leaving a plane
//!     cannot meet it again; a segment between two planar triangles crosses neither).
//! (c) Grazing and degenerate geometry: cameras looking along a plane (orthographic at
//!     cos ≈ 1e-7, perspective down to cos → 0) produce no NaN/Inf sample, and — analytic answer:
//!     a diffuse plane of albedo ρ under a uniform sky of radiance 1 has radiance ρ everywhere —
//!     the grazing rays must hit the plane and bounce off it cleanly (every pixel exactly ρ).
//!     Degenerate (point, repeated-vertex, collinear, denormal-sliver) triangles added to the
//!     Cornell box must change nothing (statistically) and produce no non-finite sample.

use crate::common::*;
use glam::{Affine3A, UVec2, Vec3};
use std::sync::OnceLock;
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::interaction::SurfaceInteraction;
use tracer::material::Material;
use tracer::ray::Ray;
use tracer::render::Rendered;
use tracer::scene::{Environment, Mesh, MeshPart, Scene};
use tracer::test_support::Rng;
use tracer::test_support::compare::{Estimate, StatTest};

/// Film and samples of the Cornell comparisons: 128² at 64 spp (a 2 % bias gives z ≈ 9 here).
const SIZE: u32 = 128;
const SPP: u32 = 64;

/// The unscaled glTF Cornell render every variant is compared with (rendered once per process).
fn base() -> &'static Rendered {
    static BASE: OnceLock<Rendered> = OnceLock::new();
    BASE.get_or_init(|| {
        let (scene, camera) = cornell_gltf();
        let r = render_plain(&scene, &camera, Job::square(SIZE, SPP, 1000));
        print_stats("base Cornell", &r);
        assert_eq!(r.stats.nonfinite_samples, 0);
        r
    })
}

/// `scene` and `camera` with every point mapped by `f` (a similarity: scale and/or translation).
fn transformed(scene: &Scene, camera: &CameraDesc, scale: f64, offset: f64) -> (Scene, CameraDesc) {
    // In f64, so the only rounding is the final one to f32: the test is about the tracer.
    let f = |p: Vec3| (p.as_dvec3() * scale + glam::DVec3::splat(offset)).as_vec3();
    let mut scene = scene.clone();
    for p in &mut scene.mesh.positions {
        *p = f(*p);
    }
    let mut camera = camera.clone();
    let m = camera.world_from_camera;
    camera.world_from_camera = Affine3A::from_mat3_translation(m.matrix3.into(), f(m.translation.into()));
    (scene, camera)
}

fn compare_with_base(what: &str, r: &Rendered) {
    print_stats(what, r);
    assert_eq!(r.stats.nonfinite_samples, 0, "{what}: NaN/Inf samples");
    let report = StatTest::default().between(estimate(r), estimate(base()));
    println!("{what} vs the unscaled box:\n{report}");
    maybe_save(what, &r.images.image);
    assert!(report.passed(), "{what} renders a different image from the unscaled box:\n{report}");
}

#[test]
fn scaled_cornell_renders_the_same_image() {
    let (scene, camera) = cornell_gltf();
    let mut unit_scale = None;
    for (i, k) in [-4, -2, 0, 2, 4].into_iter().enumerate() {
        let (s, c) = transformed(&scene, &camera, 10f64.powi(k), 0.0);
        // Emission is radiance: nothing to rescale.
        let r = render_plain(&s, &c, Job::square(SIZE, SPP, 2000 + i as u32));
        compare_with_base(&format!("Cornell × 1e{k}"), &r);
        if k == 0 {
            unit_scale = Some(r);
        }
    }
    // Power at this size: the base made 2 % darker must fail against the scale-1 render.
    let b = base();
    let darker = scaled(&b.images.image, 0.98);
    let darker_var = scaled(&b.images.variance, 0.98 * 0.98);
    let report = StatTest::default().between(
        estimate(&unit_scale.unwrap()),
        Estimate { mean: &darker, variance: &darker_var, samples: SPP },
    );
    assert!(!report.passed(), "a 2 % bias went unnoticed at {SIZE}² × {SPP} spp:\n{report}");
}

#[test]
fn cornell_far_from_the_origin_renders_the_same_image() {
    // 10^4 on every axis: coordinates near 10005, where f32 spacing is 2^-10 ≈ 1e-3, the gap
    // between the light and the ceiling. Vertices still round apart (1 or 2 ulps), and spawned
    // rays are offset by their error bound (≈ 4e-3 here): the image must not change.
    let (scene, camera) = cornell_gltf();
    let (s, c) = transformed(&scene, &camera, 1.0, 1e4);
    let r = render_plain(&s, &c, Job::square(SIZE, SPP, 3000));
    compare_with_base("Cornell + 1e4", &r);
}

/// A random non-degenerate triangle of size about `size` centred at `centre`.
fn random_triangle(rng: &mut Rng, centre: Vec3, size: f32) -> [Vec3; 3] {
    loop {
        let [a, b, c] = [rng.direction(), rng.direction(), rng.direction()];
        // Well-shaped enough to be a real triangle (area > 0.05, 4 % of the largest possible).
        if (b - a).cross(c - a).length() > 0.1 {
            return [a, b, c].map(|p| (centre.as_dvec3() + p.as_dvec3() * size as f64).as_vec3());
        }
    }
}

/// A centre up to 1e4 from the origin: a random direction times a log-uniform distance.
fn random_centre(rng: &mut Rng) -> Vec3 {
    rng.direction() * 10f32.powf(rng.range(-3.0, 4.0))
}

fn scene_of(triangles: &[[Vec3; 3]]) -> Scene {
    let positions: Vec<Vec3> = triangles.iter().flatten().copied().collect();
    let indices: Vec<u32> = (0..positions.len() as u32).collect();
    single_part_scene("random triangles", &positions, &indices, Material::diffuse("grey", Vec3::splat(0.5)))
}

/// The first hit of a ray from a random point towards a random point of triangle `tri` (as
/// stored: f32 corners), from its front or back side, or `None` if the ray found nothing (it may
/// hit another triangle first: then that one is returned). The aim starts 0.1 … 100 × `reach`
/// away, `reach` being the triangle's size or, where f32 cannot resolve that size (a 1e-4
/// triangle 1e4 from the origin lives on a 1e-3 grid), a thousand ulps of the position.
fn hit_on(tracer: &PathTracer, tri: [Vec3; 3], rng: &mut Rng) -> Option<SurfaceInteraction> {
    let b = rng.barycentrics();
    let [p0, p1, p2] = tri.map(|p| p.as_dvec3());
    let target = (p0 * b[0] as f64 + p1 * b[1] as f64 + p2 * b[2] as f64).as_vec3();
    let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
    let size = (tri[1] - tri[0]).length().max((tri[2] - tri[0]).length());
    let reach = size.max(1e3 * f32::EPSILON * target.abs().max_element());
    let side = if rng.unit() < 0.5 { n } else { -n };
    let mut w = rng.direction();
    if w.dot(side) < 0.0 {
        w = -w;
    }
    let origin = target + w * reach * 10f32.powf(rng.range(-1.0, 2.0));
    let d = (target - origin).normalize();
    let hit = tracer.bvh().intersect(&Ray::new(origin, d, 0.0), f32::INFINITY)?;
    Some(tracer.interaction(&hit))
}

/// Directions for spawning from a surface with normal `n`: random ones, their mirror images on
/// the other side, and grazing ones at |cos| = 1e-2 … 1e-6 on both sides.
fn spawn_directions(n: Vec3, rng: &mut Rng) -> Vec<Vec3> {
    let mut out = Vec::new();
    for _ in 0..4 {
        let w = rng.direction();
        out.push(w);
        out.push((w - 2.0 * w.dot(n) * n).normalize());
    }
    let tangent = (rng.direction() - n * rng.direction().dot(n)).cross(n).normalize();
    for eps in [1e-2f32, 1e-4, 1e-6] {
        for sign in [1.0f32, -1.0] {
            out.push((tangent + sign * eps * n).normalize());
        }
    }
    out
}

#[test]
fn spawned_rays_never_rehit_their_own_triangle() {
    let mut rng = Rng::new(77);
    for size in [1e-4f32, 1e4] {
        // 1500 triangles scattered up to 1e4 from the origin (the huge ones overlap: rays may
        // meet other triangles, never their own).
        let generated: Vec<[Vec3; 3]> = (0..1500)
            .map(|_| {
                let centre = random_centre(&mut rng);
                random_triangle(&mut rng, centre, size)
            })
            .collect();
        let scene = scene_of(&generated);
        let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).unwrap();
        let (mut tested, mut grazing_tested) = (0u32, 0u32);
        // Aims at well-resolved triangles (≥ 1000 ulps across) and at the rest.
        let (mut aims, mut missed, mut coarse_aims, mut coarse_missed) = (0u32, 0u32, 0u32, 0u32);
        let mut miss_examples = Vec::new();
        let mut failures = Vec::new();
        for t in 0..scene.mesh.triangle_count() {
            // The triangle as stored (rounded to f32); rounding can flatten a tiny triangle far
            // from the origin to nothing, which no ray can hit.
            let tri = scene.mesh.corners(t);
            if (tri[1] - tri[0]).cross(tri[2] - tri[0]).length_squared() == 0.0 {
                continue;
            }
            let ulps = size / (f32::EPSILON * tri[0].abs().max_element().max(f32::MIN_POSITIVE));
            let resolved = ulps >= 1000.0;
            for _ in 0..2 {
                if resolved {
                    aims += 1;
                } else {
                    coarse_aims += 1;
                }
                let Some(si) = hit_on(&tracer, tri, &mut rng) else {
                    if resolved {
                        missed += 1;
                        miss_examples.push(format!("{tri:?}"));
                    } else {
                        coarse_missed += 1;
                    }
                    continue;
                };
                for w in spawn_directions(si.n_geom, &mut rng) {
                    let ray = si.spawn_ray(w, 0.0);
                    if w.dot(si.n_geom).abs() < 0.1 {
                        grazing_tested += 1;
                    }
                    tested += 1;
                    if let Some(again) = tracer.bvh().intersect(&ray, f32::INFINITY)
                        && again.triangle == si.triangle
                    {
                        failures.push(format!(
                            "triangle {} (aimed at {t}) at {} (error {}), direction {w} (cos {:.1e}): \
                                 re-hit at t = {:e}",
                            si.triangle,
                            si.p,
                            si.p_error,
                            w.dot(si.n_geom),
                            again.t
                        ));
                    }
                }
            }
        }
        println!(
            "size {size:e}: {tested} spawned rays ({grazing_tested} grazing); aims at resolved triangles \
             {aims} ({missed} missed), at triangles under 1000 ulps {coarse_aims} ({coarse_missed} missed)"
        );
        assert!(
            failures.is_empty(),
            "size {size:e}: {} of {tested} spawned rays re-hit their own triangle, e.g.\n{}",
            failures.len(),
            failures.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
        );
        // Aims at a point inside a triangle should hit (the target can round outside it only
        // on triangles f32 barely resolves).
        assert!(
            missed * 100 < aims,
            "{missed} of {aims} aiming rays missed: {:?}",
            &miss_examples[..missed.min(5) as usize]
        );
    }
}

/// Shadow rays between points on two triangles. The error-bound offset (pbrt-v4 §6.8.6) is
/// guaranteed only when each end lies farther from the other triangle's plane than the offsets
/// (a few ulps of the coordinates): closer than that, pushing an end off its own surface can
/// carry it across the other one. Such pairs (tiny triangles a few ulps apart far from the
/// origin) are counted and reported, not asserted.
#[test]
fn shadow_rays_are_not_blocked_by_either_end() {
    let mut rng = Rng::new(78);
    let (mut tested, mut within_bounds, mut within_bounds_blocked) = (0, 0, 0);
    let mut failures = Vec::new();
    // (size of A, size of B); B's centre is 0.5 … 5 of the larger size from A's.
    let kinds = [(1e-4f32, 1e-4f32), (1e4, 1e4), (1e-4, 1e4)];
    for (size_a, size_b) in kinds {
        for _ in 0..300 {
            let centre = random_centre(&mut rng);
            let big = size_a.max(size_b);
            let a = random_triangle(&mut rng, centre, size_a);
            let centre_b = centre + rng.direction() * big * rng.range(0.5, 5.0);
            let b = random_triangle(&mut rng, centre_b, size_b);
            let scene = scene_of(&[a, b]);
            let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).unwrap();
            // A point on each (retry the aim if the other triangle is in the way).
            let on = |which: usize, rng: &mut Rng| {
                let tri = scene.mesh.corners(which);
                (0..20).find_map(|_| hit_on(&tracer, tri, rng).filter(|si| si.triangle == which as u32))
            };
            let (Some(pa), Some(pb)) = (on(0, &mut rng), on(1, &mut rng)) else {
                continue;
            };
            // Signed distance (f64) of `q` to the plane of triangle `t`.
            let plane = |t: u32, q: Vec3| {
                let [p0, p1, p2] = scene.mesh.corners(t as usize).map(|p| p.as_dvec3());
                (p1 - p0).cross(p2 - p0).normalize().dot(q.as_dvec3() - p0)
            };
            let offset = |si: &SurfaceInteraction| si.n_geom.abs().dot(si.p_error) as f64;
            let margin = 2.0 * (offset(&pa) + offset(&pb));
            let resolved = plane(pa.triangle, pb.p).abs() > margin && plane(pb.triangle, pa.p).abs() > margin;
            for (from, to) in [(&pa, &pb), (&pb, &pa)] {
                let Some((ray, t_max)) = from.spawn_ray_to(to.p, to.p_error, to.n_geom, 0.0) else {
                    failures.push(format!("no shadow ray from {} to {}", from.p, to.p));
                    continue;
                };
                let blocked = tracer.bvh().occluded(&ray, t_max);
                if !resolved {
                    within_bounds += 1;
                    within_bounds_blocked += blocked as u32;
                    continue;
                }
                tested += 1;
                if blocked {
                    let blocker = tracer.bvh().intersect(&ray, t_max);
                    failures.push(format!(
                        "sizes {size_a:e}/{size_b:e}: shadow ray {} → {} blocked by {blocker:?} (t_max {t_max:e}); \
                         start to the planes of A, B: {:.3e}, {:.3e}; offsets {:.3e}, {:.3e}",
                        from.p,
                        to.p,
                        plane(0, ray.origin),
                        plane(1, ray.origin),
                        offset(&pa),
                        offset(&pb),
                    ));
                }
            }
        }
    }
    println!(
        "{tested} shadow rays between triangle pairs; {within_bounds} more between points closer to the \
         other plane than the offsets, of which {within_bounds_blocked} blocked (not asserted)"
    );
    assert!(tested > 1200, "only {tested} shadow rays were tested");
    assert!(
        failures.is_empty(),
        "{} of {tested} shadow rays were blocked by an end, e.g.\n{}",
        failures.len(),
        failures.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
    );
}

/// A diffuse square y = `height` of half-size `half` (exactly representable corners), albedo ρ,
/// under a uniform sky of radiance 1 and nothing else.
fn plane_under_sky(height: f32, half: f32, rho: f32) -> Scene {
    let positions = [
        Vec3::new(-half, height, -half),
        Vec3::new(-half, height, half),
        Vec3::new(half, height, half),
        Vec3::new(half, height, -half),
    ];
    let mut scene = single_part_scene(
        "plane",
        &positions,
        &[0, 1, 2, 0, 2, 3],
        Material::diffuse("plane", Vec3::splat(rho)),
    );
    scene.environment = Environment { color: Vec3::ONE };
    scene
}

/// The orthographic grazing camera: parallel rays at cos = 1e-7 to the plane y = 1.5 (not 0, so
/// hit points carry a real error bound along the normal), starting 1e-5 … 3e-5 above it, so they
/// meet it 100 … 300 units away, well inside its 2048-unit extent.
fn grazing_orthographic() -> CameraDesc {
    let from = Vec3::new(0.25, 1.5 + 2e-5, 0.0);
    // Aim 1000 units ahead so the 1e-7 slope survives rounding (ulp(1.5) ≈ 1.2e-7).
    let at = from + Vec3::new(0.0, -1e-4, -1000.0);
    look_at(from, at, Vec3::Y, Projection::Orthographic { half_height: 1e-5 })
}

/// Grazing views of a plane produce no NaN/Inf. Analytic bound: a point on a diffuse plane of
/// albedo ρ that sees only a uniform sky of radiance 1 reflects radiance ρ (no other geometry, no
/// light to sample; cosine sampling gives f·cos/pdf = ρ exactly), a miss sees 1, so every sample
/// is ρ or 1 and every pixel lies in [ρ, 1] (a self-intersecting bounce would give ≤ ρ²).
#[test]
fn grazing_views_of_a_plane_give_no_nan() {
    let rho = 0.5;
    let scene = plane_under_sky(1.5, 1024.0, rho);
    let config = IntegratorConfig::DEFAULT;
    let tracer = PathTracer::new(&scene, config).unwrap();
    // Perspective along the plane (its rows near the horizon meet it at every grazing angle down
    // to 0), and the orthographic camera at cos = 1e-7.
    let from = Vec3::new(0.25, 1.5 + 1e-3, 0.0);
    let perspective = look_at(from, from - Vec3::Z, Vec3::Y, Projection::Perspective { fov_y: 0.2 });
    for (what, camera, seed) in [("perspective", perspective, 6), ("orthographic", grazing_orthographic(), 5)]
    {
        let job = Job { resolution: UVec2::new(64, 64), spp: 16, seed, config };
        let r = render_prepared(&tracer, &camera, &mut Default::default(), job);
        print_stats(&format!("grazing {what}"), &r);
        assert_eq!(r.stats.nonfinite_samples, 0, "{what}: NaN/Inf samples");
        for (i, p) in r.images.image.pixels.iter().enumerate() {
            assert!(
                p.min_element() >= rho - 1e-6 && p.max_element() <= 1.0 + 1e-6,
                "{what}: pixel {i} = {p} outside [ρ, 1]"
            );
        }
        if what == "perspective" {
            let plane = r.images.image.pixels.iter().filter(|p| (p.x - rho).abs() < 1e-6).count();
            assert!(plane > 1000, "the plane should fill the lower half: {plane} pixels at ρ");
        }
    }
}

/// Rays at cos = 1e-7 to a plane they cross 100 … 300 units away must hit it, and the bounce
/// must not re-hit it: with the analytic scene above, every pixel is exactly ρ (a miss shows the
/// sky through the floor, > ρ; a bounce re-hitting the plane gives < ρ).
///
/// The hit distance is numerically well determined here: the plane is 2048 wide, so the f32
/// cancellation in t is of order γ·2048 ≈ 1e-3 at most, far below t ≥ 100. (Hits closer than
/// about 1e-6 × a triangle's extent cannot be certified positive in f32 at all; they are not
/// asked for.)
#[test]
fn grazing_rays_hit_a_large_plane() {
    let rho = 0.5;
    let scene = plane_under_sky(1.5, 1024.0, rho);
    let job = Job { resolution: UVec2::new(64, 64), spp: 16, seed: 5, config: IntegratorConfig::DEFAULT };
    let r = render_plain(&scene, &grazing_orthographic(), job);
    assert_eq!(r.stats.nonfinite_samples, 0);
    let pixels = &r.images.image.pixels;
    let missed = pixels.iter().filter(|p| p.x > rho + 1e-6).count();
    let self_hit = pixels.iter().filter(|p| p.x < rho - 1e-6).count();
    assert!(
        missed == 0 && self_hit == 0,
        "grazing camera (cos 1e-7, plane 100 … 300 ahead): of {} pixels, {missed} saw the sky through the \
         plane (value > ρ) and {self_hit} re-hit it (value < ρ)",
        pixels.len()
    );
}

/// Degenerate triangles of every kind, inside the Cornell box (where camera and bounce rays
/// pass), with the given material.
fn degenerate_triangles(rng: &mut Rng, material: u32, count: usize) -> (Vec<Vec3>, Vec<u32>, u32) {
    let mut positions = Vec::new();
    let inside = |rng: &mut Rng| Vec3::new(rng.range(0.1, 5.4), rng.range(0.1, 5.4), rng.range(0.1, 5.5));
    for k in 0..count {
        let (a, b) = (inside(rng), inside(rng));
        let tri = match k % 6 {
            0 => [a, a, a],                              // a point
            1 => [a, a, b],                              // a repeated vertex
            2 => [a, b, (a + b) * 0.5],                  // collinear, middle vertex
            3 => [a, b, a + 2.0 * (b - a)],              // collinear, outer vertex
            4 => [a, b, a],                              // a segment there and back
            _ => [a, b, b + Vec3::new(0.0, 1e-30, 0.0)], // a sliver of denormal width
        };
        positions.extend(tri);
    }
    let indices = (0..positions.len() as u32).collect();
    (positions, indices, material)
}

#[test]
fn degenerate_triangles_change_nothing_and_give_no_nan() {
    let (mut scene, camera) = cornell_gltf();
    let light = scene.materials.iter().position(Material::is_emissive).expect("an emissive material") as u32;
    let white = scene.materials.iter().position(|m| m.name == "white").expect("material 'white'") as u32;
    let mut rng = Rng::new(79);
    let before = scene.mesh.triangle_count();
    for material in [white, light] {
        let (positions, indices, material) = degenerate_triangles(&mut rng, material, 60);
        scene
            .mesh
            .push(MeshPart {
                positions: &positions,
                normals: None,
                uvs: None,
                indices: Some(&indices),
                material,
            })
            .unwrap();
    }
    scene.validate().unwrap();
    println!("{} degenerate triangles added to {before}", scene.mesh.triangle_count() - before);
    let r = render_plain(&scene, &camera, Job::square(SIZE, SPP, 4000));
    compare_with_base("Cornell + degenerate triangles", &r);

    // A scene of nothing but degenerate triangles under a sky is the sky, exactly.
    let (positions, indices, _) = degenerate_triangles(&mut rng, 0, 600);
    let mut mesh = Mesh::default();
    mesh.push(MeshPart {
        positions: &positions,
        normals: None,
        uvs: None,
        indices: Some(&indices),
        material: 0,
    })
    .unwrap();
    let sky = Vec3::new(0.3, 0.6, 0.9);
    let scene = Scene {
        mesh,
        materials: vec![Material { emission: Vec3::ONE, ..Material::diffuse("white", Vec3::ONE) }],
        environment: Environment { color: sky },
        ..Scene::default()
    };
    let r = render_plain(&scene, &camera, Job::square(32, 16, 4001));
    assert_eq!(r.stats.nonfinite_samples, 0);
    assert!(r.images.image.pixels.iter().all(|p| *p == sky), "degenerate triangles were visible");
}
