//! The studio's server over real HTTP and WebSocket (docs/studio.md): a client that speaks the
//! page's protocol, and the tests of editing, saving, the final render and the refusals of
//! "Safe by default".

mod api;
mod autosave;
mod collage;
mod preview;
mod project;
mod safety;

pub use ::studio::client::{Client, Msg, decode, http_get};
use ::studio::{Config, EngineSettings, Running};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// The Cornell box glTF (one camera; tests duplicate it).
pub fn scene() -> PathBuf {
    crate::common::cornell_dir().join("cornell.gltf")
}

/// A fresh scratch folder under the target directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mcctrace-studio-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Small settings so tests run in seconds.
pub const RES: [u32; 2] = [48, 32];
pub const SETTINGS: EngineSettings =
    EngineSettings { preview_spp: 4, view_spp: 2, coarse_divisor: 4, render_nice: None };

/// A studio on the Cornell box at [`RES`], saving to `dir`.
pub fn start(dir: &Path) -> Running {
    let config = Config { res: Some(RES), engine: SETTINGS, ..Config::new(Some(scene()), dir.to_path_buf()) };
    ::studio::serve(config).expect("the studio starts")
}

/// Two cameras painted side by side: duplicates camera 1, turns the copy, and paints the left
/// third with camera 1 and the right third with camera 2. Returns the state after the paint.
pub async fn two_strokes(client: &mut Client) -> Value {
    let state = client.hello().await;
    let first = state["cameras"][0].clone();
    let state = client.request(json!({"type": "camera_duplicate", "index": 1})).await;
    assert_eq!(state["cameras"].as_array().unwrap().len(), 2, "{state}");
    let eye = first["eye"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect::<Vec<_>>();
    let moved = json!({"type": "camera_edit", "index": 2, "eye": [eye[0] + 0.6, eye[1], eye[2]],
                       "target": first["target"], "up": first["up"], "fov_deg": 35.0});
    let state = client.request(moved).await;
    assert_eq!(state["type"], "state", "{state}");
    let [w, h] = RES;
    let third = w / 3;
    client.paint([0, 0, third, h], &vec![1; (third * h) as usize]).await;
    client.paint([w - third, 0, third, h], &vec![2; (third * h) as usize]).await
}

/// The label map `two_strokes` leaves: camera 1 on the left third, camera 2 on the right.
pub fn two_strokes_labels() -> Vec<u8> {
    let [w, h] = RES;
    let third = w / 3;
    (0..w * h)
        .map(|p| match p % w {
            x if x < third => 1,
            x if x >= w - third => 2,
            _ => 0,
        })
        .collect()
}

/// `mcctrace rerender` (the CLI's library entry) on a saved project at `res` and `spp`, into
/// `out` (EXR and PNG).
pub fn rerender(project: &Path, res: [u32; 2], spp: u32, out: &Path) {
    let args = [
        "mcctrace".to_owned(),
        "rerender".into(),
        scene().display().to_string(),
        "--collage".into(),
        project.join("collage.png").display().to_string(),
        "--rays".into(),
        project.join("views").display().to_string(),
        "--res".into(),
        format!("{}x{}", res[0], res[1]),
        "--spp".into(),
        spp.to_string(),
        "--quiet".into(),
        "--out".into(),
        out.display().to_string(),
    ];
    mcctrace_cli::try_run(args).expect("mcctrace rerender runs");
}
