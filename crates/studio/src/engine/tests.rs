//! The priority of the denoiser's threads.

use super::priority::{RENDER_NICE, current_nice};
use crate::config::Config;
use std::path::PathBuf;
use std::sync::atomic::{AtomicI32, Ordering};
use tracer::denoise::{Denoiser, Settings};
use tracer::image::RgbImage;
use tracer::render::Progress;

/// Set in the process the test below starts.
const CHILD: &str = "MCCTRACE_STUDIO_DENOISER_PRIORITY_CHILD";

/// OIDN's threads run at the render threads' priority even when a page asks for the denoiser
/// first: checked in a process of its own, as the denoiser is one per process and other tests
/// of this binary open it.
#[test]
fn the_denoiser_runs_at_the_render_priority() {
    let exe = std::env::current_exe().expect("the test binary");
    let out = std::process::Command::new(exe)
        .args(["--ignored", "--exact", "engine::tests::denoiser_priority_process", "--nocapture"])
        .env(CHILD, "1")
        .output()
        .expect("the test binary runs");
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && text.contains("1 passed"), "{text}");
}

/// Records the nice value of the thread OIDN calls the progress monitor on: its queue thread,
/// which runs the filter.
struct Nice(AtomicI32);

impl Progress for Nice {
    fn advance(&self, _samples: u64) {}

    fn cancelled(&self) -> bool {
        self.0.store(current_nice(), Ordering::SeqCst);
        false
    }
}

#[test]
#[ignore = "the process of the_denoiser_runs_at_the_render_priority, started by it"]
fn denoiser_priority_process() {
    if std::env::var_os(CHILD).is_none() {
        return;
    }
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell/cornell.gltf");
    let dir = std::env::temp_dir().join(format!("mcctrace-denoiser-priority-{}", std::process::id()));
    let config = Config { res: Some([32, 24]), ..Config::new(Some(scene), dir.clone()) };
    assert_eq!(config.engine.render_nice, Some(RENDER_NICE));
    let running = crate::serve(config).expect("the studio starts");
    // A page's first `state` asks for the denoiser's version, on a thread at the page's priority.
    let asked = std::thread::spawn(|| Denoiser::shared().is_ok()).join().unwrap();
    let denoiser = match Denoiser::shared() {
        Ok(d) => d,
        Err(e) if std::env::var_os("MCCTRACE_CI").is_none_or(|v| v != "1") => {
            eprintln!("skipping: {e} (MCCTRACE_CI=1 makes its absence a failure)");
            return;
        }
        Err(e) => panic!("{e}"),
    };
    assert!(asked);
    let nice = Nice(AtomicI32::new(i32::MIN));
    let image = RgbImage::new(64, 64);
    denoiser.denoise_cancellable(&image, None, Settings::PREVIEW, &nice).expect("the denoise runs");
    let nice = nice.0.load(Ordering::SeqCst);
    assert!(
        nice >= RENDER_NICE,
        "OIDN's filter thread runs at nice {nice}, above the renders' {RENDER_NICE}"
    );
    drop(running);
    let _ = std::fs::remove_dir_all(&dir);
}
