//! Scenes as users author them, rendered: every feature the loaders gained (textures, samplers,
//! `KHR_texture_transform`, second texture coordinates, normal maps and tangents, alpha cut-outs,
//! glass, spot/point/directional lights in glTF units, Blender's conventions, environment maps,
//! camera lists) checked against closed forms computed here by hand, never against the
//! renderer's own output.
//!
//! Every asset is written by the test into a temporary folder: glTF JSON by hand (this package
//! has no JSON crate), buffers as `.bin` files, images with the tracer's PNG/EXR writers.
//!
//! Tolerances: where a pixel's estimate is noisy, |rendered − expected| ≤ 5·σ + a small model
//! error, with σ from the render's own per-sample variance; the expected value is the closed form
//! averaged over the pixel's footprint (the film's box filter). Where every sample is exact
//! (emission seen directly, a directional light on a plane), the tolerance is float precision.

use glam::{DVec3, Quat, UVec2, Vec2, Vec3, Vec4};
use std::f32::consts::{FRAC_PI_2, PI};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tracer::camera::{CameraDesc, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, Rendered};
use tracer::scene::{CameraSelector, EnvironmentMap, Scene};

// ---------------------------------------------------------------------------------------------
// Assets
// ---------------------------------------------------------------------------------------------

/// A temporary folder, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("mcctrace-features-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// An 8-bit RGBA PNG.
fn png(dir: &TempDir, name: &str, width: u32, height: u32, rgba: &[[u8; 4]]) {
    let bytes: Vec<u8> = rgba.iter().flatten().copied().collect();
    tracer::image_io::write_png_rgba8(&dir.path(name), width, height, &bytes).unwrap();
}

fn num(v: f32) -> String {
    assert!(v.is_finite());
    format!("{v}")
}

fn arr(v: &[f32]) -> String {
    format!("[{}]", v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", "))
}

/// A glTF file written by hand: JSON objects as strings, one external binary buffer.
#[derive(Default)]
struct Gltf {
    generator: String,
    bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
    images: Vec<String>,
    samplers: Vec<String>,
    textures: Vec<String>,
    materials: Vec<String>,
    meshes: Vec<String>,
    nodes: Vec<String>,
    cameras: Vec<String>,
    lights: Vec<String>,
}

/// A mesh primitive's data.
#[derive(Default)]
struct Prim {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uv0: Vec<Vec2>,
    uv1: Vec<Vec2>,
    tangents: Vec<Vec4>,
    indices: Vec<u32>,
}

fn push<T>(list: &mut Vec<T>, item: T) -> usize {
    list.push(item);
    list.len() - 1
}

impl Gltf {
    fn new(generator: &str) -> Self {
        Self { generator: generator.to_owned(), ..Self::default() }
    }

