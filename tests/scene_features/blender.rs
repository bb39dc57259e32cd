//! A file written as Blender's exporter writes it: its units, spot falloff and one-sided emitters.

use super::assets::*;
use super::harness::*;
use super::lights::*;
use glam::{Quat, UVec2, Vec2, Vec3};
use std::f32::consts::{FRAC_PI_2, PI};
use tracer::scene::CameraSelector;

/// What Blender 5's exporter writes for a small scene: Principled materials as baseColorFactor
/// with `KHR_materials_specular` 0 on the walls, an emissive quad (`emissiveFactor` ×
/// `KHR_materials_emissive_strength`, `doubleSided: false`) facing up, a 100 W point light and a
/// 200 W spot (size 60°, blend 0.25) as candela = W/(4π)·683, and a camera node looking down its
/// −Z. Checked: the floor under both lights against ρ/π · Σ I·falloff·cos θ/d² with Blender's
/// falloff, through the file's own perspective camera (its rays worked out by hand); the emitter
/// seen from above is exactly factor × strength; from below it is black, and its light never
/// reaches the floor beneath it.
#[test]
fn blender_style_file_units_falloff_and_one_sided_emitter() {
    let dir = TempDir::new("blender");
    let mut g = Gltf::new("Khronos glTF Blender I/O v4.2.70");
    let rho = 0.8;
    let floor = g.material(&format!(
        r#"{{"name": "Floor", "doubleSided": true, "pbrMetallicRoughness": {{"baseColorFactor": [{rho}, {rho}, {rho}, 1],
            "metallicFactor": 0, "roughnessFactor": 0.5}}, "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}}}}"#
    ));
    let lamp = g.material(
        r#"{"name": "Lamp", "emissiveFactor": [1, 0.5, 0.25], "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 10},
                           "KHR_materials_specular": {"specularFactor": 0}}}"#,
    );
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X * 6.0, Vec3::Z * 6.0, Vec3::Y), floor)], "");
    g.mesh_node(&[(&quad(Vec3::new(0.0, 4.0, 0.0), Vec3::X * 0.5, Vec3::Z * 0.5, Vec3::Y), lamp)], "");
    let watts_to_cd = |w: f32| w / (4.0 * PI) * 683.0;
    let (point_at, spot_at) = (Vec3::new(-2.0, 1.5, 0.0), Vec3::new(2.0, 2.0, 0.5));
    let (outer, blend) = (30f32.to_radians(), 0.25);
    let inner = outer - outer * blend;
    g.light(
        &format!(r#"{{"type": "point", "name": "Point", "intensity": {}}}"#, watts_to_cd(100.0)),
        point_at,
        Vec3::NEG_Z,
    );
    g.light(
        &format!(
            r#"{{"type": "spot", "name": "Spot", "intensity": {}, "spot": {{"innerConeAngle": {inner}, "outerConeAngle": {outer}}}}}"#,
            watts_to_cd(200.0)
        ),
        spot_at,
        Vec3::NEG_Y,
    );
    // Blender's camera: yfov 60°, at (0, 8, 0), turned −90° about +X so its −Z looks down −Y.
    g.cameras.push(
        r#"{"type": "perspective", "perspective": {"yfov": 1.0471976, "aspectRatio": 1.5, "znear": 0.1}}"#
            .into(),
    );
    let turn = Quat::from_rotation_x(-FRAC_PI_2);
    g.nodes.push(format!(
        r#"{{"name": "Camera", "camera": 0, "translation": [0, 8, 0], "rotation": {}}}"#,
        arr(&turn.to_array())
    ));
    let scene = load(&g.write(&dir, "blender"));

    let model = [
        Punctual { position: point_at, intensity: Vec3::splat(100.0 / (4.0 * PI)), spot: None },
        Punctual {
            position: spot_at,
            intensity: Vec3::splat(200.0 / (4.0 * PI)),
            spot: Some((Vec3::NEG_Y, inner, outer, true)),
        },
    ];
    let camera = scene.camera(&CameraSelector::Name("Camera".into())).unwrap().clone();
    let (w, h) = (48u32, 32u32);
    let r = render(&scene, &camera, UVec2::new(w, h), 512, 1);
    // The camera by hand: right +X, up −Z (the turn takes +Y to −Z), forward −Y.
    let tan = (30f32.to_radians()).tan();
    let ray = |f: Vec2| {
        let sx = (2.0 * f.x / w as f32 - 1.0) * tan * w as f32 / h as f32;
        let sy = (1.0 - 2.0 * f.y / h as f32) * tan;
        (sx * Vec3::X + sy * Vec3::NEG_Z + Vec3::NEG_Y).normalize()
    };
    let eye = Vec3::new(0.0, 8.0, 0.0);
    let on = |f: Vec2, y: f32| {
        let d = ray(f);
        eye + d * ((y - eye.y) / d.y)
    };
    let on_lamp = |p: Vec3| p.x.abs() < 0.5 && p.z.abs() < 0.5;
    let on_floor = |p: Vec3| p.x.abs() < 6.0 && p.z.abs() < 6.0;
    let (mut floor_pixels, mut lamp_pixels, mut worst) = (0, 0, 0.0f32);
    for j in 0..h {
        for i in 0..w {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .map(|(a, b)| Vec2::new(i as f32 + a, j as f32 + b));
            let hits_lamp = corners.map(|f| on_lamp(on(f, 4.0)));
            if hits_lamp.iter().all(|h| *h) {
                lamp_pixels += 1;
                let got = r.images.image.get(i, j);
                assert!(
                    (got - Vec3::new(10.0, 5.0, 2.5)).abs().max_element() < 1e-4,
                    "lamp pixel ({i}, {j}): {got}"
                );
            } else if hits_lamp.iter().all(|h| !*h) && corners.iter().all(|f| on_floor(on(*f, 0.0))) {
                // Pixels the cone's edge crosses are left to the spot test: here the spot is
                // chosen for ~10 % of the samples, too few to estimate a sliver's noise from.
                let lit = footprint(i, j, 8, |f| {
                    Vec3::splat((model[1].irradiance(on(f, 0.0)).x > 0.0) as u8 as f32)
                })
                .x;
                if lit > 0.0 && lit < 1.0 {
                    continue;
                }
                floor_pixels += 1;
                let want = footprint(i, j, 16, |f| {
                    let p = on(f, 0.0);
                    rho / PI * model.iter().map(|l| l.irradiance(p)).sum::<Vec3>()
                });
                worst = worst.max(check("Blender floor", &r, i, j, want, 2e-3, 1e-4));
            }
        }
    }
    println!(
        "Blender floor: {floor_pixels} pixels, worst at {worst:.2} of its tolerance; {lamp_pixels} lamp pixels"
    );
    assert!(floor_pixels > 800 && lamp_pixels >= 4, "{floor_pixels} floor, {lamp_pixels} lamp pixels");

    // From below, the lamp's back is black.
    let below = Ortho::new(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 4.0, 0.0), Vec3::Z, 0.4, UVec2::splat(8));
    let r = render(&scene, &below.desc, below.size, 4, 1);
    assert!(r.images.image.pixels.iter().all(|p| *p == Vec3::ZERO), "the lamp's back face emits");
}
