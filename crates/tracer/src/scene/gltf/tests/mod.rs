//! glTF loader tests: the bundled Cornell box against its OBJ twin, the GLB and data-URI
//! containers, node transforms, primitive modes, lights, and every malformed-file error. The
//! helpers (`TempDir`, `Builder`) are shared with the OBJ tests.

mod channels;
mod lobes;
mod materials;

use super::super::{CameraSelector, PunctualLight, Scene};
use crate::camera::{CameraDesc, CameraSample, Projection};
use crate::error::TracerError;
use glam::{UVec2, Vec3};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The bundled Cornell scene folder.
pub(in crate::scene) fn cornell_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell")
}

/// A fresh directory under the system temp dir, removed on drop; unique per process and call,
/// so tests running in parallel never share one.
pub(in crate::scene) struct TempDir(pub PathBuf);

impl TempDir {
    pub(in crate::scene) fn new(tag: &str) -> Self {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("mcctrace-scene-{}-{tag}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    /// Writes `contents` to `name` in the directory and returns its path.
    pub(in crate::scene) fn write(&self, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, contents).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

pub(super) fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ABC[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Builds small glTF files: accessors packed into one data-URI buffer.
#[derive(Default)]
pub(super) struct Builder {
    pub(super) bin: Vec<u8>,
    pub(super) views: Vec<Value>,
    pub(super) accessors: Vec<Value>,
}

impl Builder {
    pub(super) fn add(&mut self, bytes: Vec<u8>, component: u32, ty: &str, count: usize) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend(bytes);
        let view = self.views.len() - 1;
        self.accessors
            .push(json!({"bufferView": view, "componentType": component, "type": ty, "count": count}));
        self.accessors.len() - 1
    }

    pub(super) fn vec3(&mut self, v: &[[f32; 3]]) -> usize {
        let bytes = v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        self.add(bytes, 5126, "VEC3", v.len())
    }

    pub(super) fn indices(&mut self, v: &[u16]) -> usize {
        self.add(v.iter().flat_map(|i| i.to_le_bytes()).collect(), 5123, "SCALAR", v.len())
    }

    /// `doc` completed with the asset, buffer, views and accessors.
    pub(super) fn finish(self, mut doc: Value) -> Value {
        doc["asset"] = json!({"version": "2.0"});
        let uri = format!("data:application/octet-stream;base64,{}", base64(&self.bin));
        doc["buffers"] = json!([{"byteLength": self.bin.len(), "uri": uri}]);
        doc["bufferViews"] = Value::Array(self.views);
        doc["accessors"] = Value::Array(self.accessors);
        doc
    }
}

pub(super) const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

pub(super) fn load_json(dir: &TempDir, name: &str, doc: &Value) -> Result<Scene, TracerError> {
    Scene::load(&dir.write(name, serde_json::to_vec(doc).unwrap()))
}

/// Each triangle's corners rotated to start at the smallest (winding kept), with its material's
/// base colour and emission; sorted, so two scenes compare as sets.
fn canonical_triangles(scene: &Scene) -> Vec<Vec<f32>> {
    let mut out: Vec<Vec<f32>> = (0..scene.mesh.triangle_count())
        .map(|t| {
            let c = scene.mesh.corners(t).map(|p| p.to_array());
            let first = (0..3).min_by(|&a, &b| c[a].partial_cmp(&c[b]).unwrap()).unwrap();
            let m = &scene.materials[scene.mesh.material_ids[t] as usize];
            let mut v: Vec<f32> = (0..3).flat_map(|k| c[(first + k) % 3]).collect();
            v.extend(m.base_color.to_array());
            v.extend(m.emission.to_array());
            v.extend([m.metallic, m.roughness, m.specular]);
            v
        })
        .collect();
    out.sort_by(|a, b| a.partial_cmp(b).unwrap());
    out
}

fn assert_close(a: f32, b: f32, tol: f32, what: &str) {
    assert!((a - b).abs() <= tol * b.abs().max(1.0), "{what}: {a} vs {b}");
}

fn reference_camera() -> CameraDesc {
    let fov_y = 39.30764811610662_f64.to_radians() as f32;
    let (from, at) = (Vec3::new(2.78, 2.73, -8.0), Vec3::new(2.78, 2.73, 0.0));
    CameraDesc::look_at("cornell", from, at, Vec3::Y, Projection::Perspective { fov_y }).unwrap()
}

#[test]
fn scene_cornell_obj_and_gltf_agree() {
    let dir = cornell_dir();
    let obj = Scene::load(&dir).unwrap();
    let gltf = Scene::load(&dir.join("cornell.gltf")).unwrap();
    assert!(obj.warnings.is_empty(), "{:?}", obj.warnings);
    assert!(gltf.warnings.is_empty(), "{:?}", gltf.warnings);
    assert_eq!(obj.mesh.triangle_count(), 32);
    assert_eq!(gltf.mesh.triangle_count(), 32);
    // The eight parts share the library's four materials.
    assert_eq!(obj.materials.len(), 4);
    assert_eq!(gltf.materials.len(), 4);

    let (a, b) = (canonical_triangles(&obj), canonical_triangles(&gltf));
    for (ta, tb) in a.iter().zip(&b) {
        for (k, (x, y)) in ta.iter().zip(tb).enumerate() {
            // Corners within 1e-6; material factors within 1e-5 relative (12/17 · 17 in f32).
            let tol = if k < 9 { 1e-6 } else { 1e-5 };
            assert_close(*x, *y, tol, &format!("triangle {ta:?} vs {tb:?}, value {k}"));
        }
    }

    // The light: front face only, (17, 12, 4), black, no specular layer — in both formats.
    for scene in [&obj, &gltf] {
        let lights: Vec<_> = scene.materials.iter().filter(|m| m.is_emissive()).collect();
        assert_eq!(lights.len(), 1);
        let l = lights[0];
        assert!((l.emission - Vec3::new(17.0, 12.0, 4.0)).abs().max_element() < 1e-5, "{l:?}");
        assert!(!l.emission_two_sided && l.base_color == Vec3::ZERO && !l.has_specular());
        let t =
            scene.mesh.material_ids.iter().position(|&m| scene.materials[m as usize].is_emissive()).unwrap();
        let [p0, p1, p2] = scene.mesh.corners(t);
        assert!((p1 - p0).cross(p2 - p0).normalize().dot(-Vec3::Y) > 0.999, "light faces down");
        assert!(scene.materials.iter().filter(|m| !m.is_emissive()).all(|m| !m.has_specular()));
    }

    // The glTF camera is the reference look-at camera.
    assert!(obj.cameras.is_empty());
    assert_eq!(gltf.cameras.len(), 1);
    let cam = gltf.camera(&CameraSelector::Name("cornell".into())).unwrap();
    let want = reference_camera();
    assert!(cam.world_from_camera.abs_diff_eq(want.world_from_camera, 1e-5), "{cam:?}");
    let (Projection::Perspective { fov_y: got }, Projection::Perspective { fov_y: fov }) =
        (cam.projection, want.projection)
    else {
        panic!("{cam:?}")
    };
    assert_close(got, fov, 1e-6, "yfov");
    let (c1, c2) = (cam.build(UVec2::new(64, 64)).unwrap(), want.build(UVec2::new(64, 64)).unwrap());
    for (i, j) in [(0, 0), (63, 0), (17, 40), (32, 32), (63, 63)] {
        let (r1, r2) = (c1.generate_ray(&CameraSample::pixel_centre(i, j, 0.0)).unwrap(), {
            c2.generate_ray(&CameraSample::pixel_centre(i, j, 0.0)).unwrap()
        });
        assert!((r1.origin - r2.origin).length() < 1e-5 && (r1.direction - r2.direction).length() < 1e-5);
    }
}

/// A GLB container of `doc` and the binary chunk `bin`, chunks padded to 4 bytes (JSON with
/// spaces).
pub(super) fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json_chunk = serde_json::to_vec(doc).unwrap();
    json_chunk.resize(json_chunk.len().next_multiple_of(4), b' ');
    let mut bin_chunk = bin.to_vec();
    bin_chunk.resize(bin_chunk.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json_chunk.len() + 8 + bin_chunk.len();
    let mut glb = b"glTF".to_vec();
    for word in [2, total as u32, json_chunk.len() as u32, 0x4E4F_534A] {
        glb.extend(u32::to_le_bytes(word));
    }
    glb.extend(&json_chunk);
    glb.extend((bin_chunk.len() as u32).to_le_bytes());
    glb.extend(0x004E_4942_u32.to_le_bytes());
    glb.extend(&bin_chunk);
    glb
}

#[test]
fn scene_glb_and_data_uri_load_identically() {
    let src = cornell_dir();
    let reference = Scene::load(&src.join("cornell.gltf")).unwrap();
    let bin = std::fs::read(src.join("cornell.bin")).unwrap();
    let doc: Value = serde_json::from_slice(&std::fs::read(src.join("cornell.gltf")).unwrap()).unwrap();
    let dir = TempDir::new("containers");

    // GLB: the buffer without a URI is the BIN chunk.
    let mut glb_doc = doc.clone();
    glb_doc["buffers"][0].as_object_mut().unwrap().remove("uri");
    let glb = glb(&glb_doc, &bin);
    let from_glb = Scene::load(&dir.write("cornell.glb", &glb)).unwrap();

    let mut uri_doc = doc;
    uri_doc["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{}", base64(&bin)));
    let from_uri = load_json(&dir, "embedded.gltf", &uri_doc).unwrap();

    for scene in [&from_glb, &from_uri] {
        assert_eq!(scene.mesh, reference.mesh);
        assert_eq!(scene.materials, reference.materials);
        assert_eq!(scene.cameras, reference.cameras);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }
}

#[test]
fn scene_node_hierarchy_and_mirroring() {
    let mut b = Builder::default();
    let pos = b.vec3(&TRIANGLE);
    let nrm = b.vec3(&[[0.0, 0.0, 1.0]; 3]);
    let idx = b.indices(&[0, 1, 2]);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let doc = b.finish(json!({
        "scenes": [{"nodes": [0, 2, 3]}],
        "nodes": [
            {"name": "parent", "translation": [1, 2, 3], "rotation": [0, 0, h, h], "children": [1]},
            {"name": "child", "translation": [1, 0, 0], "scale": [2, 2, 2], "mesh": 0, "camera": 0},
            {"name": "mirror", "scale": [-1, 1, 1], "mesh": 0},
            {"name": "matrix", "mesh": 0,
             "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1]},
        ],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1.5, "znear": 0.1, "zfar": 10}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx}]}],
    }));
    let dir = TempDir::new("nodes");
    let scene = load_json(&dir, "nodes.gltf", &doc).unwrap();
    assert_eq!(scene.mesh.triangle_count(), 3);
    let close = |got: [Vec3; 3], want: [[f32; 3]; 3]| {
        got.iter().zip(want).all(|(g, w)| (*g - Vec3::from(w)).length() < 1e-5)
    };
    // child: p → T(1,2,3) · Rz(90°) · (T(1,0,0) · S(2) · p), with Rz(90°)(x, y, z) = (−y, x, z).
    let child = scene.mesh.corners(0);
    assert!(close(child, [[1.0, 3.0, 3.0], [1.0, 5.0, 3.0], [-1.0, 3.0, 3.0]]), "{child:?}");
    // mirror: x negated and the winding swapped back, so the front still faces +z.
    let mirror = scene.mesh.corners(1);
    assert!(close(mirror, [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]), "{mirror:?}");
    let matrix = scene.mesh.corners(2);
    assert!(close(matrix, [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]]), "{matrix:?}");
    for t in 0..3 {
        let [p0, p1, p2] = scene.mesh.corners(t);
        assert!((p1 - p0).cross(p2 - p0).normalize().dot(Vec3::Z) > 0.9999, "triangle {t} faces +z");
        for v in scene.mesh.triangles[t] {
            assert!((scene.mesh.normals[v as usize] - Vec3::Z).length() < 1e-6, "normal of triangle {t}");
        }
    }
    // The camera rides on the child: its node name, its world transform, ymag as half height.
    let cam = scene.camera(&CameraSelector::Index(0)).unwrap();
    assert_eq!(cam.name, "child");
    assert_eq!(cam.projection, Projection::Orthographic { half_height: 1.5 });
    assert!((Vec3::from(cam.world_from_camera.translation) - Vec3::new(1.0, 3.0, 3.0)).length() < 1e-5);
    assert!((Vec3::from(cam.world_from_camera.matrix3.x_axis) - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-5);
}