    fn accessor(&mut self, bytes: Vec<u8>, component: u32, ty: &str, count: usize, bounds: &str) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let view =
            format!(r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}}}"#, self.bin.len(), bytes.len());
        self.bin.extend(bytes);
        let v = push(&mut self.views, view);
        let a = format!(
            r#"{{"bufferView": {v}, "componentType": {component}, "type": "{ty}", "count": {count}{bounds}}}"#
        );
        push(&mut self.accessors, a)
    }

    fn floats(&mut self, values: &[f32], ty: &str, count: usize, bounds: &str) -> usize {
        self.accessor(values.iter().flat_map(|f| f.to_le_bytes()).collect(), 5126, ty, count, bounds)
    }

    fn primitive(&mut self, p: &Prim, material: usize) -> String {
        let lo = p.positions.iter().fold(Vec3::splat(f32::MAX), |a, b| a.min(*b));
        let hi = p.positions.iter().fold(Vec3::splat(f32::MIN), |a, b| a.max(*b));
        let bounds = format!(r#", "min": {}, "max": {}"#, arr(&lo.to_array()), arr(&hi.to_array()));
        let flat3: Vec<f32> = p.positions.iter().flat_map(|v| v.to_array()).collect();
        let mut attributes =
            format!(r#""POSITION": {}"#, self.floats(&flat3, "VEC3", p.positions.len(), &bounds));
        if !p.normals.is_empty() {
            let flat: Vec<f32> = p.normals.iter().flat_map(|v| v.to_array()).collect();
            write!(attributes, r#", "NORMAL": {}"#, self.floats(&flat, "VEC3", p.normals.len(), "")).unwrap();
        }
        for (set, uvs) in [(0, &p.uv0), (1, &p.uv1)] {
            if !uvs.is_empty() {
                let flat: Vec<f32> = uvs.iter().flat_map(|v| v.to_array()).collect();
                write!(attributes, r#", "TEXCOORD_{set}": {}"#, self.floats(&flat, "VEC2", uvs.len(), ""))
                    .unwrap();
            }
        }
        if !p.tangents.is_empty() {
            let flat: Vec<f32> = p.tangents.iter().flat_map(|v| v.to_array()).collect();
            write!(attributes, r#", "TANGENT": {}"#, self.floats(&flat, "VEC4", p.tangents.len(), ""))
                .unwrap();
        }
        let bytes = p.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.accessor(bytes, 5125, "SCALAR", p.indices.len(), "");
        format!(r#"{{"attributes": {{{attributes}}}, "indices": {indices}, "material": {material}}}"#)
    }

    /// A mesh of `prims` on a new node with extra node JSON (`, "translation": …`).
    fn mesh_node(&mut self, prims: &[(&Prim, usize)], node_extra: &str) -> usize {
        let list: Vec<String> = prims.iter().map(|(p, m)| self.primitive(p, *m)).collect();
        let mesh = push(&mut self.meshes, format!(r#"{{"primitives": [{}]}}"#, list.join(", ")));
        push(&mut self.nodes, format!(r#"{{"mesh": {mesh}{node_extra}}}"#))
    }

    fn material(&mut self, json: &str) -> usize {
        push(&mut self.materials, json.to_owned())
    }

    /// A texture of the image file `uri` with sampler JSON `sampler` (or none).
    fn texture(&mut self, uri: &str, sampler: Option<&str>) -> usize {
        let image = push(&mut self.images, format!(r#"{{"uri": "{uri}"}}"#));
        match sampler {
            Some(s) => {
                let s = push(&mut self.samplers, s.to_owned());
                push(&mut self.textures, format!(r#"{{"source": {image}, "sampler": {s}}}"#))
            }
            None => push(&mut self.textures, format!(r#"{{"source": {image}}}"#)),
        }
    }

    /// A light shining along `direction` (spot, directional) from `position`.
    fn light(&mut self, json: &str, position: Vec3, direction: Vec3) -> usize {
        let l = push(&mut self.lights, json.to_owned());
        let q = Quat::from_rotation_arc(Vec3::NEG_Z, direction.normalize());
        let node = format!(
            r#"{{"translation": {}, "rotation": {}, "extensions": {{"KHR_lights_punctual": {{"light": {l}}}}}}}"#,
            arr(&position.to_array()),
            arr(&q.to_array())
        );
        push(&mut self.nodes, node)
    }

    fn write(&self, dir: &TempDir, name: &str) -> PathBuf {
        let bin_name = format!("{name}.bin");
        std::fs::write(dir.path(&bin_name), &self.bin).unwrap();
        let list = |v: &[String]| format!("[{}]", v.join(", "));
        let nodes: Vec<String> = (0..self.nodes.len()).map(|i| i.to_string()).collect();
        let mut json = format!(
            r#"{{"asset": {{"version": "2.0", "generator": "{}"}},
"extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength", "KHR_lights_punctual",
                   "KHR_texture_transform", "KHR_materials_transmission", "KHR_materials_ior"],
"scene": 0, "scenes": [{{"nodes": [{}]}}],
"buffers": [{{"uri": "{bin_name}", "byteLength": {}}}],
"bufferViews": {}, "accessors": {}, "meshes": {}, "nodes": {}, "materials": {}"#,
            self.generator,
            nodes.join(", "),
            self.bin.len(),
            list(&self.views),
            list(&self.accessors),
            list(&self.meshes),
            list(&self.nodes),
            list(&self.materials),
        );
        for (key, v) in [("images", &self.images), ("samplers", &self.samplers), ("textures", &self.textures)]
        {
            if !v.is_empty() {
                write!(json, r#", "{key}": {}"#, list(v)).unwrap();
            }
        }
        if !self.cameras.is_empty() {
            write!(json, r#", "cameras": {}"#, list(&self.cameras)).unwrap();
        }
        if !self.lights.is_empty() {
            write!(
                json,
                r#", "extensions": {{"KHR_lights_punctual": {{"lights": {}}}}}"#,
                list(&self.lights)
            )
            .unwrap();
        }
        json.push('}');
        dir.write(&format!("{name}.gltf"), json)
    }
}

/// A rectangle p(s, t) = centre + (2s − 1)·a + (2t − 1)·b with texture coordinates (s, t) (so
/// +b runs down the image), wound so its front faces `facing`.
fn quad(centre: Vec3, a: Vec3, b: Vec3, facing: Vec3) -> Prim {
    let st = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
    let positions = st.iter().map(|s| centre + (2.0 * s.x - 1.0) * a + (2.0 * s.y - 1.0) * b).collect();
    let indices = if a.cross(b).dot(facing) > 0.0 { vec![0, 1, 2, 0, 2, 3] } else { vec![0, 2, 1, 0, 3, 2] };
    Prim { positions, normals: vec![facing.normalize(); 4], uv0: st.to_vec(), indices, ..Prim::default() }
}

/// A UV sphere with exact vertex normals, triangles facing outwards.
fn sphere(centre: Vec3, radius: f32, stacks: u32, slices: u32) -> Prim {
    let mut p = Prim::default();
    for i in 0..=stacks {
        let theta = PI * i as f32 / stacks as f32;
        for j in 0..=slices {
            let phi = 2.0 * PI * j as f32 / slices as f32;
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            p.positions.push(centre + radius * n);
            p.normals.push(n);
        }
    }
    let at = |i: u32, j: u32| i * (slices + 1) + j;
    for i in 0..stacks {
        for j in 0..slices {
            for [a, b, c] in
                [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]]
            {
                let [pa, pb, pc] = [a, b, c].map(|k| p.positions[k as usize]);
                let n = (pb - pa).cross(pc - pa);
                if n.length() < 1e-9 {
                    continue; // the poles' degenerate triangles
                }
                let outward = n.dot((pa + pb + pc) / 3.0 - centre) > 0.0;
                p.indices.extend(if outward { [a, b, c] } else { [a, c, b] });
            }
        }
    }
    p
}

/// A Lambertian material (`KHR_materials_specular` 0, as Blender writes walls).
fn lambert(name: &str, rho: Vec3) -> String {
    format!(
        r#"{{"name": "{name}", "doubleSided": true, "pbrMetallicRoughness": {{"baseColorFactor": [{}, {}, {}, 1],
           "metallicFactor": 0, "roughnessFactor": 1}}, "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}}}}"#,
        rho.x, rho.y, rho.z
    )
}

// ---------------------------------------------------------------------------------------------
// Rendering and checking
// ---------------------------------------------------------------------------------------------

fn load(path: &Path) -> Scene {
    let scene = Scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings.is_empty(), "unexpected warnings: {:#?}", scene.warnings);
    scene
}

fn render(scene: &Scene, camera: &CameraDesc, size: UVec2, spp: u32, max_depth: u32) -> Rendered {
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
struct Ortho {
    desc: CameraDesc,
    from: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    half: Vec2,
    size: UVec2,
}

impl Ortho {
    fn new(from: Vec3, at: Vec3, up: Vec3, half_height: f32, size: UVec2) -> Self {
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
    fn origin(&self, f: Vec2) -> Vec3 {
        let s =
            Vec2::new(2.0 * f.x / self.size.x as f32 - 1.0, 1.0 - 2.0 * f.y / self.size.y as f32) * self.half;
        self.from + s.x * self.right + s.y * self.up
    }

    /// Where the ray of film position `f` meets the plane y = `y`.
    fn on_plane_y(&self, f: Vec2, y: f32) -> Vec3 {
        let o = self.origin(f);
        o + self.forward * ((y - o.y) / self.forward.y)
    }
}

/// Mean of `value` over an n × n grid of the footprint of pixel (i, j).
fn footprint(i: u32, j: u32, n: u32, value: impl Fn(Vec2) -> Vec3) -> Vec3 {
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
fn check(what: &str, r: &Rendered, i: u32, j: u32, want: Vec3, rel: f32, abs: f32) -> f32 {
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

fn srgb(code: u8) -> f32 {
    let s = code as f64 / 255.0;
    (if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }) as f32
}

// ---------------------------------------------------------------------------------------------
// Textures
// ---------------------------------------------------------------------------------------------

/// The 2 × 2 texture of the textured-quad tests: top-left, top-right, bottom-left, bottom-right.
const QUADRANTS: [[u8; 4]; 4] = [[128, 0, 0, 255], [0, 255, 0, 255], [0, 0, 64, 255], [255, 255, 255, 255]];

/// Renders an emissive quad filling an orthographic view, textured through `texture_info`
/// (JSON after `"index": 0`), with extra primitive data, and returns the colour of each image
/// quadrant (checked uniform).
fn quadrant_colours(dir: &TempDir, name: &str, texture_info: &str, uv1: Option<Vec<Vec2>>) -> [Vec3; 4] {
    let mut g = Gltf::new("scene_features");
    let texture = g.texture("quadrants.png", Some(r#"{"magFilter": 9728, "minFilter": 9728}"#));
    let material = g.material(&format!(
        r#"{{"name": "screen", "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1]}}, "emissiveFactor": [1, 1, 1],
            "emissiveTexture": {{"index": {texture}{texture_info}}}}}"#
    ));
    // The quad, [−1.1, 1.1]² at z = 0 facing the camera at +z (u right, v down), overfills the
    // view [−1, 1]²: the image quadrants are the texture's.
    let mut prim = quad(Vec3::ZERO, Vec3::X * 1.1, -Vec3::Y * 1.1, Vec3::Z);
    if let Some(uv1) = uv1 {
        prim.uv1 = uv1;
    }
    g.mesh_node(&[(&prim, material)], "");
    let scene = load(&g.write(dir, name));
    let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, UVec2::splat(32));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    let mut colours = [Vec3::ZERO; 4];
    for (q, colour) in colours.iter_mut().enumerate() {
        let (x0, y0) = ((q as u32 % 2) * 16, (q as u32 / 2) * 16);
        *colour = r.images.image.get(x0 + 8, y0 + 8);
        // Every pixel not touching the texel boundary (a sample rounding onto u or v = 0.5 could
        // pick either texel there, legitimately).
        for y in (y0..y0 + 16).filter(|y| !(15..=16).contains(y)) {
            for x in (x0..x0 + 16).filter(|x| !(15..=16).contains(x)) {
                let p = r.images.image.get(x, y);
                assert!(
                    (p - *colour).abs().max_element() < 1e-6,
                    "{name}: quadrant {q} is not uniform at ({x}, {y})"
                );
            }
        }
    }
    colours
}

/// The linear colour of texel `t` of `QUADRANTS` (sRGB decoded by the closed form).
fn texel(t: usize) -> Vec3 {
    Vec3::new(srgb(QUADRANTS[t][0]), srgb(QUADRANTS[t][1]), srgb(QUADRANTS[t][2]))
}

#[test]
fn textured_quad_reads_each_texel_at_known_uvs() {
    let dir = TempDir::new("quad");
    png(&dir, "quadrants.png", 2, 2, &QUADRANTS);
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-6;

    // Plain: each image quadrant shows its texel; a code of 128 reads 0.2158605 (sRGB decoded).
    let plain = quadrant_colours(&dir, "plain", "", None);
    assert!((plain[0].x - 0.215_860_5).abs() < 1e-6, "sRGB decode of 128: {}", plain[0].x);
    for (q, &colour) in plain.iter().enumerate() {
        assert!(close(colour, texel(q)), "quadrant {q}: {colour} vs {}", texel(q));
    }

    // KHR_texture_transform, rotation π/2 and offset (0, 0.5): st = (−v, u + 0.5), wrapped. By
    // hand: top-left (u, v < 0.5) → st.x ∈ (−0.5, 0) → column 1, st.y ∈ (0.5, 1) → row 1: the
    // bottom-right texel; top-right → column 1, row 0 (st.y ∈ (1, 1.5)); bottom-left → column 0,
    // row 1; bottom-right → column 0, row 0.
    let info = format!(
        r#", "extensions": {{"KHR_texture_transform": {{"rotation": {}, "offset": [0, 0.5]}}}}"#,
        FRAC_PI_2
    );
    let turned = quadrant_colours(&dir, "turned", &info, None);
    for (q, t) in [(0, 3), (1, 1), (2, 2), (3, 0)] {
        assert!(
            close(turned[q], texel(t)),
            "transformed quadrant {q}: {} vs texel {t} {}",
            turned[q],
            texel(t)
        );
    }

    // TEXCOORD_1, mirrored left–right (u1 = 1 − u0): each quadrant shows its mirror's texel.
    let mirrored = vec![Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0)];
    let second = quadrant_colours(&dir, "uv1", r#", "texCoord": 1"#, Some(mirrored.clone()));
    for (q, t) in [(0, 1), (1, 0), (2, 3), (3, 2)] {
        assert!(close(second[q], texel(t)), "TEXCOORD_1 quadrant {q}: {} vs texel {t}", second[q]);
    }
    // The transform's texCoord overrides the reference's: set 1 again through the extension.
    let info = r#", "extensions": {"KHR_texture_transform": {"texCoord": 1}}"#;
    let overridden = quadrant_colours(&dir, "override", info, Some(mirrored));
    assert_eq!(overridden, second);
}

// ---------------------------------------------------------------------------------------------
// Lights in glTF units
// ---------------------------------------------------------------------------------------------

/// Blender Cycles' spot falloff (NOTES.md): smoothstep((cos θ − cos θo) / ((1 − cos θo)·b)),
/// b = 1 − inner/outer.
fn blender_falloff(cos: f32, inner: f32, outer: f32) -> f32 {
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
fn gltf_falloff(cos: f32, inner: f32, outer: f32) -> f32 {
    if cos <= outer.cos() {
        return 0.0;
    }
    let t = ((cos - outer.cos()) / (inner.cos() - outer.cos()).max(1e-3)).clamp(0.0, 1.0);
    t * t
}

/// A punctual light over a diffuse plane, in closed form.
struct Punctual {
    position: Vec3,
    /// Radiant intensity, W/sr (candela / 683).
    intensity: Vec3,
    /// Spot: axis, inner, outer, Blender falloff?
    spot: Option<(Vec3, f32, f32, bool)>,
}

impl Punctual {
    /// Irradiance on the plane y = 0 (normal +Y) at `p`: I·falloff(θ)·cos θ / d².
    fn irradiance(&self, p: Vec3) -> Vec3 {
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
fn floor_under_lights(tag: &str, generator: &str, lights: &[(&str, Vec3, Vec3)], model: &[Punctual]) {
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

// ---------------------------------------------------------------------------------------------
// Normal maps, cut-outs, glass
// ---------------------------------------------------------------------------------------------

/// A constant normal map tilting the normal ~30° along the tangent, on two ρ = 0.5 floor
/// halves lit by a 1 W/m² directional light: the left half's tangent frame comes from its
/// texture coordinates (u along +X, v along +Z: tangent +X, bitangent −∂p/∂v = −Z), the right
/// half's from a TANGENT attribute (1, 0, 0, +1) on a node turned 90° about +Y (world tangent
/// −Z, bitangent n × t = −X). Each renders ρ/π · E · (n′ · l) with n′ the map's normal in that
/// frame.
#[test]
fn normal_map_tilts_the_cosine_law() {
    let dir = TempDir::new("normal");
    let code = [191u8, 128, 237];
    png(&dir, "tilt.png", 1, 1, &[[code[0], code[1], code[2], 255]]);
    let mut g = Gltf::new("scene_features");
    let texture = g.texture("tilt.png", None);
    let material = g.material(&format!(
        r#"{{"name": "bumpy", "pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}},
            "normalTexture": {{"index": {texture}}}, "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}}}}"#
    ));
    let left = quad(Vec3::new(-1.0, 0.0, 0.0), Vec3::X, Vec3::Z, Vec3::Y);
    g.mesh_node(&[(&left, material)], "");
    let mut right = quad(Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::Y);
    right.tangents = vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4];
    let turn = Quat::from_rotation_y(FRAC_PI_2);
    g.mesh_node(
        &[(&right, material)],
        &format!(r#", "translation": [1, 0, 0], "rotation": {}"#, arr(&turn.to_array())),
    );
    let l = Vec3::new(1.0, 2.0, 0.5).normalize();
    g.light(r#"{"type": "directional", "intensity": 683}"#, Vec3::new(0.0, 5.0, 0.0), -l);
    let scene = load(&g.write(&dir, "normal"));

    let m = Vec3::from(code.map(|c| 2.0 * c as f32 / 255.0 - 1.0));
    let n_left = (m.x * Vec3::X + m.y * Vec3::NEG_Z + m.z * Vec3::Y).normalize();
    let n_right = (m.x * Vec3::NEG_Z + m.y * Vec3::NEG_X + m.z * Vec3::Y).normalize();
    let (want_left, want_right) = (0.5 / PI * n_left.dot(l), 0.5 / PI * n_right.dot(l));
    // Tilted ~30° each way: far from each other and from the flat floor's 0.5/π · 0.873.
    assert!((want_left - want_right).abs() > 0.03 && (want_left - 0.5 / PI * l.y).abs() > 0.01);

    let cam = Ortho::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 1.0, UVec2::new(32, 16));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    for j in 0..16 {
        for i in 0..32 {
            let want = if i < 16 { want_left } else { want_right };
            let got = r.images.image.get(i, j);
            assert!(
                (got - Vec3::splat(want)).abs().max_element() < 1e-4 * want,
                "({i}, {j}): {got} vs {want}"
            );
        }
    }
}

/// A leaf: a quad at height 1 over x ∈ [1, 2] whose texture's left half has alpha 0 (cut away
/// by MASK) and right half alpha 1, lit by a sun travelling along (−1, −1, 0)/√2. The floor
/// in view (x ∈ [−1, 1]) is shadowed where the light passes the leaf's opaque half (floor
/// x ∈ [0.5, 1]) and lit as if there were no leaf elsewhere (x < 0 misses the leaf; x ∈ [0, 0.5]
/// passes its cut-out half).
#[test]
fn alpha_masked_leaf_casts_a_cut_out_shadow() {
    let dir = TempDir::new("leaf");
    png(&dir, "leaf.png", 2, 1, &[[40, 200, 40, 0], [40, 200, 40, 255]]);
    let mut g = Gltf::new("scene_features");
    let texture = g.texture("leaf.png", Some(r#"{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}"#));
    let leaf = g.material(&format!(
        r#"{{"name": "leaf", "alphaMode": "MASK", "doubleSided": true,
            "pbrMetallicRoughness": {{"baseColorTexture": {{"index": {texture}}}, "metallicFactor": 0}}}}"#
    ));
    let floor = g.material(&lambert("floor", Vec3::splat(0.5)));
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X * 3.0, Vec3::Z * 3.0, Vec3::Y), floor)], "");
    g.mesh_node(&[(&quad(Vec3::new(1.5, 1.0, 0.0), Vec3::X * 0.5, Vec3::Z * 2.0, Vec3::NEG_Y), leaf)], "");
    g.light(
        r#"{"type": "directional", "intensity": 683}"#,
        Vec3::new(3.0, 3.0, 0.0),
        Vec3::new(-1.0, -1.0, 0.0),
    );
    let scene = load(&g.write(&dir, "leaf"));
    let cam = Ortho::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 1.0, UVec2::splat(32));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    let lit = 0.5 / PI * std::f32::consts::FRAC_1_SQRT_2;
    for j in 0..32 {
        for i in 0..32 {
            // Film column i covers world x ∈ [i/16 − 1, (i + 1)/16 − 1).
            let want = if i >= 24 { 0.0 } else { lit };
            let got = r.images.image.get(i, j);
            assert!(
                (got - Vec3::splat(want)).abs().max_element() < 1e-4 * lit,
                "({i}, {j}): {got} vs {want}"
            );
        }
    }
}

/// Refraction through a glass ball (transmission 1, ior 1.5, radius 1) seen by an orthographic
/// camera against an emissive backdrop at z = −3 whose red rises linearly with x
/// (R = clamp((x + 2)/4), G = 1, from a 2-texel LINEAR/CLAMP texture). For each pixel the
/// closed form refracts the parallel ray into and out of the sphere by Snell's law (vectors
/// below), lands it on the backdrop, and weights it by the exact Fresnel transmittances: the
/// expected G is (1 − F₁)(1 − F₂) and R/G the backdrop ramp where the ray lands (plus the small
/// share of paths reflected inside the ball: once, they turn back by ~160° and see the black sky;
/// twice, ~0.2 %, they reach the backdrop elsewhere).
#[test]
fn glass_ball_refracts_as_snell_and_fresnel_say() {
    let dir = TempDir::new("glass");
    png(&dir, "ramp.png", 2, 1, &[[0, 255, 0, 255], [255, 255, 0, 255]]);
    let mut g = Gltf::new("scene_features");
    let texture = g.texture("ramp.png", Some(r#"{"magFilter": 9729, "wrapS": 33071, "wrapT": 33071}"#));
    let glass = g.material(
        r#"{"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 1.5}}}"#,
    );
    let backdrop = g.material(&format!(
        r#"{{"name": "backdrop", "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1]}}, "emissiveFactor": [1, 1, 1],
            "emissiveTexture": {{"index": {texture}}}}}"#
    ));
    g.mesh_node(&[(&sphere(Vec3::ZERO, 1.0, 96, 192), glass)], "");
    g.mesh_node(
        &[(&quad(Vec3::new(0.0, 0.0, -3.0), Vec3::X * 4.0, Vec3::NEG_Y * 4.0, Vec3::Z), backdrop)],
        "",
    );
    let scene = load(&g.write(&dir, "glass"));
    let ramp = |x: f64| ((x + 2.0) / 4.0).clamp(0.0, 1.0);
    // Refraction of unit d through a surface with unit normal n facing against d, eta = n_i/n_t:
    // the transmitted direction and the unpolarised Fresnel reflectance.
    let refract = |d: DVec3, n: DVec3, eta: f64| {
        let cos_i = -n.dot(d);
        let cos_t = (1.0 - eta * eta * (1.0 - cos_i * cos_i)).sqrt();
        let t = eta * d + (eta * cos_i - cos_t) * n;
        let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        (t, 0.5 * (rs * rs + rp * rp))
    };
    // (R, G) for the ray along −z through (x, y): G = (1 − F₁)(1 − F₂), R = G × the ramp where
    // it lands, plus the paths reflected inside the ball k = 1 … 3 times before they leave
    // (weight (1 − F₁)·F^k·(1 − F); those that leave forwards and meet the backdrop count).
    let expected_at = |x: f64, y: f64| -> Vec3 {
        let rho2 = x * x + y * y;
        if rho2 >= 1.0 {
            return Vec3::new(ramp(x) as f32, 1.0, 0.0);
        }
        let mut p = DVec3::new(x, y, (1.0 - rho2).sqrt());
        let (mut d, f1) = refract(DVec3::NEG_Z, p, 1.0 / 1.5);
        let (mut w, mut rg) = (1.0 - f1, (0.0, 0.0));
        for _ in 0..4 {
            let q = p - 2.0 * p.dot(d) * d; // the next point on the sphere, from inside
            let (out, f) = refract(d, -q, 1.5);
            let land = q + out * ((-3.0 - q.z) / out.z);
            if out.z < 0.0 && land.x.abs() <= 4.0 && land.y.abs() <= 4.0 {
                rg.0 += w * (1.0 - f) * ramp(land.x);
                rg.1 += w * (1.0 - f);
            }
            d -= 2.0 * d.dot(q) * q; // reflected inside
            w *= f;
            p = q;
        }
        Vec3::new(rg.0 as f32, rg.1 as f32, 0.0)
    };

    // Chosen rays: a tiny orthographic window (1e-5 across) at offset (x, y) is one ray.
    for (x, y) in [(0.1f32, 0.0f32), (0.3, 0.0), (0.5, 0.0), (0.7, 0.0), (-0.40625, 0.28125), (0.2, -0.45)] {
        let probe = Ortho::new(Vec3::new(x, y, 5.0), Vec3::new(x, y, 0.0), Vec3::Y, 1e-5, UVec2::ONE);
        let r = render(&scene, &probe.desc, probe.size, 1024, 4);
        let (got, want) = (r.images.image.get(0, 0), expected_at(x as f64, y as f64));
        println!(
            "glass ray at ({x}, {y}): R/G {} (Snell {}), G {} (Fresnel {})",
            got.x / got.y,
            want.x / want.y,
            got.y,
            want.y
        );
        // Where it lands: R/G is the ramp there, whatever the Fresnel coin flips. (The rare paths
        // reflected twice inside, ~1.6 of the 1024 samples, add ±1e-3 of noise.)
        assert!(
            (got.x / got.y - want.x / want.y).abs() < 3e-3,
            "the ray at ({x}, {y}) lands at ramp {} but Snell's law says {}",
            got.x / got.y,
            want.x / want.y
        );
        // How much gets through: within the binomial noise of the Fresnel choices.
        let sigma = (r.images.variance.get(0, 0).y / 1024.0).sqrt();
        assert!(
            (got.y - want.y).abs() < 5.0 * sigma + 1e-3,
            "transmittance at ({x}, {y}): {} vs {}",
            got.y,
            want.y
        );
    }

    // The whole ball: every pixel's landing, in aggregate (a pixel of 64 samples holding one of
    // the rare twice-reflected paths moves by up to ~0.01: that is noise, not bias), and the
    // backdrop around it exactly.
    let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.25, UVec2::splat(40));
    let r = render(&scene, &cam.desc, cam.size, 64, 4);
    let expected = |f: Vec2| {
        let o = cam.origin(f);
        expected_at(o.x as f64, o.y as f64)
    };
    let radius_of = |i: u32, j: u32| {
        let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        let r: Vec<f32> = corners
            .iter()
            .map(|(a, b)| cam.origin(Vec2::new(i as f32 + a, j as f32 + b)).truncate().length())
            .collect();
        (r.iter().copied().fold(f32::MAX, f32::min), r.iter().copied().fold(0.0, f32::max))
    };
    let (mut diffs, mut beside) = (Vec::new(), 0);
    for j in 0..40 {
        for i in 0..40 {
            let (lo, hi) = radius_of(i, j);
            if hi < 0.8 {
                let want = footprint(i, j, 8, expected);
                let got = r.images.image.get(i, j);
                diffs.push((got.x / got.y - want.x / want.y).abs());
            } else if lo > 1.0 {
                beside += 1;
                let want = footprint(i, j, 8, expected);
                check("glass (backdrop seen directly)", &r, i, j, want, 1e-4, 1e-5);
            }
        }
    }
    let n = diffs.len() as f32;
    let mean = diffs.iter().sum::<f32>() / n;
    let within = diffs.iter().filter(|d| **d < 5e-3).count() as f32 / n;
    let max = diffs.iter().copied().fold(0.0, f32::max);
    println!(
        "glass image: {n} pixels through the ball, mean |ΔR/G| {mean:.2e}, {:.1} % within 5e-3, max {max:.3}",
        100.0 * within
    );
    assert!(n > 300.0 && beside > 300, "{n} pixels through the ball, {beside} beside it");
    assert!(mean < 2e-3 && within > 0.95 && max < 0.03, "landings disagree with Snell's law");
}

// ---------------------------------------------------------------------------------------------
// A Blender-style file
// ---------------------------------------------------------------------------------------------

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

// ---------------------------------------------------------------------------------------------
// Environment
// ---------------------------------------------------------------------------------------------

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
fn exr(dir: &TempDir, name: &str, width: u32, height: u32, f: impl Fn(u32, u32) -> Vec3) -> PathBuf {
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

// ---------------------------------------------------------------------------------------------
// Camera lists and bad inputs
// ---------------------------------------------------------------------------------------------

#[test]
fn camera_list_loads_and_bad_files_name_file_and_entry() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cams = tracer::scene::camera_list::load(&root.join("scenes/cornell/cameras.json")).unwrap();
    assert_eq!(cams.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), ["cornell", "corner"]);
    // The list's `cornell` is the glTF's camera: the same eye ray for every pixel tested.
    let gltf = Scene::load(&root.join("scenes/cornell/cornell.gltf")).unwrap();
    let (a, b) = (cams[0].build(UVec2::splat(64)).unwrap(), gltf.cameras[0].build(UVec2::splat(64)).unwrap());
    for (i, j) in [(0, 0), (63, 0), (20, 40), (63, 63)] {
        let s = tracer::camera::CameraSample::pixel_centre(i, j, 0.0);
        let (ra, rb) = (a.generate_ray(&s).unwrap(), b.generate_ray(&s).unwrap());
        assert!((ra.origin - rb.origin).length() < 1e-5 && (ra.direction - rb.direction).length() < 1e-5);
    }
    let dir = TempDir::new("camlist");
    let bad = dir.write(
        "views.json",
        r#"{"cameras": [{"name": "a", "look_from": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40},
                         {"name": "b", "look_from": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40, "lookat": [1, 1, 1]}]}"#,
    );
    let message = tracer::scene::camera_list::load(&bad).unwrap_err().to_string();
    assert!(
        message.contains("views.json")
            && message.contains("camera 1 ('b')")
            && message.contains("unknown key 'lookat'"),
        "{message}"
    );
}

/// A broken image and a missing one are warnings naming them, and the scene still renders (the
/// slots fall back to their factors); an alpha cut-off below zero is an error naming the file and
/// the material.
#[test]
fn bad_inputs_give_the_right_error_or_warning() {
    let dir = TempDir::new("bad");
    dir.write("broken.png", b"\x89PNG\r\n\x1a\n truncated");
    let mut g = Gltf::new("scene_features");
    let broken = g.texture("broken.png", None);
    let missing = g.texture("missing%20file.png", None);
    let material = g.material(&format!(
        r#"{{"name": "patchy", "emissiveFactor": [0.5, 0.5, 0.5], "emissiveTexture": {{"index": {broken}}},
            "pbrMetallicRoughness": {{"baseColorTexture": {{"index": {missing}}}}}}}"#
    ));
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X, -Vec3::Y, Vec3::Z), material)], "");
    let path = g.write(&dir, "bad");
    let scene = Scene::load(&path).unwrap();
    let warnings = scene.warnings.join("\n");
    assert!(
        warnings.contains("bad.gltf") && warnings.contains("broken.png") && warnings.contains("malformed"),
        "{warnings}"
    );
    assert!(warnings.contains("missing%20file.png") && warnings.contains("missing file.png"), "{warnings}");
    // Renders: the emissive factor alone (0.5) where the texture would have been.
    let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 0.5, UVec2::splat(8));
    let r = render(&scene, &cam.desc, cam.size, 1, 1);
    assert!(r.images.image.pixels.iter().all(|p| (*p - Vec3::splat(0.5)).abs().max_element() < 1e-6));

    let mut g = Gltf::new("scene_features");
    let material = g.material(r#"{"name": "leafy", "alphaMode": "MASK", "alphaCutoff": -0.25}"#);
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z), material)], "");
    let message = Scene::load(&g.write(&dir, "cutoff")).unwrap_err().to_string();
    assert!(
        message.contains("cutoff.gltf")
            && message.contains("'leafy'")
            && message.contains("alphaCutoff -0.25"),
        "{message}"
    );
}
