//! Layered collages: the compositing rule against a brute-force per-pixel evaluation, both
//! readers on files built byte by byte from their specifications, and malformed files.

use super::openraster::{self, ViewLayer};
use super::*;
use crate::test_util::scratch_dir;
use image::{DynamicImage, GrayAlphaImage, LumaA, Rgb, RgbImage};
use std::io::Write;

/// A layer built by hand: name, offset, alpha plane, opacity, visibility.
#[derive(Clone)]
struct TestLayer {
    name: String,
    x: i32,
    y: i32,
    alpha: GrayAlphaImage,
    opacity: f32,
    visible: bool,
}

fn layer(name: &str, x: i32, y: i32, w: u32, h: u32, alpha: impl Fn(u32, u32) -> u8) -> TestLayer {
    // Grey, except a background layer, which is black as `render --layers` writes it.
    let grey = if name == "background" { 0 } else { 128 };
    let alpha = GrayAlphaImage::from_fn(w, h, |i, j| LumaA([grey, alpha(i, j)]));
    TestLayer { name: name.into(), x, y, alpha, opacity: 1.0, visible: true }
}

/// An item of a hand-built stack: a layer or a group (name, opacity, visible, children).
#[derive(Clone)]
enum Item {
    Layer(TestLayer),
    Group(String, f32, bool, Vec<Item>),
}

fn png_bytes(image: &GrayAlphaImage) -> Vec<u8> {
    let mut out = Vec::new();
    DynamicImage::ImageLumaA8(image.clone())
        .write_with_encoder(image::codecs::png::PngEncoder::new(&mut out))
        .unwrap();
    out
}

/// Writes an OpenRaster file of `items` (first on top) with `stack.xml` as the spec lays it out.
fn write_ora(path: &Path, w: u32, h: u32, items: &[Item]) {
    fn xml(items: &[Item], out: &mut String, pngs: &mut Vec<(String, Vec<u8>)>) {
        for item in items {
            match item {
                Item::Layer(l) => {
                    let src = format!("data/l{}.png", pngs.len());
                    out.push_str(&format!(
                        "<layer name=\"{}\" src=\"{src}\" x=\"{}\" y=\"{}\" opacity=\"{}\" visibility=\"{}\"/>",
                        l.name,
                        l.x,
                        l.y,
                        l.opacity,
                        if l.visible { "visible" } else { "hidden" }
                    ));
                    pngs.push((src, png_bytes(&l.alpha)));
                }
                Item::Group(name, opacity, visible, children) => {
                    out.push_str(&format!(
                        "<stack name=\"{name}\" opacity=\"{opacity}\" visibility=\"{}\">",
                        if *visible { "visible" } else { "hidden" }
                    ));
                    xml(children, out, pngs);
                    out.push_str("</stack>");
                }
            }
        }
    }
    let mut stack = String::new();
    let mut pngs = Vec::new();
    xml(items, &mut stack, &mut pngs);
    let doc = format!(
        "<?xml version='1.0'?><image version=\"0.0.5\" w=\"{w}\" h=\"{h}\"><stack>{stack}</stack></image>"
    );
    write_zip(path, &[("mimetype", openraster::MIMETYPE.as_bytes())], &doc, &pngs);
}

