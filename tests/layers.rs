//! Layered collages end to end (issue 27, part 1), through the real `mcctrace` command line run
//! in-process:
//!
//! - `render --layers views.ora` writes one layer per camera over a black background; a script
//!   edits it as a user would in an editor (erases parts of the top view with a hard eraser and
//!   a feathered brush, a hard corner of the other); `remap` of that ORA gives exactly the ray
//!   file (byte for byte) of the equivalent tagged PNG collage, composed pixel by pixel from the
//!   tagged views by the rule (the topmost layer whose alpha is at least ½ owns a pixel),
//!   evaluated here independently of the reader.
//! - Files saved by real editors (`tests/data/layers/`, their README says how they were made):
//!   an OpenRaster file Krita 5.1 saved and a PSD GIMP 2.10 saved read as the edits they were
//!   given (analytic boundaries: a linear feather, a Gaussian-feathered selection, an offset
//!   layer, a hidden layer, a group with opacity).

use crate::common::{Scratch, mcctrace, repo_root};
use mcc::image::{self, DynamicImage, RgbaImage};
use mcc::layers::{CameraNames, open_collage};
use std::io::{Read, Write};
use std::path::Path;

const W: u32 = 48;
const H: u32 = 36;

/// Renders the Cornell box from its two listed cameras (1 `cornell`, 2 `corner`) with the lens
/// writer, the tagger and `--layers`.
fn render_views(dir: &Scratch) {
    let cornell = repo_root().join("scenes/cornell");
    let cameras = cornell.join("cameras.json");
    mcctrace(&[
        "render",
        cornell.to_str().unwrap(),
        "--cameras-file",
        cameras.to_str().unwrap(),
        "--camera",
        "cornell",
        "--camera",
        "corner",
        "--res",
        &format!("{W}x{H}"),
        "--spp",
        "2",
        "--max-depth",
        "2",
        "--lens-writer",
        "--tag",
        "--layers",
        &dir.s("views.ora"),
        "--quiet",
        "--out",
        &dir.s("views"),
    ])
    .unwrap();
}

/// The entries of a zip archive, in order.
pub(crate) fn unzip(path: &Path) -> Vec<(String, Vec<u8>)> {
    let mut zip = zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
    (0..zip.len())
        .map(|k| {
            let mut entry = zip.by_index(k).unwrap();
            let mut bytes = Vec::new();
            entry.read_to_end(&mut bytes).unwrap();
            (entry.name().unwrap().into_owned(), bytes)
        })
        .collect()
}

