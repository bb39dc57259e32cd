//! The malformed-input corpus (`tests/bad_inputs/`): layered collages (OpenRaster, PSD) read by
//! `remap --collage`, built byte by byte here (zip archives through the zip crate, PSDs by hand
//! from Adobe's layout), each case saying in code what is wrong.

use super::case::*;
use super::encoders::png;
use super::{H, W};
use std::io::Write;

/// An OpenRaster archive: `mimetype` (stored) first when given, then the entries (deflated).
fn ora(mimetype: bool, entries: &[(&str, Vec<u8>)]) -> Vec<u8> {
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = |method| zip::write::SimpleFileOptions::default().compression_method(method);
    if mimetype {
        zip.start_file("mimetype", options(zip::CompressionMethod::Stored)).unwrap();
        zip.write_all(b"image/openraster").unwrap();
    }
    for (name, bytes) in entries {
        zip.start_file(*name, options(zip::CompressionMethod::Deflated)).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// An RGBA layer PNG, opaque where `on(x, y)`.
fn layer_png(w: u32, h: u32, on: impl Fn(u32, u32) -> bool) -> Vec<u8> {
    let mut rgba = Vec::new();
    for y in 0..h {
        for x in 0..w {
            rgba.extend_from_slice(&[120, 90, 60, if on(x, y) { 255 } else { 0 }]);
        }
    }
    png(w, h, 6, 8, &rgba)
}

/// `stack.xml` of a `w × h` canvas holding `layers` (`<layer>` elements, top first).
fn stack(w: u64, h: u64, layers: &str) -> Vec<u8> {
    format!("<?xml version='1.0' encoding='UTF-8'?><image version=\"0.0.5\" w=\"{w}\" h=\"{h}\"><stack>{layers}</stack></image>")
        .into_bytes()
}

/// The good layered collage: camera 1 on the left half, camera 2 (named by its view's file
/// name, as an editor names a view opened as a layer) below it over the whole canvas.
fn good_ora() -> Vec<u8> {
    ora(
        true,
        &[
            (
                "stack.xml",
                stack(
                    W as u64,
                    H as u64,
                    "<layer name=\"1\" src=\"data/a.png\"/><layer name=\"frame0000camera02.png\" src=\"data/b.png\"/>",
                ),
            ),
            ("data/a.png", layer_png(W, H, |x, _| x < W / 2)),
            ("data/b.png", layer_png(W, H, |_, _| true)),
        ],
    )
}

/// A one-layer OpenRaster collage with its layer element and PNG.
fn one_layer(layer: &str, png: Vec<u8>) -> Vec<u8> {
    ora(true, &[("stack.xml", stack(W as u64, H as u64, layer)), ("data/a.png", png)])
}

/// A PSD of the corpus size (8-bit RGB, raw channels) with layers (name, blend key, opacity,
/// alpha per pixel) given top first; the canvas size is written as `canvas`.
fn psd(canvas: (u32, u32), layers: &[(&str, [u8; 4], u8, Vec<u8>)]) -> Vec<u8> {
    let (mut records, mut data) = (Vec::new(), Vec::new());
    for (name, blend, opacity, alpha) in layers.iter().rev() {
        let mut channels = Vec::new();
        for id in [-1i16, 0, 1, 2] {
            let mut bytes = vec![0, 0]; // raw
            bytes.extend(if id == -1 { alpha.clone() } else { vec![100; (W * H) as usize] });
            channels.push((id, bytes));
        }
        for v in [0i32, 0, H as i32, W as i32] {
            records.extend(v.to_be_bytes());
        }
        records.extend(4u16.to_be_bytes());
        for (id, bytes) in &channels {
            records.extend(id.to_be_bytes());
            records.extend((bytes.len() as u32).to_be_bytes());
        }
        records.extend(b"8BIM");
        records.extend(blend);
        records.extend([*opacity, 0, 0, 0]);
        let mut extra = vec![0; 8]; // no mask, no blending ranges
        extra.push(name.len() as u8);
        extra.extend(name.as_bytes());
        while !(extra.len() - 8).is_multiple_of(4) {
            extra.push(0);
        }
        records.extend((extra.len() as u32).to_be_bytes());
        records.extend(extra);
        channels.into_iter().for_each(|(_, bytes)| data.extend(bytes));
    }
    let mut info = (layers.len() as u16).to_be_bytes().to_vec();
    info.extend(records);
    info.extend(data);
    let mut section = (info.len() as u32).to_be_bytes().to_vec();
    section.extend(info);
    section.extend([0; 4]);
    let mut out = b"8BPS\0\x01\0\0\0\0\0\0\0\x04".to_vec();
    out.extend(canvas.1.to_be_bytes());
    out.extend(canvas.0.to_be_bytes());
    out.extend([0, 8, 0, 3, 0, 0, 0, 0, 0, 0, 0, 0]);
    out.extend((section.len() as u32).to_be_bytes());
    out.extend(section);
    out.extend([0, 0]);
    out
}

fn left_half() -> Vec<u8> {
    (0..W * H).map(|k| if k % W < W / 2 { 255 } else { 0 }).collect()
}

/// `remap --collage {dir}/<name>` with the good views.
fn remap_layers(name: &str, file: &str, bytes: Vec<u8>) -> Case {
    Case::new("layered collage", name).views().file(file, bytes).args(&format!(
        "remap --collage {{dir}}/{file} --rays {{dir}}/views --out {{out}}/rerender-frame0000.mcr -q"
    ))
}

/// Layered collages: controls, malformed archives and documents, unsupported features, bombs.
pub(crate) fn layer_cases(add: &mut impl FnMut(Case)) {
    let out = ["out/rerender-frame0000.mcr"];
    add(remap_layers("layers-ora-control", "collage.ora", good_ora()).succeeds(&out));
    let full = vec![255; (W * H) as usize];
    let good_psd =
        psd((W, H), &[("camera 1", *b"norm", 255, left_half()), ("2", *b"norm", 255, full.clone())]);
    add(remap_layers("layers-psd-control", "collage.psd", good_psd.clone()).succeeds(&out));
    // A layer too transparent to take a pixel: the run goes on and says so.
    let faded = ora(
        true,
        &[
            (
                "stack.xml",
                stack(
                    W as u64,
                    H as u64,
                    "<layer name=\"1\" src=\"data/a.png\" opacity=\"0.4\"/><layer name=\"2\" src=\"data/b.png\"/>",
                ),
            ),
            ("data/a.png", layer_png(W, H, |_, _| true)),
            ("data/b.png", layer_png(W, H, |_, _| true)),
        ],
    );
    add(Case::new("layered collage", "layers-ora-faded-layer-warns")
        .views()
        .file("collage.ora", faded)
        .args("remap --collage {dir}/collage.ora --rays {dir}/views --out {out}/rerender-frame0000.mcr")
        .warns(
            &["warning:", "collage.ora", "layer \"1\" is visible, but at 40 % opacity", "takes no pixel"],
            &out,
        ));

    // ---- malformed archives -----------------------------------------------------------------
    let mut not_zip = b"PK\x03\x04".to_vec();
    not_zip.extend(b"this is no zip archive, only its first four bytes");
    add(remap_layers("layers-ora-not-zip", "collage.ora", not_zip)
        .fails(&["collage.ora: archive: not a readable zip archive"]));
    let good = good_ora();
    add(remap_layers("layers-ora-truncated", "collage.ora", good[..good.len() - 30].to_vec())
        .fails(&["collage.ora: archive: not a readable zip archive"]));
    add(remap_layers(
        "layers-ora-no-stack",
        "collage.ora",
        ora(true, &[("data/a.png", layer_png(W, H, |_, _| true))]),
    )
    .fails(&["collage.ora: stack.xml: is missing: not an OpenRaster file"]));
    add(remap_layers("layers-ora-no-mimetype", "collage.ora", ora(false, &[("stack.xml", stack(8, 6, ""))]))
        .fails(&["collage.ora: mimetype: is missing"]));
    add(remap_layers(
        "layers-ora-bad-xml",
        "collage.ora",
        ora(true, &[("stack.xml", b"<image w=\"8\" h=".to_vec())]),
    )
    .fails(&["collage.ora: stack.xml: malformed XML"]));
    add(remap_layers(
        "layers-ora-missing-layer-png",
        "collage.ora",
        ora(true, &[("stack.xml", stack(8, 6, "<layer name=\"1\" src=\"data/a.png\"/>"))]),
    )
    .fails(&["collage.ora: stack.xml: a layer's src \"data/a.png\" is not in the archive"]));
    let png_bytes = layer_png(W, H, |_, _| true);
    add(remap_layers(
        "layers-ora-truncated-png",
        "collage.ora",
        one_layer("<layer name=\"1\" src=\"data/a.png\"/>", png_bytes[..png_bytes.len() - 16].to_vec()),
    )
    .fails(&["collage.ora: data/a.png: cannot decode the layer PNG"]));
    add(remap_layers(
        "layers-ora-canvas-wrong-size",
        "collage.ora",
        ora(
            true,
            &[
                ("stack.xml", stack(10, 6, "<layer name=\"1\" src=\"data/a.png\"/>")),
                ("data/a.png", layer_png(10, 6, |_, _| true)),
            ],
        ),
    )
    .fails(&["frame0000camera01.txt", "camera 1's ray file is 8x6, but the collage is 10x6"]));
    let mut psd_cut = good_psd.clone();
    psd_cut.truncate(good_psd.len() / 2);
    add(remap_layers("layers-psd-truncated", "collage.psd", psd_cut)
        .fails(&["collage.psd: layer and mask information: needs", "(truncated or damaged)"]));
    add(remap_layers("layers-psd-not-psd", "collage.psd", b"8BPX not a Photoshop file".to_vec())
        .fails(&["collage.psd: header: no 8BPS signature"]));

    // ---- names and unsupported features -----------------------------------------------------
    add(remap_layers(
        "layers-ora-unknown-name",
        "collage.ora",
        one_layer("<layer name=\"Layer 1\" src=\"data/a.png\"/>", png_bytes.clone()),
    )
    .fails(&["collage.ora: layer \"Layer 1\": names no camera", "\"camera 3\"", "\"background\""]));
    add(remap_layers(
        "layers-ora-camera-without-rays",
        "collage.ora",
        one_layer("<layer name=\"camera 7\" src=\"data/a.png\"/>", png_bytes.clone()),
    )
    .fails(&[
        "collage.ora: layer \"camera 7\": is camera 7, which has no ray file (cameras with ray files: 1, 2)",
    ]));
    add(remap_layers(
        "layers-ora-blend-mode",
        "collage.ora",
        one_layer("<layer name=\"1\" src=\"data/a.png\" composite-op=\"svg:multiply\"/>", png_bytes.clone()),
    )
    .fails(&["collage.ora: stack.xml: <layer name=\"1\">: blend mode \"svg:multiply\" is not supported"]));
    add(remap_layers(
        "layers-psd-blend-mode",
        "collage.psd",
        psd((W, H), &[("1", *b"scrn", 255, full.clone())]),
    )
    .fails(&["collage.psd: layer \"1\": blend mode Screen is not supported"]));
    add(remap_layers(
        "layers-psd-picture-background",
        "collage.psd",
        psd((W, H), &[("1", *b"norm", 255, left_half()), ("Background", *b"norm", 255, full)]),
    )
    .fails(&["collage.psd: layer \"Background\": is named as the background, but it holds a picture"]));

    // ---- absurd sizes and bombs: refused before allocating (memory-checked) -----------------
    add(remap_layers(
        "layers-ora-absurd-canvas",
        "collage.ora",
        ora(true, &[("stack.xml", stack(1_000_000, 1_000_000, ""))]),
    )
    .fails(&["collage.ora: stack.xml: the canvas is 1000000x1000000"])
    .memory());
    let mut absurd_png = png_bytes.clone();
    absurd_png[16..24].copy_from_slice(&[0, 1, 0x86, 0xa0, 0, 1, 0x86, 0xa0]); // 100000 × 100000
    add(remap_layers(
        "layers-ora-absurd-layer-png",
        "collage.ora",
        one_layer("<layer name=\"1\" src=\"data/a.png\"/>", absurd_png),
    )
    .fails(&["collage.ora: data/a.png: the layer is 100000x100000"])
    .memory());
    // 64 MiB of spaces in stack.xml deflate to 64 KiB: read through a 4 MiB limit.
    let mut bomb = vec![b' '; 64 << 20];
    bomb.extend(stack(8, 6, ""));
    add(remap_layers("layers-ora-zip-bomb-stack", "collage.ora", ora(true, &[("stack.xml", bomb)]))
        .fails(&["collage.ora: stack.xml: claims 67108", "more than 4194304"])
        .memory());
    // A layer PNG padded with 64 MiB of zeros after its IEND: more than an 8x6 PNG can need.
    let mut padded = png_bytes;
    padded.extend(vec![0; 64 << 20]);
    add(remap_layers(
        "layers-ora-zip-bomb-layer",
        "collage.ora",
        one_layer("<layer name=\"1\" src=\"data/a.png\"/>", padded),
    )
    .fails(&["collage.ora: data/a.png: claims 67109130 bytes, more than a 8x6 PNG can need"])
    .memory());
    add(remap_layers("layers-psd-absurd-canvas", "collage.psd", psd((1_000_000, 1_000_000), &[]))
        .fails(&["collage.psd: header: the canvas is 1000000x1000000"])
        .memory());
}
