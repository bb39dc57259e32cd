//! Render-farm building blocks through the real command line (docs/farm.md, "Bands and resume"):
//!
//! - `render --tile I/N` and `rerender --tile I/N`, merged by `merge`, equal the single run bit
//!   for bit — every layer's pixels, the PNG's bytes, the header but the seconds — for several
//!   N, bands of one row and more bands than rows included, with adaptive sampling and a crop;
//! - `merge` refuses a missing, duplicate or mismatched band, naming the file;
//! - `animate` resumes safely: an unchanged frame is skipped (same inode and mtime); a changed
//!   spp, seed or lens file, or a truncated EXR, is rendered again and said so; `--check` names
//!   every bad frame and fails; two processes rendering one frame at once leave one valid file;
//! - every failure exits non-zero with the error.
//!
//! Commands whose exit status and messages matter run in a child process: this test binary
//! re-executed with the ignored test [`super::cli_entry`] selected, which runs the command line
//! in-process and exits as `mcctrace` does (status 1 and `error: …` on stderr).

use crate::common::{Scratch, mcctrace};
use std::os::unix::fs::MetadataExt;
use std::path::Path;
use std::process::Command;
use tracer::image_io::{ExrImage, read_exr};

const CORNELL: &str = "scenes/cornell/cornell.gltf";
/// A started child running `args`.
fn spawn(args: &[&str]) -> std::process::Child {
    Command::new(std::env::current_exe().unwrap())
        .args(["farm::cli_entry", "--exact", "--ignored", "--nocapture", "--test-threads=1", "-q"])
        .env(super::ENV_ARGS, args.join("\u{1f}"))
        .env("RAYON_NUM_THREADS", "2")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Runs `args` in a child: (succeeded, stderr).
fn run(args: &[&str]) -> (bool, String) {
    let out = spawn(args).wait_with_output().unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Header keys whose values may differ between a merged image and a single run.
const TIMING: &[&str] = &["mcctrace/seconds"];

/// Work counters: with `--crop`, a single run also traces the border rows above and below the
/// output, which no band renders (docs/farm.md, "Bands and resume"), so the merged counts are
/// smaller; the pixels are the same.
const WORK: &[&str] = &["mcctrace/rays", "mcctrace/samples"];

#[track_caller]
fn assert_same_image(merged: &Path, single: &Path, what: &str) {
    assert_same_image_but(merged, single, &[], what);
}

/// [`assert_same_image`] with the header keys `skipped` compared as counts no larger than the
/// single run's instead of as equal.
#[track_caller]
fn assert_same_image_but(merged: &Path, single: &Path, skipped: &[&str], what: &str) {
    let (a, b): (ExrImage, ExrImage) = (read_exr(merged).unwrap(), read_exr(single).unwrap());
    let bits = |p: &[glam::Vec3]| p.iter().flat_map(|v| v.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!((a.rgb.width, a.rgb.height), (b.rgb.width, b.rgb.height), "{what}: size");
    assert!(bits(&a.rgb.pixels) == bits(&b.rgb.pixels), "{what}: beauty pixels differ");
    assert_eq!(a.layers.keys().collect::<Vec<_>>(), b.layers.keys().collect::<Vec<_>>(), "{what}: layers");
    for (name, layer) in &a.layers {
        assert!(format!("{layer:?}") == format!("{:?}", b.layers[name]), "{what}: layer {name} differs");
    }
    let header = |e: &ExrImage| {
        e.metadata
            .iter()
            .filter(|(k, _)| !TIMING.contains(&k.as_str()) && !skipped.contains(&k.as_str()))
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(header(&a), header(&b), "{what}: header apart from the seconds");
    for key in skipped {
        let count = |e: &ExrImage| -> u64 { e.metadata[*key].parse().unwrap() };
        assert!(0 < count(&a) && count(&a) <= count(&b), "{what}: {key} {} against {}", count(&a), count(&b));
    }
    let png = |p: &Path| std::fs::read(p.with_extension("png")).unwrap();
    assert!(png(merged) == png(single), "{what}: PNG bytes differ");
}

/// Renders every band of `n` with `command` (its output flag last) and merges them into
/// `merged`; returns nothing, panics on failure.
fn bands_then_merge(command: &[&str], out: &str, n: u32, merged: &str) {
    for i in 1..=n {
        let tile = format!("{i}/{n}");
        let mut args = command.to_vec();
        args.extend(["--out", out, "--tile", &tile, "--quiet"]);
        mcctrace(&args).unwrap_or_else(|e| panic!("band {tile}: {e:#}"));
    }
    // The bands named after `out` are found by name; merged to another file to compare.
    let bands: Vec<String> = (1..=n)
        .map(|i| tracer::job::Band { index: i, count: n }.path(Path::new(out)))
        .filter(|p| p.is_file())
        .map(|p| p.display().to_string())
        .collect();
    let mut args = vec!["merge", "--out", merged, "--quiet"];
    args.extend(bands.iter().map(String::as_str));
    mcctrace(&args).unwrap();
}

/// Renders the Cornell box's camera at `res`, 1 spp, with the lens writer into `dir/views`;
/// returns its ray file.
fn cornell_lens(dir: &Scratch, res: &str) -> String {
    let views = dir.s("views");
    mcctrace(&["render", CORNELL, "--res", res, "--spp", "1", "--lens-writer", "--out", &views, "--quiet"])
        .unwrap();
    dir.s("views/frame0000camera01.mcr")
}

#[test]
fn tiles_merge_to_the_single_render_bit_for_bit() {
    let dir = Scratch::new("farm-tiles");
    // 24 x 10 at 8 spp, adaptive (image-global counts) with every AOV layer.
    let render = [
        "render",
        CORNELL,
        "--res",
        "24x10",
        "--spp",
        "8",
        "--adaptive",
        "--aovs",
        "--max-depth",
        "2",
        "--seed",
        "3",
    ];
    let single = dir.s("single.exr");
    let mut args = render.to_vec();
    args.extend(["--out", &single, "--quiet"]);
    mcctrace(&args).unwrap();
    for n in [1, 3, 10, 13] {
        let out = dir.s(&format!("n{n}/view.exr"));
        let merged = dir.s(&format!("n{n}/merged.exr"));
        bands_then_merge(&render, &out, n, &merged);
        assert_same_image(Path::new(&merged), Path::new(&single), &format!("render in {n} bands"));
        // More bands than rows: the bands past the image wrote nothing.
        let written =
            (1..=n).filter(|&i| tracer::job::Band { index: i, count: n }.path(Path::new(&out)).is_file());
        assert_eq!(written.count() as u32, n.min(10), "{n} bands of 10 rows");
    }
    // Without band arguments, merge takes the bands named after --out.
    mcctrace(&["merge", "--out", &dir.s("n3/view.exr"), "--quiet"]).unwrap();
    assert_same_image(&dir.path("n3/view.exr"), Path::new(&single), "merge by name");

    // rerender through a lens file with a crop: bands are of the output, after the crop.
    let lens = cornell_lens(&dir, "20x12");
    let rerender =
        ["rerender", CORNELL, "--lens", &lens, "--crop", "2", "--spp", "4", "--adaptive", "--max-depth", "2"];
    let single = dir.s("re/single.exr");
    let mut args = rerender.to_vec();
    args.extend(["--out", &single, "--quiet"]);
    mcctrace(&args).unwrap();
    for n in [2, 8, 11] {
        let out = dir.s(&format!("re{n}/final.exr"));
        let merged = dir.s(&format!("re{n}/merged.exr"));
        bands_then_merge(&rerender, &out, n, &merged);
        assert_same_image_but(
            Path::new(&merged),
            Path::new(&single),
            WORK,
            &format!("rerender in {n} bands"),
        );
    }
}

#[test]
fn merge_refuses_missing_duplicate_and_mismatched_bands() {
    let dir = Scratch::new("farm-merge-refuses");
    let out = dir.s("view.exr");
    let band = |tile: &str, spp: &str| {
        mcctrace(&[
            "render",
            CORNELL,
            "--res",
            "12x6",
            "--spp",
            spp,
            "--max-depth",
            "2",
            "--out",
            &out,
            "--tile",
            tile,
            "--quiet",
        ])
        .unwrap()
    };
    band("1/3", "2");
    band("3/3", "2");
    let (b1, b2, b3) = (dir.s("view.tile1of3.exr"), dir.s("view.tile2of3.exr"), dir.s("view.tile3of3.exr"));
    let merged = dir.s("merged.exr");
    let (ok, err) = run(&["merge", "--out", &merged, &b1, &b3]);
    assert!(
        !ok && err.contains("view.tile2of3.exr") && err.contains("band 2/3 (rows 2..4) is missing"),
        "{err}"
    );
    let (ok, err) = run(&["merge", "--out", &merged, &b1, &b3, &b1]);
    assert!(!ok && err.contains("band 1/3 is given twice"), "{err}");
    band("2/3", "4");
    let (ok, err) = run(&["merge", "--out", &merged, &b1, &b2, &b3]);
    assert!(!ok && err.contains(&b2) && err.contains("spp 4 ≠ 2"), "{err}");
    assert!(
        !Path::new(&merged).exists() && !dir.path("merged.png").exists(),
        "a refused merge writes nothing"
    );
    // The stale band is re-rendered, and said so, when its task runs again with the settings.
    let (ok, err) = run(&[
        "render",
        CORNELL,
        "--res",
        "12x6",
        "--spp",
        "2",
        "--max-depth",
        "2",
        "--out",
        &out,
        "--tile",
        "2/3",
    ]);
    assert!(ok && err.contains("band 2/3: spp 4 ≠ 2, re-rendering"), "{err}");
    mcctrace(&["merge", "--out", &merged, &b1, &b2, &b3, "--quiet"]).unwrap();
    let (ok, err) = run(&["merge", "--out", &merged, &dir.s("merged.png")]);
    assert!(!ok && err.contains("merged.png"), "{err}");
}

/// (inode, mtime in ns) of `path`.
fn stamp(path: &Path) -> (u64, i64) {
    let m = std::fs::metadata(path).unwrap();
    (m.ino(), m.mtime() * 1_000_000_000 + m.mtime_nsec())
}

#[test]
fn animate_resumes_only_what_is_finished_with_the_same_settings() {
    let dir = Scratch::new("farm-resume");
    let rays = cornell_lens(&dir, "16x8");
    std::fs::create_dir_all(dir.path("lens")).unwrap();
    for f in 0..=2 {
        std::fs::copy(&rays, dir.path(&format!("lens/rerender-frame{f:04}.mcr"))).unwrap();
    }
    let (lens, out) = (dir.s("lens"), dir.s("frames"));
    let animate = |extra: &[&str]| {
        let mut args = vec![
            "animate",
            CORNELL,
            "--lens-dir",
            &lens,
            "--frames",
            "0..=2",
            "--out",
            &out,
            "--max-depth",
            "2",
        ];
        args.extend(extra);
        run(&args)
    };
    let frame = |f: u32| dir.path(&format!("frames/frame{f:04}.exr"));
    let (ok, err) = animate(&["--spp", "2", "--preview", "none"]);
    assert!(ok, "{err}");
    let stamps: Vec<_> = (0..=2).map(|f| stamp(&frame(f))).collect();
    std::thread::sleep(std::time::Duration::from_millis(20));
    let (ok, err) = animate(&["--spp", "2", "--preview", "none"]);
    assert!(ok && err.contains("3 of 3 frames already finished"), "{err}");
    assert_eq!((0..=2).map(|f| stamp(&frame(f))).collect::<Vec<_>>(), stamps, "unchanged frames untouched");

    // Another spp or seed: every frame again, said so.
    let (ok, err) = animate(&["--spp", "3", "--preview", "none"]);
    assert!(ok && (0..=2).all(|f| err.contains(&format!("frame {f}: spp 2 ≠ 3, re-rendering"))), "{err}");
    let (ok, err) = animate(&["--spp", "3", "--seed", "5", "--preview", "none"]);
    assert!(ok && err.contains("frame 1: seed 0 ≠ 5, re-rendering"), "{err}");
    let stamps: Vec<_> = (0..=2).map(|f| stamp(&frame(f))).collect();
    // A changed lens file re-renders its frame only; a truncated EXR is damaged.
    let mut rays = mcc::RayFile::read(&dir.path("lens/rerender-frame0001.mcr")).unwrap();
    rays.rays.reverse();
    rays.write(&dir.path("lens/rerender-frame0001.mcr"), mcc::RayFormat::Binary).unwrap();
    let bytes = std::fs::read(frame(2)).unwrap();
    std::fs::write(frame(2), &bytes[..bytes.len() - 100]).unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    let (ok, err) = animate(&["--spp", "3", "--seed", "5", "--preview", "none"]);
    assert!(
        ok && err.contains("frame 1: rays_sha256 ")
            && err.contains("frame 2: ")
            && err.contains("is damaged"),
        "{err}"
    );
    assert!(!err.contains("frame 0:"), "{err}");
    assert_eq!(stamp(&frame(0)), stamps[0], "frame 0 untouched");
    assert!(stamp(&frame(1)) != stamps[1] && read_exr(&frame(2)).is_ok(), "frames 1 and 2 rendered again");

    // --check names every bad frame and fails; once mended it passes and writes the preview.
    std::fs::remove_file(dir.path("frames/frame0000.png")).unwrap();
    let bytes = std::fs::read(frame(2)).unwrap();
    std::fs::write(frame(2), &bytes[..bytes.len() / 2]).unwrap();
    let (ok, err) = animate(&["--spp", "3", "--seed", "5", "--check"]);
    assert!(!ok && err.contains("frame 0: ") && err.contains("frame0000.png is missing"), "{err}");
    assert!(
        err.contains("frame 2: ") && err.contains("error: 2 of 3 frames") && err.contains(": 0, 2"),
        "{err}"
    );
    assert!(!err.contains("frame 1:") && !dir.path("frames/preview.gif").exists(), "{err}");
    let (ok, err) = animate(&["--spp", "3", "--seed", "4", "--check"]);
    assert!(!ok && err.contains("frame 1: seed 5 ≠ 4"), "{err}");
    let (ok, err) = animate(&["--spp", "3", "--seed", "5", "--preview", "none"]);
    assert!(ok, "{err}");
    let (ok, err) = animate(&["--spp", "3", "--seed", "5", "--check"]);
    assert!(ok && dir.path("frames/preview.gif").is_file(), "{err}");
}

#[test]
fn two_processes_rendering_one_frame_leave_one_valid_file() {
    let dir = Scratch::new("farm-race");
    let rays = cornell_lens(&dir, "24x12");
    std::fs::create_dir_all(dir.path("lens")).unwrap();
    std::fs::copy(&rays, dir.path("lens/rerender-frame0000.mcr")).unwrap();
    let (lens, out) = (dir.s("lens"), dir.s("frames"));
    let args = [
        "animate",
        CORNELL,
        "--lens-dir",
        &lens,
        "--frames",
        "0..=0",
        "--out",
        &out,
        "--spp",
        "16",
        "--preview",
        "none",
        "--quiet",
    ];
    let children = [spawn(&args), spawn(&args)];
    for child in children {
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    let mut names: Vec<String> = std::fs::read_dir(dir.path("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["frame0000.exr", "frame0000.png"], "one frame, no temporary files");
    let single = dir.s("single.exr");
    let lens_file = dir.s("lens/rerender-frame0000.mcr");
    mcctrace(&["rerender", CORNELL, "--lens", &lens_file, "--spp", "16", "--out", &single, "--quiet"])
        .unwrap();
    let (a, b) =
        (read_exr(&dir.path("frames/frame0000.exr")).unwrap(), read_exr(Path::new(&single)).unwrap());
    assert!(a.rgb.pixels == b.rgb.pixels, "the frame is whole and the render's");
}

#[test]
fn failures_exit_non_zero_with_the_error() {
    let dir = Scratch::new("farm-failures");
    let cases: [(&[&str], &str); 4] = [
        (&["render", "no-such-scene.gltf", "--out", &dir.s("x.exr"), "--tile", "1/2"], "no-such-scene.gltf"),
        (&["render", CORNELL, "--out", &dir.s("x.exr"), "--tile", "3/2"], "tile"),
        (
            &[
                "animate",
                CORNELL,
                "--lens-dir",
                &dir.s("none"),
                "--frames",
                "0..=1",
                "--out",
                &dir.s("f"),
                "--check",
            ],
            "--lens-dir",
        ),
        (&["merge", "--out", &dir.s("nothing.exr")], "no band files"),
    ];
    for (args, needle) in cases {
        let (ok, err) = run(args);
        assert!(!ok && err.contains(needle), "{args:?}: {err}");
    }
}