fn write_zip(path: &Path, first: &[(&str, &[u8])], stack_xml: &str, rest: &[(String, Vec<u8>)]) {
    let mut zip = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    let stored = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let deflated =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, bytes) in first {
        zip.start_file(*name, stored).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.start_file("stack.xml", deflated).unwrap();
    zip.write_all(stack_xml.as_bytes()).unwrap();
    for (name, bytes) in rest {
        zip.start_file(name.as_str(), deflated).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap();
}

/// The rule evaluated per pixel, the slow way: walk the items top to bottom, the first visible
/// layer whose alpha/255 · opacity (groups' included) ≥ ½ there names the pixel.
fn brute_force(items: &[Item], w: u32, h: u32, id_of: &dyn Fn(&str) -> u32) -> Vec<u32> {
    fn at(items: &[Item], x: i32, y: i32, opacity: f64, id_of: &dyn Fn(&str) -> u32) -> Option<u32> {
        for item in items {
            match item {
                Item::Layer(l) if l.visible => {
                    let (i, j) = (x - l.x, y - l.y);
                    if i >= 0 && j >= 0 && (i as u32) < l.alpha.width() && (j as u32) < l.alpha.height() {
                        let a = l.alpha.get_pixel(i as u32, j as u32).0[1] as f64 / 255.0;
                        if a * opacity * l.opacity as f64 >= 0.5 {
                            return Some(id_of(&l.name));
                        }
                    }
                }
                Item::Group(_, o, true, children) => {
                    if let Some(id) = at(children, x, y, opacity * *o as f64, id_of) {
                        return Some(id);
                    }
                }
                _ => {}
            }
        }
        None
    }
    let mut out = Vec::new();
    for y in 0..h as i32 {
        for x in 0..w as i32 {
            out.push(at(items, x, y, 1.0, id_of).unwrap_or(0));
        }
    }
    out
}

fn id_of(name: &str) -> u32 {
    match CameraNames::ids(None).resolve(name).unwrap() {
        Some(Role::Camera(id)) => id,
        _ => 0,
    }
}

/// A stack that exercises every rule: soft and feathered alpha, offsets past every edge,
/// opacity, a hidden layer, a hidden group, nested group opacity, a background layer above a
/// camera, exactly-½ thresholds.
fn busy_stack() -> Vec<Item> {
    let soft = |i: u32, j: u32| ((i * 37 + j * 11) % 256) as u8;
    let mut faded = layer("camera 4", 0, 0, 20, 12, |_, _| 255);
    faded.opacity = 0.5; // 255/255 · 0.5 = ½ exactly: claims
    let mut hidden = layer("camera 9", 0, 0, 20, 12, |_, _| 255);
    hidden.visible = false;
    vec![
        Item::Layer(hidden),
        Item::Layer(layer("left (camera 1)", -3, -2, 9, 7, soft)),
        Item::Group(
            "fx".into(),
            0.8,
            true,
            vec![
                Item::Layer(layer("3", 14, 8, 10, 10, |i, _| if i % 2 == 0 { 160 } else { 255 })),
                Item::Group(
                    "inner".into(),
                    0.7,
                    true,
                    vec![Item::Layer(layer("camera 2", 5, 3, 6, 6, |_, _| 255))],
                ),
            ],
        ),
        Item::Group("off".into(), 1.0, false, vec![Item::Layer(layer("camera 7", 0, 0, 20, 12, |_, _| 255))]),
        Item::Layer(layer("background", 10, 0, 3, 12, |_, _| 255)),
        Item::Layer(layer("frame0000camera05.png copy", 2, 5, 14, 3, |i, _| (i * 19) as u8)),
        Item::Layer(faded),
    ]
}

#[test]
fn openraster_composite_matches_brute_force() {
    let dir = scratch_dir("layers-busy");
    let path = dir.join("cut.ora");
    let items = busy_stack();
    write_ora(&path, 20, 12, &items);
    let names = CameraNames::ids(Some([1, 2, 3, 4, 5].into()));
    let opened = open_collage(&path, None, &names, CollageOptions::default()).unwrap();
    let want = brute_force(&items, 20, 12, &id_of);
    assert_eq!(opened.collage.ids, want);
    // Every camera and the background layer are really exercised.
    for id in [0, 1, 3, 4, 5] {
        assert!(want.contains(&id), "camera {id} takes no pixel: the stack tests less than it claims");
    }
    // Camera 2 sits at 0.8 · 0.7 = 0.56 ≥ ½ but under camera 3's odd columns (255 · 0.8 ≥ ½).
    assert!(want.contains(&2));
    assert_eq!(opened.regions_from, RegionSource::None);
    assert_eq!(opened.regions.count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn threshold_is_exact() {
    assert_eq!(threshold(1.0), Some(32768)); // 8-bit 128 · 257 = 32896 ≥, 127 · 257 = 32639 <
    assert_eq!(threshold(0.5), Some(OPAQUE));
    assert_eq!(threshold(0.499), None);
    assert_eq!(threshold(0.0), None);
    for opacity in [0.5f32, 0.51, 0.6, 0.75, 0.9, 0.999, 1.0] {
        let t = threshold(opacity).unwrap() as f64;
        assert!(t * opacity as f64 >= 32767.5 && (t - 1.0) * (opacity as f64) < 32767.5, "{opacity}");
    }
}

#[test]
fn regions_group_and_layered_region_file() {
    let dir = scratch_dir("layers-regions");
    let path = dir.join("cut.ora");
    let items = vec![
        Item::Group(
            "Regions".into(),
            1.0,
            true,
            vec![
                Item::Layer(layer("sky", 0, 0, 8, 2, |_, _| 255)),
                Item::Layer(layer("floor", 0, 4, 8, 2, |_, _| 255)),
            ],
        ),
        Item::Layer(layer("1", 0, 0, 4, 6, |_, _| 255)),
        Item::Layer(layer("2", 4, 0, 4, 6, |_, _| 255)),
    ];
    write_ora(&path, 8, 6, &items);
    let names = CameraNames::ids(Some([1, 2].into()));
    let opened = open_collage(&path, None, &names, CollageOptions::default()).unwrap();
    assert_eq!(opened.regions_from, RegionSource::Group);
    assert_eq!(opened.collage.id(0, 0), 1);
    assert_eq!(opened.collage.id(7, 5), 2);
    // sky (rows 0-1) is region 0, the rest (rows 2-3) region 1, floor (rows 4-5) region 2.
    let rows: Vec<u32> = (0..6).map(|y| opened.regions.at(3, y)).collect();
    assert_eq!(rows, vec![0, 0, 1, 1, 2, 2]);
    assert_eq!(opened.regions.info[0].to_string(), "layer \"sky\", first pixel (0, 0)");
    // A region image beside the collage too: ambiguous, refused.
    crate::png::write_png(&Regions::beside(&path), &DynamicImage::ImageRgb8(RgbImage::new(8, 6))).unwrap();
    let err = open_collage(&path, None, &names, CollageOptions::default()).unwrap_err().to_string();
    assert!(
        err.contains("cut.ora") && err.contains("group \"regions\"") && err.contains("cut-regions.png"),
        "{err}"
    );
    // The same regions as a separate layered file, for a tagged-free collage without the group.
    let plain = dir.join("plain.ora");
    write_ora(&plain, 8, 6, &items[1..]);
    let region_file = dir.join("zones.ora");
    write_ora(
        &region_file,
        8,
        6,
        match &items[0] {
            Item::Group(_, _, _, children) => children,
            _ => unreachable!(),
        },
    );
    let opened = open_collage(&plain, Some(&region_file), &names, CollageOptions::default()).unwrap();
    assert_eq!(opened.regions_from, RegionSource::File(region_file.clone()));
    assert_eq!((0..6).map(|y| opened.regions.at(3, y)).collect::<Vec<_>>(), rows);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn names_are_checked_against_the_ray_files() {
    let dir = scratch_dir("layers-names");
    let path = dir.join("cut.ora");
    let names = CameraNames::ids(Some([1, 2].into()));
    let open = |items: &[Item]| {
        write_ora(&path, 4, 4, items);
        open_collage(&path, None, &names, CollageOptions::default()).map(|o| o.collage.ids)
    };
    let err = open(&[Item::Layer(layer("Layer 1", 0, 0, 4, 4, |_, _| 255))]).unwrap_err().to_string();
    assert!(err.contains("cut.ora: layer \"Layer 1\": names no camera"), "{err}");
    let err = open(&[Item::Layer(layer("camera 7", 0, 0, 4, 4, |_, _| 255))]).unwrap_err().to_string();
    assert!(
        err.contains("layer \"camera 7\": is camera 7, which has no ray file (cameras with ray files: 1, 2)"),
        "{err}"
    );
    // A hidden misnamed layer is no error; a layer inside a group named after a camera is it.
    let mut hidden = layer("sketch", 0, 0, 4, 4, |_, _| 255);
    hidden.visible = false;
    let ids = open(&[
        Item::Layer(hidden),
        Item::Group(
            "camera 2".into(),
            1.0,
            true,
            vec![Item::Layer(layer("Paint Layer 3", 0, 0, 2, 4, |_, _| 255))],
        ),
    ])
    .unwrap();
    assert_eq!(ids, [2, 2, 0, 0].repeat(4));
    // GIMP names the first view it opens "Background": a picture there is not the background.
    let mut picture = layer("Background", 0, 0, 4, 4, |_, _| 255);
    picture.alpha.put_pixel(1, 1, LumaA([200, 255]));
    let err = open(&[Item::Layer(picture)]).unwrap_err().to_string();
    assert!(
        err.contains("layer \"Background\": is named as the background, but it holds a picture"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn written_views_read_back() {
    let dir = scratch_dir("layers-write");
    let path = dir.join("views.ora");
    let a = RgbImage::from_fn(6, 4, |x, y| Rgb([x as u8 * 40, y as u8 * 60, 7]));
    let b = RgbImage::from_pixel(6, 4, Rgb([1, 2, 3]));
    let views = [
        ViewLayer { id: 2, name: "right & <wide>", image: &b },
        ViewLayer { id: 1, name: "left", image: &a },
    ];
    openraster::write(&path, &views).unwrap();
    let ora = openraster::OpenRaster::open(&path).unwrap();
    let tree = ora.tree();
    let names: Vec<&str> = tree.nodes.iter().map(|n| n.name.as_str()).collect();
    assert_eq!(names, ["left (camera 1)", "right & <wide> (camera 2)", "background"]);
    assert_eq!((tree.width, tree.height), (6, 4));
    // The top view covers everything.
    let opened =
        open_collage(&path, None, &CameraNames::ids(Some([1, 2].into())), CollageOptions::default()).unwrap();
    assert!(opened.collage.ids.iter().all(|&id| id == 1));
    // The archive is what editors expect: mimetype first and stored, the merged image present.
    let mut zip = zip::ZipArchive::new(std::fs::File::open(&path).unwrap()).unwrap();
    let first = zip.by_index(0).unwrap();
    assert_eq!(
        (first.name().unwrap().into_owned(), first.compression()),
        ("mimetype".to_owned(), zip::CompressionMethod::Stored)
    );
    drop(first);
    let mut merged = Vec::new();
    std::io::Read::read_to_end(&mut zip.by_name("mergedimage.png").unwrap(), &mut merged).unwrap();
    let merged = image::load_from_memory(&merged).unwrap().to_rgb8();
    assert_eq!(merged, a);
    assert!(zip.by_name("Thumbnails/thumbnail.png").is_ok());
    // Views of two sizes are refused before anything is written.
    let small = RgbImage::new(3, 3);
    let other = dir.join("bad.ora");
    let err =
        openraster::write(&other, &[views[1], ViewLayer { id: 3, name: "c", image: &small }]).unwrap_err();
    assert!(err.to_string().contains("camera 3's view is 3x3"), "{err}");
    assert!(!other.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A malformed OpenRaster file and the words its error must contain (besides the file name).
fn ora_error(dir: &Path, name: &str, build: impl FnOnce(&Path), want: &[&str]) {
    let path = dir.join(name);
    build(&path);
    let err = open_collage(&path, None, &CameraNames::ids(None), CollageOptions::default())
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(err.contains(name), "{err:?} does not name the file");
    for w in want {
        assert!(err.contains(w), "{err:?} lacks {w:?}");
    }
}

#[test]
fn malformed_openraster_files_are_refused_by_entry() {
    let dir = scratch_dir("layers-bad-ora");
    let mime = [("mimetype", openraster::MIMETYPE.as_bytes())];
    let doc = |body: &str| format!("<image w=\"4\" h=\"4\"><stack>{body}</stack></image>");
    let png = png_bytes(&GrayAlphaImage::from_pixel(4, 4, LumaA([0, 255])));
    let one_layer = doc("<layer name=\"1\" src=\"data/a.png\"/>");
    ora_error(
        &dir,
        "notzip.ora",
        |p| std::fs::write(p, b"not a zip at all").unwrap(),
        &["archive", "not a readable zip"],
    );
    ora_error(
        &dir,
        "nostack.ora",
        |p| {
            let mut zip = zip::ZipWriter::new(std::fs::File::create(p).unwrap());
            zip.start_file("mimetype", zip::write::SimpleFileOptions::default()).unwrap();
            zip.write_all(openraster::MIMETYPE.as_bytes()).unwrap();
            zip.finish().unwrap();
        },
        &["stack.xml", "is missing"],
    );
    ora_error(
        &dir,
        "nomime.ora",
        |p| write_zip(p, &[], &one_layer, &[("data/a.png".into(), png.clone())]),
        &["mimetype: is missing"],
    );
    ora_error(
        &dir,
        "badmime.ora",
        |p| write_zip(p, &[("mimetype", b"image/png")], &one_layer, &[]),
        &["mimetype", "image/png"],
    );
    ora_error(
        &dir,
        "badxml.ora",
        |p| write_zip(p, &mime, "<image w=\"4\"", &[]),
        &["stack.xml", "malformed XML"],
    );
    ora_error(
        &dir,
        "huge.ora",
        |p| write_zip(p, &mime, "<image w=\"100000\" h=\"100000\"><stack/></image>", &[]),
        &["stack.xml", "100000x100000"],
    );
    ora_error(
        &dir,
        "nosrc.ora",
        |p| write_zip(p, &mime, &one_layer, &[]),
        &["stack.xml", "data/a.png", "not in the archive"],
    );
    ora_error(
        &dir,
        "multiply.ora",
        |p| {
            write_zip(
                p,
                &mime,
                &doc("<layer name=\"1\" src=\"data/a.png\" composite-op=\"svg:multiply\"/>"),
                &[("data/a.png".into(), png.clone())],
            )
        },
        &["svg:multiply", "Normal"],
    );
    ora_error(
        &dir,
        "text.ora",
        |p| write_zip(p, &mime, &doc("<text name=\"t\"/>"), &[]),
        &["<text>", "not supported"],
    );
    ora_error(
        &dir,
        "opacity.ora",
        |p| {
            write_zip(
                p,
                &mime,
                &doc("<layer name=\"1\" src=\"data/a.png\" opacity=\"NaN\"/>"),
                &[("data/a.png".into(), png.clone())],
            )
        },
        &["opacity \"NaN\""],
    );
    ora_error(
        &dir,
        "notpng.ora",
        |p| write_zip(p, &mime, &one_layer, &[("data/a.png".into(), b"GIF89a....".repeat(5))]),
        &["data/a.png", "not a PNG"],
    );
    // A PNG whose IHDR claims 2^30 pixels: refused from the header, before anything is decoded.
    let mut absurd = png.clone();
    absurd[16..24].copy_from_slice(&[0, 0, 0x80, 0, 0, 0, 0x80, 0]);
    ora_error(
        &dir,
        "bigpng.ora",
        |p| write_zip(p, &mime, &one_layer, &[("data/a.png".into(), absurd)]),
        &["data/a.png", "32768x32768"],
    );
    // A zip bomb: 64 MiB of spaces deflate to a few kilobytes.
    let bomb = format!("{}{}", " ".repeat(64 << 20), one_layer);
    ora_error(
        &dir,
        "bomb.ora",
        |p| write_zip(p, &mime, &bomb, &[]),
        &["stack.xml", "claims 67108", "more than 4194304"],
    );
    // The same bomb lying about its size (100 bytes in both headers): the zip crate stops at the
    // declared size (and the read limit would stop it at 4 MiB anyway).
    ora_error(
        &dir,
        "liar.ora",
        |p| {
            write_zip(p, &mime, &bomb, &[]);
            let mut bytes = std::fs::read(p).unwrap();
            let size = (bomb.len() as u32).to_le_bytes();
            let at: Vec<usize> =
                bytes.windows(4).enumerate().filter(|(_, w)| *w == size).map(|(k, _)| k).collect();
            assert_eq!(at.len(), 2, "the local and central headers each hold the size once");
            for k in at {
                bytes[k..k + 4].copy_from_slice(&100u32.to_le_bytes());
            }
            std::fs::write(p, bytes).unwrap();
        },
        &["stack.xml: cannot read it", "larger than its declared uncompressed size"],
    );
    ora_error(
        &dir,
        "offset.ora",
        |p| {
            write_zip(
                p,
                &mime,
                &doc("<layer name=\"1\" src=\"data/a.png\" x=\"2000000000\"/>"),
                &[("data/a.png".into(), png.clone())],
            )
        },
        &["offset", "2000000000"],
    );
    let mut cut = png.clone();
    cut.truncate(png.len() - 20);
    ora_error(
        &dir,
        "truncated.ora",
        |p| write_zip(p, &mime, &one_layer, &[("data/a.png".into(), cut)]),
        &["data/a.png", "cannot decode"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

mod psd;
