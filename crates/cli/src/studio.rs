//! `mcctrace studio`: parses the flags, starts the studio's server (`studio::serve`,
//! docs/studio.md) and prints its URL; the server runs until the process is stopped.

use crate::args::Resolution;
use anyhow::{Context, bail};
use clap::Args;
use std::net::IpAddr;
use std::path::PathBuf;

/// Arguments of `mcctrace studio`.
#[derive(Args, Debug)]
pub struct StudioArgs {
    /// A scene file (.gltf, .glb, .obj) to start a new project from, or a project folder a
    /// studio saved (it holds studio.json) to reopen.
    pub input: PathBuf,
    /// A scene camera to paint with, by name or by number counted from 1, as `render --camera`
    /// takes it (repeat; default: all the scene's cameras).
    #[arg(long = "camera", value_name = "NAME|NUMBER")]
    pub cameras: Vec<String>,
    /// Collage resolution (default: the --collage's own size, else 480x270).
    #[arg(long)]
    pub res: Option<Resolution>,
    /// The first key's frame.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Start from an existing collage cut elsewhere: a tagged image, or a layered OpenRaster
    /// (.ora) or Photoshop (.psd) file with a layer per camera, as `remap` takes it (a region
    /// image beside it is used too).
    #[arg(long)]
    pub collage: Option<PathBuf>,
    /// The project folder saves go to (default: <scene-stem>-studio in the current folder).
    #[arg(long)]
    pub project: Option<PathBuf>,
    /// Port to listen on; 0 takes any free port.
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// Address to listen on. The default, 127.0.0.1, keeps the studio on this machine; any other
    /// address lets other machines reach it (they still need the token).
    #[arg(long, default_value = "127.0.0.1")]
    pub listen: IpAddr,
    /// Open the page in the default browser.
    #[arg(long)]
    pub open: bool,
}

pub fn run(a: StudioArgs) -> anyhow::Result<()> {
    let is_project = a.input.join(::studio::project::PROJECT_FILE).is_file();
    let (scene, project) = if is_project {
        if a.collage.is_some() || !a.cameras.is_empty() {
            bail!(
                "{}: a project folder keeps its cameras and collages; --camera and --collage are for a scene",
                a.input.display()
            );
        }
        (None, a.project.unwrap_or_else(|| a.input.clone()))
    } else {
        let stem =
            a.input.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
        (Some(a.input.clone()), a.project.unwrap_or_else(|| PathBuf::from(format!("{stem}-studio"))))
    };
    let config = ::studio::Config {
        cameras: a.cameras,
        res: a.res.map(|r| [r.0.x, r.0.y]),
        frame: a.frame,
        collage: a.collage,
        listen: a.listen,
        port: a.port,
        ..::studio::Config::new(scene, project.clone())
    };
    let running =
        ::studio::serve(config).with_context(|| format!("starting the studio on {}", a.input.display()))?;
    println!("studio: {}", running.url());
    println!("project folder: {} (Ctrl-C stops the studio, keeping unsaved changes)", project.display());
    if a.open {
        open_browser(running.url());
    }
    wait_for_stop();
    // Stopped: unsaved changes go to the autosave beside the project, and the user is told.
    let kept = running.autosave().context("keeping the unsaved changes");
    running.stop();
    match kept? {
        Some(dir) => println!(
            "studio: stopped; unsaved changes kept in {} (the next `mcctrace studio` on this project offers to \
             restore them)",
            dir.display()
        ),
        None => {
            println!("studio: stopped; no unsaved changes (the project folder holds the last save, if any)")
        }
    }
    Ok(())
}

/// Set by SIGINT or SIGTERM.
static STOP: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

extern "C" fn on_stop_signal(_: libc::c_int) {
    // Only an atomic store: all a signal handler may safely do.
    STOP.store(true, std::sync::atomic::Ordering::SeqCst);
}

/// Returns once Ctrl-C (SIGINT) or SIGTERM arrives, instead of dying on it, so unsaved changes
/// can be kept.
fn wait_for_stop() {
    let handler = on_stop_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
    // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
    unsafe {
        libc::signal(libc::SIGINT, handler);
        libc::signal(libc::SIGTERM, handler);
    }
    while !STOP.load(std::sync::atomic::Ordering::SeqCst) {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// Asks the desktop to open `url`; a failure is only a note (the URL is printed).
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(windows) {
        "explorer"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(opener).arg(url).spawn() {
        eprintln!("note: could not open a browser ({opener}: {e}); open the URL above");
    }
}
