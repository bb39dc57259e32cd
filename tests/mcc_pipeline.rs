//! The multicamera collage end to end (docs/design.md §4–6, §8), through the real `mcctrace`
//! command line run in-process: render two Cornell views with the lens writer and tagger, compose a
//! collage from a label mask, remap, rerender.
//!
//! - A collage that is entirely camera 1 gives back exactly camera 1's rays at every pixel
//!   centre, and its rerender equals a plain render of camera 1 statistically (an independent
//!   path: no MCC at all).
//! - A mixed collage rerenders like its golden EXR (`tests/data/golden/`), checked by the golden
//!   suite's machinery (`common/golden.rs`: docs/testing.md §2's statistical test on both images'
//!   per-sample variances). `UPDATE_GOLDEN=1 cargo test --release -p mcctrace-suite --test
//!   suite -- mcc_pipeline::mixed` re-renders the golden and prints how it changed.
//! - Malformed inputs give errors naming the file, and leave no output behind.

use crate::common::golden::{Sampled, assert_darker_fails, check_golden};
use crate::common::{CORNELL_SECOND_VIEW, Scratch, mcctrace};
use std::path::Path;
use tracer::image::RgbImage;
use tracer::image_io::read_exr;
use tracer::test_support::compare::{Estimate, StatTest};

const CORNELL: &str = "scenes/cornell/cornell.gltf";
// 96² at 128 spp: enough samples that a 2 % bias shows (image-level z ≈ 7 > 5).
const SIZE: u32 = 96;
const RES: &str = "96x96";

/// Views 1 (the scene's camera) and 2 (a second camera to its right, turned towards the box)
/// with the lens writer and tagger.
fn render_views(dir: &Scratch) {
    let views = dir.s("views");
    let common =
        ["--res", RES, "--spp", "16", "--max-depth", "4", "--lens-writer", "--tag", "--quiet", "--out"];
    let mut one = vec!["render", CORNELL];
    one.extend(common);
    one.push(&views);
    mcctrace(&one).unwrap();
    let mut two = vec!["render", CORNELL];
    two.extend(CORNELL_SECOND_VIEW);
    two.extend(["--first-id", "2"]);
    two.extend(common);
    two.push(&views);
    mcctrace(&two).unwrap();
}

/// A label mask: `red_cols` columns of camera 1 on the left, `green_cols` of camera 2 on the
/// right, black between.
fn write_mask(path: &Path, red_cols: u32, green_cols: u32) {
    let mut img = mcc::image::RgbImage::new(SIZE, SIZE);
    for (x, _, p) in img.enumerate_pixels_mut() {
        *p = if x < red_cols {
            mcc::image::Rgb([255, 0, 0])
        } else if x >= SIZE - green_cols {
            mcc::image::Rgb([0, 255, 0])
        } else {
            mcc::image::Rgb([0, 0, 0])
        };
    }
    img.save(path).unwrap();
}

/// Composes the collage for `mask` and rerenders it at `spp` with `seed`; returns (mean,
/// variance).
fn rerender(dir: &Scratch, mask: &Path, spp: u32, seed: u32, tag: &str) -> (RgbImage, RgbImage) {
    let collage = dir.s(&format!("collage-{tag}.png"));
    mcctrace(&["collage", "--mask", mask.to_str().unwrap(), "--views", &dir.s("views"), "--out", &collage])
        .unwrap();
    let out = dir.s(&format!("final-{tag}/final.exr"));
    let (spp, seed) = (spp.to_string(), seed.to_string());
    mcctrace(&[
        "rerender",
        CORNELL,
        "--collage",
        &collage,
        "--rays",
        &dir.s("views"),
        "--out",
        &out,
        "--spp",
        &spp,
        "--max-depth",
        "4",
        "--seed",
        &seed,
        "--aovs",
        "--quiet",
    ])
    .unwrap();
    let exr = read_exr(Path::new(&out)).unwrap();
    let variance = exr.rgb_layer("variance").expect("--aovs writes a variance layer").clone();
    (exr.rgb, variance)
}

