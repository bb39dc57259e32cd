//! Furnace tests: scenes whose every pixel has a closed-form radiance (docs/testing.md §1;
//! pbrt-v4's analytic-scene tests), so the reference is mathematics, not another renderer.
//!
//! (a) A camera inside a closed diffuse sphere of albedo ρ whose wall emits radiance Le towards
//!     the inside. Every wall point sees only wall, so with unlimited depth the radiance L is the
//!     same everywhere and satisfies L = Le + ρ·L, i.e. L = Le / (1 − ρ); a path of at most D
//!     scattering vertices collects Le·(1 + ρ + … + ρ^D) = Le·(1 − ρ^(D+1)) / (1 − ρ). This holds
//!     for *any* closed surface, so the polyhedral sphere is exact and every pixel can be tested
//!     against the constant with the statistical golden test, not only the image mean.
//! (b) A point light of radiant intensity I = π W/sr at the centre of a sphere of radius R = 1
//!     and albedo ρ = 0.5 (formula below): radiance 1 − 0.5^D after D scattering vertices.
//!
//! Each case checks the image mean within 0.5 % of the closed form and *first* asserts that the
//! 0.5 % is at least five standard errors of the mean (from the render's own per-sample variance,
//! an upper bound for its stratified samples) plus the geometric model error, so the tolerance is
//! honest: a correct renderer fails by chance with probability below 1e-6, and one 1 % off fails
//! with near certainty. Cameras: perspective and equirectangular, both at the sphere's centre;
//! with and without Russian roulette.

use crate::common::*;
use glam::{UVec2, Vec3};
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::IntegratorConfig;
use tracer::material::Material;
use tracer::render::Rendered;
use tracer::scene::{PunctualLight, Scene};
use tracer::test_support::compare::{StatTest, statistical_test};

const CENTRE: Vec3 = Vec3::new(1.0, -2.0, 3.0);
const SPP: u32 = 64;
/// Relative tolerance on the image mean.
const TOLERANCE: f64 = 0.005;

/// The two camera models at the sphere's centre.
fn cameras() -> Vec<(&'static str, CameraDesc, UVec2)> {
    let at = CENTRE + Vec3::new(0.3, 0.2, -1.0);
    vec![
        (
            "perspective",
            look_at(CENTRE, at, Vec3::Y, Projection::Perspective { fov_y: 90f32.to_radians() }),
            UVec2::new(64, 48),
        ),
        ("equirectangular", look_at(CENTRE, at, Vec3::Y, Projection::Equirectangular), UVec2::new(96, 48)),
    ]
}

/// Checks the image mean of `r` against `expected` per channel; `model_error` is a bound on the
/// relative deviation of the scene's true radiance from the closed form (tessellation).
fn check_mean(what: &str, r: &Rendered, expected: Vec3, model_error: f64) {
    print_stats(what, r);
    assert_eq!(r.stats.nonfinite_samples, 0, "{what}: NaN/Inf samples");
    let mean = mean_f64(&r.images.image);
    let se = standard_error_of_mean(estimate(r));
    for c in 0..3 {
        let want = expected[c] as f64;
        let tol = TOLERANCE * want;
        println!(
            "{what} channel {c}: mean {:.6} expected {want:.6} (rel. diff {:+.2e}, σ_mean {:.2e} = {:.2e} rel.)",
            mean[c],
            (mean[c] - want) / want,
            se[c],
            se[c] / want
        );
        // Honest tolerance: five standard errors plus the model error fit inside it.
        assert!(
            5.0 * se[c] + model_error * want <= tol,
            "{what}: the 0.5 % tolerance is not well above the noise (σ_mean {:.2e}, model error {model_error:.1e}); \
             render more samples",
            se[c]
        );
        assert!(
            (mean[c] - want).abs() <= tol,
            "{what} channel {c}: image mean {:.6} is not within 0.5 % of the closed form {want:.6}",
            mean[c]
        );
    }
}

/// A closed sphere of `levels` subdivisions around `CENTRE`, triangles facing inwards, with one
/// material.
fn sphere_scene(name: &str, levels: u32, material: Material) -> Scene {
    let (positions, indices) = icosphere(levels, CENTRE, 1.0, true);
    single_part_scene(name, &positions, &indices, material)
}

