//! Glass beyond the smooth interface (issue 39, deliver 4): Beer–Lambert absorption inside a
//! closed transmissive mesh (`KHR_materials_volume`) against the closed form, and goldens of the
//! Khronos sample models for rough transmission and for volume attenuation. The rough lobe's
//! own checks (white furnace, density, reciprocity, grazing angles) are unit tests in
//! `bsdf/rough_dielectric.rs`; its parity with Cycles is `cycles_parity::rough_glass`.

use crate::common::golden::{Sampled, check_golden};
use crate::common::*;
use crate::gltf_samples::sample;
use glam::{UVec2, Vec3};
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::job::SceneSetup;
use tracer::lens::LensChain;
use tracer::material::Material;

/// A box [−5, 5]² × [0, `depth`], triangles facing out.
fn slab(depth: f32) -> (Vec<Vec3>, Vec<u32>) {
    let p = |x: f32, y: f32, z: f32| Vec3::new(x * 5.0, y * 5.0, z * depth);
    let positions = vec![
        p(-1.0, -1.0, 0.0),
        p(1.0, -1.0, 0.0),
        p(1.0, 1.0, 0.0),
        p(-1.0, 1.0, 0.0),
        p(-1.0, -1.0, 1.0),
        p(1.0, -1.0, 1.0),
        p(1.0, 1.0, 1.0),
        p(-1.0, 1.0, 1.0),
    ];
    #[rustfmt::skip]
    let indices = vec![
        0, 2, 1, 0, 3, 2, // bottom (−z)
        4, 5, 6, 4, 6, 7, // top (+z)
        0, 1, 5, 0, 5, 4, // −y
        2, 3, 7, 2, 7, 6, // +y
        1, 2, 6, 1, 6, 5, // +x
        3, 0, 4, 3, 4, 7, // −x
    ];
    (positions, indices)
}

/// Seen straight through a slab of absorbing glass of index 1 (no Fresnel reflection, no
/// bending) under a white sky, every pixel is the Beer–Lambert transmittance exp(−σa·d) exactly,
/// per channel; the same glass with no volume is clear.
#[test]
fn beer_lambert_through_a_slab() {
    let (depth, sigma) = (0.6f32, Vec3::new(0.5, 1.0, 2.0));
    let (positions, indices) = slab(depth);
    let glass = Material {
        transmission: 1.0,
        roughness: 0.0,
        ior: 1.0,
        base_color: Vec3::ONE,
        attenuation: sigma,
        ..Material::diffuse("absorbing glass", Vec3::ONE)
    };
    let camera = look_at(
        Vec3::new(0.1, 0.2, 3.0),
        Vec3::new(0.1, 0.2, 0.0),
        Vec3::Y,
        Projection::Orthographic { half_height: 1.0 },
    );
    let job = Job { resolution: UVec2::new(16, 12), spp: 4, seed: 1, config: IntegratorConfig::DEFAULT };
    for (absorbing, expected) in [(true, (-sigma * depth).exp()), (false, Vec3::ONE)] {
        let material = Material { attenuation: if absorbing { sigma } else { Vec3::ZERO }, ..glass.clone() };
        let mut scene = single_part_scene("slab", &positions, &indices, material);
        scene.environment.color = Vec3::ONE;
        let r = render_plain(&scene, &camera, job);
        assert_eq!(r.stats.nonfinite_samples, 0);
        for p in &r.images.image.pixels {
            assert!((*p - expected).abs().max_element() < 1e-4 * expected.max_element(), "{p} vs {expected}");
        }
    }
}

/// A sample model under a white sky, framed as the corpus test frames it: `render(spp, seed)`.
fn sample_render(name: &str) -> impl Fn(u32, u32) -> Sampled {
    let setup = SceneSetup { sky: Some(Vec3::splat(1.0)), ..SceneSetup::default() };
    let scene = setup.load(&sample(name)).expect("load the sample model");
    assert!(
        !scene.warnings.iter().any(|w| w.contains("not supported") || w.contains("rough transmission")),
        "{name}: {:?}",
        scene.warnings
    );
    let (lo, hi) = scene.bounds().expect("geometry");
    let (centre, radius) = ((lo + hi) * 0.5, (hi - lo).length() * 0.5);
    let camera: CameraDesc = look_at(
        centre + Vec3::new(0.0, 0.15, 1.0).normalize() * radius * 1.6,
        centre,
        Vec3::Y,
        Projection::Perspective { fov_y: 0.8 },
    );
    let tracer = PathTracer::new(&scene, IntegratorConfig::DEFAULT).expect("prepare");
    move |spp, seed| {
        let job = Job { resolution: UVec2::new(64, 48), spp, seed, config: IntegratorConfig::DEFAULT };
        Sampled::from_rendered(render_prepared(&tracer, &camera, &mut LensChain::new(), job), spp)
    }
}

/// TransmissionRoughnessTest: rows of glass from smooth to frosted (rough transmission).
#[test]
fn transmission_roughness_sample() {
    let name = "TransmissionRoughnessTest";
    check_golden("transmission-roughness", &format!("{name}, white sky"), 64, sample_render(name));
}

/// AttenuationTest: slabs of coloured absorbing glass of growing thickness (volume attenuation).
#[test]
fn attenuation_sample() {
    let name = "AttenuationTest";
    check_golden("attenuation", &format!("{name}, white sky"), 64, sample_render(name));
}