#[test]
fn one_camera_collage_is_that_camera() {
    let dir = Scratch::new("mcc-one");
    render_views(&dir);
    let mask = dir.path("all-red.png");
    write_mask(&mask, SIZE, 0);
    let (mean, variance) = rerender(&dir, &mask, 64, 0, "one");

    // Exactly camera 1's rays at every pixel centre.
    let remapped = mcc::RayFile::read(&dir.path("final-one/final.mcr")).unwrap();
    let source = mcc::RayFile::read(&dir.path("views/frame0000camera01.mcr")).unwrap();
    assert_eq!(remapped.rays.len(), source.rays.len());
    for (a, b) in remapped.rays.iter().zip(&source.rays) {
        assert_eq!(a.origin.to_array().map(f32::to_bits), b.origin.to_array().map(f32::to_bits));
        assert_eq!(a.direction.to_array().map(f32::to_bits), b.direction.to_array().map(f32::to_bits));
    }

    // And the image is camera 1's plain render, statistically (a different seed, so the two
    // estimates are independent).
    let plain = dir.s("plain.exr");
    mcctrace(&[
        "render",
        CORNELL,
        "--res",
        RES,
        "--spp",
        "64",
        "--max-depth",
        "4",
        "--seed",
        "7",
        "--aovs",
        "--quiet",
        "--out",
        &plain,
    ])
    .unwrap();
    let p = read_exr(Path::new(&plain)).unwrap();
    let report = StatTest::default().between(
        Estimate { mean: &mean, variance: &variance, samples: 64 },
        Estimate { mean: &p.rgb, variance: p.rgb_layer("variance").unwrap(), samples: 64 },
    );
    println!("{report}");
    assert!(report.passed(), "{report}");
}

#[test]
fn mixed_collage_matches_its_golden() {
    let dir = Scratch::new("mcc-mixed");
    render_views(&dir);
    let mask = dir.path("mask.png");
    write_mask(&mask, 36, 24);
    let render = |spp, seed| {
        let (mean, variance) = rerender(&dir, &mask, spp, seed, &format!("{spp}spp"));
        // The CLI's EXR does not carry the NaN/Inf sample count (the film records such samples
        // as black); non-finite pixels would still fail the comparison.
        Sampled { mean, variance, spp, nonfinite_samples: 0 }
    };
    let name = "mcc-cornell-collage";
    let (test, golden, _) =
        check_golden(name, "mcc_pipeline: mixed collage of two Cornell views", 128, render);
    // The same check fails for an image 2 % too dark: it can fail.
    assert_darker_fails(name, &test, &golden);
}

#[test]
fn malformed_inputs_name_the_file_and_leave_nothing() {
    let dir = Scratch::new("mcc-bad");
    render_views(&dir);
    let views = dir.s("views");
    let mask = dir.path("mask.png");
    write_mask(&mask, 24, 16);
    let collage = dir.s("collage.png");
    mcctrace(&["collage", "--mask", mask.to_str().unwrap(), "--views", &views, "--out", &collage]).unwrap();

    // A stray, antialiased-looking pixel: non-black, and its tag bits name no camera we have.
    let strayed = dir.path("strayed.png");
    let mut img = mcc::image::open(&collage).unwrap().to_rgb8();
    img.put_pixel(30, 30, mcc::image::Rgb([131, 130, 134]));
    img.save(&strayed).unwrap();
    let out = dir.s("out/stray.mcr");
    let err = mcctrace(&["remap", "--collage", strayed.to_str().unwrap(), "--rays", &views, "--out", &out])
        .unwrap_err();
    let msg = format!("{err:#}");
    assert!(msg.contains("strayed.png") && msg.contains("(30, 30)"), "{msg}");
    assert!(!Path::new(&out).exists(), "no output after a refusal");
    // …accepted when asked to treat strays as background.
    mcctrace(&[
        "remap",
        "--collage",
        strayed.to_str().unwrap(),
        "--rays",
        &views,
        "--out",
        &out,
        "--ignore-strays",
        "--quiet",
    ])
    .unwrap();
    assert!(Path::new(&out).exists());

    // Regions of the wrong size.
    let regions = dir.path("regions.png");
    mcc::image::RgbImage::new(SIZE + 1, SIZE).save(&regions).unwrap();
    let err = mcctrace(&[
        "remap",
        "--collage",
        &collage,
        "--rays",
        &views,
        "--regions",
        regions.to_str().unwrap(),
        "--out",
        &dir.s("r.mcr"),
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("regions.png"), "{err:#}");

    // A rays directory without this frame's files.
    let err = mcctrace(&[
        "remap",
        "--collage",
        &collage,
        "--rays",
        &views,
        "--frame",
        "9",
        "--out",
        &dir.s("f.mcr"),
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("views"), "{err:#}");

    // A collage of the wrong size for the views' rays.
    let small = dir.path("small.png");
    mcc::image::RgbImage::from_pixel(8, 8, mcc::image::Rgb([255, 255, 255])).save(&small).unwrap();
    let err = mcctrace(&[
        "remap",
        "--collage",
        small.to_str().unwrap(),
        "--rays",
        &views,
        "--out",
        &dir.s("s.mcr"),
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("small.png"), "{err:#}");

    // A truncated ray file given to the reader.
    let truncated = dir.path("views/truncated.mcr");
    let bytes = std::fs::read(dir.path("views/frame0000camera01.mcr")).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let final_exr = dir.s("t/final.exr");
    let err = mcctrace(&[
        "rerender",
        CORNELL,
        "--lens",
        truncated.to_str().unwrap(),
        "--out",
        &final_exr,
        "--quiet",
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("truncated.mcr"), "{err:#}");
    assert!(!Path::new(&final_exr).exists());
}
