//! The studio's latencies and memory, through its own server API (docs/studio.md; no browser):
//! each step timed from the message that starts it to the message that delivers its result,
//! on the café at 480×270 with four cameras (the targets: a stroke to the first
//! full-frame preview ≤ 150 ms, remap at the collage resolution ≤ 20 ms, a camera move to its
//! thumbnail ≤ 100 ms, 8 cameras ≤ 1 GiB). Figures go to docs/performance.md.
//!
//! `cargo bench --bench studio` (`-- ROUNDS`, default 7; `-- remap ROUNDS`: the remap timings
//! only, `-- remap glassner ROUNDS`: the column's blend only, `-- strokes ROUNDS`: the remap and stroke timings only, e.g. under
//! `valgrind --tool=callgrind`; `-- toggle ROUNDS`: strokes in one session toggled denoised,
//! raw, denoised).

use glam::UVec2;
use mcc::lens_writer::pixel_centre_rays;
use mcc::remap::{RemapConfig, remap};
use mcc::{Collage, Regions};
use serde_json::json;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use studio::client::{Client, Msg};
use tracer::lens::{FrameInfo, LensChain};

const RES: [u32; 2] = [480, 270];

fn cafe() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cafe/cafe.gltf")
}

fn summary(name: &str, mut ms: Vec<f64>) {
    ms.sort_by(f64::total_cmp);
    let median = ms[ms.len() / 2];
    println!(
        "{name}: median {median:.1} ms (min {:.1}, max {:.1}, {} rounds)",
        ms[0],
        ms[ms.len() - 1],
        ms.len()
    );
}

/// Vertical strips, one per camera, background between them.
fn strips(cameras: u32) -> Vec<u8> {
    let [w, h] = RES;
    let band = w / (2 * cameras);
    (0..w * h).map(|p| ((p % w) / band) as u8).map(|b| if b % 2 == 0 { b / 2 + 1 } else { 0 }).collect()
}

