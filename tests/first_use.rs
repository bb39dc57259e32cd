//! What a first-time user hit (issue 27, part 2), through the real `mcctrace` command line run
//! in-process: the demo at a size other than its mask's, and an overscanned shot finished inside
//! the tool by `rerender`, `keys`, `inbetween` and `animate` with `--crop`, where `--res` is the
//! size after the crop; the EXR headers say how each picture was made (docs/design/tracer.md §3.6).

use crate::common::{CORNELL_SECOND_VIEW, Scratch, mcctrace};
use std::path::Path;
use tracer::image_io::read_exr;

const CORNELL: &str = "scenes/cornell/cornell.gltf";
/// The views' picture size, and the overscan border around it.
const W: u32 = 40;
const H: u32 = 24;
const BORDER: u32 = 4;

/// Width, height and the `mcctrace/…` header of an EXR.
fn exr(path: &str) -> (u32, u32, std::collections::BTreeMap<String, String>) {
    let e = read_exr(Path::new(path)).unwrap_or_else(|err| panic!("{path}: {err}"));
    (e.rgb.width, e.rgb.height, e.metadata)
}

/// `demo --res 160x90` once failed after rendering both views ("camera 1's tagged view is
/// 160x90, but …/collage-mask.png is 480x270"): the bundled mask is scaled to any size.
#[test]
fn the_demo_runs_at_any_resolution() {
    let dir = Scratch::new("first-use-demo");
    let out = dir.s("demo");
    mcctrace(&["demo", "--res", "160x90", "--spp", "1", "--threads", "2", "-q", "--out", &out]).unwrap();
    let (w, h, _) = exr(&dir.s("demo/final.exr"));
    assert_eq!((w, h), (160, 90));
    let mask = mcc::image::open(dir.path("demo/collage-mask.png")).unwrap();
    assert_eq!((mask.width(), mask.height()), (160, 90));
    let (_, _, view) = exr(&dir.s("demo/views/frame0000camera01.exr"));
    assert!(view["mcctrace/projection"].starts_with("perspective fov_y="), "{view:?}");
}

/// Two overscanned views of the Cornell box, a collage of them (camera 1 left, 2 right).
fn overscanned_views(dir: &Scratch) -> String {
    let (res, border) = (format!("{W}x{H}"), BORDER.to_string());
    let quick = [
        "--res",
        &res,
        "--overscan",
        &border,
        "--spp",
        "1",
        "--threads",
        "2",
        "--lens-writer",
        "--tag",
        "-q",
    ];
    let views = dir.s("views");
    let mut one = vec!["render", CORNELL];
    one.extend(quick);
    mcctrace(&[&one[..], &["--out", &views]].concat()).unwrap();
    let mut two = vec!["render", CORNELL];
    two.extend(CORNELL_SECOND_VIEW);
    two.extend(["--first-id", "2"]);
    two.extend(quick);
    mcctrace(&[&two[..], &["--out", &views]].concat()).unwrap();
    let (fw, fh) = (W + 2 * BORDER, H + 2 * BORDER);
    let mask = mcc::image::RgbImage::from_fn(fw, fh, |x, _| {
        mcc::image::Rgb(if x < fw / 2 { [255, 0, 0] } else { [0, 255, 0] })
    });
    mask.save(dir.path("mask.png")).unwrap();
    let collage = dir.s("collage.png");
    mcctrace(&["collage", "--mask", &dir.s("mask.png"), "--views", &views, "--out", &collage]).unwrap();
    collage
}

/// `rerender --crop 8 --res 320x180` from 176x106 views once wrote 290x150: --res is the
/// output after the crop. `keys`, `inbetween` and `animate` crop too, and the headers record
/// the collage, lens file or lens folder, the shutter, rr_depth and --adaptive.
#[test]
fn an_overscanned_shot_finishes_inside_the_tool() {
    let dir = Scratch::new("first-use-crop");
    let collage = overscanned_views(&dir);
    let (views, border) = (dir.s("views"), BORDER.to_string());
    let quick = ["--spp", "1", "--threads", "2", "-q"];

    let out = dir.s("rerender/final.exr");
    let args =
        ["rerender", CORNELL, "--collage", &collage, "--rays", &views, "--crop", &border, "--res", "80x48"];
    mcctrace(&[&args[..], &quick, &["--adaptive", "--out", &out]].concat()).unwrap();
    let (w, h, header) = exr(&out);
    assert_eq!((w, h), (80, 48));
    assert_eq!(header["mcctrace/collage"], collage);
    assert_eq!(header["mcctrace/adaptive"], "true");
    assert!(header.contains_key("mcctrace/rr_depth") && header["mcctrace/shutter"] == "0..0", "{header:?}");
    let rays = dir.s("rerender/final.mcr");
    let out = dir.s("lens-file/final.exr");
    mcctrace(
        &[&["rerender", CORNELL, "--lens", &rays, "--crop", &border][..], &quick, &["--out", &out]].concat(),
    )
    .unwrap();
    let (w, h, header) = exr(&out);
    assert_eq!((w, h, header["mcctrace/lens_file"].as_str()), (W, H, rays.as_str()));

    // keys: the remapped key loses its border before in-betweening.
    let lens = dir.s("keys");
    let key = format!("0={collage}");
    mcctrace(&[
        "keys", "--key", &key, "--rays", &views, "--crop", &border, "--frames", "0..=1", "-q", "--out", &lens,
    ])
    .unwrap();
    let key_rays = mcc::RayFile::read(&dir.path("keys/rerender-frame0001.mcr")).unwrap();
    assert_eq!((key_rays.width, key_rays.height), (W, H));
    // inbetween: the same from the uncropped ray file.
    let between = dir.s("between");
    let key = format!("0={rays}");
    mcctrace(&["inbetween", "--key", &key, "--crop", &border, "--frames", "0..=1", "-q", "--out", &between])
        .unwrap();
    let cropped = mcc::RayFile::read(&dir.path("between/rerender-frame0001.mcr")).unwrap();
    assert_eq!(cropped.rays, key_rays.rays);
    // animate: uncropped per-frame rays, cropped in the render, at --res after the crop.
    let uncropped = dir.s("uncropped");
    mcctrace(&["inbetween", "--key", &key, "--frames", "0..=1", "-q", "--out", &uncropped]).unwrap();
    let frames = dir.s("frames");
    let args = ["animate", CORNELL, "--lens-dir", &uncropped, "--frames", "0..=1", "--crop", &border];
    mcctrace(
        &[
            &args[..],
            &quick,
            &["--res", "20x12", "--shutter", "0..0.5", "--preview", "none", "--out", &frames],
        ]
        .concat(),
    )
    .unwrap();
    let (w, h, header) = exr(&dir.s("frames/frame0001.exr"));
    assert_eq!((w, h), (20, 12));
    assert_eq!(
        (header["mcctrace/lens_dir"].as_str(), header["mcctrace/shutter"].as_str()),
        (uncropped.as_str(), "0..0.5")
    );
    let err = mcctrace(
        &[&args[..4], &["--frames", "0..=1", "--crop", "16"], &quick, &["--out", &dir.s("none")]].concat(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("--crop 16 leaves nothing of a 48x32 image"), "{err}");
}
