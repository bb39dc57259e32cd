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

/// Item 2: `rerender` saved its rays as `rerender-frameFFFF.mcr` beside `--out`, replacing a
/// `remap --seamless` file of that name. Its rays are named after `--out` now.
#[test]
fn rerender_leaves_a_ray_file_it_did_not_make() {
    let dir = Scratch::new("week-rerender-rays");
    let collage = views_and_collage(&dir);
    let views = dir.s("views");
    let seamless = dir.s("out/rerender-frame0000.mcr");
    mcctrace(&["remap", "--collage", &collage, "--rays", &views, "--seamless", "-q", "--out", &seamless])
        .unwrap();
    let before = std::fs::read(&seamless).unwrap();
    let column = dir.s("column.mcr");
    mcctrace(&["remap", "--collage", &collage, "--rays", &views, "-q", "--out", &column]).unwrap();
    let (scene, _) = cornell();
    let out = dir.s("out/final.exr");
    let quick = ["--spp", "1", "--max-depth", "2", "--threads", "2", "-q"];
    mcctrace(
        &[&["rerender", &scene, "--collage", &collage, "--rays", &views][..], &quick, &["--out", &out]]
            .concat(),
    )
    .unwrap();
    assert_eq!(std::fs::read(&seamless).unwrap(), before, "rerender replaced the seamless ray file");
    let saved = mcc::RayFile::read(&dir.path("out/final.mcr")).expect("the rays named after --out");
    assert_eq!(saved.rays, mcc::RayFile::read(Path::new(&column)).unwrap().rays);
    assert_ne!(std::fs::read(dir.path("out/final.mcr")).unwrap(), before);
}

/// Item 3: `animate --shutter` rendered the last frame sharp (no next frame's rays to blend)
/// while its header recorded the shutter. Now one warning names the frame and the header says
/// what the blur did; a second run finds both frames finished.
#[test]
fn a_shutter_without_the_next_rays_says_so() {
    let dir = Scratch::new("week-shutter");
    render_views(&dir, "views", false);
    let (lens, frames) = (dir.s("lens"), dir.s("frames"));
    let (k0, k1) = (
        format!("0={}", dir.s("views/frame0000camera01.mcr")),
        format!("1={}", dir.s("views/frame0000camera02.mcr")),
    );
    mcctrace(&["inbetween", "--key", &k0, "--key", &k1, "--frames", "0..=1", "-q", "--out", &lens]).unwrap();
    let (scene, _) = cornell();
    let args = [
        "animate",
        &scene,
        "--lens-dir",
        &lens,
        "--frames",
        "0..=1",
        "--shutter",
        "0..0.5",
        "--spp",
        "1",
        "--max-depth",
        "2",
        "--threads",
        "2",
        "--preview",
        "none",
        "--out",
        &frames,
    ];
    let run = child::run(&args);
    assert!(run.ok, "{run:?}");
    let warnings: Vec<&str> = run.stderr.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{}", run.stderr);
    for want in
        // The camera-ray part alone: moving geometry blurs without the next frame.
        [
            "--shutter 0..0.5",
            "frame 1 has no next frame's ray file",
            "rerender-frame0002.mcr",
            "the camera's rays hold over the shutter",
            "moving geometry still blurs",
        ]
    {
        assert!(warnings[0].contains(want), "{want:?} not in {}", warnings[0]);
    }
    let (h0, h1) = (header(&dir.path("frames/frame0000.exr")), header(&dir.path("frames/frame0001.exr")));
    assert_eq!(h0["mcctrace/ray_blur"], "frames 0 and 1");
    assert!(h1["mcctrace/ray_blur"].starts_with("none: no ray file for frame 2"), "{h1:?}");
    assert_eq!(h1["mcctrace/shutter"], "0..0.5");
    let again = child::run(&args);
    assert!(again.ok && again.stderr.contains("2 of 2 frames already finished"), "{again:?}");
    assert!(!again.stderr.contains("warning:"), "{}", again.stderr);
}