/// Le·(1 − ρ^(D+1)) / (1 − ρ) per channel (D = `u32::MAX` for unlimited depth).
fn emissive_furnace(le: Vec3, rho: Vec3, depth: u32) -> Vec3 {
    let f = |le: f32, rho: f32| {
        let tail = if depth == u32::MAX { 0.0 } else { (rho as f64).powi(depth as i32 + 1) };
        (le as f64 * (1.0 - tail) / (1.0 - rho as f64)) as f32
    };
    Vec3::new(f(le.x, rho.x), f(le.y, rho.y), f(le.z, rho.z))
}

#[test]
fn emissive_diffuse_sphere_matches_closed_form() {
    let rho = Vec3::new(0.2, 0.5, 0.8);
    let le = Vec3::new(1.0, 0.5, 0.25);
    // Emission from the front face only: the triangles face inwards, so the inside glows (an
    // outward-facing sphere would render black, which the check would catch).
    let material =
        Material { emission: le, emission_two_sided: false, ..Material::diffuse("glowing wall", rho) };
    // Level 4: 5120 triangles. Any closed surface gives the same closed form.
    let scene = sphere_scene("emissive sphere", 4, material);
    assert!(scene.mesh.triangle_count() >= 5000);
    // D = 3 without roulette and D = 3 with roulette from the first vertex, through both
    // cameras; then unlimited depth (D = 200: the ρ^(D+1) term, 0.8^201 ≈ 3e-20, is nothing)
    // with the default roulette through the panorama. Roulette at ρ = 0.8 makes the path length
    // geometric (mean 5): from the first vertex the per-sample relative spread is ≈ 0.75, so
    // that case takes ~7e5 samples to keep 5σ of the mean inside 0.5 %.
    let no_rr = IntegratorConfig::DEFAULT.with_max_depth(3).with_rr_depth(u32::MAX);
    let rr = IntegratorConfig::DEFAULT.with_max_depth(3).with_rr_depth(1);
    let unlimited = IntegratorConfig::DEFAULT.with_max_depth(200);
    let [(p_name, perspective, p_res), (e_name, equirect, e_res)]: [_; 2] = cameras().try_into().unwrap();
    let cases = [
        (p_name, &perspective, p_res, "D=3 no RR", no_rr, 3, SPP),
        (p_name, &perspective, p_res, "D=3 RR from 1", rr, 3, SPP),
        (e_name, &equirect, e_res, "D=3 no RR", no_rr, 3, SPP),
        (e_name, &equirect, e_res, "D=3 RR from 1", rr, 3, SPP),
        // First-vertex splitting: the branches' weight 1/N (N = 3, not a power of two) and
        // their resuming at the first hit without its emission counted again.
        (p_name, &perspective, p_res, "D=3 split 3", no_rr.with_split(3), 3, SPP),
        (e_name, &equirect, e_res, "D=3 RR from 1, split 2", rr.with_split(2), 3, SPP),
        (e_name, &equirect, e_res, "D=200 default RR", unlimited, 200, 160),
    ];
    for (seed, (camera_name, camera, resolution, config_name, config, depth, spp)) in
        cases.into_iter().enumerate()
    {
        let what = format!("emissive sphere, {camera_name}, {config_name}");
        let expected = emissive_furnace(le, rho, depth);
        let job = Job { resolution, spp, seed: seed as u32 + 1, config };
        let r = render_plain(&scene, camera, job);
        check_mean(&what, &r, expected, 0.0);
        // Exact for the polyhedron too, so every pixel is tested against the constant.
        let reference = constant_image(resolution.x, resolution.y, expected);
        let report = statistical_test(estimate(&r), &reference);
        println!("{report}");
        assert!(report.passed(), "{what}: pixels differ from the closed form:\n{report}");
    }
    // Unlimited depth matches Le / (1 − ρ) to the last digit of the formula used above.
    let unlimited = emissive_furnace(le, rho, u32::MAX);
    assert!((unlimited - le / (Vec3::ONE - rho)).abs().max_element() < 1e-6);
}

