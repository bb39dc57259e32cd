//! Tests of the ray-file encodings (docs/design/mcc.md §4.2): round trips and every malformed case.

use super::*;
use crate::test_util::{Rng, scratch_dir};
use std::path::PathBuf;

fn sample(width: u32, height: u32, seed: u64) -> RayFile {
    let mut rng = Rng::new(seed);
    let mut rays: Vec<StoredRay> = (0..width * height)
        .map(|_| {
            let o = Vec3::new(rng.unit(), rng.unit(), rng.unit()) * 2000.0 - 1000.0;
            StoredRay::new(o, rng.direction())
        })
        .collect();
    // Awkward values must survive too: signed zeros, subnormals, huge and tiny magnitudes.
    rays[0].origin = Vec3::new(-0.0, f32::MIN_POSITIVE / 3.0, 3.4e38);
    rays[0].direction = Vec3::new(-0.0, 0.0, -1.0);
    let mut f = RayFile::new(width, height, 5, 3, rays).unwrap();
    f.computed = seed.is_multiple_of(2);
    f
}

fn bits(f: &RayFile) -> Vec<u32> {
    bytemuck::cast_slice::<StoredRay, u32>(&f.rays).to_vec()
}

fn encode(f: &RayFile, format: RayFormat) -> Vec<u8> {
    let mut v = Vec::new();
    f.encode(&mut v, format).unwrap();
    v
}

/// Writes `bytes` to a scratch file and reads it back as a ray file.
fn read_bytes(dir: &Path, name: &str, bytes: &[u8]) -> (PathBuf, Result<RayFile>) {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let from_file = RayFile::read(&path);
    let from_memory = RayFile::parse(bytes, &path);
    // Both entry points agree on every input.
    assert_eq!(
        from_file.as_ref().map_err(|e| e.to_string()),
        from_memory.as_ref().map_err(|e| e.to_string())
    );
    (path, from_file)
}

fn expect_error(dir: &Path, name: &str, bytes: &[u8], wants: &[&str]) {
    let (_, result) = read_bytes(dir, name, bytes);
    let message = result.expect_err(name).to_string();
    assert!(message.contains(name), "{message:?} should name the file {name}");
    for want in wants {
        assert!(message.contains(want), "{message:?} should contain {want:?}");
    }
}

