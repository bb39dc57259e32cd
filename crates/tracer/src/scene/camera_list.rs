//! Camera-list files: named cameras for scenes that carry none (OBJ), as JSON.
//!
//! ```json
//! {"cameras": [
//!   {"name": "left", "model": "perspective", "look_from": [0, 1, 5], "look_at": [0, 1, 0],
//!    "up": [0, 1, 0], "fov": 40},
//!   {"name": "plan", "model": "orthographic", "look_from": [0, 10, 0], "look_at": [0, 0, 0],
//!    "up": [0, 0, -1], "half_height": 3}
//! ]}
//! ```
//!
//! Keys of an entry: `name` (default `camera<i>`; names must be unique), `model` (default
//! `perspective`; also `orthographic`, `thin-lens`, `fisheye`, `equirectangular`), `look_from`,
//! `look_at` (required), `up` (default +Y), and what the model needs: `fov` in degrees (vertical
//! for perspective and thin lens, across the image circle for fisheye), `half_height`
//! (orthographic, world units), `lens_radius` and `focus_distance` (thin lens; the focus
//! distance defaults to |look_at − look_from|). A key that is unknown or does not apply to the
//! model is an error, so a typo can never be silently ignored; so is a missing or out-of-range
//! value. Every error names the file, the entry (index and name) and what is wrong.

use crate::camera::{CameraDesc, Projection};
use crate::error::{Result, TracerError};
use glam::Vec3;
use serde_json::{Map, Value};
use std::path::Path;

/// The camera models and the keys each takes besides the common ones.
const MODELS: &[(&str, &[&str])] = &[
    ("perspective", &["fov"]),
    ("orthographic", &["half_height"]),
    ("thin-lens", &["fov", "lens_radius", "focus_distance"]),
    ("fisheye", &["fov"]),
    ("equirectangular", &[]),
];

/// Keys every entry may have.
const COMMON: &[&str] = &["name", "model", "look_from", "look_at", "up"];

/// Loads a camera-list file.
pub fn load(path: &Path) -> Result<Vec<CameraDesc>> {
    let bytes = std::fs::read(path).map_err(|e| TracerError::io(path, e))?;
    parse(&bytes).map_err(|m| TracerError::scene(path, m))
}

