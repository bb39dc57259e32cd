//! What a user hit in a week of use (issue 41: items 2–4 and 8–12), through the real `mcctrace`
//! command line: in-process where only the files matter, in a child process
//! (`common::child`) where what it prints is the point. Each test failed before its fix.

use crate::common::child;
use crate::common::{Scratch, mcctrace, repo_root};
use mcc::image::{self, DynamicImage};
use std::collections::BTreeMap;
use std::path::Path;
use tracer::image_io::read_exr;

/// The views' size.
const W: u32 = 40;
const H: u32 = 24;
const RES: &str = "40x24";

/// The Cornell box as OBJ with its camera list: cameras 1 `cornell` and 2 `corner`.
fn cornell() -> (String, String) {
    let dir = repo_root().join("scenes/cornell");
    (dir.display().to_string(), dir.join("cameras.json").display().to_string())
}

/// Renders both listed cameras into `views/` with the lens writer and, if `tag`, the tagger and
/// `--layers views.ora`.
fn render_views(dir: &Scratch, out: &str, tag: bool) {
    let (scene, cameras) = cornell();
    let mut args =
        vec!["render", &scene, "--cameras-file", &cameras, "--camera", "cornell", "--camera", "corner"];
    args.extend(["--res", RES, "--spp", "1", "--max-depth", "2", "--threads", "2", "--lens-writer", "-q"]);
    let (ora, out) = (dir.s("views.ora"), dir.s(out));
    if tag {
        args.extend(["--tag", "--layers", &ora]);
    }
    args.extend(["--out", &out]);
    mcctrace(&args).unwrap();
}

/// The views and a collage of them: camera 1 on the left, camera 2 on the right, a black band
/// between them to blend.
fn views_and_collage(dir: &Scratch) -> String {
    render_views(dir, "views", true);
    let mask = image::RgbImage::from_fn(W, H, |x, _| {
        image::Rgb(match x {
            0..16 => [255, 0, 0],
            16..24 => [0, 0, 0],
            _ => [0, 255, 0],
        })
    });
    mask.save(dir.path("mask.png")).unwrap();
    let collage = dir.s("collage.png");
    mcctrace(&["collage", "--mask", &dir.s("mask.png"), "--views", &dir.s("views"), "--out", &collage])
        .unwrap();
    collage
}

/// The `mcctrace/…` header of an EXR.
fn header(path: &Path) -> BTreeMap<String, String> {
    read_exr(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).metadata
}

/// Item 12: the demo wrote `collage-mask.png` (and the animation `keyFFFF-mask.png` and key 0's
/// regions) without listing them. Every file it writes at the top of its folder is listed.
#[test]
fn the_demo_lists_every_file_it_writes() {
    let dir = Scratch::new("week-demo-list");
    let still = ["demo", "--res", "48x27", "--spp", "1", "--threads", "2", "-q", "--out"];
    let animation = [
        "demo",
        "--animation",
        "--res",
        "48x27",
        "--spp",
        "1",
        "--frames",
        "2",
        "--frame-res",
        "24x14",
        "--frame-spp",
        "1",
        "--threads",
        "2",
        "-q",
        "--out",
    ];
    for (args, out) in [(&still[..], dir.s("still")), (&animation[..], dir.s("animation"))] {
        let run = child::run(&[args, &[out.as_str()]].concat());
        assert!(run.ok, "{run:?}");
        let mut files = 0;
        for entry in std::fs::read_dir(&out).unwrap() {
            let path = entry.unwrap().path();
            if path.is_file() {
                files += 1;
                assert!(
                    run.stdout.contains(&path.display().to_string()),
                    "{} not listed:\n{}",
                    path.display(),
                    run.stdout
                );
            }
        }
        assert!(files >= 4, "{files} files in {out}");
    }
}
