//! glTF animation tests: hand-computed poses of meshes, cameras and lights at chosen times
//! through a parent/child hierarchy and through each interpolation mode as read from a file,
//! `Scene::load` against `at_time(0)`, static scenes, warnings, every malformed-animation error,
//! and re-flattening the café.

use super::{Builder, TRIANGLE, TempDir, cornell_dir, expect_error, load_json};
use crate::camera::Projection;
use crate::scene::{PunctualLight, Scene, SpotFalloff};
use glam::{Quat, Vec3};
use serde_json::{Value, json};
use std::f32::consts::{FRAC_1_SQRT_2, FRAC_PI_4};

impl Builder {
    /// A `SCALAR` float accessor (key times).
    fn times(&mut self, t: &[f32]) -> usize {
        self.add(t.iter().flat_map(|f| f.to_le_bytes()).collect(), 5126, "SCALAR", t.len())
    }

    /// A `VEC4` float accessor (quaternions).
    fn quats(&mut self, q: &[[f32; 4]]) -> usize {
        self.add(q.iter().flatten().flat_map(|f| f.to_le_bytes()).collect(), 5126, "VEC4", q.len())
    }
}

/// The test files' POSITION accessors lack min/max, which the loader mentions; nothing else.
#[track_caller]
fn assert_only_bounds_warnings(scene: &Scene) {
    assert!(scene.warnings.iter().all(|w| w.contains("POSITION accessor(s) lack")), "{:?}", scene.warnings);
}

fn near(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

#[track_caller]
fn assert_near(a: Vec3, b: Vec3, tol: f32, what: &str) {
    assert!(near(a, b, tol), "{what}: {a} vs {b}");
}

/// Rotation by `angle` about +Y as a glTF quaternion (xyzw).
fn ry(angle: f32) -> [f32; 4] {
    [0.0, (angle / 2.0).sin(), 0.0, (angle / 2.0).cos()]
}

/// A parent rotating about +Y (LINEAR, keys at 1 s and 3 s: 0° → 90°) with a spot light, and a
/// child translating along +X (LINEAR, keys at 0 s and 4 s: (1, 0, 0) → (3, 0, 0); rest pose
/// (7, 7, 7), which no time shows) carrying a triangle, a camera and a point light; plus a static
/// node with the same triangle.
fn hierarchy_doc() -> Value {
    let mut b = Builder::default();
    let pos = b.vec3(&TRIANGLE);
    let idx = b.indices(&[0, 1, 2]);
    let rot_t = b.times(&[1.0, 3.0]);
    let rot_v = b.quats(&[ry(0.0), ry(std::f32::consts::FRAC_PI_2)]);
    let tr_t = b.times(&[0.0, 4.0]);
    let tr_v = b.vec3(&[[1.0, 0.0, 0.0], [3.0, 0.0, 0.0]]);
    b.finish(json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 683},
            {"type": "spot", "intensity": 683, "spot": {"outerConeAngle": 0.5}},
        ]}},
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "parent", "children": [1], "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "child", "translation": [7, 7, 7], "mesh": 0, "camera": 0,
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "still", "translation": [0, 5, 0], "mesh": 0},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx}]}],
        "animations": [{
            "name": "spin",
            "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 1, "path": "translation"}},
            ],
            "samplers": [
                {"input": rot_t, "output": rot_v},
                {"input": tr_t, "output": tr_v, "interpolation": "LINEAR"},
            ],
        }],
    }))
}

