//! Loading and rendering the test scenes, and checking pixels against closed forms within the render's own noise.

use glam::{DVec3, UVec2, Vec2, Vec3};
use std::path::Path;
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, Rendered};
use tracer::scene::Scene;

/// Loads a scene, panicking with the loader's message.
pub(crate) fn load(path: &Path) -> Scene {
    let scene = Scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "unexpected warnings: {:#?}", scene.warnings);
    scene
}

/// Renders `scene` through `camera` at `size` (seed 7, no lens shaders), checking that no sample is NaN/Inf.
pub(crate) fn render(scene: &Scene, camera: &CameraDesc, size: UVec2, spp: u32, max_depth: u32) -> Rendered {
    let config = IntegratorConfig::DEFAULT.with_max_depth(max_depth);
    let tracer = PathTracer::new(scene, config).unwrap();
    let built = camera.build(size).unwrap();
    let settings = RenderSettings { seed: 7, ..RenderSettings::still(spp) };
    let r = tracer::render::render(&tracer, built.as_ref(), &mut LensChain::new(), &settings, &NoProgress)
        .unwrap();
    assert_eq!(r.stats.nonfinite_samples, 0, "NaN/Inf samples");
    r
}

/// An orthographic camera and its film → world map (the glTF orthographic model, written out
/// here: screen (2x/W − 1, 1 − 2y/H) scaled by (half height × aspect, half height)).
pub(crate) struct Ortho {
    pub(crate) desc: CameraDesc,
    pub(crate) from: Vec3,
    pub(crate) right: Vec3,
    pub(crate) up: Vec3,
    pub(crate) forward: Vec3,
    pub(crate) half: Vec2,
    pub(crate) size: UVec2,
}

impl Ortho {
    pub(crate) fn new(from: Vec3, at: Vec3, up: Vec3, half_height: f32, size: UVec2) -> Self {
        let desc =
            CameraDesc::look_at("ortho", from, at, up, Projection::Orthographic { half_height }).unwrap();
        let forward = (at - from).normalize();
        let right = forward.cross(up).normalize();
        let aspect = size.x as f32 / size.y as f32;
        Self {
            desc,
            from,
            right,
            up: right.cross(forward),
            forward,
            half: Vec2::new(half_height * aspect, half_height),
            size,
        }
    }

    /// The ray origin for film position `f` (direction: `forward`).
    pub(crate) fn origin(&self, f: Vec2) -> Vec3 {
        let s =
            Vec2::new(2.0 * f.x / self.size.x as f32 - 1.0, 1.0 - 2.0 * f.y / self.size.y as f32) * self.half;
        self.from + s.x * self.right + s.y * self.up
    }

    /// Where the ray of film position `f` meets the plane y = `y`.
    pub(crate) fn on_plane_y(&self, f: Vec2, y: f32) -> Vec3 {
        let o = self.origin(f);
        o + self.forward * ((y - o.y) / self.forward.y)
    }
}

/// Mean of `value` over an n × n grid of the footprint of pixel (i, j).
pub(crate) fn footprint(i: u32, j: u32, n: u32, value: impl Fn(Vec2) -> Vec3) -> Vec3 {
    let mut sum = DVec3::ZERO;
    for a in 0..n {
        for b in 0..n {
            let f = Vec2::new(i as f32 + (a as f32 + 0.5) / n as f32, j as f32 + (b as f32 + 0.5) / n as f32);
            sum += value(f).as_dvec3();
        }
    }
    (sum / (n * n) as f64).as_vec3()
}

/// Checks pixel (i, j) against `want` within 5σ (the render's own variance) + `rel`·want + `abs`;
/// returns the error in units of that tolerance.
pub(crate) fn check(what: &str, r: &Rendered, i: u32, j: u32, want: Vec3, rel: f32, abs: f32) -> f32 {
    let got = r.images.image.get(i, j);
    let spp = (r.stats.samples / (r.images.image.width as u64 * r.images.image.height as u64)) as f32;
    let sigma = (r.images.variance.get(i, j) / spp).max(Vec3::ZERO).to_array().map(f32::sqrt);
    let mut worst = 0.0f32;
    for c in 0..3 {
        let tol = 5.0 * sigma[c] + rel * want[c].abs() + abs;
        let err = (got[c] - want[c]).abs();
        assert!(
            err <= tol,
            "{what}: pixel ({i}, {j}) channel {c} is {} but the closed form gives {} (tolerance {tol:.2e}, σ {:.2e})",
            got[c],
            want[c],
            sigma[c]
        );
        worst = worst.max(err / tol);
    }
    worst
}

/// Asserts that every pixel is the grey `want` of its column within `tol`, both given by
/// `column(i)`: for renders where every sample is exact (emission seen directly, a directional
/// light on a plane), so no noise enters the tolerance.
pub(crate) fn assert_exact_columns(r: &Rendered, column: impl Fn(u32) -> (f32, f32)) {
    let image = &r.images.image;
    for j in 0..image.height {
        for i in 0..image.width {
            let (want, tol) = column(i);
            let got = image.get(i, j);
            assert!((got - Vec3::splat(want)).abs().max_element() < tol, "({i}, {j}): {got} vs {want}");
        }
    }
}

/// The linear value of an sRGB 8-bit code.
pub(crate) fn srgb(code: u8) -> f32 {
    let s = code as f64 / 255.0;
    (if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }) as f32
}