/// Item 4: a visible layer hidden under an opaque one, and a collage with no background pixel,
/// went without a word. The unedited `render --layers` file is both: its top view covers all.
#[test]
fn a_layer_that_takes_no_pixel_is_named() {
    let dir = Scratch::new("week-hidden-layer");
    render_views(&dir, "views", true);
    let args =
        ["remap", "--collage", &dir.s("views.ora"), "--rays", &dir.s("views"), "--out", &dir.s("r.mcr")];
    let run = child::run(&args);
    assert!(run.ok, "{run:?}");
    let said = |want: &[&str]| {
        assert!(
            run.stderr.lines().any(|l| l.starts_with("warning:") && want.iter().all(|w| l.contains(w))),
            "no warning with {want:?}:\n{}",
            run.stderr
        )
    };
    said(&[
        "layer \"corner (camera 2)\" is visible",
        "(\"cornell (camera 1)\") cover every pixel",
        "takes no pixel",
    ]);
    said(&["layer \"background\" is visible", "takes no pixel"]);
    said(&["views.ora", "has no background pixel", "nothing is blended"]);
}

/// Item 8: an untagged picture, a JPEG or a resampled collage got a list of 61 camera ids and
/// advice about tag widths and views to render. Now two lines say what the file is and how to
/// make a collage that works.
#[test]
fn an_untagged_jpeg_or_resampled_collage_says_what_it_is() {
    let dir = Scratch::new("week-untagged");
    render_views(&dir, "views", true);
    render_views(&dir, "plain", false);
    let tagged = image::open(dir.path("views/frame0000camera01.png")).unwrap();
    tagged.to_rgb8().save_with_format(dir.path("collage.jpg"), image::ImageFormat::Jpeg).unwrap();
    let small = tagged.resize_exact(30, 18, image::imageops::FilterType::Triangle);
    DynamicImage::ImageRgb8(small.to_rgb8()).save(dir.path("resampled.png")).unwrap();
    let views = dir.s("views");
    for (collage, cause) in [
        (dir.s("plain/frame0000camera01.png"), "carry no camera tags"),
        (dir.s("collage.jpg"), "is a JPEG"),
        (dir.s("resampled.png"), "is 30x18 but the views are 40x24: it was resampled"),
    ] {
        let err =
            mcctrace(&["remap", "--collage", &collage, "--rays", &views, "-q", "--out", &dir.s("r.mcr")])
                .unwrap_err();
        let message = format!("{err:#}");
        let lines: Vec<&str> = message.lines().collect();
        assert_eq!(lines.len(), 2, "{message}");
        assert!(lines[0].contains(&collage) && lines[0].contains(cause), "{message}");
        assert!(lines[1].contains("`render --tag`") && lines[1].contains("hard-edged"), "{message}");
        assert!(lines[1].contains(".ora or .psd") && lines[1].contains("`render --layers`"), "{message}");
        // At most a few ids listed (`mcc::collage::LISTED_IDS`), not 61.
        assert!(message.matches('×').count() <= 4, "{message}");
        for misleading in ["--tag-bits", "cover whole areas", "render their views"] {
            assert!(!message.contains(misleading), "{misleading:?} in {message}");
        }
    }
    assert!(!dir.path("r.mcr").exists());
}