/// Parses a camera list; the message says where and what is wrong (the caller adds the file).
pub fn parse(bytes: &[u8]) -> std::result::Result<Vec<CameraDesc>, String> {
    let root: Value =
        serde_json::from_slice(bytes).map_err(|e| format!("malformed camera-list JSON: {e}"))?;
    let Value::Object(root) = root else {
        return Err("a camera list is a JSON object with a \"cameras\" array".to_owned());
    };
    if let Some(key) = root.keys().find(|k| k.as_str() != "cameras") {
        return Err(format!("unknown key '{key}' at the top level (only \"cameras\" is allowed)"));
    }
    let entries = match root.get("cameras") {
        Some(Value::Array(a)) => a,
        Some(other) => return Err(format!("\"cameras\" must be an array, not {}", kind(other))),
        None => return Err("no \"cameras\" array".to_owned()),
    };
    if entries.is_empty() {
        return Err("the \"cameras\" array is empty".to_owned());
    }
    let mut cameras: Vec<CameraDesc> = Vec::with_capacity(entries.len());
    for (i, entry) in entries.iter().enumerate() {
        let camera = parse_entry(i, entry)?;
        if let Some(j) = cameras.iter().position(|c| c.name == camera.name) {
            return Err(format!("camera {i} ('{}'): the name is already used by camera {j}", camera.name));
        }
        cameras.push(camera);
    }
    Ok(cameras)
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

fn parse_entry(i: usize, entry: &Value) -> std::result::Result<CameraDesc, String> {
    let Value::Object(e) = entry else {
        return Err(format!("camera {i}: an entry must be a JSON object, not {}", kind(entry)));
    };
    let name = match e.get("name") {
        None => format!("camera{i}"),
        Some(Value::String(s)) if !s.is_empty() => s.clone(),
        Some(other) => return Err(format!("camera {i}: \"name\" must be a non-empty string, not {other}")),
    };
    let at = format!("camera {i} ('{name}')");
    let model = match e.get("model") {
        None => "perspective",
        Some(Value::String(s)) => s.as_str(),
        Some(other) => return Err(format!("{at}: \"model\" must be a string, not {other}")),
    };
    let Some(&(_, model_keys)) = MODELS.iter().find(|(m, _)| *m == model) else {
        let known: Vec<&str> = MODELS.iter().map(|(m, _)| *m).collect();
        return Err(format!("{at}: unknown model '{model}' (expected one of {})", known.join(", ")));
    };
    for key in e.keys() {
        if COMMON.contains(&key.as_str()) || model_keys.contains(&key.as_str()) {
            continue;
        }
        let applies_elsewhere = MODELS.iter().any(|(_, keys)| keys.contains(&key.as_str()));
        return Err(if applies_elsewhere {
            let article = if model.starts_with(['a', 'e', 'i', 'o', 'u']) { "an" } else { "a" };
            format!("{at}: key '{key}' does not apply to {article} {model} camera")
        } else {
            let mut allowed: Vec<&str> = COMMON.iter().chain(model_keys.iter()).copied().collect();
            allowed.sort_unstable();
            format!("{at}: unknown key '{key}' (a {model} camera takes {})", allowed.join(", "))
        });
    }
    let field = Field { at: &at, e };
    let from = field.vec3("look_from")?.ok_or_else(|| format!("{at}: \"look_from\" is missing"))?;
    let look = field.vec3("look_at")?.ok_or_else(|| format!("{at}: \"look_at\" is missing"))?;
    let up = field.vec3("up")?.unwrap_or(Vec3::Y);
    let fov = |max: f32| -> std::result::Result<f32, String> {
        let deg = field.number("fov")?.ok_or_else(|| format!("{at}: \"fov\" (degrees) is missing"))?;
        if !(deg > 0.0 && deg < max) {
            return Err(format!("{at}: \"fov\" {deg}° must be in (0°, {max}°)"));
        }
        Ok(deg.to_radians())
    };
    let projection = match model {
        "perspective" => Projection::Perspective { fov_y: fov(180.0)? },
        "fisheye" => Projection::Fisheye { fov: fov(360.0 + 1e-3)? },
        "equirectangular" => Projection::Equirectangular,
        "orthographic" => {
            let h = field
                .number("half_height")?
                .ok_or_else(|| format!("{at}: \"half_height\" (world units) is missing"))?;
            if h <= 0.0 {
                return Err(format!("{at}: \"half_height\" {h} must be positive"));
            }
            Projection::Orthographic { half_height: h }
        }
        _ => {
            let fov_y = fov(180.0)?;
            let lens_radius = field
                .number("lens_radius")?
                .ok_or_else(|| format!("{at}: \"lens_radius\" (world units) is missing"))?;
            if lens_radius < 0.0 {
                return Err(format!("{at}: \"lens_radius\" {lens_radius} must be ≥ 0"));
            }
            let focus_distance = field.number("focus_distance")?.unwrap_or((look - from).length());
            if focus_distance <= 0.0 {
                return Err(format!("{at}: \"focus_distance\" {focus_distance} must be positive"));
            }
            Projection::ThinLens { fov_y, lens_radius, focus_distance }
        }
    };
    CameraDesc::look_at(&name, from, look, up, projection).map_err(|e| {
        // The look-at error reads "invalid setting: camera look-at: …"; keep the part after it.
        let message = e.to_string();
        let what = message.split_once("look-at: ").map_or(message.as_str(), |(_, w)| w).to_owned();
        format!("{at}: {what}")
    })
}

/// Typed access to an entry's keys with messages naming the entry.
struct Field<'a> {
    at: &'a str,
    e: &'a Map<String, Value>,
}

