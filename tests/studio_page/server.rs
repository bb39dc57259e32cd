//! `mcctrace studio` for the page's test: the command in a child process, its URL read from what
//! it prints, and the batch `rerender` of a project it saved. The child is this test binary run
//! again on [`studio_process`], which hands its arguments to `mcctrace_cli::main_with_args`, the
//! whole of the `mcctrace` binary's `main`: no prebuilt binary is needed, and the server is
//! stopped with its process.

use crate::common::{Scratch, mcctrace, repo_root};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// A running `mcctrace studio` on the café; stopped on drop.
pub struct Studio {
    /// The page's URL with its token, as the command printed it.
    pub url: String,
    child: Child,
}

/// The environment variable that carries the child's `mcctrace` arguments, one per line.
const ARGS_VAR: &str = "MCCTRACE_STUDIO_PAGE_ARGS";

/// Runs `mcctrace ARGS…` with the arguments in [`ARGS_VAR`] (the server of the page's test, run
/// by [`Studio::start`] in a process of its own); ignored in a normal test run.
#[test]
#[ignore = "the studio process of studio_page's browser test, started by it"]
fn studio_process() {
    let Ok(args) = std::env::var(ARGS_VAR) else { return };
    let code = mcctrace_cli::main_with_args(std::iter::once("mcctrace").chain(args.lines()));
    panic!("mcctrace studio ended: {code:?}");
}

impl Studio {
    /// Starts the studio on the café with its `left` and `right` cameras at `res`.
    pub fn start(scratch: &Scratch, res: (u32, u32)) -> Self {
        let scene = repo_root().join("scenes/cafe/cafe.gltf");
        let project = scratch.path("project");
        let args = [
            "studio".to_string(),
            scene.display().to_string(),
            "--camera".into(),
            "left".into(),
            "--camera".into(),
            "right".into(),
            "--res".into(),
            format!("{}x{}", res.0, res.1),
            "--project".into(),
            project.display().to_string(),
        ];
        let exe = std::env::current_exe().expect("the test binary's path");
        let mut child = Command::new(exe)
            .args(["--ignored", "--exact", "studio_page::server::studio_process", "--nocapture"])
            .env(ARGS_VAR, args.join("\n"))
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("start mcctrace studio");
        // Read what it prints on a thread that keeps draining the pipe, so later lines never
        // block the server or break its pipe.
        let stdout = child.stdout.take().expect("studio stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                println!("[studio] {line}");
                if let Some(url) = line.strip_prefix("studio: ").filter(|u| u.starts_with("http://")) {
                    let _ = tx.send(url.to_owned());
                }
            }
        });
        let url =
            rx.recv_timeout(std::time::Duration::from_secs(120)).expect("mcctrace studio printed no URL");
        Self { url, child }
    }

    /// The tagged view PNG of `camera` in a saved project folder.
    pub fn view_png(&self, dir: &Path, camera: u32) -> PathBuf {
        dir.join(format!("views/frame0000camera{camera:02}.png"))
    }

    /// `mcctrace rerender` of the saved project at `(w, h, spp)` into `NAME.exr` (+ PNG) in the
    /// scratch folder, as the project folder's documentation gives the command; the 8-bit PNG.
    pub fn rerender(
        &self,
        dir: &Path,
        scratch: &Scratch,
        (w, h, spp): (u32, u32, u32),
        name: &str,
    ) -> image::RgbImage {
        let scene = repo_root().join("scenes/cafe/cafe.gltf");
        let out = scratch.path(&format!("{name}.exr"));
        let args = [
            "rerender".to_string(),
            scene.display().to_string(),
            "--collage".into(),
            dir.join("collage.png").display().to_string(),
            "--rays".into(),
            dir.join("views").display().to_string(),
            "--frame".into(),
            "0".into(),
            "--res".into(),
            format!("{w}x{h}"),
            "--spp".into(),
            spp.to_string(),
            "--out".into(),
            out.display().to_string(),
        ];
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        mcctrace(&args).expect("mcctrace rerender on the saved project");
        image::open(out.with_extension("png")).expect("rerender's PNG").to_rgb8()
    }
}

impl Drop for Studio {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
