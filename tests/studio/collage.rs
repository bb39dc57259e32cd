//! Collages opened with `studio SCENE --collage FILE` (issue 41): layers `NAME (camera N)` that
//! `render --layers` wrote with its own numbering are the session's cameras by name.

use super::{Client, Msg, SETTINGS, decode, scratch};
use crate::common::{mcctrace, repo_root};
use crate::layers::{edit_png, rezip, unzip};
use serde_json::{Value, json};
use std::path::Path;

/// The café rendered from `right` and `wide` only (views 1 and 2 of that render) with
/// `--layers`, then `right`'s layer erased from x = 12 on: written to `dir/rw.ora`.
fn right_and_wide(dir: &Path, res: [u32; 2]) {
    let cafe = repo_root().join("scenes/cafe/cafe.gltf");
    let (ora, out) = (dir.join("views.ora"), dir.join("views"));
    let size = format!("{}x{}", res[0], res[1]);
    let args = ["render", cafe.to_str().unwrap(), "--camera", "right", "--camera", "wide", "--frame", "0"];
    let more = ["--lens-writer", "--layers", ora.to_str().unwrap(), "--res", &size, "--spp", "1"];
    mcctrace(&[&args[..], &more[..], &["--max-depth", "1", "-q", "--out", out.to_str().unwrap()]].concat())
        .unwrap();
    let mut entries = unzip(&ora);
    let stack = String::from_utf8(entries.iter().find(|(n, _)| n == "stack.xml").unwrap().1.clone()).unwrap();
    assert!(stack.contains("\"right (camera 1)\"") && stack.contains("\"wide (camera 2)\""), "{stack}");
    let entry = entries.iter_mut().find(|(n, _)| n == "data/camera01.png").unwrap();
    entry.1 = edit_png(&entry.1, |x, _| if x >= 12 { 0.0 } else { 1.0 }).0;
    rezip(&dir.join("rw.ora"), &entries);
}

/// The size and label map a studio on the café opened with `collage` shows (at `res` if given,
/// else leaving the size to the defaults).
async fn labels_of(dir: &Path, collage: &Path, res: Option<[u32; 2]>) -> Result<(Value, Vec<u8>), String> {
    let cafe = repo_root().join("scenes/cafe/cafe.gltf");
    let mut config = ::studio::Config {
        engine: SETTINGS,
        collage: Some(collage.to_path_buf()),
        ..::studio::Config::new(Some(cafe), dir.join(format!("project-{}", res.is_some())))
    };
    if let Some(res) = res {
        config.res = Some(res);
    }
    let running = ::studio::serve(config).map_err(|e| e.to_string())?;
    let mut client = Client::connect(&running).await;
    let state = client.hello().await;
    let names: Vec<_> = state["cameras"].as_array().unwrap().iter().map(|c| c["name"].clone()).collect();
    assert_eq!(names, [json!("left"), json!("right"), json!("wide")], "the studio's own numbering");
    client.send(json!({"type": "hello"})).await;
    let Msg::Json(labels) =
        client.until(|m| matches!(m, Msg::Json(v) if v["type"] == "labels" && v["layer"] == "labels")).await
    else {
        unreachable!()
    };
    Ok((state["res"].clone(), decode(&labels["data"])))
}

/// Issue 41, item 1: `render --camera right --camera wide --layers` names its layers
/// `right (camera 1)` and `wide (camera 2)`; the studio numbers the café's cameras `left` 1,
/// `right` 2, `wide` 3. The layers are the studio's `right` and `wide`, not its 1 and 2.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn numbered_layers_open_as_the_cameras_they_name() {
    let dir = scratch("collage-names");
    let res = [32, 18];
    right_and_wide(&dir, res);
    let (_, labels) = labels_of(&dir, &dir.join("rw.ora"), Some(res)).await.unwrap();
    let want: Vec<u8> = (0..res[0] * res[1]).map(|p| if p % res[0] < 12 { 2 } else { 3 }).collect();
    assert_eq!(labels, want, "right's kept part is camera 2 (right), the rest camera 3 (wide)");

    // Issue 41, item 16: without a resolution the session takes the collage's size.
    let (size, unsized_labels) = labels_of(&dir, &dir.join("rw.ora"), None).await.unwrap();
    assert_eq!(size, json!(res), "the collage's own size");
    assert_eq!(unsized_labels, want);

    // A layer naming a camera the session lacks is refused, not read by its number.
    let mut entries = unzip(&dir.join("rw.ora"));
    let stack = entries.iter_mut().find(|(n, _)| n == "stack.xml").unwrap();
    stack.1 = String::from_utf8(stack.1.clone())
        .unwrap()
        .replace("right (camera 1)", "tele (camera 1)")
        .into_bytes();
    rezip(&dir.join("tele.ora"), &entries);
    let err = labels_of(&dir, &dir.join("tele.ora"), Some(res)).await.unwrap_err();
    assert!(
        err.contains("layer \"tele (camera 1)\"")
            && err.contains("\"tele\", which this session does not have")
            && err.contains("camera 1 is \"left\""),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