/// Item 10: `--frames 5..12` meant 5..=11 without a word. `A..B` is refused with both readings;
/// `A..=B` and one frame `F`, what the help documents, are taken.
#[test]
fn frame_ranges_mean_what_the_help_says() {
    let dir = Scratch::new("week-frames");
    let collage = views_and_collage(&dir);
    let (key, views, lens) = (format!("0={collage}"), dir.s("views"), dir.s("lens"));
    let keys = |frames: &str| {
        mcctrace(&["keys", "--key", &key, "--rays", &views, "--frames", frames, "-q", "--out", &lens])
    };
    let message = format!("{:#}", keys("5..12").unwrap_err());
    for want in ["--frames", "'5..12' is ambiguous", "5..=12 to include frame 12", "5..=11 to stop before it"]
    {
        assert!(message.contains(want), "{want:?} not in {message}");
    }
    assert!(!dir.path("lens").exists(), "a refused range wrote frames");
    keys("5..=6").unwrap();
    keys("9").unwrap();
    let written: Vec<String> = std::fs::read_dir(dir.path("lens"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    for f in [5, 6, 9] {
        assert!(written.contains(&format!("rerender-frame{f:04}.mcr")), "{written:?}");
    }
    assert!(!written.iter().any(|n| n.contains("frame0007") || n.contains("frame0008")), "{written:?}");
}

/// Item 11: `--camera` was a 0-based index in `render`, a name in `studio`, a number from 1 in
/// `tag`; `tag` spelled the tag width `--bits`. One rule now: a camera's name or its number from
/// 1, as views are numbered; `--camera 0` is refused, saying so; old spellings are aliases.
#[test]
fn cameras_are_numbered_from_one_everywhere() {
    let dir = Scratch::new("week-camera-numbers");
    let (scene, cameras) = cornell();
    let render = |camera: &str, out: &str| {
        mcctrace(&[
            "render",
            &scene,
            "--cameras-file",
            &cameras,
            "--camera",
            camera,
            "--res",
            "8x6",
            "--spp",
            "1",
            "-q",
            "--out",
            out,
        ])
    };
    for (number, name) in [("1", "cornell"), ("2", "corner")] {
        let out = dir.s(&format!("camera{number}.exr"));
        render(number, &out).unwrap();
        assert_eq!(header(Path::new(&out))["mcctrace/camera"], name);
    }
    let message = format!("{:#}", render("0", &dir.s("zero.exr")).unwrap_err());
    for want in ["--camera 0", "numbered from 1", "--camera 1", "1 'cornell', 2 'corner'"] {
        assert!(message.contains(want), "{want:?} not in {message}");
    }
    let message = format!("{:#}", render("3", &dir.s("three.exr")).unwrap_err());
    assert!(message.contains("no camera number 3") && message.contains("1 'cornell'"), "{message}");
    assert!(!dir.path("zero.exr").exists() && !dir.path("three.exr").exists());

    // `tag` takes --tag-bits as every other command does, and still --bits.
    render("1", &dir.s("view.exr")).unwrap();
    for flag in ["--tag-bits", "--bits"] {
        let out = dir.s(&format!("tagged{flag}.png"));
        mcctrace(&["tag", &dir.s("view.png"), "--camera", "9", flag, "3", "--out", &out]).unwrap();
        let tagged = image::open(&out).unwrap().to_rgb8();
        let code = mcc::TagCode::new(3).unwrap();
        assert!(tagged.pixels().filter(|p| p.0 != [0, 0, 0]).all(|p| code.decode(p.0) == 9));
    }

    // Help texts speak of their own command and say each default once.
    let help = |command: &str| {
        let run = child::run(&[command, "--help"]);
        assert!(run.ok, "{run:?}");
        run.stdout
    };
    for command in ["rerender", "animate"] {
        let text = help(command);
        let res = text.split("--res <WxH>").nth(1).expect("--res in the help");
        let res = &res[..res.find("\n      --").unwrap_or(res.len())];
        assert!(!res.contains("`rerender`") && !res.contains("640x360"), "{command} --res: {res}");
        assert!(res.contains("the size after the crop"), "{command} --res: {res}");
    }
    let studio = help("studio");
    assert!(!studio.contains("(default: any free port)"), "{studio}");
    assert!(studio.contains("0 takes any free port"), "{studio}");
    assert!(studio.contains("(.ora)") && studio.contains("(.psd)"), "{studio}");
    assert!(studio.contains("--camera <NAME|NUMBER>"), "{studio}");
    assert!(help("render").contains("--camera <NAME|NUMBER>"));
    assert!(help("tag").contains("--tag-bits <B>") && help("tag").contains("--bits"));
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
