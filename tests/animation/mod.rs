//! Animation through the real `mcctrace` command line, run in-process (docs/design/workflow.md §6–8):
//!
//! - `inbetween` writes exactly the asked frames; key frames (and the holds outside the keys)
//!   reproduce the keys bit for bit, a key of another size is resampled by the lens reader's
//!   rule, linear frames equal lerp/slerp computed directly, smooth frames are unit and finite;
//!   a missing key file is an error naming it, leaving nothing behind.
//! - `keys` gives, at each key frame, exactly what `remap` gives for that frame's collage.
//! - `animate` renders exactly the requested sub-range, renders each frame through that frame's
//!   rays (bit for bit like `rerender --lens`), skips finished frames on a re-run, redoes a frame
//!   left half-written, and makes a preview GIF of every finished frame.
//! - Motion blur: a static lens with `--shutter 0..1` renders statistically like no blur; a
//!   moving lens blurs, and its blurred frame matches the time average of sharp renders of the
//!   in-between cameras.
//! - Scene time: a glTF with an animated node (the mesh, or the camera) renders where the hand-
//!   computed pose puts it at frame / fps, and `--fps` changes which time is sampled.

use crate::common::{Scratch, mcctrace};
use glam::Vec3;
use mcc::{RayFile, StoredRay};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tracer::image::RgbImage;
use tracer::image_io::read_exr;
use tracer::test_support::compare::{Estimate, StatTest, mse};

// Scene time: an animated glTF written here, rendered at several frames and rates.
mod scene_time;

// Geometry motion blur: a sliding square against its time-averaged coverage.
pub(crate) mod motion_blur;

// A moving emitter: its time-averaged light on a floor against the closed form.
mod moving_light;

// `animate` refits the BVH per frame: a resumed shot keeps a continuous run's bits.
mod refit;

// Rigid motion blur: a bar turning half a turn, along the arc (slerp), not the chords.
mod rigid_motion;

const CORNELL: &str = "scenes/cornell/cornell.gltf";

/// The file names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn bits(r: &StoredRay) -> [u32; 6] {
    let (o, d) = (r.origin, r.direction);
    [o.x, o.y, o.z, d.x, d.y, d.z].map(f32::to_bits)
}

#[track_caller]
fn assert_same_rays(a: &[StoredRay], b: &[StoredRay], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: ray count");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert_eq!(bits(x), bits(y), "{what}: ray {i}: {x:?} vs {y:?}");
    }
}

/// A pinhole camera's eye rays (vertical half-angle tan 0.4).
fn camera_rays(eye: Vec3, target: Vec3, w: u32, h: u32) -> RayFile {
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let mut rays = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let sx = (2.0 * (x as f32 + 0.5) / w as f32 - 1.0) * 0.4 * w as f32 / h as f32;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / h as f32) * 0.4;
            rays.push(StoredRay::new(eye, (forward + sx * right + sy * up).normalize()));
        }
    }
    RayFile::new(w, h, 0, 1, rays).unwrap()
}

fn rerender_file(dir: &Path, frame: u32) -> PathBuf {
    dir.join(format!("rerender-frame{frame:04}.mcr"))
}