/// Where the hierarchy's parts are when the parent has turned `angle` about +Y and the child
/// sits at `x` along the parent's +X: Ry(θ)(x, y, z) = (x cos θ + z sin θ, y, −x sin θ + z cos θ).
fn check_hierarchy(scene: &Scene, angle: f32, x: f32, when: &str) {
    let ry = |p: Vec3| {
        Vec3::new(p.x * angle.cos() + p.z * angle.sin(), p.y, -p.x * angle.sin() + p.z * angle.cos())
    };
    // The child's triangle: each corner moved by (x, 0, 0), then turned.
    let corners = scene.mesh.corners(0);
    for (got, local) in corners.iter().zip(TRIANGLE) {
        let want = ry(Vec3::from(local) + Vec3::new(x, 0.0, 0.0));
        assert_near(*got, want, 1e-5, &format!("{when}: child corner {local:?}"));
    }
    // The static node's triangle never moves.
    let still = scene.mesh.corners(1);
    for (got, local) in still.iter().zip(TRIANGLE) {
        assert_near(*got, Vec3::from(local) + Vec3::new(0.0, 5.0, 0.0), 0.0, &format!("{when}: still"));
    }
    // The camera rides on the child: at its position, its axes turned with the parent.
    let cam = &scene.cameras[0];
    assert_eq!((cam.name.as_str(), cam.projection), ("child", Projection::Perspective { fov_y: 0.8 }));
    let m = cam.world_from_camera;
    assert_near(Vec3::from(m.translation), ry(Vec3::new(x, 0.0, 0.0)), 1e-5, &format!("{when}: camera"));
    assert_near(Vec3::from(m.matrix3.x_axis), ry(Vec3::X), 1e-6, &format!("{when}: camera right"));
    assert_near(Vec3::from(m.matrix3.y_axis), Vec3::Y, 1e-6, &format!("{when}: camera up"));
    assert_near(Vec3::from(m.matrix3.z_axis), ry(Vec3::Z), 1e-6, &format!("{when}: camera back"));
    // Lights in node order: the parent's spot (at the origin, aimed down its turning −Z), then
    // the child's point light.
    let PunctualLight::Spot { position, direction, falloff, .. } = scene.lights[0] else {
        panic!("{when}: {:?}", scene.lights)
    };
    assert_eq!((position, falloff), (Vec3::ZERO, SpotFalloff::Gltf));
    assert_near(direction, ry(Vec3::NEG_Z), 1e-6, &format!("{when}: spot direction"));
    let PunctualLight::Point { position, intensity } = scene.lights[1] else {
        panic!("{when}: {:?}", scene.lights)
    };
    assert_near(position, ry(Vec3::new(x, 0.0, 0.0)), 1e-5, &format!("{when}: point light"));
    assert_eq!(intensity, Vec3::ONE);
}

#[test]
fn scene_animation_moves_meshes_cameras_and_lights_through_the_hierarchy() {
    let dir = TempDir::new("anim-hierarchy");
    let scene = load_json(&dir, "spin.gltf", &hierarchy_doc()).unwrap();
    assert_only_bounds_warnings(&scene);
    assert_eq!(scene.duration(), 4.0);
    assert_eq!(scene.animation.as_ref().unwrap().channel_count(), 2);

    // Loaded at t = 0: the child at its first key (1, 0, 0), not its rest (7, 7, 7); the
    // parent before its first key (1 s), so at that key's 0°.
    check_hierarchy(&scene, 0.0, 1.0, "load");
    // t = 2 s: the rotation halfway (45°), the translation halfway (x = 2).
    check_hierarchy(&scene.at_time(2.0).unwrap(), FRAC_PI_4, 2.0, "t = 2");
    // t = 1 s: the rotation at its first key, the translation a quarter of the way.
    check_hierarchy(&scene.at_time(1.0).unwrap(), 0.0, 1.5, "t = 1");
    // t = 3.5 s: the rotation held at 90° since its last key (3 s); x = 1 + 2 · 3.5 / 4.
    check_hierarchy(&scene.at_time(3.5).unwrap(), 2.0 * FRAC_PI_4, 2.75, "t = 3.5");
    // Clamped at both ends.
    check_hierarchy(&scene.at_time(-5.0).unwrap(), 0.0, 1.0, "t = -5");
    check_hierarchy(&scene.at_time(60.0).unwrap(), 2.0 * FRAC_PI_4, 3.0, "t = 60");

    // The nodes' own sampled TRS (rig nodes are in depth-first order: parent, child, still).
    let animation = scene.animation.as_ref().unwrap();
    let (t, r, s) = animation.node_trs(0, 2.0).unwrap();
    assert_eq!((t, s), (Vec3::ZERO, Vec3::ONE));
    assert!(r.abs_diff_eq(Quat::from_rotation_y(FRAC_PI_4), 1e-6), "{r}");
    let (t, r, s) = animation.node_trs(1, 3.0).unwrap();
    assert_eq!((r, s), (Quat::IDENTITY, Vec3::ONE));
    assert_near(t, Vec3::new(2.5, 0.0, 0.0), 1e-6, "child translation at 3 s");
    assert!(animation.node_trs(2, 1.0).is_none(), "the static node has no channel");
}

