//! The worker's order of work after the page's denoise toggle.

use super::*;
use crate::config::Config;
use crate::engine::EngineSettings;
use crate::protocol::{Layer, Outbound};
use base64::Engine as _;
use serde_json::Value;
use std::path::PathBuf;
use tracer::denoise::DenoiseError;

/// Whether the denoiser is installed; under CI (`MCCTRACE_CI=1`, `.ci/run` installs it) its
/// absence fails the test, elsewhere it skips it after a note.
fn denoiser_installed() -> bool {
    match Denoiser::shared() {
        Ok(_) => true,
        Err(e @ DenoiseError::NotFound { .. })
            if std::env::var_os("MCCTRACE_CI").is_none_or(|v| v != "1") =>
        {
            eprintln!("skipping: {e} (MCCTRACE_CI=1 makes its absence a failure)");
            false
        }
        Err(e) => panic!("{e}"),
    }
}

/// The image headers `out` holds (kind, seq, camera), in the order they were sent.
fn images(out: &mut tokio::sync::broadcast::Receiver<Outbound>) -> Vec<(String, u64, Value)> {
    std::iter::from_fn(|| out.try_recv().ok())
        .filter_map(|m| match m {
            Outbound::Image { header, .. } => {
                let h: Value = serde_json::from_str(&header).expect("a JSON header");
                Some((
                    h["kind"].as_str().unwrap().to_owned(),
                    h["seq"].as_u64().unwrap(),
                    h["camera"].clone(),
                ))
            }
            Outbound::Text(_) => None,
        })
        .collect()
}

/// After the toggle, the next stroke's first preview comes before the thumbnails that are shown
/// again the other way: they held it up by a render each (seconds on a loaded machine, at the
/// render threads' low priority), both toggling off and on.
#[test]
fn after_the_toggle_the_strokes_first_preview_comes_before_the_thumbnails() {
    if !denoiser_installed() {
        return;
    }
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell/cornell.gltf");
    let dir = std::env::temp_dir().join(format!("mcctrace-worker-toggle-{}", std::process::id()));
    let engine = EngineSettings { preview_spp: 1, view_spp: 1, coarse_divisor: 4, render_nice: None };
    let config = Config { res: Some([48, 32]), engine, ..Config::new(Some(scene), dir.clone()) };
    let shared = Arc::new(crate::project::open_session(&config).expect("the session opens"));
    let mut out = shared.out.subscribe();
    let mut worker = Worker::new(Arc::clone(&shared));
    let cameras = shared.session().key().cameras.len();
    // A stroke of camera 1 over columns x..x+8, after the toggle set to `denoise`; then the
    // worker's refresh of that state.
    let mut stroke = |x: u32, denoise: bool| {
        let snap = {
            let mut session = shared.session();
            session.set_denoise(denoise);
            let data = base64::engine::general_purpose::STANDARD.encode([1u8; 8 * 32]);
            assert!(
                session.paint(Layer::Labels, [x, 0, 8, 32], &data).unwrap(),
                "the stroke changes the labels"
            );
            shared.changed(&session);
            session.snapshot()
        };
        shared.pool.install(|| worker.refresh(&snap)).expect("the refresh runs");
        snap.seq
    };
    stroke(0, true);
    let first = images(&mut out);
    assert_eq!(
        first.iter().filter(|(k, ..)| k == "thumb").count(),
        cameras,
        "every camera's thumbnail: {first:?}"
    );
    for (x, denoise) in [(8, false), (16, true)] {
        let seq = stroke(x, denoise);
        let sent = images(&mut out);
        assert!(sent.iter().all(|(_, s, _)| *s == seq), "{sent:?}");
        let kinds: Vec<&str> = sent.iter().map(|(k, ..)| k.as_str()).collect();
        assert_eq!(
            kinds.first(),
            Some(&"preview"),
            "denoise {denoise}: the stroke's first picture: {kinds:?}"
        );
        assert_eq!(kinds.iter().filter(|k| **k == "thumb").count(), cameras, "shown again: {kinds:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