#[test]
fn scene_primitive_modes_materials_and_warnings() {
    let mut b = Builder::default();
    let quad = b.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]);
    let fan = b.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
    let list = b.vec3(&TRIANGLE);
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_texture_transform", "KHR_materials_specular", "KHR_materials_emissive_strength"],
        "nodes": [{"mesh": 0}],
        "meshes": [{"name": "modes", "primitives": [
            {"attributes": {"POSITION": quad}, "mode": 5, "material": 0},
            {"attributes": {"POSITION": fan}, "mode": 6},
            {"attributes": {"POSITION": quad}, "mode": 1},
            {"attributes": {"POSITION": list}, "material": 1},
        ]}],
        "materials": [
            {"name": "textured", "emissiveFactor": [1, 0.5, 0], "doubleSided": true,
             "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [0.5, 0.25, 1, 1],
                                      "metallicFactor": 0.25, "roughnessFactor": 0.75},
             "normalTexture": {"index": 0},
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4},
                            "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.5, 0.5]}}},
            {},
        ],
        "textures": [{"source": 0}],
        "images": [{"uri": "never-read.png"}],
    }));
    let dir = TempDir::new("modes");
    let scene = load_json(&dir, "modes.gltf", &doc).unwrap();
    // Strip 0,1,2,3 → (0,1,2), (1,3,2); fan 0,1,2,3 → (1,2,0), (2,3,0); lines skipped; then the
    // non-indexed list's one triangle.
    assert_eq!(scene.mesh.triangle_count(), 5);
    let local: Vec<[u32; 3]> = scene.mesh.triangles.iter().map(|t| t.map(|i| i % 4)).collect();
    assert_eq!(local[..4], [[0, 1, 2], [1, 3, 2], [1, 2, 0], [2, 3, 0]]);
    for t in 0..4 {
        let [p0, p1, p2] = scene.mesh.corners(t);
        assert!((p1 - p0).cross(p2 - p0).z > 0.0, "triangle {t} stays counter-clockwise");
    }
    let m = &scene.materials[0];
    assert_eq!((m.base_color, m.metallic, m.roughness), (Vec3::new(0.5, 0.25, 1.0), 0.25, 0.75));
    assert_eq!((m.specular, m.specular_color), (0.5, Vec3::new(1.0, 0.5, 0.5)));
    assert_eq!((m.emission, m.emission_two_sided), (Vec3::new(4.0, 2.0, 0.0), true));
    // Material 1 is `{}`: glTF defaults, specular layer included (no extension = specular 1).
    let m = &scene.materials[1];
    assert_eq!((m.base_color, m.metallic, m.roughness, m.specular), (Vec3::ONE, 1.0, 1.0, 1.0));
    // The fan had no material: glTF's default material, appended after the file's.
    let default = &scene.materials[scene.mesh.material_ids[2] as usize];
    assert_eq!((default.base_color, default.metallic, default.roughness), (Vec3::ONE, 1.0, 1.0));
    assert_eq!(scene.materials.len(), 3);

    // The image is missing: one warning naming it, both slots left empty.
    assert_eq!(m_textures_of(&scene, 0), (false, false));
    let warnings = scene.warnings.join("\n");
    assert!(
        !warnings.contains("KHR_texture_transform") && !warnings.contains("KHR_materials_specular"),
        "{warnings}"
    );
    assert!(
        warnings.contains("image 0 ('never-read.png')")
            && warnings.contains("material 'textured'")
            && warnings.contains("left out"),
        "{warnings}"
    );
    assert_eq!(warnings.matches("image 0 ('never-read.png')").count(), 1, "{warnings}");
    assert!(warnings.contains("Lines primitives are not rendered"), "{warnings}");
    assert!(warnings.lines().all(|w| w.contains("modes.gltf")), "{warnings}");
}