#[test]
fn scene_animation_interpolation_modes_from_a_file() {
    let mut b = Builder::default();
    let pos = b.vec3(&TRIANGLE);
    // STEP translation: (0,0,0) until 1 s, (1,0,0) until 2 s, then (5,0,0).
    let step_t = b.times(&[0.0, 1.0, 2.0]);
    let step_v = b.vec3(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [5.0, 0.0, 0.0]]);
    // CUBICSPLINE scale, keys at 0 s and 2 s (dt = 2), uniform: key 0 value 1, out-tangent 1;
    // key 1 in-tangent −1, value 3. At 1 s (u = ½): ½·1 + ⅛·(2·1) + ½·3 − ⅛·(2·−1) = 2.5.
    let cubic_t = b.times(&[0.0, 2.0]);
    let cubic_v = b.vec3(&[[7.0; 3], [1.0; 3], [1.0; 3], [-1.0; 3], [3.0; 3], [7.0; 3]]);
    // LINEAR rotation as normalised shorts: identity → 90° about +Z over 1 s.
    let lin_t = b.times(&[0.0, 1.0]);
    let h = (FRAC_1_SQRT_2 * 32767.0).round() as i16;
    let shorts: Vec<u8> = [0i16, 0, 0, 32767, 0, 0, h, h].iter().flat_map(|v| v.to_le_bytes()).collect();
    let lin_v = b.add(shorts, 5122, "VEC4", 2);
    let mut doc = b.finish(json!({
        "nodes": [
            {"name": "step", "mesh": 0},
            {"name": "cubic", "mesh": 0, "translation": [0, 0, 10]},
            {"name": "linear", "mesh": 0, "translation": [0, 0, 20]},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "animations": [
            {"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
             "samplers": [{"input": step_t, "output": step_v, "interpolation": "STEP"}]},
            {"channels": [
                {"sampler": 0, "target": {"node": 1, "path": "scale"}},
                {"sampler": 1, "target": {"node": 2, "path": "rotation"}},
             ],
             "samplers": [
                {"input": cubic_t, "output": cubic_v, "interpolation": "CUBICSPLINE"},
                {"input": lin_t, "output": lin_v},
             ]},
        ],
    }));
    doc["accessors"][lin_v]["normalized"] = json!(true);
    let dir = TempDir::new("anim-modes");
    let scene = load_json(&dir, "modes.gltf", &doc).unwrap();
    assert_only_bounds_warnings(&scene);
    assert_eq!(scene.duration(), 2.0);
    // Corner 1 of each node's triangle is its local (1, 0, 0).
    let corner = |s: &Scene, node: usize| s.mesh.corners(node)[1];
    let at = |t: f32| scene.at_time(t).unwrap();

    for (t, x) in
        [(-1.0, 1.0), (0.0, 1.0), (0.5, 1.0), (0.999, 1.0), (1.0, 2.0), (1.99, 2.0), (2.0, 6.0), (9.0, 6.0)]
    {
        assert_near(corner(&at(t), 0), Vec3::new(x, 0.0, 0.0), 0.0, &format!("STEP at {t}"));
    }
    for (t, s) in [(0.0, 1.0), (1.0, 2.5), (2.0, 3.0), (5.0, 3.0)] {
        assert_near(corner(&at(t), 1), Vec3::new(s, 0.0, 10.0), 1e-6, &format!("CUBICSPLINE at {t}"));
    }
    // The CUBICSPLINE scale at ½ s (u = ¼): 0.84375·1 + 0.140625·2 + 0.15625·3 − 0.046875·(−2).
    let s = 0.84375 + 0.140625 * 2.0 + 0.15625 * 3.0 + 0.046875 * 2.0;
    assert_near(corner(&at(0.5), 1), Vec3::new(s, 0.0, 10.0), 1e-6, "CUBICSPLINE at 0.5");
    // Rotation: slerp halfway is 45° about +Z (shorts quantise the keys to ~1e-5).
    for (t, angle) in [(0.0, 0.0), (0.5, FRAC_PI_4), (0.25, FRAC_PI_4 / 2.0), (1.0, 2.0 * FRAC_PI_4)] {
        let want = Vec3::new(angle.cos(), angle.sin(), 20.0);
        assert_near(corner(&at(t), 2), want, 1e-4, &format!("LINEAR rotation at {t}"));
    }
}