fn remap_timing(rounds: usize) {
    let source = studio::source::SceneSource::load(cafe(), Vec::new()).expect("the café loads");
    let mut cameras = source.cameras(0).unwrap();
    cameras.push(studio::camera::StudioCamera { index: 4, ..cameras[0].clone() });
    let res = UVec2::new(RES[0], RES[1]);
    let files: BTreeMap<u32, mcc::RayFile> = cameras
        .iter()
        .map(|c| {
            let camera = c.desc().unwrap().build(res).unwrap();
            let info = FrameInfo { frame: 0, camera_id: c.index, shutter: (0.0, 0.0) };
            (
                c.index,
                pixel_centre_rays(&LensChain::new().generator(camera.as_ref()), res, info, Vec::new())
                    .unwrap(),
            )
        })
        .collect();
    let ids = strips(4).iter().map(|&l| l as u32).collect();
    let collage = Collage::new(RES[0], RES[1], ids).unwrap();
    let regions = Regions::single(RES[0], RES[1]);
    let only_glassner = std::env::args().any(|a| a == "glassner");
    for (name, config) in [("glassner", RemapConfig::GLASSNER), ("seamless", RemapConfig::SEAMLESS)] {
        if only_glassner && name != "glassner" {
            continue;
        }
        let ms = (0..rounds)
            .map(|_| {
                let t = Instant::now();
                remap(&collage, &regions, &files, 0, &config).unwrap();
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        summary(&format!("remap 480x270, 4 cameras, {name}"), ms);
    }
}

/// Stroke → first full-frame preview, `rounds` times ([`stroke_series`]), in a session of its own whose preview is shown denoised or raw from the
/// start; `None` when denoising is asked for and the denoiser is not installed.
async fn strokes(rounds: usize, denoise: bool) -> Option<Vec<f64>> {
    let dir = std::env::temp_dir().join(format!("mcctrace-studio-bench-{}-{denoise}", std::process::id()));
    let config = studio::Config { res: Some(RES), ..studio::Config::new(Some(cafe()), dir.clone()) };
    let running = studio::serve(config).expect("the studio starts");
    let mut client = Client::connect(&running).await;
    let state = client.request(json!({"type": "denoise", "on": denoise})).await;
    if denoise && state["denoiser"].is_null() {
        return None;
    }
    client.request(json!({"type": "camera_duplicate", "index": 1})).await;
    let stroke_ms = stroke_series(&mut client, rounds, 0).await.split_off(1);
    drop(running);
    let _ = std::fs::remove_dir_all(&dir);
    Some(stroke_ms)
}

/// The times of `rounds` + 1 strokes on `client`'s session (the first one's apart: it comes
/// after a change of its own, e.g. the toggle), 300 ms apart: a 40-pixel-wide
/// band of camera k, moving right each round; series `series` shifts k by one, so that a later
/// series paints over an earlier one's bands with another camera. A stroke must change the
/// labels: one that repeats what is painted leaves the state (and its `seq`) as it is, so no
/// preview follows it (a mid-session toggle once waited here for a minute for the picture of
/// such a stroke, which had come before the stroke's reply).
async fn stroke_series(client: &mut Client, rounds: usize, series: u8) -> Vec<f64> {
    let h = RES[1];
    let mut stroke_ms = Vec::new();
    let mut seq = None;
    for round in 0..rounds + 1 {
        let (x, k) = (10 + 45 * (round as u32 % 10), 1 + (round as u8 + series) % 4);
        let t = Instant::now();
        let state = client.paint([x, 0, 40, h], &vec![k; (40 * h) as usize]).await;
        let now = state["seq"].as_u64().unwrap();
        assert!(seq < Some(now), "stroke {round} of series {series} changed no label: no preview follows");
        seq = Some(now);
        client.preview(now, 1).await;
        stroke_ms.push(t.elapsed().as_secs_f64() * 1e3);
        tokio::time::sleep(Duration::from_millis(300)).await;
    }
    stroke_ms
}

/// Strokes denoised, then raw, then denoised again in one session, the page's toggle between
/// the series (`-- toggle ROUNDS`).
async fn toggled(rounds: usize) {
    let dir = std::env::temp_dir().join(format!("mcctrace-studio-bench-{}-toggle", std::process::id()));
    let config = studio::Config { res: Some(RES), ..studio::Config::new(Some(cafe()), dir.clone()) };
    let running = studio::serve(config).expect("the studio starts");
    let mut client = Client::connect(&running).await;
    client.request(json!({"type": "camera_duplicate", "index": 1})).await;
    for (series, denoise) in [true, false, true].into_iter().enumerate() {
        client.request(json!({"type": "denoise", "on": denoise})).await;
        let shown = if denoise { "denoised" } else { "raw" };
        let mut ms = stroke_series(&mut client, rounds, series as u8).await;
        // The session starts denoised: its first stroke waits for the first thumbnails instead.
        let what = if series == 0 {
            "the session's first stroke".into()
        } else {
            format!("the stroke right after the toggle to {shown}")
        };
        println!("{what}: {:.1} ms", ms[0]);
        let ms = ms.split_off(1);
        summary(
            &format!(
                "stroke -> first full-frame preview, series {} of a toggled session ({shown})",
                series + 1
            ),
            ms,
        );
    }
    drop(running);
    let _ = std::fs::remove_dir_all(&dir);
}

async fn session(rounds: usize) {
    if std::env::args().any(|a| a == "toggle") {
        return toggled(rounds).await;
    }
    for denoise in [true, false] {
        let shown = if denoise { "denoised" } else { "raw" };
        let what = format!("stroke -> first full-frame preview (480x270, 4 cameras, {shown})");
        match strokes(rounds, denoise).await {
            Some(ms) => summary(&what, ms),
            None => println!("{what}: skipped (no denoiser installed)"),
        }
    }
    if std::env::args().any(|a| a == "strokes") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("mcctrace-studio-bench-{}", std::process::id()));
    let config = studio::Config { res: Some(RES), ..studio::Config::new(Some(cafe()), dir.clone()) };
    let running = studio::serve(config).expect("the studio starts");
    let mut client = Client::connect(&running).await;
    let state = client.hello().await;
    assert_eq!(state["cameras"].as_array().unwrap().len(), 3, "the café has three cameras");
    let state = client.request(json!({"type": "camera_duplicate", "index": 1})).await;
    let fourth = state["cameras"][3].clone();
    let [w, h] = RES;
    let mut move_ms = Vec::new();
    for round in 0..rounds {
        let eye = fourth["eye"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect::<Vec<_>>();
        let dx = 0.02 * (round as f64 + 1.0);
        let edit = json!({"type": "camera_edit", "index": 4, "eye": [eye[0] + dx, eye[1], eye[2]],
                          "target": fourth["target"], "up": fourth["up"], "fov_deg": fourth["fov_deg"]});
        let t = Instant::now();
        let seq = client.request(edit).await["seq"].clone();
        client
            .until(|m| matches!(m, Msg::Image(hd, _) if hd["kind"] == "thumb" && hd["camera"] == 4 && hd["seq"] == seq))
            .await;
        move_ms.push(t.elapsed().as_secs_f64() * 1e3);
        tokio::time::sleep(Duration::from_millis(300)).await;
    }
    summary("camera move -> its thumbnail (120x67, 1 spp)", move_ms);
    // Memory: eight cameras painted, the preview refined to its idle sample count.
    for _ in 0..4 {
        client.request(json!({"type": "camera_duplicate", "index": 2})).await;
    }
    let labels = strips(8);
    let t = Instant::now();
    let state = client.paint([0, 0, w, h], &labels).await;
    let spp = studio::EngineSettings::default().preview_spp;
    // Eight views at the collage size come first, with no message for minutes on a loaded
    // machine: wait longer than the client's usual minute.
    let seq = state["seq"].clone();
    loop {
        match client.try_recv(Duration::from_secs(1800)).await.expect("the studio answers within 30 min") {
            Msg::Image(hd, _) if hd["kind"] == "preview" && hd["seq"] == seq && hd["spp"] == json!(spp) => {
                break;
            }
            _ => {}
        }
    }
    let idle = t.elapsed().as_secs_f64();
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let peak = status.lines().find(|l| l.starts_with("VmHWM")).unwrap_or("VmHWM: unknown");
    println!(
        "8 cameras at 480x270, preview refined to {spp} spp in {idle:.1} s: peak resident memory {}",
        peak.trim_start_matches("VmHWM:").trim()
    );
    drop(running);
    let _ = std::fs::remove_dir_all(&dir);
}

fn main() {
    let rounds = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(7);
    remap_timing(rounds);
    if std::env::args().any(|a| a == "remap") {
        return;
    }
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build().unwrap();
    runtime.block_on(session(rounds));
}
