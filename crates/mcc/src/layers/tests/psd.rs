//! PSD: files built from the specification's layout (8-bit RGB, raw or PackBits channels), read
//! against the same brute-force rule.

use super::*;

/// One PSD layer record to write: the test layer, plus a blend key, a section divider type
/// (0 layer, 1 open folder, 3 bounding divider) and extra tagged blocks.
struct PsdRecord {
    layer: TestLayer,
    blend: [u8; 4],
    section: u32,
    rle: bool,
    clipped: bool,
    extra: Vec<([u8; 4], Vec<u8>)>,
}

fn psd_layer(layer: TestLayer) -> PsdRecord {
    PsdRecord { layer, blend: *b"norm", section: 0, rle: false, clipped: false, extra: Vec::new() }
}

fn packbits(row: &[u8]) -> Vec<u8> {
    // Repeat runs for equal bytes, literals otherwise (a valid, if not optimal, encoding).
    let mut out = Vec::new();
    let mut i = 0;
    while i < row.len() {
        let mut n = 1;
        while i + n < row.len() && row[i + n] == row[i] && n < 128 {
            n += 1;
        }
        if n > 1 {
            out.push((1i16 - n as i16) as i8 as u8);
            out.push(row[i]);
        } else {
            out.push(0);
            out.push(row[i]);
        }
        i += n;
    }
    out
}

/// Writes records (given top first, as a user sees them) as a PSD; `depth` 8.
fn write_psd(path: &Path, w: u32, h: u32, top_first: &[PsdRecord]) {
    let be16 = |v: u16| v.to_be_bytes();
    let be32 = |v: u32| v.to_be_bytes();
    let mut records = Vec::new();
    let mut data = Vec::new();
    for r in top_first.iter().rev() {
        let l = &r.layer;
        let (lw, lh) = if r.section == 0 { l.alpha.dimensions() } else { (0, 0) };
        let alpha: Vec<u8> = l.alpha.pixels().map(|p| p.0[1]).collect();
        let channel = |plane: &[u8]| -> Vec<u8> {
            if lw == 0 || lh == 0 {
                return be16(0).to_vec();
            }
            if r.rle {
                let rows: Vec<Vec<u8>> = plane.chunks(lw as usize).map(packbits).collect();
                let mut out = be16(1).to_vec();
                for row in &rows {
                    out.extend(be16(row.len() as u16));
                }
                rows.iter().for_each(|row| out.extend(row));
                out
            } else {
                let mut out = be16(0).to_vec();
                out.extend(plane);
                out
            }
        };
        let grey: Vec<u8> = l.alpha.pixels().map(|p| p.0[0]).collect();
        let channels: Vec<(i16, Vec<u8>)> = if r.section == 0 {
            vec![(-1, channel(&alpha)), (0, channel(&grey)), (1, channel(&grey)), (2, channel(&grey))]
        } else {
            vec![(-1, channel(&[])), (0, channel(&[])), (1, channel(&[])), (2, channel(&[]))]
        };
        let mut rec = Vec::new();
        for v in [l.y, l.x, l.y + lh as i32, l.x + lw as i32] {
            rec.extend(v.to_be_bytes());
        }
        rec.extend(be16(channels.len() as u16));
        for (id, bytes) in &channels {
            rec.extend(id.to_be_bytes());
            rec.extend(be32(bytes.len() as u32));
        }
        rec.extend(b"8BIM");
        rec.extend(r.blend);
        rec.push((l.opacity * 255.0).round() as u8);
        rec.push(r.clipped as u8);
        rec.push(if l.visible { 0 } else { 2 });
        rec.push(0);
        let mut extra = Vec::new();
        extra.extend(be32(0)); // no mask
        extra.extend(be32(0)); // no blending ranges
        let name = l.name.as_bytes();
        extra.push(name.len() as u8);
        extra.extend(name);
        while (extra.len() - 8) % 4 != 0 {
            extra.push(0);
        }
        let mut blocks = r.extra.clone();
        if r.section != 0 {
            let mut b = be32(r.section).to_vec();
            b.extend(b"8BIMpass");
            blocks.push((*b"lsct", b));
        }
        for (key, bytes) in blocks {
            extra.extend(b"8BIM");
            extra.extend(key);
            extra.extend(be32(bytes.len() as u32));
            extra.extend(bytes);
        }
        rec.extend(be32(extra.len() as u32));
        rec.extend(extra);
        records.push(rec);
        channels.into_iter().for_each(|(_, bytes)| data.extend(bytes));
    }
    let mut info = be16(top_first.len() as u16).to_vec();
    records.iter().for_each(|r| info.extend(r));
    info.extend(data);
    let mut section = be32(info.len() as u32).to_vec();
    section.extend(info);
    section.extend(be32(0)); // global layer mask info
    let mut out = b"8BPS".to_vec();
    out.extend(be16(1));
    out.extend([0; 6]);
    out.extend(be16(4));
    out.extend(be32(h));
    out.extend(be32(w));
    out.extend(be16(8));
    out.extend(be16(3));
    out.extend(be32(0)); // colour mode data
    out.extend(be32(0)); // image resources
    out.extend(be32(section.len() as u32));
    out.extend(section);
    out.extend(be16(0)); // merged image, raw (its contents are not read)
    std::fs::write(path, out).unwrap();
}