#[test]
fn scene_animation_at_time_zero_is_the_loaded_scene_and_static_scenes_stay() {
    let dir = TempDir::new("anim-zero");
    let scene = load_json(&dir, "spin.gltf", &hierarchy_doc()).unwrap();
    let zero = scene.at_time(0.0).unwrap();
    assert_eq!(zero.mesh, scene.mesh);
    assert_eq!(zero.cameras, scene.cameras);
    assert_eq!(zero.lights, scene.lights);
    assert_eq!(zero.materials, scene.materials);
    assert_eq!(zero.warnings, scene.warnings);
    let later = scene.at_time(2.0).unwrap();
    assert_ne!(later.mesh, scene.mesh);
    // Flattening again from a flattened scene starts from the file, not from the last time.
    assert_eq!(later.at_time(0.0).unwrap().mesh, scene.mesh);

    // Cameras added after the file's own (a camera-list file) are kept.
    let mut extra = scene.clone();
    let mut added = scene.cameras[0].clone();
    added.name = "from-list".into();
    extra.cameras.push(added.clone());
    let moved = extra.at_time(2.0).unwrap();
    assert_eq!(moved.cameras.len(), 2);
    assert_eq!(moved.cameras[0], later.cameras[0]);
    assert_eq!(moved.cameras[1], added);

    // A static glTF and an OBJ scene: no animation, and any time is the scene itself.
    for path in [cornell_dir().join("cornell.gltf"), cornell_dir()] {
        let still = Scene::load(&path).unwrap();
        assert!(still.animation.is_none());
        assert_eq!(still.duration(), 0.0);
        let at = still.at_time(12.5).unwrap();
        assert_eq!(at.mesh, still.mesh);
        assert_eq!(at.cameras, still.cameras);
        assert_eq!(at.lights, still.lights);
        assert_eq!(at.materials, still.materials);
    }
    assert!(scene.at_time(f32::NAN).unwrap_err().to_string().contains("spin.gltf"));
}

#[test]
fn scene_animation_errors_at_a_time_name_file_time_and_light() {
    // A spot light whose node's scale is keyed down to zero at 1 s has no direction there.
    let mut b = Builder::default();
    let t = b.times(&[0.0, 1.0]);
    let v = b.vec3(&[[1.0; 3], [0.0; 3]]);
    let doc = b.finish(json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "spot", "name": "lamp", "spot": {}}]}},
        "nodes": [{"extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "scale"}}],
                        "samplers": [{"input": t, "output": v}]}],
    }));
    let dir = TempDir::new("anim-time-error");
    let scene = load_json(&dir, "vanish.gltf", &doc).unwrap();
    assert!(scene.at_time(0.5).is_ok());
    let message = scene.at_time(1.0).unwrap_err().to_string();
    for needle in ["vanish.gltf", "at t = 1 s", "light 0 ('lamp')", "no direction"] {
        assert!(message.contains(needle), "'{message}' does not say '{needle}'");
    }
}