/// Whether material `m` has a base colour and a normal texture.
fn m_textures_of(scene: &Scene, m: usize) -> (bool, bool) {
    let t = &scene.materials[m].textures;
    (t.base_color.is_some(), t.normal.is_some())
}

#[test]
fn scene_point_light_candela_to_radiant_intensity() {
    let doc = Builder::default().finish(json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.5, 0.25], "intensity": 2732},
            {"type": "spot", "name": "cone", "intensity": 10, "spot": {}},
            {"type": "directional", "name": "sun"},
        ]}},
        "scenes": [{"nodes": [0]}],
        "scene": 0,
        "nodes": [
            {"translation": [10, 0, 0], "children": [1, 2, 3]},
            {"translation": [1, 2, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}},
        ],
    }));
    let dir = TempDir::new("lights");
    let scene = load_json(&dir, "lights.gltf", &doc).unwrap();
    // 2732 cd = 4 × 683: radiant intensity 4 W/sr times the colour.
    assert_eq!(
        scene.lights[..1],
        [PunctualLight::Point { position: Vec3::new(11.0, 2.0, 3.0), intensity: Vec3::new(4.0, 2.0, 1.0) }]
    );
    // The spot's defaults (inner 0, outer π/4) and the sun's intensity 1 lux; both shine down
    // their node's −Z; no generator, so the glTF falloff.
    assert_eq!(
        scene.lights[1..],
        [
            PunctualLight::Spot {
                position: Vec3::new(10.0, 0.0, 0.0),
                direction: Vec3::NEG_Z,
                intensity: Vec3::splat(10.0 / 683.0),
                inner_cone: 0.0,
                outer_cone: std::f32::consts::FRAC_PI_4,
                falloff: crate::scene::SpotFalloff::Gltf,
            },
            PunctualLight::Directional { direction: Vec3::NEG_Z, irradiance: Vec3::splat(1.0 / 683.0) },
        ]
    );
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

