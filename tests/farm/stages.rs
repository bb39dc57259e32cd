//! A resubmitted shot redoes no finished stage (docs/farm.md, "Resume"): the views stage's
//! `render --lens-writer --tag --resume` skips a view whose EXR, tagged PNG and ray file are
//! finished with the same settings, and `keys` skips when its ray files are finished for the
//! same keys, views and settings; a changed setting or input, or a missing or damaged file, makes
//! them again and says why.

use super::bands::{CORNELL, run, stamp};
use crate::common::Scratch;
use std::path::PathBuf;

type Stamp = (u64, i64);

fn stamps(files: &[PathBuf]) -> Vec<Stamp> {
    files.iter().map(|f| stamp(f)).collect()
}

/// Runs `command` twice: the first run makes `files` without redoing anything, the second skips
/// them (saying `skipped` and "skipped") and leaves them untouched; returns their stamps.
#[track_caller]
fn made_then_skipped(command: &dyn Fn() -> (bool, String), files: &[PathBuf], skipped: &str) -> Vec<Stamp> {
    let (ok, err) = command();
    assert!(ok && !["skipped", "re-rendering", "again"].iter().any(|w| err.contains(w)), "{err}");
    let first = stamps(files);
    std::thread::sleep(std::time::Duration::from_millis(20));
    let (ok, err) = command();
    assert!(ok && err.contains(skipped) && err.contains("skipped"), "{err}");
    assert_eq!(stamps(files), first, "an unchanged stage is not done again");
    first
}

#[test]
fn views_and_keys_skip_what_is_finished_and_redo_what_changed() {
    let dir = Scratch::new("farm-stages");
    let views = dir.s("views");
    let view = |spp: &str| {
        run(&[
            "render",
            CORNELL,
            "--res",
            "16x10",
            "--spp",
            spp,
            "--max-depth",
            "2",
            "--lens-writer",
            "--tag",
            "--resume",
            "--out",
            &views,
        ])
    };
    let files: Vec<PathBuf> =
        ["exr", "png", "mcr"].iter().map(|e| dir.path(&format!("views/frame0000camera01.{e}"))).collect();
    let view_stamps = || stamps(&files);
    let first = made_then_skipped(&|| view("1"), &files, "view finished in");
    let (ok, err) = view("2");
    assert!(ok && err.contains("view: spp 1 ≠ 2, re-rendering"), "{err}");
    let second = view_stamps();
    assert!(second[0] != first[0] && second[1] != first[1], "the changed view is rendered again");
    std::fs::remove_file(&files[2]).unwrap();
    let (ok, err) = view("2");
    assert!(ok && err.contains("frame0000camera01.mcr is missing, re-rendering"), "{err}");
    std::fs::copy(dir.path("views/frame0000camera01.exr"), &files[1]).unwrap();
    let (ok, err) = view("2");
    assert!(ok && err.contains("frame0000camera01.png is damaged"), "{err}");

    // keys: the tagged view is a one-camera collage, keyed at frames 0 and 2.
    let (collage, lens) = (dir.s("views/frame0000camera01.png"), dir.s("lens"));
    let keys = |mode: &str| {
        let key = format!("0={collage}");
        run(&["keys", "--key", &key, "--rays", &views, "--frames", "0..=2", "--out", &lens, "--mode", mode])
    };
    let lens_files: Vec<PathBuf> =
        (0..=2).map(|f| dir.path(&format!("lens/rerender-frame{f:04}.mcr"))).collect();
    let lens_stamps = || stamps(&lens_files);
    let first = made_then_skipped(&|| keys("smooth"), &lens_files, "keys: the ray files in");
    let (ok, err) = keys("linear");
    assert!(ok && err.contains("keys: mode Smooth ≠ Linear, making them again"), "{err}");
    assert!(lens_stamps().iter().zip(&first).all(|(a, b)| a != b), "changed keys are made again");
    // A view rendered again at another spp changes the collage's pixels: an input.
    let (ok, err) = view("3");
    assert!(ok, "{err}");
    let (ok, err) = keys("linear");
    assert!(ok && err.contains(&format!("keys: input {collage} ")), "{err}");
    std::fs::write(&lens_files[1], b"not rays").unwrap();
    let (ok, err) = keys("linear");
    assert!(ok && err.contains("rerender-frame0001.mcr is damaged"), "{err}");
    let (ok, err) = keys("linear");
    assert!(ok && err.contains("skipped"), "{err}");
}