/// (b) Point light in a ρ = 0.5 sphere.
///
/// Derivation, for a sphere of radius R with the light at its centre: every wall point receives
/// direct irradiance E = I·cos θ / R² = I / R² (the light is along the normal), so its direct
/// radiance is L₁ = (ρ/π)·E = ρ·I / (π R²) = 0.5 for I = π, R = 1. Each further bounce multiplies
/// by ρ: a wall point sees only wall, and a uniform wall radiance L gives irradiance π·L, hence
/// reflected radiance ρ·L. With D scattering vertices the camera sees
/// L = Σ_{k=1..D} ρ^k = 1 − 0.5^D (the first vertex sees the light directly; the camera ray
/// itself carries no emission).
///
/// Tessellation error: the walls are flat triangles whose planes lie at distance h < 1 from the
/// centre. On a face, E/E_sphere = cos θ/d² · R² = h/d³ ranges over [h, 1/h²] (nearest point
/// d = h, farthest vertex d = 1), so the direct term deviates by at most δ = max(1/h² − 1, 1 − h).
/// The bounces keep that bound: a closed convex surface maps a radiance field bounded by c to
/// reflected radiance bounded by ρ·c, so an error ε·L₁ in the direct term becomes at most
/// ε·L₁/(1 − ρ) = ε·(1 − 0.5^∞) in the total: at most δ relative to the closed form.
/// With 20 · 4^5 = 20480 faces, h_min ≈ 0.9998 and δ ≈ 4e-4 (computed below from the mesh),
/// ten times below the 0.5 % tolerance.
#[test]
fn point_light_in_diffuse_sphere_matches_closed_form() {
    let levels = 5;
    let mut scene = sphere_scene("point-lit sphere", levels, Material::diffuse("wall", Vec3::splat(0.5)));
    scene
        .lights
        .push(PunctualLight::Point { position: CENTRE, intensity: Vec3::splat(std::f32::consts::PI) });
    scene.validate().unwrap();
    assert_eq!(scene.mesh.triangle_count(), 20480);

    // The model error δ, from the actual f32 mesh.
    let h_min = (0..scene.mesh.triangle_count())
        .map(|t| {
            let [a, b, c] = scene.mesh.corners(t).map(|p| (p - CENTRE).as_dvec3());
            let n = (b - a).cross(c - a).normalize();
            n.dot(a).abs()
        })
        .fold(f64::INFINITY, f64::min);
    let delta = (1.0 / (h_min * h_min) - 1.0).max(1.0 - h_min);
    println!("tessellation: h_min = {h_min:.6}, model error bound δ = {delta:.2e}");
    assert!(delta < 1e-3);

    let mut seed = 100;
    for (camera_name, camera, resolution) in cameras() {
        // (D, roulette from, spp): roulette (default depth 3) adds noise, so those runs take
        // more samples; without it every sample of D ≤ 2 is nearly the exact value.
        // (D, roulette from, spp, split): splitting takes the light sample of the first
        // vertex once and N branches from it.
        for (depth, rr, spp, split) in [
            (1, u32::MAX, SPP, 1),
            (2, u32::MAX, SPP, 1),
            (2, u32::MAX, SPP, 4),
            (4, 3, SPP, 1),
            (64, 3, 2 * SPP, 1),
        ] {
            let config = IntegratorConfig::DEFAULT.with_max_depth(depth).with_rr_depth(rr).with_split(split);
            let what = format!("point light in sphere, {camera_name}, D={depth}, rr {rr}, split {split}");
            let expected = 1.0 - 0.5f64.powi(depth as i32);
            let job = Job { resolution, spp, seed, config };
            seed += 1;
            let r = render_plain(&scene, &camera, job);
            check_mean(&what, &r, Vec3::splat(expected as f32), delta);
            // Per pixel too (the tessellation error is far below per-pixel noise; only the
            // outlier count is used, since the image-level bias check is sensitive to δ).
            let reference = constant_image(resolution.x, resolution.y, Vec3::splat(expected as f32));
            let report = StatTest::default().against_reference(estimate(&r), &reference);
            assert!(report.pixels_passed(), "{what}: pixels differ from the closed form:\n{report}");
        }
    }
}