impl Field<'_> {
    fn number(&self, key: &str) -> std::result::Result<Option<f32>, String> {
        match self.e.get(key) {
            None => Ok(None),
            Some(v) => match v.as_f64().map(|x| x as f32) {
                Some(x) if x.is_finite() => Ok(Some(x)),
                _ => Err(format!("{}: \"{key}\" must be a finite number, not {v}", self.at)),
            },
        }
    }

    fn vec3(&self, key: &str) -> std::result::Result<Option<Vec3>, String> {
        let Some(v) = self.e.get(key) else { return Ok(None) };
        let values: Option<Vec<f32>> =
            v.as_array().map(|a| a.iter().filter_map(|x| x.as_f64().map(|x| x as f32)).collect());
        match values {
            Some(xs) if xs.len() == 3 && v.as_array().is_some_and(|a| a.len() == 3) => {
                let p = Vec3::new(xs[0], xs[1], xs[2]);
                if p.is_finite() {
                    Ok(Some(p))
                } else {
                    Err(format!("{}: \"{key}\" must be finite", self.at))
                }
            }
            _ => Err(format!("{}: \"{key}\" must be an array of three numbers [x, y, z], not {v}", self.at)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::gltf::tests::{TempDir, cornell_dir};

    fn error(json: &str) -> String {
        parse(json.as_bytes()).unwrap_err()
    }

    #[test]
    fn scene_camera_list_models_and_defaults() {
        let cams = parse(
            br#"{"cameras": [
                {"name": "p", "look_from": [0, 0, 5], "look_at": [0, 0, 0], "fov": 90},
                {"name": "o", "model": "orthographic", "look_from": [0, 10, 0], "look_at": [0, 0, 0],
                 "up": [0, 0, -1], "half_height": 2.5},
                {"model": "thin-lens", "look_from": [0, 0, 4], "look_at": [0, 0, 0], "fov": 30, "lens_radius": 0.1},
                {"name": "f", "model": "fisheye", "look_from": [0, 0, 0], "look_at": [1, 0, 0], "fov": 180},
                {"name": "e", "model": "equirectangular", "look_from": [1, 2, 3], "look_at": [1, 2, 2]}
            ]}"#,
        )
        .unwrap();
        assert_eq!(cams.len(), 5);
        assert_eq!(cams[0].projection, Projection::Perspective { fov_y: 90f32.to_radians() });
        assert_eq!(Vec3::from(cams[0].world_from_camera.translation), Vec3::new(0.0, 0.0, 5.0));
        assert_eq!(cams[1].projection, Projection::Orthographic { half_height: 2.5 });
        // The camera looks down −Z in camera space: world −Y here, with camera +Y along world −Z.
        let m = cams[1].world_from_camera.matrix3;
        assert!(
            (Vec3::from(m.z_axis) - Vec3::Y).length() < 1e-6
                && (Vec3::from(m.y_axis) + Vec3::Z).length() < 1e-6
        );
        assert_eq!(cams[2].name, "camera2");
        assert_eq!(
            cams[2].projection,
            Projection::ThinLens { fov_y: 30f32.to_radians(), lens_radius: 0.1, focus_distance: 4.0 }
        );
        assert_eq!(cams[3].projection, Projection::Fisheye { fov: std::f32::consts::PI });
        assert_eq!(cams[4].projection, Projection::Equirectangular);
    }

    #[test]
    fn scene_camera_list_errors_name_entry_and_problem() {
        let cases: &[(&str, &[&str])] = &[
            ("[1, 2]", &["JSON object"]),
            ("{\"cams\": []}", &["unknown key 'cams'"]),
            ("{\"cameras\": []}", &["empty"]),
            ("{\"cameras\": {}}", &["must be an array"]),
            ("{\"cameras\": [", &["malformed camera-list JSON", "line 1"]),
            (
                r#"{"cameras": [{"name": "a", "look_from": [0,0,1], "look_at": [0,0,0], "fov": 40},
                                {"name": "b", "look_from": [0,0,1], "look_at": [0,0,0], "fvo": 40}]}"#,
                &["camera 1 ('b')", "unknown key 'fvo'", "fov"],
            ),
            (
                r#"{"cameras": [{"name": "o", "model": "orthographic", "look_from": [0,0,1], "look_at": [0,0,0], "fov": 40}]}"#,
                &["camera 0 ('o')", "'fov' does not apply to an orthographic camera"],
            ),
            (
                r#"{"cameras": [{"look_from": [0,0,1], "look_at": [0,0,0]}]}"#,
                &["camera 0 ('camera0')", "\"fov\""],
            ),
            (
                r#"{"cameras": [{"name": "x", "look_at": [0,0,0], "fov": 40}]}"#,
                &["camera 0 ('x')", "look_from"],
            ),
            (
                r#"{"cameras": [{"name": "x", "look_from": [0,0], "look_at": [0,0,0], "fov": 40}]}"#,
                &["camera 0 ('x')", "three numbers"],
            ),
            (
                r#"{"cameras": [{"name": "x", "look_from": [0,0,1], "look_at": [0,0,0], "fov": 200}]}"#,
                &["camera 0 ('x')", "200°"],
            ),
            (
                r#"{"cameras": [{"name": "x", "look_from": [0,0,1], "look_at": [0,0,1], "fov": 40}]}"#,
                &["camera 0 ('x')", "same point"],
            ),
            (
                r#"{"cameras": [{"name": "x", "look_from": [0,1,0], "look_at": [0,0,0], "fov": 40}]}"#,
                &["camera 0 ('x')", "parallel"],
            ),
            (
                r#"{"cameras": [{"name": "x", "model": "pinhole", "look_from": [0,0,1], "look_at": [0,0,0]}]}"#,
                &["unknown model 'pinhole'", "thin-lens"],
            ),
            (
                r#"{"cameras": [{"name": "x", "model": "thin-lens", "look_from": [0,0,1], "look_at": [0,0,0], "fov": 40, "lens_radius": -1}]}"#,
                &["camera 0 ('x')", "lens_radius"],
            ),
            (
                r#"{"cameras": [{"name": "x", "look_from": [0,0,1], "look_at": [0,0,0], "fov": 40},
                                {"name": "x", "look_from": [0,0,2], "look_at": [0,0,0], "fov": 40}]}"#,
                &["camera 1 ('x')", "already used by camera 0"],
            ),
            (r#"{"cameras": [{"name": 7}]}"#, &["camera 0", "\"name\""]),
        ];
        for (json, needles) in cases {
            let message = error(json);
            for needle in *needles {
                assert!(message.contains(needle), "'{message}' does not say '{needle}' for {json}");
            }
        }
    }

    #[test]
    fn scene_camera_list_files() {
        let dir = TempDir::new("camera-list");
        let bad = dir.write("typo.json", r#"{"cameras": [{"name": "v", "look_from": [0,0,1], "look_at": [0,0,0], "fov": 40, "upp": [0,1,0]}]}"#);
        let message = load(&bad).unwrap_err().to_string();
        assert!(
            message.contains("typo.json") && message.contains("camera 0 ('v')") && message.contains("'upp'"),
            "{message}"
        );
        let message = load(&dir.0.join("absent.json")).unwrap_err().to_string();
        assert!(message.contains("absent.json"), "{message}");
        // The Cornell box's list: the reference camera first, then a second view.
        let cams = load(&cornell_dir().join("cameras.json")).unwrap();
        assert_eq!(cams[0].name, "cornell");
        assert!(cams.len() >= 2 && cams[1].world_from_camera != cams[0].world_from_camera);
        let gltf = crate::scene::Scene::load(&cornell_dir().join("cornell.gltf")).unwrap();
        assert!(cams[0].world_from_camera.abs_diff_eq(gltf.cameras[0].world_from_camera, 1e-5));
        let (Projection::Perspective { fov_y: a }, Projection::Perspective { fov_y: b }) =
            (cams[0].projection, gltf.cameras[0].projection)
        else {
            panic!("{cams:?}")
        };
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    }
}