pub(crate) fn rezip(path: &Path, entries: &[(String, Vec<u8>)]) {
    let mut zip = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    for (name, bytes) in entries {
        let method = if name == "mimetype" {
            zip::CompressionMethod::Stored
        } else {
            zip::CompressionMethod::Deflated
        };
        zip.start_file(name.as_str(), zip::write::SimpleFileOptions::default().compression_method(method))
            .unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap();
}

/// What the edit script does to a layer's alpha at (x, y): a factor in [0, 1] to multiply by.
pub(crate) type Edit = fn(u32, u32) -> f64;

/// Camera 1 (top): a hard eraser over a band on the right, and a feathered round brush (hard
/// core of radius 5, soft to radius 11) dabbed along a line on the left.
fn erase_top(x: u32, y: u32) -> f64 {
    if x >= 34 {
        return 0.0;
    }
    let mut keep: f64 = 1.0;
    for k in 0..5 {
        let (cx, cy) = (8.0 + 4.0 * k as f64, 10.0 + 3.0 * k as f64);
        let d = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt();
        let brush = ((11.0 - d) / 6.0).clamp(0.0, 1.0);
        keep = keep.min(1.0 - brush);
    }
    keep
}

/// Camera 2: a hard-edged corner erased, where the background shows.
fn erase_second(x: u32, y: u32) -> f64 {
    if x >= 40 && y < 10 { 0.0 } else { 1.0 }
}

/// Applies `edit` to a layer PNG's alpha the way an editor stores it: 8-bit, rounded.
pub(crate) fn edit_png(bytes: &[u8], edit: Edit) -> (Vec<u8>, RgbaImage) {
    let mut img = image::load_from_memory(bytes).unwrap().to_rgba8();
    for (x, y, p) in img.enumerate_pixels_mut() {
        p.0[3] = (p.0[3] as f64 * edit(x, y)).round() as u8;
    }
    let mut out = Vec::new();
    DynamicImage::ImageRgba8(img.clone())
        .write_with_encoder(image::codecs::png::PngEncoder::new(&mut out))
        .unwrap();
    (out, img)
}

fn remap(dir: &Scratch, collage: &str, out: &str) -> Vec<u8> {
    mcctrace(&["remap", "--collage", &dir.s(collage), "--rays", &dir.s("views"), "--out", &dir.s(out), "-q"])
        .unwrap();
    std::fs::read(dir.path(out)).unwrap()
}

#[test]
fn edited_openraster_remaps_like_the_equivalent_tagged_collage() {
    let dir = Scratch::new("layers-edited");
    render_views(&dir);
    let mut entries = unzip(&dir.path("views.ora"));
    assert_eq!(entries[0], ("mimetype".to_owned(), b"image/openraster".to_vec()));
    let stack = String::from_utf8(entries.iter().find(|(n, _)| n == "stack.xml").unwrap().1.clone()).unwrap();
    assert!(
        stack.contains("name=\"cornell (camera 1)\"") && stack.contains("name=\"corner (camera 2)\""),
        "{stack}"
    );
    // The "user" edits both view layers.
    let mut alpha = Vec::new();
    for (name, edit) in [("data/camera01.png", erase_top as Edit), ("data/camera02.png", erase_second)] {
        let entry = entries.iter_mut().find(|(n, _)| n == name).unwrap();
        let (bytes, img) = edit_png(&entry.1, edit);
        entry.1 = bytes;
        alpha.push(img);
    }
    rezip(&dir.path("cut.ora"), &entries);
    // The equivalent tagged collage: the rule, pixel by pixel, on the tagged views.
    let views: Vec<_> = (1..=2)
        .map(|id| image::open(dir.path(&format!("views/frame0000camera{id:02}.png"))).unwrap().to_rgb8())
        .collect();
    let mut collage = image::RgbImage::new(W, H);
    let mut owners = [0usize; 3];
    for (x, y, p) in collage.enumerate_pixels_mut() {
        let owner = (0..2).find(|&k| alpha[k].get_pixel(x, y).0[3] as f64 / 255.0 >= 0.5);
        owners[owner.map_or(0, |k| k + 1)] += 1;
        if let Some(k) = owner {
            *p = *views[k].get_pixel(x, y);
        }
    }
    // Every kind of pixel is there: camera 1, camera 2 (under the erased parts), background.
    assert!(owners.iter().all(|&n| n > 20), "{owners:?}");
    collage.save(dir.path("cut.png")).unwrap();
    let from_layers = remap(&dir, "cut.ora", "from-layers.mcr");
    let from_tags = remap(&dir, "cut.png", "from-tags.mcr");
    assert!(from_layers == from_tags, "the layered collage remaps differently from its tagged equivalent");
    // And the collages themselves agree id for id.
    let names = CameraNames::ids(Some([1, 2].into()));
    let a = open_collage(&dir.path("cut.ora"), None, &names, Default::default()).unwrap().collage;
    let b = open_collage(&dir.path("cut.png"), None, &names, Default::default()).unwrap().collage;
    assert_eq!(a, b);
}

#[test]
fn a_layer_named_after_its_camera_resolves_through_the_views_exr() {
    let dir = Scratch::new("layers-names");
    render_views(&dir);
    let mut entries = unzip(&dir.path("views.ora"));
    let stack = entries.iter_mut().find(|(n, _)| n == "stack.xml").unwrap();
    let renamed = String::from_utf8(stack.1.clone())
        .unwrap()
        .replace("corner (camera 2)", "corner")
        .replace("cornell (camera 1)", "Layer 1");
    stack.1 = renamed.into_bytes();
    // A layer renamed to something that names no camera is an error naming the layer.
    rezip(&dir.path("renamed.ora"), &entries);
    let err = mcctrace(&[
        "remap",
        "--collage",
        &dir.s("renamed.ora"),
        "--rays",
        &dir.s("views"),
        "--out",
        &dir.s("r.mcr"),
        "-q",
    ])
    .unwrap_err();
    let msg = format!("{err:#}");
    assert!(
        msg.contains("renamed.ora: layer \"Layer 1\": names no camera") && msg.contains("\"corner\" (2)"),
        "{msg}"
    );
    assert!(!dir.path("r.mcr").exists());
    // With camera 1's layer named by its camera's name too, the whole top view is camera 1.
    let stack = entries.iter_mut().find(|(n, _)| n == "stack.xml").unwrap();
    stack.1 = String::from_utf8(stack.1.clone()).unwrap().replace("Layer 1", "Cornell").into_bytes();
    rezip(&dir.path("renamed.ora"), &entries);
    let names = CameraNames::from_views([1, 2].into(), dir.path("views"), 0);
    let c = open_collage(&dir.path("renamed.ora"), None, &names, Default::default()).unwrap().collage;
    assert!(c.ids.iter().all(|&id| id == 1));
}

/// Issue 41, item 1: a layer `NAME (camera N)` whose name and number disagree over the views
/// (`wide (camera 1)` over views whose camera 1 is `cornell`) is refused, naming the layer,
/// both readings and the fix, and writes nothing.
#[test]
fn remap_refuses_a_layer_whose_name_and_number_disagree() {
    let dir = Scratch::new("layers-disagree");
    render_views(&dir);
    let entries = unzip(&dir.path("views.ora"));
    let remap_renamed = |from: &str, to: &str| {
        let mut entries = entries.clone();
        let stack = entries.iter_mut().find(|(n, _)| n == "stack.xml").unwrap();
        stack.1 = String::from_utf8(stack.1.clone()).unwrap().replace(from, to).into_bytes();
        rezip(&dir.path("renamed.ora"), &entries);
        let args = ["remap", "--collage", &dir.s("renamed.ora"), "--rays", &dir.s("views")];
        let out = dir.s("r.mcr");
        let result = mcctrace(&[&args[..], &["--out", &out, "-q"]].concat());
        assert!(result.is_err() != dir.path("r.mcr").exists(), "a refused remap writes nothing");
        let _ = std::fs::remove_file(dir.path("r.mcr"));
        result.map_err(|e| format!("{e:#}"))
    };
    // The name of another view: both readings and both renames are offered.
    let msg = remap_renamed("cornell (camera 1)", "corner (camera 1)").unwrap_err();
    assert!(
        msg.contains("layer \"corner (camera 1)\"")
            && msg.contains("its name says camera 2 (\"corner\")")
            && msg.contains("camera 1, which the views name \"cornell\"")
            && msg.contains("\"cornell (camera 1)\"")
            && msg.contains("\"corner (camera 2)\""),
        "{msg}"
    );
    // A name no view records, over a view that records another.
    let msg = remap_renamed("cornell (camera 1)", "wide (camera 1)").unwrap_err();
    assert!(
        msg.contains("layer \"wide (camera 1)\"")
            && msg.contains("\"wide\", which no view records")
            && msg.contains("the views name \"cornell\""),
        "{msg}"
    );
    // Name and number agreeing (the way `render --layers` writes them) still remap.
    remap_renamed("cornell (camera 1)", "Cornell (camera 1)").unwrap();
}

/// The fixture folder.
fn fixture(name: &str) -> std::path::PathBuf {
    repo_root().join("tests/data/layers").join(name)
}

#[test]
fn an_openraster_file_saved_by_krita_reads_as_edited() {
    // tests/data/layers/README.md: Krita opened views.ora (written by `render --layers`, 64x48),
    // erased camera 1's layer with a linear feather (alpha 1 up to x = 24, 0 from x = 40), moved
    // camera 2's layer into a group "right side" at 90 % opacity, erased camera 2's top right
    // corner (x ≥ 44, y < 12), added a hidden layer "sketch" on top and an opaque 10x6 layer
    // "camera 1 patch" at (50, 30), and saved as OpenRaster.
    let path = fixture("krita-edited.ora");
    let names = CameraNames::ids(Some([1, 2].into()));
    let opened = open_collage(&path, None, &names, Default::default()).unwrap();
    let c = &opened.collage;
    assert_eq!((c.width, c.height), (64, 48));
    for y in 0..48 {
        for x in 0..64 {
            let patch = (50..60).contains(&x) && (30..36).contains(&y);
            let feathered = x <= 31; // alpha = 255 · (39.5 − x) / 16 ≥ 127.5 ⇔ x ≤ 31.5
            let want = if patch || feathered {
                1
            } else if x >= 44 && y < 12 {
                0
            } else {
                2
            };
            assert_eq!(c.id(x, y), want, "pixel ({x}, {y})");
        }
    }
}

#[test]
fn a_psd_saved_by_gimp_reads_as_edited() {
    // tests/data/layers/README.md: GIMP opened the tagged views frame0000camera02.png, then
    // frame0000camera01.png as a layer above it (layers named after the files), put camera 2
    // into a group "right side" at 90 % opacity, erased camera 1 through a rectangle selection
    // x ≥ 32 feathered by 8 pixels, erased camera 2's corner x ≥ 44, y < 12 (hard), added a
    // hidden layer "sketch" and an opaque 10x6 layer "camera 1 patch" at (50, 30), and exported
    // PSD. GIMP names the first image's layer "Background": it was renamed to its file name.
    let path = fixture("gimp-edited.psd");
    let names = CameraNames::ids(Some([1, 2].into()));
    let c = open_collage(&path, None, &names, Default::default()).unwrap().collage;
    assert_eq!((c.width, c.height), (64, 48));
    let mut boundary = Vec::new();
    for y in 0..48 {
        // A feathered edge is symmetric about the selection's edge (x = 32): camera 1 keeps
        // alpha ≥ ½ left of it, within a pixel of rounding.
        let last_one = (0..64).take_while(|&x| c.id(x, y) == 1).last();
        boundary.push(last_one);
        for x in 0..64 {
            let id = c.id(x, y);
            if (50..60).contains(&x) && (30..36).contains(&y) {
                assert_eq!(id, 1, "patch ({x}, {y})");
            } else if x <= 30 {
                assert_eq!(id, 1, "({x}, {y})");
            } else if x >= 33 {
                let want = if x >= 44 && y < 12 { 0 } else { 2 };
                assert_eq!(id, want, "({x}, {y})");
            }
        }
    }
    assert!(boundary.iter().all(|b| matches!(b, Some(30..=32))), "{boundary:?}");
}
