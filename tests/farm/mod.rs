//! Render-farm jobs run by real schedulers (docs/farm.md, "Schedulers"): a small café shot (keys
//! at frames 0 and 11, two cameras each, twelve 64×36 frames) written by `mcctrace farm` and
//!
//! - submitted to a one-node Slurm cluster (`.ci/slurm.sh` starts it) with `farm slurm
//!   --submit`: every frame equals, bit for bit, a local `keys` + `animate` of the same shot; then
//!   again with one chunk cancelled midway (`scancel`), and a resubmission completes the shot
//!   without touching the frames already finished (same inode, same modification time);
//! - as an Open Job Description template: `openjd check` accepts it and `openjd run` runs the
//!   whole job locally to the same frames;
//! - one big still cut into bands and merged, on both (`still`); finished views and keys
//!   skipped by a resubmission (`stages`).
//!
//! The scheduler's tasks run the `mcctrace` program: here a small wrapper script that re-runs
//! this test binary on [`cli_entry`] (the root package has no binary target, and a guessed path
//! under the target folder could be a stale build; see `bad_inputs`).

mod bands;
mod checks;
mod cluster;
mod stages;
mod still;

use crate::common::external::external;
use crate::common::{Scratch, mcctrace, repo_root};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Environment variable carrying the wrapper's arguments (separated by U+001F).
pub(crate) const ENV_ARGS: &str = "MCCTRACE_FARM_ARGS";

/// Runs `mcctrace` with the arguments the wrapper passed and exits with its status: the
/// scheduler's tasks run this (ignored: not a test of its own).
#[test]
#[ignore = "the farm tests' mcctrace program; runs only when the wrapper selects it"]
fn cli_entry() {
    let Some(args) = std::env::var_os(ENV_ARGS) else { return };
    let args = args.to_string_lossy().into_owned();
    let words = args.split('\x1f').filter(|w| !w.is_empty());
    let code = match mcctrace_cli::try_run(std::iter::once("mcctrace").chain(words)) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e:#}");
            1
        }
    };
    std::process::exit(code);
}

