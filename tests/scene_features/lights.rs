//! Spot, point and directional lights in glTF's photometric units, against closed-form irradiance.

use super::assets::*;
use super::harness::*;
use glam::{UVec2, Vec3};
use std::f32::consts::PI;

/// Blender Cycles' spot falloff (docs/design/tracer.md §3.10): smoothstep((cos θ − cos θo) / ((1 − cos
/// θo)·b)), b = 1 − inner/outer.
pub(crate) fn blender_falloff(cos: f32, inner: f32, outer: f32) -> f32 {
    if cos <= outer.cos() {
        return 0.0;
    }
    let b = 1.0 - inner / outer;
    if b <= 0.0 {
        return 1.0;
    }
    let x = ((cos - outer.cos()) / ((1.0 - outer.cos()) * b)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The glTF specification's recommended falloff: the square of the linear ramp in cos θ.
pub(crate) fn gltf_falloff(cos: f32, inner: f32, outer: f32) -> f32 {
    if cos <= outer.cos() {
        return 0.0;
    }
    let t = ((cos - outer.cos()) / (inner.cos() - outer.cos()).max(1e-3)).clamp(0.0, 1.0);
    t * t
}

/// A punctual light over a diffuse plane, in closed form.
pub(crate) struct Punctual {
    pub(crate) position: Vec3,
    /// Radiant intensity, W/sr (candela / 683).
    pub(crate) intensity: Vec3,
    /// Spot: axis, inner, outer, Blender falloff?
    pub(crate) spot: Option<(Vec3, f32, f32, bool)>,
}

impl Punctual {
    /// Irradiance on the plane y = 0 (normal +Y) at `p`: I·falloff(θ)·cos θ / d².
    pub(crate) fn irradiance(&self, p: Vec3) -> Vec3 {
        let to = self.position - p;
        let d2 = to.length_squared();
        let w = to / d2.sqrt();
        let cos_receiver = w.y.max(0.0);
        let falloff = match self.spot {
            None => 1.0,
            Some((axis, inner, outer, blender)) => {
                let cos = axis.dot(-w);
                if blender { blender_falloff(cos, inner, outer) } else { gltf_falloff(cos, inner, outer) }
            }
        };
        self.intensity * falloff * cos_receiver / d2
    }
}

/// Renders a ρ = 0.5 floor under `lights` (JSON, position, direction) from above (an
/// orthographic view of x, z ∈ [−2, 2]) and checks every pixel against ρ/π · Σ E.
pub(crate) fn floor_under_lights(
    tag: &str,
    generator: &str,
    lights: &[(&str, Vec3, Vec3)],
    model: &[Punctual],
) {
    let dir = TempDir::new(tag);
    let rho = 0.5;
    let mut g = Gltf::new(generator);
    let floor = g.material(&lambert("floor", Vec3::splat(rho)));
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X * 10.0, Vec3::Z * 10.0, Vec3::Y), floor)], "");
    for (json, position, direction) in lights {
        g.light(json, *position, *direction);
    }
    let scene = load(&g.write(&dir, tag));
    let cam = Ortho::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 2.0, UVec2::splat(32));
    let r = render(&scene, &cam.desc, cam.size, 64, 1);
    let mut worst = 0.0f32;
    for j in 0..32 {
        for i in 0..32 {
            let want = footprint(i, j, 16, |f| {
                let p = cam.on_plane_y(f, 0.0);
                rho / PI * model.iter().map(|l| l.irradiance(p)).sum::<Vec3>()
            });
            // The absolute term (2.5e-4 of the peak 0.4) covers pixels at the cone's edge, where
            // a few samples see a sliver of light the 16 × 16 grid resolves differently.
            worst = worst.max(check(tag, &r, i, j, want, 2e-3, 1e-4));
        }
    }
    println!("{tag}: worst pixel at {worst:.2} of its tolerance");
}

/// Spot lights with Blender's falloff (a Blender-written file) and the glTF one (any other
/// writer): a 30°/20° cone 2 above a ρ = 0.5 plane. The view (±2) covers the full-intensity
/// centre (r < 0.73), both ramps (Blender's from r = 0.91, glTF's from 0.73, to the edge at
/// r = 1.15) and the dark outside; 10 × 683 cd is 10 W/sr.
#[test]
fn spot_light_falloff_and_units_against_closed_form() {
    let (inner, outer) = (20f32.to_radians(), 30f32.to_radians());
    let json = format!(
        r#"{{"type": "spot", "color": [1, 0.5, 0.25], "intensity": 6830, "range": 3,
            "spot": {{"innerConeAngle": {inner}, "outerConeAngle": {outer}}}}}"#
    );
    let position = Vec3::new(0.1, 2.0, -0.2);
    let intensity = Vec3::new(10.0, 5.0, 2.5);
    for (tag, generator, blender) in [
        ("spot-blender", "Khronos glTF Blender I/O v4.2.70", true),
        ("spot-gltf", "some other exporter", false),
    ] {
        let model = [Punctual { position, intensity, spot: Some((Vec3::NEG_Y, inner, outer, blender)) }];
        floor_under_lights(tag, generator, &[(&json, position, Vec3::NEG_Y)], &model);
    }
    // The two falloffs differ where the test looks: inside the ramp by up to ~3×.
    let cos = 25f32.to_radians().cos();
    assert!(blender_falloff(cos, inner, outer) > 2.0 * gltf_falloff(cos, inner, outer));
}

/// A point light of 3 × 683 cd = 3 W/sr over the plane; a directional light of 683·2 lux =
/// 2 W/m² at 60° from the vertical: radiance ρ/π · E · cos 60° everywhere.
#[test]
fn point_and_directional_lights_against_closed_form() {
    let position = Vec3::new(0.5, 1.5, -0.3);
    let model = [Punctual { position, intensity: Vec3::new(3.0, 3.0, 1.5), spot: None }];
    let json = r#"{"type": "point", "color": [1, 1, 0.5], "intensity": 2049}"#;
    floor_under_lights("point", "scene_features", &[(json, position, Vec3::NEG_Z)], &model);

    let dir = TempDir::new("sun");
    let mut g = Gltf::new("scene_features");
    let floor = g.material(&lambert("floor", Vec3::splat(0.5)));
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X * 10.0, Vec3::Z * 10.0, Vec3::Y), floor)], "");
    let travel = Vec3::new(60f32.to_radians().sin(), -60f32.to_radians().cos(), 0.0);
    g.light(r#"{"type": "directional", "intensity": 1366}"#, Vec3::new(0.0, 9.0, 0.0), travel);
    let scene = load(&g.write(&dir, "sun"));
    let cam = Ortho::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 2.0, UVec2::splat(16));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    let want = 0.5 / PI * 2.0 * 0.5;
    for p in &r.images.image.pixels {
        assert!((*p - Vec3::splat(want)).abs().max_element() < 1e-5 * want, "{p} vs {want}");
    }
}