#[test]
fn inbetween_writes_the_frames_asked_keys_bit_exact_linear_is_lerp_slerp() {
    let dir = Scratch::new("inbetween");
    // Key A (16x12) at frame 2, key B (8x6, resampled to 16x12) at frame 6: different cameras.
    let a = camera_rays(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, 16, 12);
    let b = camera_rays(Vec3::new(4.0, 2.0, -1.0), Vec3::new(0.0, 0.5, 0.0), 8, 6);
    a.write(&dir.path("a.mcr"), mcc::RayFormat::Binary).unwrap();
    b.write(&dir.path("b.txt"), mcc::RayFormat::Text).unwrap();
    let b16 = {
        let sampler =
            mcc::lens_reader::RaySampler::new(Arc::new(b.clone()), glam::UVec2::new(16, 12)).unwrap();
        let mut v = Vec::new();
        for y in 0..12 {
            for x in 0..16 {
                v.push(sampler.at(glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5)));
            }
        }
        v
    };
    let (ka, kb) = (format!("2={}", dir.s("a.mcr")), format!("6={}", dir.s("b.txt")));
    for (mode, out) in [("linear", "lin"), ("smooth", "smooth")] {
        let out_dir = dir.s(out);
        mcctrace(&[
            "inbetween",
            "--key",
            &kb,
            "--key",
            &ka,
            "--frames",
            "0..=8",
            "--mode",
            mode,
            "--out",
            &out_dir,
            "--quiet",
        ])
        .unwrap();
        let expected: Vec<String> = (0..=8).map(|f| format!("rerender-frame{f:04}.mcr")).collect();
        assert_eq!(names(&dir.path(out)), expected, "{mode}: exactly the frames asked, no temporaries");
        let frame = |f| RayFile::read(&rerender_file(&dir.path(out), f)).unwrap();
        for f in 0..=2 {
            assert_same_rays(&frame(f).rays, &a.rays, &format!("{mode} frame {f} (key A or its hold)"));
        }
        for f in 6..=8 {
            assert_same_rays(
                &frame(f).rays,
                &b16,
                &format!("{mode} frame {f} (key B resampled, or its hold)"),
            );
        }
        for f in 3..=5 {
            let got = frame(f);
            assert_eq!((got.width, got.height, got.frame), (16, 12, f));
            if mode == "linear" {
                let s = (f - 2) as f32 / 4.0;
                let direct: Vec<StoredRay> =
                    a.rays.iter().zip(&b16).map(|(p, q)| mcc::slerp::lerp_rays(p, q, s)).collect();
                assert_same_rays(&got.rays, &direct, &format!("linear frame {f} = lerp/slerp at s = {s}"));
            }
            for r in &got.rays {
                assert!(
                    r.origin.is_finite() && (r.direction.length() - 1.0).abs() < 1e-5,
                    "{mode} {f}: {r:?}"
                );
            }
        }
    }
    // The keys' own frame numbers select the frames when --frames is left out.
    mcctrace(&["inbetween", "--key", &ka, "--key", &kb, "--out", &dir.s("default"), "--quiet"]).unwrap();
    assert_eq!(names(&dir.path("default")).len(), 5, "frames 2..=6");

    // A missing key is refused by name before anything is written.
    let missing = dir.s("nope.mcr");
    let err = mcctrace(&[
        "inbetween",
        "--key",
        &ka,
        "--key",
        &format!("9={missing}"),
        "--frames",
        "0..=9",
        "--out",
        &dir.s("bad"),
        "--quiet",
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("nope.mcr"), "{err:#}");
    assert!(!dir.path("bad").exists() || names(&dir.path("bad")).is_empty(), "nothing written");
    // Two keys for one frame are refused.
    let err = mcctrace(&[
        "inbetween",
        "--key",
        &ka,
        "--key",
        &format!("2={}", dir.s("b.txt")),
        "--out",
        &dir.s("bad"),
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("frame 2"), "{err:#}");
}

/// Renders Cornell views `views/frameFFFFcamera01/02.*` at `frame` with the lens writer and tagger:
/// camera 1 from `eye1`, camera 2 from `eye2`, both looking down +z.
fn cornell_views(views: &str, frame: u32, eye1: &str, eye2: &str, res: &str) {
    for (id, eye) in [("1", eye1), ("2", eye2)] {
        let at = {
            let v: Vec<f32> = eye.split(',').map(|c| c.parse().unwrap()).collect();
            format!("{},{},{}", v[0], v[1], v[2] + 8.0)
        };
        let f = frame.to_string();
        mcctrace(&[
            "render",
            CORNELL,
            "--look-from",
            eye,
            "--look-at",
            &at,
            "--fov",
            "39.3",
            "--first-id",
            id,
            "--frame",
            &f,
            "--res",
            res,
            "--spp",
            "1",
            "--lens-writer",
            "--tag",
            "--quiet",
            "--out",
            views,
        ])
        .unwrap();
    }
}

/// A label mask: camera 1 (red) left of column `a`, camera 2 (green) right of column `b`.
fn write_mask(path: &Path, w: u32, h: u32, a: u32, b: u32) {
    let mut rgb = Vec::new();
    for _ in 0..h {
        for x in 0..w {
            rgb.extend_from_slice(if x < a {
                &[255, 0, 0]
            } else if x >= b {
                &[0, 255, 0]
            } else {
                &[0, 0, 0]
            });
        }
    }
    tracer::image_io::write_png_rgb8(path, w, h, &rgb).unwrap();
}

#[test]
fn keys_remaps_each_key_against_its_frame_like_remap() {
    let dir = Scratch::new("keys");
    let views = dir.s("views");
    // Each key has its own cameras.
    cornell_views(&views, 0, "2.78,2.73,-8", "1.5,2.73,-8", "32x24");
    cornell_views(&views, 5, "3.5,2.0,-7", "4.0,3.3,-8", "32x24");
    for (frame, a, b) in [(0u32, 12, 20), (5, 8, 22)] {
        let mask = dir.path(&format!("mask{frame}.png"));
        write_mask(&mask, 32, 24, a, b);
        let f = frame.to_string();
        let collage = dir.s(&format!("collage{frame}.png"));
        mcctrace(&[
            "collage",
            "--mask",
            &mask.display().to_string(),
            "--views",
            &views,
            "--frame",
            &f,
            "--out",
            &collage,
        ])
        .unwrap();
        let out = dir.s(&format!("remap{frame}.mcr"));
        mcctrace(&[
            "remap",
            "--collage",
            &collage,
            "--rays",
            &views,
            "--frame",
            &f,
            "--out",
            &out,
            "--quiet",
        ])
        .unwrap();
    }
    let (k0, k5) = (format!("0={}", dir.s("collage0.png")), format!("5={}", dir.s("collage5.png")));
    let lens = dir.s("lens");
    mcctrace(&[
        "keys", "--key", &k0, "--key", &k5, "--rays", &views, "--frames", "0..=6", "--out", &lens, "--quiet",
    ])
    .unwrap();
    // The 7 frames' ray files and keys' record (docs/farm.md: a re-run with the same inputs is
    // skipped), nothing else.
    let mut want: Vec<String> = (0..=6).map(|f| format!("rerender-frame{f:04}.mcr")).collect();
    want.push(mcc::job::RECORD_NAME.to_string());
    want.sort();
    assert_eq!(names(&dir.path("lens")), want);
    for frame in [0u32, 5, 6] {
        let key = if frame == 0 { 0 } else { 5 };
        let remapped = RayFile::read(&dir.path(&format!("remap{key}.mcr"))).unwrap();
        let got = RayFile::read(&rerender_file(&dir.path("lens"), frame)).unwrap();
        assert_same_rays(&got.rays, &remapped.rays, &format!("keys frame {frame} vs remap of key {key}"));
    }
    // A key whose frame has no views is an error naming the frame's missing views.
    let err = mcctrace(&[
        "keys",
        "--key",
        &k0,
        "--key",
        &format!("3={}", dir.s("collage5.png")),
        "--rays",
        &views,
        "--out",
        &dir.s("bad"),
        "--quiet",
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("frame 3"), "{err:#}");
}

/// `views/frame0000camera01.mcr` (the Cornell camera) and `camera02` (moved 0.6 to +x) at 32².
fn two_lenses(dir: &Scratch) -> (PathBuf, PathBuf) {
    cornell_views(&dir.s("views"), 0, "2.78,2.73,-8", "3.38,2.73,-8", "32x32");
    (dir.path("views/frame0000camera01.mcr"), dir.path("views/frame0000camera02.mcr"))
}

fn read_rgb(path: &Path) -> (RgbImage, RgbImage) {
    let exr = read_exr(path).unwrap();
    let variance = exr.rgb_layer("variance").expect("--aovs writes a variance layer").clone();
    (exr.rgb, variance)
}

#[test]
fn animate_renders_exactly_the_range_skips_finished_frames_and_previews() {
    let dir = Scratch::new("animate");
    let (cam1, cam2) = two_lenses(&dir);
    let lens = dir.s("lens");
    let (k0, k4) = (format!("0={}", cam1.display()), format!("4={}", cam2.display()));
    mcctrace(&["inbetween", "--key", &k0, "--key", &k4, "--frames", "0..=4", "--out", &lens, "--quiet"])
        .unwrap();
    let frames = dir.path("frames");
    let out = frames.display().to_string();
    let animate = |range: &str, preview: &str| {
        mcctrace(&[
            "animate",
            CORNELL,
            "--lens-dir",
            &lens,
            "--frames",
            range,
            "--out",
            &out,
            "--spp",
            "4",
            "--max-depth",
            "3",
            "--preview",
            preview,
            "--quiet",
        ])
        .unwrap()
    };
    animate("1..=3", "none");
    let rendered: Vec<String> =
        (1..=3).flat_map(|f| [format!("frame{f:04}.exr"), format!("frame{f:04}.png")]).collect();
    assert_eq!(names(&frames), rendered, "exactly frames 1..=3, nothing else");

    // Frame 2 went through frame 2's rays: the same image, bit for bit, as rerendering that file.
    let single = dir.s("single.exr");
    mcctrace(&[
        "rerender",
        CORNELL,
        "--lens",
        &rerender_file(&dir.path("lens"), 2).display().to_string(),
        "--frame",
        "2",
        "--out",
        &single,
        "--spp",
        "4",
        "--max-depth",
        "3",
        "--quiet",
    ])
    .unwrap();
    let via_animate = read_exr(&frames.join("frame0002.exr")).unwrap().rgb;
    assert_eq!(
        via_animate.pixels,
        read_exr(Path::new(&single)).unwrap().rgb.pixels,
        "frame 2 = rerender --lens"
    );

    // Mark the finished frames: a re-run over 0..=4 must leave them alone and render 0 and 4.
    let marker = std::fs::read(frames.join("frame0001.png")).unwrap();
    std::fs::write(frames.join("frame0002.png"), &marker).unwrap();
    let before: Vec<Vec<u8>> =
        (1..=3).map(|f| std::fs::read(frames.join(format!("frame{f:04}.exr"))).unwrap()).collect();
    // Frame 3 as a crash would leave it: the EXR written, the PNG not yet.
    std::fs::remove_file(frames.join("frame0003.png")).unwrap();
    let t3 = std::fs::metadata(frames.join("frame0003.exr")).unwrap().modified().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    animate("0..=4", "gif");
    assert_eq!(
        std::fs::read(frames.join("frame0002.png")).unwrap(),
        marker,
        "finished frame 2 was not redone"
    );
    for f in 1..=2 {
        let now = std::fs::read(frames.join(format!("frame{f:04}.exr"))).unwrap();
        assert!(now == before[f as usize - 1], "finished frame {f} was redone");
    }
    let t3_after = std::fs::metadata(frames.join("frame0003.exr")).unwrap().modified().unwrap();
    assert!(t3_after > t3 && frames.join("frame0003.png").is_file(), "half-finished frame 3 rendered again");
    let mut expected: Vec<String> =
        (0..=4).flat_map(|f| [format!("frame{f:04}.exr"), format!("frame{f:04}.png")]).collect();
    expected.push("preview.gif".into());
    expected.sort();
    assert_eq!(names(&frames), expected);

    // The preview holds every finished frame, at the frames' size.
    use image::AnimationDecoder;
    let gif = std::io::BufReader::new(std::fs::File::open(frames.join("preview.gif")).unwrap());
    let decoded = image::codecs::gif::GifDecoder::new(gif).unwrap().into_frames().collect_frames().unwrap();
    assert_eq!(decoded.len(), 5);
    assert_eq!(decoded[0].buffer().dimensions(), (32, 32));
}

#[test]
fn static_lens_with_motion_blur_renders_like_no_blur() {
    let dir = Scratch::new("blur-static");
    let (cam1, _) = two_lenses(&dir);
    std::fs::create_dir_all(dir.path("lens")).unwrap();
    for f in 0..=1 {
        std::fs::copy(&cam1, rerender_file(&dir.path("lens"), f)).unwrap();
    }
    let lens = dir.s("lens");
    let render = |out: &str, seed: &str, shutter: Option<&str>| {
        let mut args = vec![
            "animate",
            CORNELL,
            "--lens-dir",
            &lens,
            "--frames",
            "0",
            "--out",
            out,
            "--spp",
            "64",
            "--seed",
            seed,
            "--max-depth",
            "4",
            "--aovs",
            "--preview",
            "none",
            "--quiet",
        ];
        if let Some(s) = shutter {
            args.extend(["--shutter", s]);
        }
        mcctrace(&args).unwrap();
        read_rgb(&Path::new(out).join("frame0000.exr"))
    };
    let (blur, blur_var) = render(&dir.s("blur"), "1", Some("0..1"));
    let (still, still_var) = render(&dir.s("still"), "2", None);
    let report = StatTest::default().between(
        Estimate { mean: &blur, variance: &blur_var, samples: 64 },
        Estimate { mean: &still, variance: &still_var, samples: 64 },
    );
    assert!(report.passed(), "a static lens blurred must look unblurred: {report:?}");
}

#[test]
fn moving_lens_blurs_like_the_time_average_of_its_cameras() {
    let dir = Scratch::new("blur-moving");
    let (cam1, cam2) = two_lenses(&dir);
    std::fs::create_dir_all(dir.path("lens")).unwrap();
    std::fs::copy(&cam1, rerender_file(&dir.path("lens"), 0)).unwrap();
    std::fs::copy(&cam2, rerender_file(&dir.path("lens"), 1)).unwrap();
    let render = |lens: &str, frames: &str, out: &str, spp: &str, seed: &str, shutter: Option<&str>| {
        let mut args = vec![
            "animate",
            CORNELL,
            "--lens-dir",
            lens,
            "--frames",
            frames,
            "--out",
            out,
            "--spp",
            spp,
            "--seed",
            seed,
            "--max-depth",
            "4",
            "--aovs",
            "--preview",
            "none",
            "--quiet",
        ];
        if let Some(s) = shutter {
            args.extend(["--shutter", s]);
        }
        mcctrace(&args).unwrap();
    };
    let lens = dir.s("lens");
    render(&lens, "0", &dir.s("blur"), "64", "1", Some("0..1"));
    render(&lens, "0..=1", &dir.s("sharp"), "64", "2", None);
    let (blur, blur_var) = read_rgb(&dir.path("blur/frame0000.exr"));
    let (sharp0, sharp0_var) = read_rgb(&dir.path("sharp/frame0000.exr"));
    let (sharp1, _) = read_rgb(&dir.path("sharp/frame0001.exr"));
    let report = StatTest::default().between(
        Estimate { mean: &blur, variance: &blur_var, samples: 64 },
        Estimate { mean: &sharp0, variance: &sharp0_var, samples: 64 },
    );
    assert!(!report.passed(), "a moving lens must blur: {report:?}");

    // The blurred frame integrates the cameras between the two files over the shutter: compare
    // with the trapezoid average of sharp renders of 9 linear in-between cameras (the lens
    // reader blends frames f and f+1 exactly as linear in-betweening does).
    let sub = dir.s("sub");
    let (k0, k8) = (format!("0={}", cam1.display()), format!("8={}", cam2.display()));
    mcctrace(&["inbetween", "--key", &k0, "--key", &k8, "--mode", "linear", "--out", &sub, "--quiet"])
        .unwrap();
    render(&sub, "0..=8", &dir.s("subframes"), "32", "3", None);
    let mut average = RgbImage::new(32, 32);
    for f in 0..=8u32 {
        let weight = if f == 0 || f == 8 { 1.0 / 16.0 } else { 1.0 / 8.0 };
        let (img, _) = read_rgb(&dir.path(&format!("subframes/frame{f:04}.exr")));
        for (a, p) in average.pixels.iter_mut().zip(&img.pixels) {
            *a += *p * weight;
        }
    }
    let (to_average, to_start, to_end) = (mse(&blur, &average), mse(&blur, &sharp0), mse(&blur, &sharp1));
    println!(
        "blurred frame MSE: vs time average {to_average:.3e}, vs start {to_start:.3e}, vs end {to_end:.3e}"
    );
    assert!(
        to_average < 0.3 * to_start.min(to_end),
        "blur should match the time average ({to_average:.3e}) far better than either end ({to_start:.3e}, {to_end:.3e})"
    );
}