/// Writes the `mcctrace` wrapper into `dir`: it re-runs this test binary on [`cli_entry`].
fn wrapper(dir: &Path) -> PathBuf {
    let me = std::env::current_exe().expect("the test binary's path");
    let path = dir.join("mcctrace");
    let quoted = format!("'{}'", me.display().to_string().replace('\'', r"'\''"));
    let body = format!(
        "#!/bin/sh\n# mcctrace for the farm tests: this test binary, on farm::cli_entry.\n\
         {ENV_ARGS}=\"$(printf '%s\\037' \"$@\")\" exec {quoted} farm::cli_entry --exact --ignored --nocapture --quiet \
         --test-threads 1\n"
    );
    std::fs::write(&path, body).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

/// The café, its key cameras, and the shot's settings (shared by the local reference and the
/// farm command).
const CAFE: &str = "scenes/cafe/cafe.gltf";
const KEYS: [(u32, [&str; 2]); 2] = [(0, ["left", "right"]), (11, ["wide", "right"])];
const FRAMES: &str = "0..=11";
const RES: &str = "64x36";
const VIEW_SPP: &str = "4";

/// A shot ready to farm: collages cut from locally rendered views (a label image per key: camera
/// 1 on the left, camera 2 on the right, a black band between them to blend), and the reference
/// frames of a local `keys` + `animate` at `spp`.
struct Shot {
    scratch: Scratch,
    spp: String,
}

impl Shot {
    fn new(name: &str, spp: u32) -> Self {
        let scratch = Scratch::new(name);
        let s = Self { scratch, spp: spp.to_string() };
        let scene = repo_root().join(CAFE).display().to_string();
        let views = s.scratch.s("local/views");
        for (frame, cameras) in KEYS {
            let f = frame.to_string();
            let mut args = vec![
                "render",
                scene.as_str(),
                "--frame",
                f.as_str(),
                "--lens-writer",
                "--tag",
                "--out",
                views.as_str(),
            ];
            args.extend(["--res", RES, "--spp", VIEW_SPP, "--quiet"]);
            for c in cameras {
                args.extend(["--camera", c]);
            }
            mcctrace(&args).unwrap();
            let mask = s.scratch.path(&format!("mask{frame}.png"));
            let labels = image::RgbImage::from_fn(64, 36, |x, _| match x {
                0..28 => image::Rgb([255, 0, 0]),
                28..36 => image::Rgb([0, 0, 0]),
                _ => image::Rgb([0, 255, 0]),
            });
            labels.save(&mask).unwrap();
            let collage = s.collage(frame);
            mcctrace(&[
                "collage",
                "--mask",
                mask.to_str().unwrap(),
                "--views",
                &views,
                "--frame",
                &f,
                "--out",
                &collage,
            ])
            .unwrap();
        }
        let lens = s.scratch.s("local/lens");
        let mut keys = vec!["keys".to_owned()];
        for (frame, _) in KEYS {
            keys.extend(["--key".into(), format!("{frame}={}", s.collage(frame))]);
        }
        keys.extend(
            ["--rays", &views, "--frames", FRAMES, "--out", &lens, "--res", RES, "--quiet"].map(String::from),
        );
        mcctrace(&keys.iter().map(String::as_str).collect::<Vec<_>>()).unwrap();
        let out = s.scratch.s("local/frames");
        mcctrace(&[
            "animate",
            &scene,
            "--lens-dir",
            &lens,
            "--frames",
            FRAMES,
            "--out",
            &out,
            "--res",
            RES,
            "--spp",
            &s.spp,
            "--quiet",
        ])
        .unwrap();
        s
    }

    /// The collage of the key at `frame` (its name has a space: paths are quoted all the way).
    fn collage(&self, frame: u32) -> String {
        self.scratch.s(&format!("collage {frame}.png"))
    }

    /// `mcctrace farm SCHEDULER …` of this shot into `dir`, run by `program` (the wrapper).
    fn farm_args(&self, scheduler: &str, dir: &Path, program: &Path) -> Vec<String> {
        let mut a: Vec<String> =
            vec!["farm".into(), scheduler.into(), repo_root().join(CAFE).display().to_string()];
        for (frame, cameras) in KEYS {
            a.extend(["--key".into(), format!("{frame}={}", self.collage(frame))]);
            a.extend(["--cameras".into(), format!("{frame}={}", cameras.join(","))]);
        }
        let dir = dir.display().to_string();
        let program = program.display().to_string();
        a.extend(
            [
                "--frames",
                FRAMES,
                "--dir",
                &dir,
                "--chunk",
                "5",
                "--view-res",
                RES,
                "--view-spp",
                VIEW_SPP,
                "--spp",
                &self.spp,
            ]
            .map(String::from),
        );
        a.extend(["--cpus-per-task", "1", "--mcctrace", program.as_str()].map(String::from));
        a
    }

    /// Every frame in `frames` equals the local render: the EXR's pixels bit for bit (its header
    /// names the folders, which differ) and the PNG byte for byte.
    #[track_caller]
    fn assert_same_frames(&self, frames: &Path) {
        let local = self.scratch.path("local/frames");
        for f in 0..=11 {
            let name = format!("frame{f:04}");
            let read = |dir: &Path| {
                let path = dir.join(format!("{name}.exr"));
                tracer::image_io::read_exr_rgb(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            };
            let (a, b) = (read(&local), read(frames));
            assert_eq!((a.width, a.height), (b.width, b.height), "{name}");
            let bits = |i: &tracer::image::RgbImage| {
                i.pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect::<Vec<_>>()
            };
            assert!(bits(&a) == bits(&b), "{name}.exr: the farm's pixels differ from the local render's");
            let png = |dir: &Path| std::fs::read(dir.join(format!("{name}.png"))).unwrap();
            assert!(png(&local) == png(frames), "{name}.png differs from the local render's");
        }
    }
}

/// Prints every log the tasks wrote (for a failure's message).
fn print_logs(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir.join("logs")) else { return };
    let mut paths: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
    paths.sort();
    for p in paths {
        eprintln!("===== {}\n{}", p.display(), std::fs::read_to_string(&p).unwrap_or_default());
    }
}

/// The shot on a real Slurm: submitted, waited for, the same frames; then cancelled midway and
/// resubmitted, finished frames untouched.
#[test]
fn slurm_renders_the_shot_and_resumes_after_a_cancelled_chunk() {
    let Some(cluster) = cluster::Cluster::find() else { return };
    let shot = Shot::new("farm-slurm", 48);
    let program = wrapper(shot.scratch.dir());

    // 1. The whole shot.
    let dir = shot.scratch.path("farm one");
    let jobs = cluster.submit(&program, &shot.farm_args("slurm", &dir, &program));
    assert_eq!(jobs.len(), 4, "four stages: {jobs:?}");
    cluster.wait(&jobs, &dir);
    cluster.assert_completed(&jobs, &dir);
    shot.assert_same_frames(&dir.join("frames"));
    assert!(dir.join("frames/preview.gif").is_file(), "the check stage writes the preview");

    // 2. The first chunk (frames 0..=4) cancelled once it has finished a frame.
    let dir = shot.scratch.path("farm two");
    let jobs = cluster.submit(&program, &shot.farm_args("slurm", &dir, &program));
    let frames = dir.join("frames");
    let done = |f: u32| frames.join(format!("frame{f:04}.png")).is_file();
    cluster.cancel_when(&format!("{}_0", jobs[2].1), &jobs, &dir, || done(0) || done(1));
    cluster.wait(&jobs, &dir);
    let finished: Vec<u32> = (0..=11).filter(|&f| done(f)).collect();
    assert!(
        (0..5).any(|f| !finished.contains(&f)),
        "the cancelled chunk finished before the cancel reached it (frames {finished:?}): no midway kill was tested"
    );
    let stamp = |f: u32| bands::stamp(&frames.join(format!("frame{f:04}.exr")));
    let before: Vec<_> = finished.iter().map(|&f| (f, stamp(f))).collect();
    // The views and the key rays were finished before the cancel: the resubmission skips them.
    let made = |sub: &str| {
        let mut files: Vec<PathBuf> =
            std::fs::read_dir(dir.join(sub)).unwrap().map(|e| e.unwrap().path()).collect();
        files.sort();
        files.into_iter().map(|p| (bands::stamp(&p), p)).collect::<Vec<_>>()
    };
    let (views, lens) = (made("views"), made("lens"));
    assert!(
        views.len() >= 12 && lens.len() == 13,
        "4 views × (EXR, PNG, rays); 12 frames' rays and the record"
    );
    let again = cluster.submit(&program, &shot.farm_args("slurm", &dir, &program));
    cluster.wait(&again, &dir);
    cluster.assert_completed(&again, &dir);
    shot.assert_same_frames(&frames);
    assert_eq!(made("views"), views, "finished views are not rendered again");
    assert_eq!(made("lens"), lens, "finished key rays are not made again");
    for (f, s) in before {
        assert_eq!(
            stamp(f),
            s,
            "frame {f} was finished before the resubmission and must not be rendered again"
        );
    }
}

/// The template passes `openjd check`, and `openjd run` runs the whole job to the same frames.
#[test]
fn openjd_template_checks_and_runs_to_the_same_frames() {
    let Some(openjd) = external("openjd") else { return };
    let shot = Shot::new("farm-openjd", 8);
    let program = wrapper(shot.scratch.dir());
    let dir = shot.scratch.path("farm openjd");
    mcctrace(&shot.farm_args("openjd", &dir, &program).iter().map(String::as_str).collect::<Vec<_>>())
        .unwrap();
    let template = dir.join(farm::openjd::TEMPLATE_NAME);
    let run = |args: &[&str]| {
        let out = Command::new(&openjd).args(args).arg(&template).output().expect("run openjd");
        let said =
            format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert!(
            out.status.success(),
            "openjd {args:?} failed:\n{said}\n{}",
            std::fs::read_to_string(&template).unwrap()
        );
        said
    };
    run(&["check"]);
    run(&["run"]);
    shot.assert_same_frames(&dir.join("frames"));
    assert!(dir.join("frames/preview.gif").is_file(), "the check step writes the preview");
}
