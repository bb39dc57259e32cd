//! Environment lighting: the white furnace for metal balls and an environment map on a diffuse ball.

use super::assets::*;
use super::harness::*;
use glam::{UVec2, Vec2, Vec3};
use std::path::PathBuf;
use tracer::scene::EnvironmentMap;

/// White furnace: white metal balls (roughness 0.2, 0.5, 1) in a uniform white environment
/// reflect ≈ 1 everywhere (Blender-like energy compensation: single-scattering GGX loses up to
/// ~10 % at roughness 1, far outside the tolerance), and never NaN.
#[test]
fn white_furnace_metal_balls_reflect_everything() {
    let dir = TempDir::new("furnace");
    for roughness in [0.2f32, 0.5, 1.0] {
        let mut g = Gltf::new("scene_features");
        let metal = g.material(&format!(
            r#"{{"name": "metal", "pbrMetallicRoughness": {{"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 1, "roughnessFactor": {roughness}}}}}"#
        ));
        g.mesh_node(&[(&sphere(Vec3::ZERO, 1.0, 48, 96), metal)], "");
        let mut scene = load(&g.write(&dir, &format!("furnace{roughness}")));
        scene.environment.color = Vec3::ONE;
        let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, UVec2::splat(24));
        let r = render(&scene, &cam.desc, cam.size, 64, 16);
        // Pixels whose footprint is inside the ball's silhouette.
        let (mut sum, mut n) = (0.0f64, 0);
        for j in 0..24 {
            for i in 0..24 {
                let far = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .map(|(a, b)| cam.origin(Vec2::new(i as f32 + a, j as f32 + b)).truncate().length());
                if far.iter().all(|r| *r < 0.95) {
                    n += 1;
                    sum += r.images.image.get(i, j).element_sum() as f64 / 3.0;
                    check(&format!("furnace roughness {roughness}"), &r, i, j, Vec3::ONE, 0.03, 0.0);
                }
            }
        }
        let mean = sum / n as f64;
        println!("furnace roughness {roughness}: mean {mean:.4} over {n} pixels");
        assert!((mean - 1.0).abs() < 0.015, "roughness {roughness}: mean {mean} is not ≈ 1");
    }
}

/// Writes an equirectangular EXR of `width × height` with radiance `f(column, row)`.
pub(crate) fn exr(
    dir: &TempDir,
    name: &str,
    width: u32,
    height: u32,
    f: impl Fn(u32, u32) -> Vec3,
) -> PathBuf {
    let mut image = tracer::image::RgbImage::new(width, height);
    for y in 0..height {
        for x in 0..width {
            image.set(x, y, f(x, y));
        }
    }
    let path = dir.path(name);
    tracer::image_io::write_exr(&path, &image, &[], &[]).unwrap();
    path
}

/// A diffuse ball (ρ = 0.6) lit only by an environment image. A constant map of radiance L
/// gives ρ·L on the ball and L around it, as the constant `environment.color` of the same value
/// does. A map bright only in its top half (the +Y hemisphere) gives ρ·L·(1 + n_y)/2, the
/// sphere's irradiance from a uniform half-sky; bright only in its right half (+X), ρ·L·(1 + n_x)/2.
#[test]
fn environment_map_lights_a_diffuse_ball() {
    let dir = TempDir::new("envmap");
    let rho = 0.6;
    let mut g = Gltf::new("scene_features");
    let m = g.material(&lambert("ball", Vec3::splat(rho)));
    g.mesh_node(&[(&sphere(Vec3::ZERO, 1.0, 64, 128), m)], "");
    let base = load(&g.write(&dir, "ball"));
    let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.25, UVec2::splat(24));
    let l = Vec3::new(0.5, 1.0, 2.0);

    // (map, closed form of the ball's radiance for normal n, the background for the view ray).
    type Case = (PathBuf, Box<dyn Fn(Vec3) -> Vec3>);
    let cases: [(&str, Case); 3] = [
        ("constant", (exr(&dir, "constant.exr", 16, 8, |_, _| l), Box::new(move |_| rho * l))),
        (
            "upper half",
            (
                exr(&dir, "sky.exr", 32, 16, |_, y| if y < 8 { l } else { Vec3::ZERO }),
                Box::new(move |n: Vec3| rho * l * (1.0 + n.y) / 2.0),
            ),
        ),
        (
            "right half",
            (
                exr(&dir, "east.exr", 32, 16, |x, _| if x >= 16 { l } else { Vec3::ZERO }),
                Box::new(move |n: Vec3| rho * l * (1.0 + n.x) / 2.0),
            ),
        ),
    ];
    let mut constant_mean = Vec3::ZERO;
    for (what, (path, closed_form)) in &cases {
        let map = EnvironmentMap::load(path, 0.0, 1.0).unwrap();
        assert!(map.warnings().is_empty(), "{:?}", map.warnings());
        let mut scene = base.clone();
        scene.environment_map = Some(map);
        let r = render(&scene, &cam.desc, cam.size, 256, 1);
        for j in 0..24 {
            for i in 0..24 {
                let radii = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .map(|(a, b)| cam.origin(Vec2::new(i as f32 + a, j as f32 + b)).truncate().length());
                if radii.iter().all(|r| *r < 0.97) {
                    let want = footprint(i, j, 4, |f| {
                        let p = cam.origin(f).truncate();
                        closed_form(Vec3::new(p.x, p.y, (1.0 - p.length_squared()).max(0.0).sqrt()))
                    });
                    check(&format!("environment {what}, ball"), &r, i, j, want, 0.01, 2e-3);
                } else if radii.iter().all(|r| *r > 1.0) && *what == "constant" {
                    check("environment constant, background", &r, i, j, l, 1e-5, 0.0);
                }
            }
        }
        if *what == "constant" {
            constant_mean = r.images.image.mean();
        }
    }
    // The same value as a constant environment colour renders the same image (up to noise).
    let mut scene = base.clone();
    scene.environment.color = l;
    let r = render(&scene, &cam.desc, cam.size, 256, 1);
    let diff = (r.images.image.mean() - constant_mean).abs().max_element();
    assert!(diff < 0.01 * l.max_element(), "map {constant_mean} vs colour {}", r.images.image.mean());
}