/// A thin-walled smooth glass of index 1.5 with a sheen of `color` and roughness 0.4.
fn sheer_glass(color: Vec3) -> Material {
    Material {
        transmission: 1.0,
        roughness: 0.0,
        ior: 1.5,
        thin_walled: true,
        sheen: color,
        sheen_roughness: 0.4,
        ..Material::diffuse("sheer glass", Vec3::ONE)
    }
}

/// Sheen over glass, as Cycles' Principled BSDF lays it (the sheen on top of the transmission,
/// which keeps 1 − the sheen's albedo): (a) a closed thin-walled glass ball under a white sheen
/// in a white sky is a furnace (every interaction passes on all the light it gets: the sheen's
/// albedo R plus the glass's (1 − R)·(F + 1 − F)), so every pixel is 1; (b) a red sheen on a
/// thin glass sheet seen at cos θ = 0.5 shows (1, 1 − R, 1 − R), R the sheen's albedo there: the
/// red the sheen reflects and the white it takes from the glass. Without the sheen over the
/// glass (only the opaque part carrying it), (b) renders white: G and B 1, R away.
#[test]
fn sheen_over_glass_keeps_energy_and_takes_its_share() {
    let centre = Vec3::new(0.0, 0.0, 0.0);
    let (positions, indices) = icosphere(3, centre, 1.0, false);
    let mut ball = single_part_scene("sheer ball", &positions, &indices, sheer_glass(Vec3::ONE));
    ball.environment.color = Vec3::ONE;
    let camera = look_at(Vec3::new(0.5, 0.3, 3.0), centre, Vec3::Y, Projection::Perspective { fov_y: 0.8 });
    let config = IntegratorConfig::DEFAULT.with_max_depth(64).with_rr_depth(u32::MAX);
    let r = render_plain(&ball, &camera, Job { resolution: UVec2::new(32, 24), spp: 256, seed: 3, config });
    check_mean("white sheen over thin glass, white sky", &r, Vec3::ONE, 0.0);
    let report = statistical_test(estimate(&r), &constant_image(32, 24, Vec3::ONE));
    println!("{report}");
    assert!(report.passed(), "the sheer ball is not a furnace:\n{report}");

    // (b) The sheet in the xy plane, seen along a direction at cos θ 0.5 by a narrow camera.
    let corners = [
        Vec3::new(-4.0, -4.0, 0.0),
        Vec3::new(4.0, -4.0, 0.0),
        Vec3::new(4.0, 4.0, 0.0),
        Vec3::new(-4.0, 4.0, 0.0),
    ];
    let red = Vec3::X;
    let mut sheet = single_part_scene("sheer sheet", &corners, &[0, 1, 2, 0, 2, 3], sheer_glass(red));
    sheet.environment.color = Vec3::ONE;
    let wo = Vec3::new(0.75f32.sqrt(), 0.0, 0.5);
    let camera = look_at(wo * 2.0, Vec3::ZERO, Vec3::Y, Projection::Perspective { fov_y: 0.01 });
    let r = render_plain(&sheet, &camera, Job { resolution: UVec2::new(16, 16), spp: 512, seed: 4, config });
    let albedo = tracer::bsdf::sheen::Sheen::new(Vec3::ONE, 0.4, Vec3::Z, Vec3::Z, wo).albedo();
    let want = Vec3::new(1.0, 1.0 - albedo, 1.0 - albedo);
    let mean = mean_f64(&r.images.image);
    let se = standard_error_of_mean(estimate(&r));
    println!(
        "red sheen over a thin glass sheet at cos θ 0.5: mean {mean:?} ± {se:?}, expected {want} (R {albedo})"
    );
    assert_eq!(r.stats.nonfinite_samples, 0);
    assert!(
        albedo > 0.02 && 5.0 * se[1] < 0.25 * albedo as f64,
        "the sheen's share {albedo} is not well above the noise {se:?}"
    );
    for c in 0..3 {
        assert!(
            (mean[c] - want[c] as f64).abs() < 5.0 * se[c] + 1e-3,
            "channel {c}: {} where the sheen over the glass gives {} (R {albedo})",
            mean[c],
            want[c]
        );
    }
}
