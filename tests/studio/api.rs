//! Editing over the socket: paint, undo and redo, camera edits, the preview's progress, and a
//! malformed message changing nothing.

use super::{Client, Msg, RES, SETTINGS, decode, scene, scratch, start, two_strokes, two_strokes_labels};
use ::studio::Config;
use serde_json::{Value, json};
use std::time::Duration;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn paint_undo_redo_and_camera_edits() {
    let dir = scratch("api-edit");
    let running = start(&dir);
    let mut client = Client::connect(&running).await;
    let state = client.hello().await;
    assert_eq!(state["res"], json!(RES));
    assert_eq!(state["can_undo"], false);
    let after = two_strokes(&mut client).await;
    assert_eq!(after["can_undo"], true);
    assert_eq!(after["cameras"][1]["fov_deg"], 35.0);
    assert_eq!(after["cameras"][1]["name"], "cornell copy");
    let painted = two_strokes_labels();
    // A second tab sees the maps as painted.
    let mut other = Client::connect(&running).await;
    other.send(json!({"type": "hello"})).await;
    let labels = other.until(|m| m.kind() == "labels").await;
    let Msg::Json(labels) = labels else { unreachable!() };
    assert_eq!(labels["layer"], "labels");
    assert_eq!(decode(&labels["data"]), painted);

    // Undo takes the second stroke away, redo brings it back; each says so with the whole map.
    let id = client.send(json!({"type": "undo"})).await;
    let Msg::Json(labels) = client.until(|m| m.kind() == "labels").await else { unreachable!() };
    let undone: Vec<u8> = painted.iter().map(|&l| if l == 2 { 0 } else { l }).collect();
    assert_eq!(decode(&labels["data"]), undone);
    let Msg::Json(state) = client.until(|m| matches!(m, Msg::Json(v) if v["id"] == json!(id))).await else {
        unreachable!()
    };
    assert_eq!((state["can_undo"].clone(), state["can_redo"].clone()), (json!(true), json!(true)));
    client.send(json!({"type": "redo"})).await;
    let Msg::Json(labels) = client.until(|m| m.kind() == "labels").await else { unreachable!() };
    assert_eq!(decode(&labels["data"]), painted);

    // A malformed paint is refused with its id and changes nothing.
    let seq = client.hello().await["seq"].clone();
    for bad in [
        json!({"type": "paint", "layer": "labels", "rect": [40, 0, 20, 1], "data": "AAAA"}),
        json!({"type": "paint", "layer": "labels", "rect": [0, 0, 1, 1], "data": "Bw=="}),
        json!({"type": "paint", "layer": "labels", "rect": [0, 0, 2, 1], "data": "AQ=="}),
        json!({"type": "paint", "layer": "labels", "rect": [0, 0, 1, 1], "data": "!!"}),
        json!({"type": "camera_edit", "index": 9, "eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0], "fov_deg": 40}),
        json!({"type": "camera_edit", "index": 1, "eye": [0, 0, 0], "target": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 40}),
        json!({"type": "view", "mode": "weights"}),
        json!({"type": "fly"}),
    ] {
        let reply = client.request(bad.clone()).await;
        assert_eq!(reply["type"], "error", "{bad} → {reply}");
    }
    client.send_text("{not json".into()).await;
    let Msg::Json(reply) = client.until(|m| m.kind() == "error").await else { unreachable!() };
    assert!(reply["message"].as_str().unwrap().contains("not JSON"), "{reply}");
    let state = client.hello().await;
    assert_eq!(state["seq"], seq, "refused messages changed the state");
    let Msg::Json(labels) = client.until(|m| m.kind() == "labels").await else { unreachable!() };
    assert_eq!(decode(&labels["data"]), painted);

    // The preview arrives coarse first, then refines to the idle sample count.
    let seq = state["seq"].as_u64().unwrap();
    client.request(json!({"type": "settings", "seamless": true})).await;
    let seq = seq + 1;
    let (coarse, _) = client.preview(seq, 1).await;
    assert_eq!((coarse["w"].clone(), coarse["h"].clone()), (json!(RES[0]), json!(RES[1])));
    let (last, png) = client.preview(seq, SETTINGS.preview_spp).await;
    assert_eq!(last["kind"], "preview");
    assert!(png.starts_with(b"\x89PNG"));

    // The debug views come from the same remap.
    client.request(json!({"type": "view", "mode": "dominant"})).await;
    let Msg::Image(header, _) = client.until(|m| matches!(m, Msg::Image(h, _) if h["kind"] == "view")).await
    else {
        unreachable!()
    };
    assert_eq!(header["w"], json!(RES[0]));
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Camera edits are undo steps in the order made, among the strokes; a second tab sees every
/// stroke, undo and camera move of the first as it happens.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn camera_edits_undo_in_order_and_tabs_see_each_other() {
    let dir = scratch("api-undo-tabs");
    let running = start(&dir);
    let mut client = Client::connect(&running).await;
    let mut other = Client::connect(&running).await;
    other.hello().await;
    let before = client.hello().await;
    let after = two_strokes(&mut client).await;
    let moved = after["cameras"][1].clone();
    assert_ne!(moved["eye"], before["cameras"][0]["eye"], "two_strokes moves the copy");

    // The other tab got the second stroke's map without asking.
    let painted = two_strokes_labels();
    let seen = other
        .until(|m| matches!(m, Msg::Json(v) if v["type"] == "labels" && decode(&v["data"]) == painted))
        .await;
    assert_eq!(seen.kind(), "labels");

    // Undo: the second stroke, the first, then the camera edit (the copy goes back to the
    // duplicate's pose), each seen by the other tab.
    for _ in 0..2 {
        client.request(json!({"type": "undo"})).await;
    }
    let state = client.request(json!({"type": "undo"})).await;
    assert_eq!(state["cameras"][1]["eye"], before["cameras"][0]["eye"], "{state}");
    assert_eq!(state["cameras"][1]["fov_deg"], before["cameras"][0]["fov_deg"]);
    let seq = state["seq"].clone();
    let Msg::Json(seen) =
        other.until(|m| matches!(m, Msg::Json(v) if v["type"] == "state" && v["seq"] == seq)).await
    else {
        unreachable!()
    };
    assert_eq!(seen["cameras"][1]["eye"], before["cameras"][0]["eye"]);
    assert_eq!(state["can_undo"], false, "duplicating is not an edit of a pose: nothing is left");
    // Redo brings the edit back, then the strokes.
    let state = client.request(json!({"type": "redo"})).await;
    assert_eq!(state["cameras"][1], moved);
    client.request(json!({"type": "redo"})).await;
    client.send(json!({"type": "redo"})).await;
    let seen = other
        .until(|m| matches!(m, Msg::Json(v) if v["type"] == "labels" && decode(&v["data"]) == painted))
        .await;
    assert_eq!(seen.kind(), "labels");
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A tab that stops reading while another makes many strokes falls behind the broadcast queue
/// and loses messages; when it reads again it must still end with the server's maps and state
/// (docs/studio.md, "Safe by default": tabs see each other's changes).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tab_far_behind_its_queue_ends_with_the_latest_state() {
    let dir = scratch("api-lag");
    // Big maps (a labels message is ~90 kB) fill the stalled tab's socket buffers (a few MB)
    // after a few dozen strokes; the queue (256 messages) overflows after a hundred more.
    let res = [256u32, 256];
    let config = Config { res: Some(res), engine: SETTINGS, ..Config::new(Some(scene()), dir.clone()) };
    let running = ::studio::serve(config).expect("the studio starts");
    let mut slow = Client::connect(&running).await;
    slow.hello().await;
    let mut client = Client::connect(&running).await;
    client.hello().await;
    // Label strokes, then more region strokes than the queue holds: every labels message the
    // slow tab has not read yet is gone from the queue.
    for i in 0..300u32 {
        let x = (i * 7) % (res[0] - 16);
        client.paint([x, (i * 3) % (res[1] - 16), 16, 16], &[(i % 2) as u8; 256]).await;
    }
    for i in 0..400u32 {
        client.paint_layer("regions", [(i * 5) % (res[0] - 8), 0, 8, 8], &[1 + (i % 5) as u8; 64]).await;
    }
    let state = client.hello().await;
    let seq = state["seq"].clone();
    let (mut labels, mut regions) = (None, None);
    while labels.is_none() || regions.is_none() {
        if let Msg::Json(v) = client.until(|m| m.kind() == "labels").await {
            *if v["layer"] == "labels" { &mut labels } else { &mut regions } = Some(decode(&v["data"]));
        }
    }
    // The slow tab reads again: whatever it keeps last of each kind must be the server's.
    let (mut seen_state, mut seen_labels, mut seen_regions) = (None, None, None);
    let (mut caught_up, mut maps_read) = (false, 0);
    loop {
        let wait = Duration::from_secs(if caught_up { 3 } else { 60 });
        let Some(message) = slow.try_recv(wait).await else { break };
        if let Msg::Json(v) = message {
            match v["type"].as_str() {
                Some("state") => {
                    caught_up |= v["seq"] == seq;
                    seen_state = Some(v["seq"].clone());
                }
                Some("labels") if v["layer"] == "labels" => {
                    maps_read += 1;
                    seen_labels = Some(decode(&v["data"]));
                }
                Some("labels") => {
                    maps_read += 1;
                    seen_regions = Some(decode(&v["data"]));
                }
                _ => {}
            }
        }
    }
    // 700 strokes sent 700 maps: fewer reached the slow tab, so it did fall behind the queue.
    assert!(
        maps_read < 700,
        "the slow tab read all {maps_read} maps: it never fell behind, nothing is tested"
    );
    assert!(caught_up, "the slow tab never got the last state");
    assert_eq!(seen_state, Some(seq), "the slow tab's last state is not the server's");
    assert!(seen_labels == labels, "the slow tab's label map is not the server's");
    assert!(seen_regions == regions, "the slow tab's region map is not the server's");
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 41, item 13: a camera drag is one undo step. The page sends a drag as an edit every
/// 40 ms and the last pose again on release, all with the drag's gesture number; one undo puts
/// the camera back where the drag started, the next undoes the stroke before it, and a second
/// drag is a step of its own.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_camera_drag_is_one_undo_step() {
    let dir = scratch("api-drag");
    let running = start(&dir);
    let mut client = Client::connect(&running).await;
    let start_state = client.hello().await;
    let first = start_state["cameras"][0].clone();
    client.paint([0, 0, 4, 4], &[1; 16]).await;
    let eye: Vec<f64> = first["eye"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let pose = |k: usize, gesture: u64| {
        json!({"type": "camera_edit", "index": 1, "eye": [eye[0] + 0.05 * k as f64, eye[1], eye[2]],
               "target": first["target"], "up": first["up"], "fov_deg": first["fov_deg"], "gesture": gesture})
    };
    let drag = |gesture: u64, from: usize| {
        // Ten timed edits, then the release sends the last pose again.
        (from..from + 10).map(move |k| pose(k, gesture)).chain(std::iter::once(pose(from + 9, gesture)))
    };
    let mut dragged = Value::Null;
    for edit in drag(7, 1) {
        dragged = client.request(edit).await;
    }
    let moved_eye = dragged["cameras"][0]["eye"].clone();
    assert_ne!(moved_eye, first["eye"]);
    let mut second = Value::Null;
    for edit in drag(8, 11) {
        second = client.request(edit).await;
    }
    assert_ne!(second["cameras"][0]["eye"], moved_eye);

    // One undo: the second drag, whole.
    let state = client.request(json!({"type": "undo"})).await;
    assert_eq!(state["cameras"][0]["eye"], moved_eye, "{state}");
    // The next: the first drag, whole; the stroke is still there.
    let state = client.request(json!({"type": "undo"})).await;
    assert_eq!(state["cameras"][0]["eye"], first["eye"], "{state}");
    assert_eq!(state["can_undo"], true, "the stroke is left to undo");
    // Then the stroke.
    let id = client.send(json!({"type": "undo"})).await;
    let Msg::Json(labels) = client.until(|m| m.kind() == "labels").await else { unreachable!() };
    assert!(decode(&labels["data"]).iter().all(|&l| l == 0));
    let Msg::Json(state) = client.until(|m| matches!(m, Msg::Json(v) if v["id"] == json!(id))).await else {
        unreachable!()
    };
    assert_eq!(state["can_undo"], false);
    // Redo brings the first drag back in one step.
    client.request(json!({"type": "redo"})).await;
    let state = client.request(json!({"type": "redo"})).await;
    assert_eq!(state["cameras"][0]["eye"], moved_eye, "{state}");
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}
