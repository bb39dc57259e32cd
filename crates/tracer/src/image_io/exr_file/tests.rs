//! Tests of the OpenEXR reader and writer, including hostile and damaged files.

use super::*;
use exr::prelude::f16;
use std::path::PathBuf;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mcctrace-exr-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The independent Mitsuba 3 Cornell-box reference (tests/data/cornell/README.md).
pub(crate) fn reference_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/cornell/reference-mitsuba3-16384spp.exr")
}

fn ramp(width: u32, height: u32, seed: f32) -> RgbImage {
    let pixels = (0..width * height)
        .map(|i| Vec3::new(i as f32 * 0.25 + seed, -seed / (i + 1) as f32, 1e-30 * seed))
        .collect();
    RgbImage { width, height, pixels }
}

#[test]
fn exr_round_trips_beauty_aovs_and_metadata_exactly() {
    let dir = temp_dir("roundtrip");
    let path = dir.join("render.exr");
    let (w, h) = (37, 19); // Not a multiple of ZIP's 16-line blocks.
    let beauty = ramp(w, h, 1.0);
    let albedo = ramp(w, h, 2.0);
    let mut variance = ramp(w, h, 3.0);
    variance.pixels[5] = Vec3::new(f32::INFINITY, f32::NAN, f32::MIN_POSITIVE);
    let depth = GrayImage { width: w, height: h, pixels: (0..w * h).map(|i| i as f32 * 1e3).collect() };
    let aovs = [
        Aov::Rgb { name: "albedo", image: &albedo },
        Aov::Gray { name: "depth", image: &depth },
        Aov::Rgb { name: "variance", image: &variance },
    ];
    let metadata =
        [("spp", "64".to_string()), ("camera", "Kamera “links” ü".to_string()), ("seed", String::new())];
    write_exr(&path, &beauty, &aovs, &metadata).unwrap();

    let read = read_exr(&path).unwrap();
    assert_eq!(read.rgb, beauty);
    assert_eq!(read.rgb_layer("albedo"), Some(&albedo));
    assert_eq!(read.gray_layer("depth"), Some(&depth));
    let v = read.rgb_layer("variance").unwrap();
    assert_eq!(v.pixels[5].x, f32::INFINITY);
    assert!(v.pixels[5].y.is_nan());
    assert_eq!(v.pixels[5].z, f32::MIN_POSITIVE);
    for (i, (a, b)) in v.pixels.iter().zip(&variance.pixels).enumerate() {
        assert!(i == 5 || a == b, "pixel {i}: {a} != {b}");
    }
    assert_eq!(read.layers.len(), 3);
    for (key, value) in &metadata {
        assert_eq!(read.metadata.get(*key), Some(value));
    }
    assert!(read.metadata["software"].starts_with("mcctrace"));
    assert_eq!(read_exr_rgb(&path).unwrap(), beauty);

    // What other tools see: one part, f32 channels with the conventional names, ZIP.
    let meta = MetaData::read_from_file(&path, true).unwrap();
    let header = &meta.headers[0];
    assert_eq!(meta.headers.len(), 1);
    assert_eq!(header.compression, Compression::ZIP16);
    let names: Vec<String> = header.channels.list.iter().map(|c| c.name.to_string()).collect();
    let expected = [
        "B",
        "G",
        "R",
        "albedo.B",
        "albedo.G",
        "albedo.R",
        "depth.Y",
        "variance.B",
        "variance.G",
        "variance.R",
    ];
    assert_eq!(names, expected);
    assert!(header.channels.list.iter().all(|c| c.sample_type == exr::prelude::SampleType::F32));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn exr_writer_refuses_bad_input_and_leaves_old_file_alone() {
    let dir = temp_dir("refuse");
    let path = dir.join("out.exr");
    let beauty = ramp(4, 3, 1.0);
    write_exr(&path, &beauty, &[], &[]).unwrap();
    let before = std::fs::read(&path).unwrap();
    let small = ramp(3, 3, 1.0);
    let gray = GrayImage { width: 4, height: 3, pixels: vec![0.0; 11] };
    // (AOVs, metadata, expected words of the error)
    type Case<'a> = (Vec<Aov<'a>>, Vec<(&'a str, String)>, &'a str);
    let cases: Vec<Case<'_>> = vec![
        (vec![Aov::Rgb { name: "albedo", image: &small }], vec![], "is 3 × 3 but the image is 4 × 3"),
        (vec![Aov::Gray { name: "depth", image: &gray }], vec![], "holds 11 values instead of 12"),
        (vec![Aov::Rgb { name: "al bedo", image: &beauty }], vec![], "AOV name"),
        (vec![Aov::Rgb { name: "", image: &beauty }], vec![], "AOV name"),
        (
            vec![Aov::Rgb { name: "a", image: &beauty }, Aov::Rgb { name: "a", image: &beauty }],
            vec![],
            "two AOVs",
        ),
        (vec![], vec![("compression", "none".into())], "standard OpenEXR attribute"),
        (vec![], vec![("spp", "1".into()), ("spp", "2".into())], "given twice"),
        (vec![], vec![("", "1".into())], "metadata key"),
    ];
    for (aovs, metadata, expected) in cases {
        let err = write_exr(&path, &beauty, &aovs, &metadata).unwrap_err().to_string();
        assert!(err.contains("out.exr") && err.contains(expected), "{err} (wanted {expected})");
    }
    let err = write_exr(&path, &RgbImage::new(0, 5), &[], &[]).unwrap_err().to_string();
    assert!(err.contains("at least one pixel"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary left behind");
    let err = write_exr(&dir.join("no/such/dir.exr"), &beauty, &[], &[]).unwrap_err();
    assert!(matches!(err, TracerError::Io { .. }), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn exr_reads_mitsuba_reference() {
    let image = read_exr(&reference_path()).unwrap();
    assert_eq!((image.rgb.width, image.rgb.height), (256, 256));
    assert!(image.layers.is_empty());
    assert_eq!(image.metadata.get("generatedBy").map(String::as_str), Some("Mitsuba version 3.9.1"));
    assert!(image.rgb.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0));
    // Values as the OpenEXR library itself (Python bindings 3.x) decodes them.
    let mean = image.rgb.mean();
    assert!(mean.abs_diff_eq(Vec3::new(0.18971832, 0.12597685, 0.03732826), 1e-6), "mean {mean}");
    let max = image.rgb.pixels.iter().fold(0.0f32, |m, p| m.max(p.max_element()));
    assert_eq!(max, 17.0, "the light's radiance, seen directly");
    assert_eq!(image.rgb.get(0, 0), Vec3::ZERO);
    assert!(image.rgb.get(128, 128).abs_diff_eq(Vec3::new(0.09108504, 0.06851417, 0.01939647), 1e-7));
    assert!(image.rgb.get(200, 10).abs_diff_eq(Vec3::new(0.04405135, 0.03440024, 0.00792876), 1e-7));
}

/// Writes channels with the exr crate directly, as another tool would.
fn write_foreign(path: &Path, size: (usize, usize), channels: Vec<(&str, FlatSamples)>) {
    let list = channels.into_iter().map(|(n, s)| AnyChannel::new(n, s)).collect();
    let layer =
        Layer::new(size, LayerAttributes::default(), Encoding::FAST_LOSSLESS, AnyChannels::sort(list));
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn exr_reads_f16_luminance_and_rgba_files() {
    let dir = temp_dir("foreign");
    let half = |v: &[f32]| FlatSamples::F16(v.iter().map(|&x| f16::from_f32(x)).collect());
    let path = dir.join("half.exr");
    write_foreign(
        &path,
        (2, 1),
        vec![
            ("R", half(&[0.5, 1.0])),
            ("G", half(&[0.25, 2.0])),
            ("B", half(&[0.125, 4.0])),
            ("A", half(&[1.0, 0.5])),
            ("Z", FlatSamples::F32(vec![3.0, 4.0])),
        ],
    );
    let read = read_exr(&path).unwrap();
    assert_eq!(read.rgb.pixels, vec![Vec3::new(0.5, 0.25, 0.125), Vec3::new(1.0, 2.0, 4.0)]);
    assert_eq!(read.gray_layer("A").unwrap().pixels, vec![1.0, 0.5]);
    assert_eq!(read.gray_layer("Z").unwrap().pixels, vec![3.0, 4.0]);

    let path = dir.join("luminance.exr");
    write_foreign(&path, (1, 2), vec![("Y", half(&[0.5, 0.75])), ("n.Y", FlatSamples::U32(vec![7, 8]))]);
    let read = read_exr(&path).unwrap();
    assert_eq!(read.rgb.pixels, vec![Vec3::splat(0.5), Vec3::splat(0.75)]);
    assert_eq!(read.gray_layer("n").unwrap().pixels, vec![7.0, 8.0]);

    let path = dir.join("nobeauty.exr");
    write_foreign(&path, (1, 1), vec![("albedo.R", half(&[0.5]))]);
    let err = read_exr(&path).unwrap_err().to_string();
    assert!(
        err.contains("nobeauty.exr") && err.contains("no beauty channels") && err.contains("albedo.R"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Overwrites the value of the header attribute `name` (a box2i) in an EXR file's bytes.
fn patch_box(bytes: &mut [u8], name: &str, min: (i32, i32), max: (i32, i32)) {
    let key = format!("{name}\0box2i\0");
    let at = bytes.windows(key.len()).position(|w| w == key.as_bytes()).unwrap() + key.len() + 4;
    for (i, v) in [min.0, min.1, max.0, max.1].into_iter().enumerate() {
        bytes[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
}

#[test]
fn exr_reader_refuses_absurd_sizes_before_allocating() {
    let dir = temp_dir("huge");
    let path = dir.join("small.exr");
    write_exr(&path, &ramp(4, 4, 1.0), &[], &[]).unwrap();
    let good = std::fs::read(&path).unwrap();
    for (max, expected) in [((999_999, 999_999), "1000000 × 1000000 pixels"), ((-5, 3), "malformed")] {
        let mut bytes = good.clone();
        patch_box(&mut bytes, "dataWindow", (0, 0), max);
        let huge = dir.join("huge.exr");
        std::fs::write(&huge, &bytes).unwrap();
        let err = read_exr(&huge).unwrap_err().to_string();
        assert!(err.contains("huge.exr") && err.contains(expected), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// xorshift64*: a few lines, fixed seeds, no dependency.
fn next(state: &mut u64) -> u64 {
    *state ^= *state >> 12;
    *state ^= *state << 25;
    *state ^= *state >> 27;
    state.wrapping_mul(0x2545_F491_4F6C_DD1D)
}

#[test]
fn exr_reader_reports_damaged_files_without_panicking() {
    let dir = temp_dir("damaged");
    let path = dir.join("good.exr");
    let depth = GrayImage { width: 40, height: 35, pixels: (0..1400).map(|i| i as f32).collect() };
    write_exr(
        &path,
        &ramp(40, 35, 1.0),
        &[Aov::Gray { name: "depth", image: &depth }],
        &[("spp", "4".into())],
    )
    .unwrap();
    let good = std::fs::read(&path).unwrap();
    let bad = dir.join("bad.exr");
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let check = |bytes: &[u8], must_fail: bool| {
        std::fs::write(&bad, bytes).unwrap();
        match read_exr(&bad) {
            Err(TracerError::Image { path, message }) => assert!(path == bad && !message.is_empty()),
            Err(other) => panic!("unexpected error kind: {other}"),
            Ok(_) => assert!(!must_fail, "a damaged file read as valid"),
        }
    };
    // Every truncation inside the header and offset table, and a spread of them in the pixels.
    for len in (0..good.len()).filter(|&n| n < 600 || n % 97 == 0) {
        check(&good[..len], true);
    }
    std::fs::write(&bad, &good[..good.len() / 2]).unwrap();
    let err = read_exr(&bad).unwrap_err().to_string();
    assert!(err.contains("bad.exr") && err.contains("the file ends before its data does"), "{err}");
    // Random byte damage: a corrupt pixel block may still decode (to wrong values); a panic or a
    // non-Image error may not happen.
    for _ in 0..400 {
        let mut bytes = good.clone();
        for _ in 0..1 + next(&mut state) % 4 {
            let at = (next(&mut state) % bytes.len() as u64) as usize;
            bytes[at] = next(&mut state) as u8;
        }
        check(&bytes, false);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