/// The busy stack as PSD records (groups become folder … divider pairs), top first.
fn psd_records(items: &[Item], rle: bool, out: &mut Vec<PsdRecord>) {
    for item in items {
        match item {
            Item::Layer(l) => out.push(PsdRecord { rle, ..psd_layer(l.clone()) }),
            Item::Group(name, opacity, visible, children) => {
                let mut folder = layer(name, 0, 0, 0, 0, |_, _| 0);
                folder.opacity = *opacity;
                folder.visible = *visible;
                out.push(PsdRecord { section: 1, ..psd_layer(folder) });
                psd_records(children, rle, out);
                out.push(PsdRecord {
                    section: 3,
                    ..psd_layer(layer("</Layer group>", 0, 0, 0, 0, |_, _| 0))
                });
            }
        }
    }
}

#[test]
fn psd_composite_matches_brute_force() {
    let dir = scratch_dir("layers-psd");
    let items = busy_stack();
    let names = CameraNames::ids(Some([1, 2, 3, 4, 5].into()));
    // PSD opacity is a byte: 0.8 and 0.7 become 204/255 and 179/255, so the brute force gets
    // the same rounded values.
    let rounded = |items: &[Item]| -> Vec<Item> {
        fn round(items: &[Item]) -> Vec<Item> {
            items
                .iter()
                .map(|i| match i {
                    Item::Layer(l) => {
                        Item::Layer(TestLayer { opacity: (l.opacity * 255.0).round() / 255.0, ..l.clone() })
                    }
                    Item::Group(n, o, v, c) => {
                        Item::Group(n.clone(), (o * 255.0).round() / 255.0, *v, round(c))
                    }
                })
                .collect()
        }
        round(items)
    };
    let want = brute_force(&rounded(&items), 20, 12, &id_of);
    for rle in [false, true] {
        let path = dir.join(if rle { "rle.psd" } else { "raw.psd" });
        let mut records = Vec::new();
        psd_records(&items, rle, &mut records);
        write_psd(&path, 20, 12, &records);
        let opened = open_collage(&path, None, &names, CollageOptions::default()).unwrap();
        assert_eq!(opened.collage.ids, want, "rle {rle}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn psd_unsupported_features_are_refused_by_name() {
    let dir = scratch_dir("layers-psd-bad");
    let base = || psd_layer(layer("1", 0, 0, 4, 4, |_, _| 255));
    let cases: Vec<(&str, PsdRecord, &[&str])> = vec![
        ("multiply.psd", PsdRecord { blend: *b"mul ", ..base() }, &["layer \"1\"", "blend mode Multiply"]),
        ("clip.psd", PsdRecord { clipped: true, ..base() }, &["clipping mask"]),
        (
            "adjust.psd",
            PsdRecord { extra: vec![(*b"levl", vec![0; 4])], ..base() },
            &["adjustment or fill layer"],
        ),
        ("vmask.psd", PsdRecord { extra: vec![(*b"vmsk", vec![0; 8])], ..base() }, &["vector mask"]),
    ];
    for (name, record, want) in cases {
        let path = dir.join(name);
        write_psd(&path, 4, 4, &[record]);
        let err = open_collage(&path, None, &CameraNames::ids(None), CollageOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains(name), "{err}");
        for w in want {
            assert!(err.contains(w), "{err:?} lacks {w:?}");
        }
    }
    // Fill opacity multiplies the opacity: 40 % fill leaves a full layer under ½.
    let path = dir.join("fill.psd");
    write_psd(&path, 4, 4, &[PsdRecord { extra: vec![(*b"iOpa", vec![102, 0, 0, 0])], ..base() }]);
    let opened = open_collage(&path, None, &CameraNames::ids(None), CollageOptions::default()).unwrap();
    assert!(opened.collage.ids.iter().all(|&id| id == 0));
    assert!(opened.notes[0].contains("takes no pixel"), "{:?}", opened.notes);
    // Truncated anywhere: an error naming the part, never a panic.
    let full = std::fs::read(&path).unwrap();
    // (The last two bytes are the merged image's compression field, which is not read.)
    for cut in (0..full.len() - 2).step_by(7) {
        let p = dir.join("cut.psd");
        std::fs::write(&p, &full[..cut]).unwrap();
        let err = open_collage(&p, None, &CameraNames::ids(None), CollageOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("cut.psd"), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tagged_images_read_as_before() {
    let dir = scratch_dir("layers-tagged");
    let code = crate::tag::TagCode::default();
    let img = RgbImage::from_fn(5, 3, |x, _| {
        if x < 2 { Rgb(code.encode([90, 90, 90], 2).unwrap()) } else { Rgb([0, 0, 0]) }
    });
    let path = dir.join("cut.png");
    crate::png::write_png(&path, &DynamicImage::ImageRgb8(img)).unwrap();
    let names = CameraNames::ids(Some([2].into()));
    let opened = open_collage(&path, None, &names, CollageOptions::default()).unwrap();
    let (direct, _) = Collage::load(&path, names.known(), CollageOptions::default()).unwrap();
    assert_eq!(opened.collage, direct);
    assert_eq!(Format::of(&path).unwrap(), Format::Image);
    std::fs::remove_dir_all(&dir).unwrap();
}