#[test]
fn binary_and_text_round_trip_bit_exactly() {
    let dir = scratch_dir("rayfile-roundtrip");
    for (w, h, seed) in [(1, 1, 1), (7, 5, 2), (16, 9, 3)] {
        let f = sample(w, h, seed);
        for format in [RayFormat::Binary, RayFormat::Text] {
            let path = dir.join(format!("f{w}x{h}.{}", format.extension()));
            f.write(&path, format).unwrap();
            let g = RayFile::read(&path).unwrap();
            assert_eq!((g.width, g.height), (w, h));
            assert_eq!(bits(&g), bits(&f), "{format:?} must round-trip bit for bit");
            if format == RayFormat::Binary {
                assert_eq!((g.frame, g.camera_id, g.computed), (f.frame, f.camera_id, f.computed));
                let len = std::fs::metadata(&path).unwrap().len() as usize;
                assert_eq!(len, HEADER_LEN + RECORD_LEN * (w * h) as usize);
            }
        }
    }
    // The encoding is recognised from the content, whatever the name says.
    let f = sample(3, 2, 4);
    let swapped = dir.join("binary-named.txt");
    f.write(&swapped, RayFormat::Binary).unwrap();
    assert_eq!(bits(&RayFile::read(&swapped).unwrap()), bits(&f));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn binary_layout_is_as_documented() {
    let f = RayFile::new(2, 1, 7, 9, vec![StoredRay::new(Vec3::new(1.0, 2.0, 3.0), Vec3::Z); 2]).unwrap();
    let b = encode(&f, RayFormat::Binary);
    assert_eq!(&b[..8], b"\x89MCR\r\n\x1a\n");
    let words: Vec<u32> = b[8..32].chunks(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
    assert_eq!(words, [1, 2, 1, 7, 9, 0]);
    assert_eq!(&b[32..36], &1.0f32.to_le_bytes());
    assert_eq!(&b[52..56], &1.0f32.to_le_bytes(), "dz of pixel (0, 0)");
    assert_eq!(b.len(), 32 + 2 * 24);
}

#[test]
fn shuffled_text_lines_read_the_same() {
    let dir = scratch_dir("rayfile-shuffle");
    let f = sample(6, 4, 9);
    let text = String::from_utf8(encode(&f, RayFormat::Text)).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    let header = lines.remove(0);
    let mut rng = Rng::new(77);
    for k in (1..lines.len()).rev() {
        lines.swap(k, rng.below(k as u32 + 1) as usize);
    }
    // Blank lines and CRLF endings are tolerated.
    let shuffled = format!("{header}\r\n{}\n\n", lines.join("\r\n"));
    let (_, g) = read_bytes(&dir, "shuffled.txt", shuffled.as_bytes());
    assert_eq!(bits(&g.unwrap()), bits(&f));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn malformed_text_files_name_the_file_and_the_line() {
    let dir = scratch_dir("rayfile-bad-text");
    let rest = "0.5 0.25 0.125 0 0 1";
    let good = format!("2 2\n0 0 {rest}\n1 0 {rest}\n0 1 {rest}\n1 1 {rest}\n");
    assert!(read_bytes(&dir, "good.txt", good.as_bytes()).1.is_ok());
    let sub = |from: &str, to: &str| good.replacen(from, to, 1);
    let cases: &[(&str, String, &[&str])] = &[
        ("empty.txt", String::new(), &["empty"]),
        ("blank.txt", "\n \n".into(), &["empty"]),
        ("garbage.txt", "hello world\n".into(), &["neither a binary ray file"]),
        (
            "truncated.txt",
            good.lines().take(4).collect::<Vec<_>>().join("\n"),
            &["pixel (1, 1)", "no record", "3 of 4"],
        ),
        ("cut-line.txt", sub(&format!("1 1 {rest}\n"), "1 1 0.5 0.25 0.125"), &["line 5", "5 fields"]),
        ("duplicate.txt", sub("1 1 0.5", "1 0 0.5"), &["line 5 (pixel (1, 0))", "second record"]),
        ("missing.txt", sub(&format!("1 1 {rest}\n"), "\n"), &["pixel (1, 1)", "no record"]),
        ("outside.txt", sub("1 1 0.5", "2 1 0.5"), &["line 5", "column 2 is outside"]),
        ("negative.txt", sub("1 1 0.5", "-1 1 0.5"), &["line 5", "`-1` is not a pixel index"]),
        ("nan.txt", sub("0 1 0.5", "0 1 NaN"), &["line 4 (pixel (0, 1))", "not finite"]),
        (
            "inf.txt",
            sub(&format!("0 1 {rest}"), "0 1 0.5 0.25 0.125 0 0 inf"),
            &["line 4 (pixel (0, 1))", "not finite"],
        ),
        (
            "nonunit.txt",
            sub(&format!("1 0 {rest}"), "1 0 0.5 0.25 0.125 0 0 1.01"),
            &["line 3 (pixel (1, 0))", "not unit"],
        ),
        ("word.txt", sub("1 0 0.5", "1 0 x"), &["line 3 (pixel (1, 0))", "`x` is not a number"]),
        (
            "extra.txt",
            sub(&format!("1 0 {rest}"), &format!("1 0 {rest} 9")),
            &["line 3", "more than 8 fields"],
        ),
        ("header-bigger.txt", good.replacen("2 2", "3 2", 1), &["pixel (2, 0)", "no record"]),
        ("header-smaller.txt", good.replacen("2 2", "1 2", 1), &["line 3", "column 1 is outside"]),
        ("absurd.txt", format!("1000000 1000000\n0 0 {rest}\n"), &["line 1", "beyond the limits"]),
        ("big-short.txt", format!("10000 10000\n0 0 {rest}\n"), &["cannot hold", "truncated"]),
        ("zero.txt", "0 4\n".into(), &["empty"]),
    ];
    for (name, text, wants) in cases {
        expect_error(&dir, name, text.as_bytes(), wants);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn malformed_binary_files_name_the_file_and_the_record() {
    let dir = scratch_dir("rayfile-bad-binary");
    let good = encode(&sample(3, 2, 5), RayFormat::Binary);
    let set_f32 = |b: &mut Vec<u8>, record: usize, field: usize, v: f32| {
        let o = HEADER_LEN + record * RECORD_LEN + field * 4;
        b[o..o + 4].copy_from_slice(&v.to_le_bytes());
    };
    let set_word =
        |b: &mut Vec<u8>, k: usize, v: u32| b[8 + 4 * k..12 + 4 * k].copy_from_slice(&v.to_le_bytes());
    let with = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = good.clone();
        f(&mut b);
        b
    };
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        ("truncated.mcr", good[..good.len() - 5].to_vec(), &["truncated", "3x2"]),
        ("header-only.mcr", good[..20].to_vec(), &["truncated binary header"]),
        ("trailing.mcr", [good.as_slice(), &[0, 0]].concat(), &["trailing bytes"]),
        ("nan.mcr", with(&|b| set_f32(b, 4, 1, f32::NAN)), &["record 4 (pixel (1, 1))", "not finite"]),
        ("inf.mcr", with(&|b| set_f32(b, 2, 5, f32::INFINITY)), &["record 2 (pixel (2, 0))", "not finite"]),
        ("nonunit.mcr", with(&|b| set_f32(b, 5, 3, 0.5)), &["record 5 (pixel (2, 1))", "not unit"]),
        (
            "zero-dir.mcr",
            with(&|b| (3..6).for_each(|f| set_f32(b, 1, f, 0.0))),
            &["record 1 (pixel (1, 0))", "not unit"],
        ),
        ("wrong-size.mcr", with(&|b| set_word(b, 1, 4)), &["a 4x2 binary ray file is"]),
        ("absurd.mcr", with(&|b| (1..3).for_each(|k| set_word(b, k, 1_000_000))), &["beyond the limits"]),
        ("empty-size.mcr", with(&|b| set_word(b, 2, 0)), &["is empty"]),
        ("version.mcr", with(&|b| set_word(b, 0, 2)), &["version 2 is not supported"]),
        ("flags.mcr", with(&|b| set_word(b, 5, 6)), &["unknown flags"]),
        ("empty.mcr", Vec::new(), &["empty"]),
    ];
    for (name, bytes, wants) in &cases {
        expect_error(&dir, name, bytes, wants);
    }
    // Random garbage (with and without the magic) is refused, never a panic.
    let mut rng = Rng::new(3);
    for k in 0..200 {
        let len = rng.below(300) as usize;
        let mut b: Vec<u8> = (0..len).map(|_| rng.below(256) as u8).collect();
        if k % 2 == 0 && b.len() >= 8 {
            b[..8].copy_from_slice(&MAGIC);
        }
        let _ = RayFile::parse(&b, Path::new("garbage.mcr"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_files_and_bad_rays_on_write_are_errors() {
    let dir = scratch_dir("rayfile-write");
    let err = RayFile::read(&dir.join("nope.mcr")).unwrap_err().to_string();
    assert!(err.contains("nope.mcr"), "{err}");
    let mut f = sample(2, 2, 1);
    f.rays[3].direction = Vec3::new(0.0, 0.0, 2.0);
    let err = f.write(&dir.join("bad.mcr"), RayFormat::Binary).unwrap_err().to_string();
    assert!(err.contains("bad.mcr") && err.contains("pixel (1, 1)"), "{err}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
    assert!(RayFile::new(2, 2, 0, 0, vec![StoredRay::default(); 3]).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Cutting a border keeps the inner rays bit for bit, in place, and the header's fields.
#[test]
fn a_border_is_cut_exactly() {
    let f = RayFile { frame: 7, camera_id: 3, ..sample(9, 6, 11) };
    let inner = f.without_border(2).unwrap();
    assert_eq!((inner.width, inner.height, inner.frame, inner.camera_id), (5, 2, 7, 3));
    for (i, j) in [(0, 0), (4, 0), (2, 1), (4, 1)] {
        assert_eq!(bytemuck::bytes_of(inner.get(i, j)), bytemuck::bytes_of(f.get(i + 2, j + 2)));
    }
    assert_eq!(f.without_border(0).map(|g| bits(&g)), Some(bits(&f)));
    assert!(f.without_border(3).is_none());
}