#[test]
fn scene_animation_warnings_for_what_is_ignored() {
    let mut b = Builder::default();
    let pos = b.vec3(&TRIANGLE);
    let t = b.times(&[0.0, 1.0]);
    let weights = b.add([0.0f32, 1.0].iter().flat_map(|f| f.to_le_bytes()).collect(), 5126, "SCALAR", 2);
    let rot = b.quats(&[[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]]);
    let tr = b.vec3(&[[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
    let doc = b.finish(json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [
            // A matrix (translate (0, 0, 5), scale 2) on an animated node: split into TRS.
            {"name": "boxed", "mesh": 0, "matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 5, 1]},
            {"name": "offstage", "mesh": 0},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "animations": [
            {"name": "a", "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "weights"}},
                {"sampler": 1, "target": {"node": 0, "path": "rotation"}},
                {"sampler": 2, "target": {"node": 1, "path": "translation"}},
             ],
             "samplers": [{"input": t, "output": weights}, {"input": t, "output": rot}, {"input": t, "output": tr}]},
            {"name": "b", "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "weights"}},
                {"sampler": 1, "target": {"node": 0, "path": "rotation"}},
             ],
             "samplers": [{"input": t, "output": weights}, {"input": t, "output": rot}]},
        ],
    }));
    let dir = TempDir::new("anim-warnings");
    let scene = load_json(&dir, "warn.gltf", &doc).unwrap();
    let warnings = scene.warnings.join("\n");
    assert!(warnings.lines().all(|w| w.contains("warn.gltf")), "{warnings}");
    // Weights channels on a mesh without morph targets: each named, then ignored.
    assert_eq!(warnings.matches("the node's mesh has no morph targets; ignored").count(), 2, "{warnings}");
    assert!(
        warnings.contains("animation 1 ('b') channel 0 (node 0 ('boxed') morph weights 0..=3)"),
        "{warnings}"
    );
    assert!(warnings.contains("animation 1 ('b') channel 1 (node 0 ('boxed') rotation): animation 0 ('a') channel 1 already animates this"), "{warnings}");
    assert!(warnings.contains("node 0 ('boxed') is animated but has a matrix"), "{warnings}");
    // The rotation channel (the first) turns the matrix node 180° about +Z by 1 s, keeping its
    // translation and scale; the off-stage node's channel is read but changes nothing.
    let animation = scene.animation.as_ref().unwrap();
    assert_eq!(animation.channel_count(), 1);
    assert_eq!(scene.mesh.triangle_count(), 1);
    assert_near(scene.mesh.corners(0)[1], Vec3::new(2.0, 0.0, 5.0), 1e-6, "rest");
    let turned = scene.at_time(1.0).unwrap();
    assert_near(turned.mesh.corners(0)[1], Vec3::new(-2.0, 0.0, 5.0), 1e-5, "turned");

    // Nothing but weights channels, on a mesh without targets: a static scene.
    let mut only_weights = doc.clone();
    only_weights["animations"] = json!([{"channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}],
                                         "samplers": [{"input": t, "output": weights}]}]);
    let scene = load_json(&dir, "weights.gltf", &only_weights).unwrap();
    assert!(scene.animation.is_none());
    assert!(scene.warnings.join("\n").contains("the node's mesh has no morph targets; ignored"));

    // Alternative takes (the Khronos Fox's Survey, Walk, Run): a later clip animating only what
    // the first animates is not played and not warned of; the first plays.
    let mut takes = doc.clone();
    let turn = |sampler: u32| json!({"sampler": sampler, "target": {"node": 0, "path": "rotation"}});
    takes["nodes"][0] = json!({"name": "boxed", "mesh": 0});
    takes["animations"] = json!([
        {"name": "first", "channels": [turn(0)], "samplers": [{"input": t, "output": rot}]},
        {"name": "second", "channels": [turn(0)], "samplers": [{"input": t, "output": rot}]},
    ]);
    let scene = load_json(&dir, "takes.gltf", &takes).unwrap();
    assert_only_bounds_warnings(&scene);
    assert_eq!(scene.animation.as_ref().unwrap().channel_count(), 1);
}

#[test]
fn scene_animation_malformed_errors_name_file_animation_channel_and_key() {
    let dir = TempDir::new("anim-errors");
    // Animation 0 ('walk'): channel 0 a sound translation; channel 1 the rotation under test,
    // keys `times`, values `quats`, interpolation `interp`.
    let doc = |times: &[f32], quats: &[[f32; 4]], interp: &str| {
        let mut b = Builder::default();
        let pos = b.vec3(&TRIANGLE);
        let t0 = b.times(&[0.0, 1.0]);
        let v0 = b.vec3(&[[0.0; 3], [1.0; 3]]);
        let t1 = b.times(times);
        let v1 = b.quats(quats);
        b.finish(json!({
            "nodes": [{"name": "hips", "mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
            "animations": [{"name": "walk",
                "channels": [
                    {"sampler": 0, "target": {"node": 0, "path": "translation"}},
                    {"sampler": 1, "target": {"node": 0, "path": "rotation"}},
                ],
                "samplers": [{"input": t0, "output": v0}, {"input": t1, "output": v1, "interpolation": interp}],
            }],
        }))
    };
    let bytes = |doc: &Value| serde_json::to_vec(doc).unwrap();
    let id = [0.0, 0.0, 0.0, 1.0];
    let channel = "animation 0 ('walk') channel 1 (node 0 ('hips') rotation)";
    // The sound file loads.
    load_json(&dir, "sound.gltf", &doc(&[0.0, 1.0, 2.0], &[id; 3], "LINEAR")).unwrap();

    let decreasing = doc(&[0.0, 2.0, 1.0], &[id; 3], "LINEAR");
    expect_error(&dir, "decreasing.gltf", &bytes(&decreasing), &[channel, "key 2", "increase strictly"]);
    let repeated = doc(&[0.0, 1.0, 1.0], &[id; 3], "STEP");
    expect_error(&dir, "repeated.gltf", &bytes(&repeated), &[channel, "key 2", "not after key 1"]);
    let nan_time = doc(&[0.0, f32::NAN, 2.0], &[id; 3], "LINEAR");
    expect_error(&dir, "nan-time.gltf", &bytes(&nan_time), &[channel, "key 1", "time NaN is not finite"]);
    let nan_value = doc(&[0.0, 1.0, 2.0], &[id, [0.0, f32::NAN, 0.0, 1.0], id], "LINEAR");
    expect_error(
        &dir,
        "nan-value.gltf",
        &bytes(&nan_value),
        &[channel, "key 1", "rotation value", "not finite"],
    );
    let counts = doc(&[0.0, 1.0, 2.0], &[id; 2], "LINEAR");
    expect_error(&dir, "counts.gltf", &bytes(&counts), &[channel, "2 output values for 3 keys"]);
    let cubic = doc(&[0.0, 1.0, 2.0], &[id; 3], "CUBICSPLINE");
    expect_error(&dir, "cubic.gltf", &bytes(&cubic), &[channel, "3 output values for 3 keys", "three"]);
    let nan_tangent = doc(&[0.0, 1.0], &[id, id, [f32::NAN; 4], id, id, id], "CUBICSPLINE");
    expect_error(
        &dir,
        "tangent.gltf",
        &bytes(&nan_tangent),
        &[channel, "key 0", "out-tangent", "not finite"],
    );
    let zero = doc(&[0.0, 1.0, 2.0], &[id, id, [0.0; 4]], "LINEAR");
    expect_error(&dir, "zero.gltf", &bytes(&zero), &[channel, "key 2", "quaternion", "is zero"]);

    let mut missing = doc(&[0.0, 1.0], &[id; 2], "LINEAR");
    missing["animations"][0]["channels"][1]["target"]["node"] = json!(9);
    expect_error(
        &dir,
        "missing.gltf",
        &bytes(&missing),
        &["animation 0 ('walk') channel 1 targets node 9", "1 nodes"],
    );
    let mut sampler = doc(&[0.0, 1.0], &[id; 2], "LINEAR");
    sampler["animations"][0]["channels"][1]["sampler"] = json!(5);
    expect_error(&dir, "sampler.gltf", &bytes(&sampler), &["animation 0 ('walk') channel 1 uses sampler 5"]);
    let mut accessor = doc(&[0.0, 1.0], &[id; 2], "LINEAR");
    accessor["animations"][0]["samplers"][1]["output"] = json!(99);
    expect_error(
        &dir,
        "accessor.gltf",
        &bytes(&accessor),
        &["animation 0 ('walk') sampler 1", "output accessor 99"],
    );
    // Key times must be floats; rotations VEC4.
    let mut vec3_times = doc(&[0.0, 1.0], &[id; 2], "LINEAR");
    vec3_times["animations"][0]["samplers"][1]["input"] = json!(0);
    expect_error(&dir, "times.gltf", &bytes(&vec3_times), &[channel, "used as animation input is Vec3"]);
    let mut vec3_rotation = doc(&[0.0, 1.0], &[id; 2], "LINEAR");
    vec3_rotation["animations"][0]["samplers"][1]["output"] = json!(2);
    expect_error(
        &dir,
        "rotation.gltf",
        &bytes(&vec3_rotation),
        &[channel, "used as rotation output is Vec3"],
    );
    let mut overrun = doc(&[0.0, 1.0], &[id; 2], "LINEAR");
    overrun["accessors"][4]["count"] = json!(40);
    expect_error(&dir, "overrun.gltf", &bytes(&overrun), &[channel, "accessor 4", "need"]);
}

/// The café is static; loading it with its hierarchy kept lets a test flatten it again, as
/// `at_time` does for an animated scene, and time that.
#[test]
fn scene_animation_cafe_reflattens_identically_and_quickly() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cafe/cafe.gltf");
    let loaded = Scene::load(&path).unwrap();
    let rigged = super::super::load_with(&path, true).unwrap();
    assert_eq!(rigged.animation.as_ref().map(|a| a.channel_count()), Some(0));
    assert!(loaded.animation.is_none());
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let start = std::time::Instant::now();
        let again = rigged.at_time(1.0).unwrap();
        best = best.min(start.elapsed().as_secs_f64());
        assert_eq!(again.mesh, loaded.mesh);
        assert_eq!(again.cameras, loaded.cameras);
        assert_eq!(again.lights, loaded.lights);
    }
    println!("café: {} triangles flattened again in {:.1} ms", loaded.mesh.triangle_count(), best * 1e3);
    assert!(loaded.mesh.triangle_count() > 300_000);
    assert!(best < 1.0, "re-flattening the café took {best:.3} s");
}