/// Loads `doc` (or raw bytes) as `name` and checks the error names the file and each needle.
pub(super) fn expect_error(dir: &TempDir, name: &str, contents: &[u8], needles: &[&str]) {
    let path = dir.write(name, contents);
    let message = match Scene::load(&path) {
        Ok(_) => panic!("{name} loaded"),
        Err(e) => e.to_string(),
    };
    assert!(message.contains(name), "{name}: '{message}' does not name the file");
    for needle in needles {
        assert!(message.contains(needle), "{name}: '{message}' does not say '{needle}'");
    }
}

#[test]
fn scene_gltf_errors_name_file_and_problem() {
    let dir = TempDir::new("errors");
    let src = cornell_dir();
    let text = std::fs::read(src.join("cornell.gltf")).unwrap();
    let bin = std::fs::read(src.join("cornell.bin")).unwrap();

    let missing = dir.0.join("absent.gltf");
    let message = Scene::load(&missing).unwrap_err().to_string();
    assert!(message.contains("absent.gltf"), "{message}");
    let message = super::load(&missing).unwrap_err().to_string();
    assert!(message.contains("absent.gltf"), "{message}");

    expect_error(&dir, "truncated.gltf", &text[..text.len() / 2], &["malformed glTF JSON", "line"]);
    expect_error(
        &dir,
        "truncated.glb",
        b"glTF\x02\0\0\0\xff\0\0\0",
        &["malformed GLB", "declares 255 bytes"],
    );
    expect_error(&dir, "version1.gltf", br#"{"asset": {"version": "1.0"}}"#, &["version 1.0"]);
    let with_bin =
        |uri: &str| String::from_utf8_lossy(&text).replace("\"cornell.bin\"", &format!("\"{uri}\""));
    expect_error(&dir, "nobin.gltf", with_bin("missing.bin").as_bytes(), &["buffer 0", "missing.bin"]);
    dir.write("short.bin", &bin[..100]);
    expect_error(
        &dir,
        "short.gltf",
        with_bin("short.bin").as_bytes(),
        &["short.bin", "has 100 bytes", "960"],
    );
    expect_error(
        &dir,
        "scheme.gltf",
        with_bin("https://example.invalid/a.bin").as_bytes(),
        &["relative path"],
    );

    let mut required: Value = serde_json::from_slice(&text).unwrap();
    required["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    required["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    expect_error(
        &dir,
        "required.gltf",
        &serde_json::to_vec(&required).unwrap(),
        &["KHR_draco_mesh_compression"],
    );

    let triangle = |indices: &[u16], positions: &[[f32; 3]]| {
        let mut b = Builder::default();
        let (p, i) = (b.vec3(positions), b.indices(indices));
        b.finish(json!({"nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "indices": i}]}]}))
    };
    let bytes = |doc: &Value| serde_json::to_vec(doc).unwrap();
    expect_error(
        &dir,
        "index.gltf",
        &bytes(&triangle(&[0, 1, 5], &TRIANGLE)),
        &["primitive 0", "index 5 out of range"],
    );
    let nan = [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]];
    expect_error(&dir, "nan.gltf", &bytes(&triangle(&[0, 1, 2], &nan)), &["vertex 1", "non-finite"]);

    let mut overrun = triangle(&[0, 1, 2], &TRIANGLE);
    overrun["accessors"][0]["count"] = json!(4);
    expect_error(&dir, "overrun.gltf", &bytes(&overrun), &["accessor 0", "need 48 bytes", "has 36"]);
    let mut view = triangle(&[0, 1, 2], &TRIANGLE);
    view["bufferViews"][0]["byteLength"] = json!(400);
    expect_error(&dir, "view.gltf", &bytes(&view), &["buffer view 0", "runs past the end of buffer 0"]);
    let mut huge = triangle(&[0, 1, 2], &TRIANGLE);
    huge["accessors"][0]["count"] = json!(u64::MAX / 2);
    expect_error(&dir, "huge.gltf", &bytes(&huge), &["accessor 0"]);
    let mut vec2 = triangle(&[0, 1, 2], &TRIANGLE);
    vec2["accessors"][0]["type"] = json!("VEC2");
    expect_error(&dir, "vec2.gltf", &bytes(&vec2), &["accessor 0 used as POSITION is Vec2"]);
    let mut stride = triangle(&[0, 1, 2], &TRIANGLE);
    stride["bufferViews"][0]["byteStride"] = json!(4);
    expect_error(&dir, "stride.gltf", &bytes(&stride), &["byteStride 4"]);
    let mut partial = triangle(&[0, 1, 2], &TRIANGLE);
    partial["meshes"][0]["primitives"][0].as_object_mut().unwrap().remove("indices");
    partial["accessors"][0]["count"] = json!(2);
    expect_error(&dir, "partial.gltf", &bytes(&partial), &["not a whole number of triangles"]);

    let mut cycle = triangle(&[0, 1, 2], &TRIANGLE);
    cycle["scenes"] = json!([{"nodes": [0]}]);
    cycle["nodes"] = json!([{"children": [1]}, {"children": [0], "name": "loop"}]);
    expect_error(&dir, "cycle.gltf", &bytes(&cycle), &["node 0", "reached twice"]);
    let mut dangling = triangle(&[0, 1, 2], &TRIANGLE);
    dangling["nodes"][0]["mesh"] = json!(7);
    expect_error(&dir, "dangling.gltf", &bytes(&dangling), &["invalid glTF", "mesh"]);
    let mut light = triangle(&[0, 1, 2], &TRIANGLE);
    light["nodes"][0]["extensions"] = json!({"KHR_lights_punctual": {"light": 3}});
    expect_error(&dir, "light.gltf", &bytes(&light), &["invalid glTF"]);
    let mut camera = triangle(&[0, 1, 2], &TRIANGLE);
    camera["nodes"][0]["camera"] = json!(0);
    camera["cameras"] =
        json!([{"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0, "zfar": 1}}]);
    expect_error(&dir, "camera.gltf", &bytes(&camera), &["camera 0", "projection"]);
    let mut zero_quat = triangle(&[0, 1, 2], &TRIANGLE);
    zero_quat["nodes"][0]["rotation"] = json!([0, 0, 0, 0]);
    expect_error(&dir, "quat.gltf", &bytes(&zero_quat), &["node 0", "non-finite transform"]);

    // A camera that is not there: the error lists the ones that are.
    let scene = Scene::load(&src.join("cornell.gltf")).unwrap();
    let message = scene.camera(&CameraSelector::Name("nope".into())).unwrap_err().to_string();
    assert!(
        message.contains("cornell.gltf") && message.contains("'nope'") && message.contains("1 'cornell'"),
        "{message}"
    );
    let message = scene.camera(&CameraSelector::Index(3)).unwrap_err().to_string();
    assert!(message.contains("number 4 (index 3)") && message.contains("1 camera: 1 'cornell'"), "{message}");
    // A command line counts cameras from 1, as views are numbered: 1 is the first, 0 none.
    assert_eq!(scene.camera(&CameraSelector::parse("1")).unwrap().name, "cornell");
    let message = scene.camera(&CameraSelector::parse("0")).unwrap_err().to_string();
    assert!(message.contains("numbered from 1"), "{message}");
    let message = scene.camera(&CameraSelector::parse("2")).unwrap_err().to_string();
    assert!(message.contains("no camera number 2;"), "{message}");
}
