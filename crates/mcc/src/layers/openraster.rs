//! OpenRaster (`.ora`, the layered format of Krita, GIMP and MyPaint; layer stack
//! specification 0.0.5): a zip archive whose first entry is an uncompressed `mimetype`
//! (`image/openraster`), then `stack.xml` (`<image w h><stack>` of `<layer src name x y opacity
//! visibility composite-op>` and nested `<stack>`s, first child on top), one PNG per layer,
//! `mergedimage.png` and `Thumbnails/thumbnail.png`.
//!
//! Read: every attribute the baseline defines is honoured (offsets, opacity, visibility, groups
//! with their opacity and visibility); a `composite-op` other than `svg:src-over` (normal) and
//! `<text>` or other elements are refused by name. Layers may reach past the canvas, as the
//! specification allows: what lies outside is cropped. Nothing is trusted before it is checked:
//! the archive's entry count, the XML's size (read through a limit, whatever the archive
//! claims), the canvas and layer sizes, and each layer PNG's decompressed size (bounded by what
//! its IHDR's size can need, before it is decoded). `mergedimage.png` and the thumbnail are not
//! read: the layers are the collage.
//!
//! Written ([`write`]): one layer per view, named `NAME (camera ID)`, in id order from the top,
//! over an opaque black `background` layer, with the merged image (the top view) and a
//! thumbnail, so an editor opens it as it would its own file.

use super::{
    Alpha, LayerTree, LayeredFile, MAX_LAYERS, Node, NodeKind, check_canvas, check_layer, read_limited,
};
use crate::error::{MccError, Result};
use image::codecs::png::PngEncoder;
use image::{DynamicImage, RgbImage};
use std::fs::File;
use std::io::{BufReader, Cursor, Write};
use std::path::{Path, PathBuf};
use zip::ZipArchive;
use zip::write::SimpleFileOptions;

/// The `mimetype` entry's content.
pub const MIMETYPE: &str = "image/openraster";
/// The most entries an archive may hold (layers, the merged image, thumbnails and extras).
pub const MAX_ENTRIES: usize = 2 * MAX_LAYERS + 64;
/// The most bytes `stack.xml` may decompress to.
pub const MAX_STACK_XML: u64 = 4 << 20;
/// Bytes a layer PNG may hold beyond its pixel data (ancillary chunks: colour profiles, text).
const PNG_OVERHEAD: u64 = 16 << 20;

/// An OpenRaster file being read.
pub struct OpenRaster {
    path: PathBuf,
    archive: ZipArchive<BufReader<File>>,
    tree: LayerTree,
    /// Each layer's `src` entry, by layer index.
    sources: Vec<String>,
}

impl OpenRaster {
    /// Opens the archive and reads its layer stack.
    pub fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).map_err(|e| MccError::io(path, e))?;
        let mut archive = ZipArchive::new(BufReader::new(file))
            .map_err(|e| MccError::layered(path, "archive", format!("not a readable zip archive: {e}")))?;
        if archive.len() > MAX_ENTRIES {
            return Err(MccError::layered(
                path,
                "archive",
                format!("holds {} entries; an OpenRaster file has at most {MAX_ENTRIES} here", archive.len()),
            ));
        }
        let mimetype = read_entry(&mut archive, path, "mimetype", 256, "a mimetype")?;
        if mimetype.trim_ascii() != MIMETYPE.as_bytes() {
            return Err(MccError::layered(
                path,
                "mimetype",
                format!("is {:?}, not {MIMETYPE:?}", String::from_utf8_lossy(&mimetype)),
            ));
        }
        let xml = read_entry(&mut archive, path, "stack.xml", MAX_STACK_XML, "a layer stack")?;
        let xml = std::str::from_utf8(&xml)
            .map_err(|e| MccError::layered(path, "stack.xml", format!("is not UTF-8 text: {e}")))?;
        let mut parser = StackParser { path, sources: Vec::new(), count: 0 };
        let tree = parser.parse(xml)?;
        for src in &parser.sources {
            if archive.index_for_name(src).is_none() {
                return Err(MccError::layered(
                    path,
                    "stack.xml",
                    format!("a layer's src {src:?} is not in the archive"),
                ));
            }
        }
        Ok(Self { path: path.to_path_buf(), archive, tree, sources: parser.sources })
    }
}

/// Reads entry `name` whole, refusing more than `limit` bytes (`what` says what it is).
fn read_entry(
    archive: &mut ZipArchive<BufReader<File>>,
    path: &Path,
    name: &str,
    limit: u64,
    what: &str,
) -> Result<Vec<u8>> {
    let entry = archive.by_name(name).map_err(|e| match e {
        zip::result::ZipError::FileNotFound => {
            MccError::layered(path, name, "is missing: not an OpenRaster file")
        }
        other => MccError::layered(path, name, format!("cannot be read: {other}")),
    })?;
    if entry.size() > limit {
        return Err(MccError::layered(
            path,
            name,
            format!("claims {} bytes, more than {limit}, more than {what} can need", entry.size()),
        ));
    }
    read_limited(entry, limit, path, name, what)
}

/// `stack.xml` → [`LayerTree`], with each layer's `src`.
struct StackParser<'a> {
    path: &'a Path,
    sources: Vec<String>,
    count: usize,
}

impl StackParser<'_> {
    fn error(&self, message: impl Into<String>) -> MccError {
        MccError::layered(self.path, "stack.xml", message)
    }

    fn parse(&mut self, xml: &str) -> Result<LayerTree> {
        let doc = roxmltree::Document::parse(xml).map_err(|e| self.error(format!("malformed XML: {e}")))?;
        let image = doc.root_element();
        if image.tag_name().name() != "image" {
            return Err(self.error(format!("the root element is <{}>, not <image>", image.tag_name().name())));
        }
        let size = |attr: &str| -> Result<u64> {
            let value = image
                .attribute(attr)
                .ok_or_else(|| self.error(format!("<image> has no {attr} attribute")))?;
            value
                .trim()
                .parse()
                .map_err(|_| self.error(format!("<image {attr}={value:?}> is not a pixel count")))
        };
        let (width, height) = check_canvas(self.path, "stack.xml", size("w")?, size("h")?)?;
        let stacks: Vec<_> = image.children().filter(|n| n.is_element()).collect();
        let [stack] = stacks.as_slice() else {
            return Err(self.error(format!("<image> must hold one <stack>, not {} elements", stacks.len())));
        };
        if stack.tag_name().name() != "stack" {
            return Err(self.error(format!("<image> holds <{}>, not <stack>", stack.tag_name().name())));
        }
        let nodes = self.children(*stack, 0)?;
        Ok(LayerTree { width, height, nodes })
    }

    fn children(&mut self, stack: roxmltree::Node<'_, '_>, depth: usize) -> Result<Vec<Node>> {
        if depth > super::MAX_DEPTH {
            return Err(self.error(format!("stacks nest deeper than {} levels", super::MAX_DEPTH)));
        }
        let mut nodes = Vec::new();
        for element in stack.children().filter(|n| n.is_element()) {
            self.count += 1;
            if self.count > MAX_LAYERS {
                return Err(self.error(format!("more than {MAX_LAYERS} layers and stacks")));
            }
            let name = element.attribute("name").unwrap_or_default().to_owned();
            let what = format!("<{} name={name:?}>", element.tag_name().name());
            let visible = match element.attribute("visibility").unwrap_or("visible") {
                "visible" => true,
                "hidden" => false,
                other => {
                    return Err(
                        self.error(format!("{what}: visibility {other:?} is neither visible nor hidden"))
                    );
                }
            };
            let opacity = match element.attribute("opacity") {
                None => 1.0,
                Some(v) => match v.trim().parse::<f32>() {
                    Ok(o) if (0.0..=1.0).contains(&o) => o,
                    _ => return Err(self.error(format!("{what}: opacity {v:?} is not a number from 0 to 1"))),
                },
            };
            let op = element.attribute("composite-op").unwrap_or("svg:src-over");
            let kind = match element.tag_name().name() {
                "layer" => {
                    if op != "svg:src-over" {
                        return Err(self.unsupported_op(&what, op));
                    }
                    let src =
                        element.attribute("src").ok_or_else(|| self.error(format!("{what} has no src")))?;
                    let offset = |attr: &str| -> Result<i64> {
                        match element.attribute(attr) {
                            None => Ok(0),
                            Some(v) => v.trim().parse::<i32>().map(i64::from).map_err(|_| {
                                self.error(format!("{what}: {attr}={v:?} is not a whole number of pixels"))
                            }),
                        }
                    };
                    let (x, y) = (offset("x")?, offset("y")?);
                    check_layer(self.path, &format!("stack.xml: {what}"), x, y, 0, 0)?;
                    self.sources.push(src.to_owned());
                    NodeKind::Layer { x, y, index: self.sources.len() - 1 }
                }
                "stack" => {
                    // Only an isolated stack composites with its own operator; a pass-through
                    // ("auto") stack's is ignored by the specification.
                    let isolated = element.attribute("isolation").unwrap_or("isolate") != "auto";
                    if isolated && op != "svg:src-over" {
                        return Err(self.unsupported_op(&what, op));
                    }
                    NodeKind::Group(self.children(element, depth + 1)?)
                }
                other => {
                    return Err(self.error(format!(
                        "<{other}> elements are not supported (only <layer> and <stack>); \
                         rasterize it into a pixel layer"
                    )));
                }
            };
            nodes.push(Node { name, visible, opacity, kind });
        }
        Ok(nodes)
    }

    fn unsupported_op(&self, what: &str, op: &str) -> MccError {
        self.error(format!(
            "{what}: blend mode {op:?} is not supported; set the layer's blend mode to Normal \
             (svg:src-over): only its alpha decides which pixels it takes"
        ))
    }
}

impl LayeredFile for OpenRaster {
    fn path(&self) -> &Path {
        &self.path
    }

    fn tree(&self) -> &LayerTree {
        &self.tree
    }

    fn alpha(&mut self, index: usize) -> Result<Alpha> {
        Ok(alpha_of(&self.decode(index)?))
    }

    fn holds_picture(&mut self, index: usize) -> Result<bool> {
        let image = self.decode(index)?.to_rgba8();
        Ok(image.pixels().any(|p| p.0[3] >= 128 && p.0[..3].iter().any(|&c| c > super::BLACK_TOLERANCE)))
    }
}

impl OpenRaster {
    /// Decodes layer `index`'s PNG, bounding its decompressed size by its header's first.
    fn decode(&mut self, index: usize) -> Result<DynamicImage> {
        let path = self.path.clone();
        let name = self.sources[index].clone();
        let mut entry = self
            .archive
            .by_name(&name)
            .map_err(|e| MccError::layered(&path, &name, format!("cannot be read: {e}")))?;
        // The IHDR first: its size bounds how many bytes the rest may decompress to.
        let mut head = [0u8; 33];
        std::io::Read::read_exact(&mut entry, &mut head)
            .map_err(|e| MccError::layered(&path, &name, format!("is not a PNG image (too short: {e})")))?;
        if &head[..8] != b"\x89PNG\r\n\x1a\n" || &head[12..16] != b"IHDR" {
            return Err(MccError::layered(
                &path,
                &name,
                "is not a PNG image; OpenRaster layers here must be PNG",
            ));
        }
        let be32 =
            |at: usize| u32::from_be_bytes([head[at], head[at + 1], head[at + 2], head[at + 3]]) as u64;
        let (w, h) = (be32(16), be32(20));
        if w == 0 || h == 0 {
            return Err(MccError::layered(&path, &name, format!("the layer PNG is {w}x{h}: no pixel")));
        }
        check_layer(&path, &name, 0, 0, w, h)?;
        // 8 bytes per pixel is the most a PNG pixel holds (16-bit RGBA), plus a filter byte a row.
        let need = h * (w * 8 + 1);
        let limit = 2 * need + PNG_OVERHEAD;
        if entry.size() > limit {
            return Err(MccError::layered(
                &path,
                &name,
                format!("claims {} bytes, more than a {w}x{h} PNG can need", entry.size()),
            ));
        }
        let rest =
            read_limited(&mut entry, limit - head.len() as u64, &path, &name, &format!("a {w}x{h} PNG"))?;
        drop(entry);
        let mut bytes = head.to_vec();
        bytes.extend_from_slice(&rest);
        let bad = |message: String| MccError::layered(&path, &name, message);
        tracer::image_io::check_png_header(&bytes).map_err(bad)?;
        image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
            .map_err(|e| bad(format!("cannot decode the layer PNG: {e}")))
    }
}

/// A decoded layer's alpha, widened to 16 bits (`None`: no alpha channel, opaque).
fn alpha_of(image: &DynamicImage) -> Alpha {
    let (width, height) = (image.width(), image.height());
    let values = match image {
        DynamicImage::ImageRgba8(img) => Some(img.pixels().map(|p| p.0[3] as u16 * 257).collect()),
        DynamicImage::ImageLumaA8(img) => Some(img.pixels().map(|p| p.0[1] as u16 * 257).collect()),
        DynamicImage::ImageRgba16(img) => Some(img.pixels().map(|p| p.0[3]).collect()),
        DynamicImage::ImageLumaA16(img) => Some(img.pixels().map(|p| p.0[1]).collect()),
        other if other.color().has_alpha() => Some(other.to_rgba16().pixels().map(|p| p.0[3]).collect()),
        _ => None,
    };
    Alpha { width, height, values }
}

/// One view to write as a layer.
#[derive(Clone, Copy, Debug)]
pub struct ViewLayer<'a> {
    /// The camera id.
    pub id: u32,
    /// The camera's name.
    pub name: &'a str,
    /// The view, 8-bit sRGB.
    pub image: &'a RgbImage,
}

/// A linear render as the 8-bit sRGB picture a layer shows.
pub fn srgb8(image: &tracer::image::RgbImage) -> RgbImage {
    let bytes =
        image.pixels.iter().flat_map(|p| p.to_array().map(tracer::image_io::linear_to_srgb8)).collect();
    RgbImage::from_raw(image.width, image.height, bytes).expect("a tracer image holds width × height pixels")
}

/// Refuses an output path [`write`] cannot serve (not `.ora`), before any work is done.
pub fn check_path(path: &Path) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if ext.as_deref() != Some("ora") {
        return Err(MccError::input(
            path.display().to_string(),
            "layers are written as OpenRaster only: give a file name ending in .ora (Krita, GIMP \
             and MyPaint open it; save it as PSD from there if you wish)",
        ));
    }
    Ok(())
}

/// The layer name [`write`] gives camera `id` named `name`: `left (camera 3)`.
pub fn layer_name(name: &str, id: u32) -> String {
    format!("{name} (camera {id})")
}

/// Writes `views` (all one size) as an OpenRaster file at `path`, atomically: one layer per
/// view in id order from the top, then an opaque black `background` layer.
pub fn write(path: &Path, views: &[ViewLayer<'_>]) -> Result<()> {
    let bytes = encode(views)
        .map_err(|message| MccError::input(format!("OpenRaster file {}", path.display()), message))?;
    tracer::atomic::write_atomically(path, |w| w.write_all(&bytes))?;
    Ok(())
}

/// The archive's bytes (messages for in-memory inconsistencies).
fn encode(views: &[ViewLayer<'_>]) -> std::result::Result<Vec<u8>, String> {
    let mut views = views.to_vec();
    views.sort_by_key(|v| v.id);
    let Some(top) = views.first() else { return Err("no views to write".to_owned()) };
    let (width, height) = top.image.dimensions();
    if let Some(v) = views.iter().find(|v| v.image.dimensions() != (width, height)) {
        let (w, h) = v.image.dimensions();
        return Err(format!(
            "camera {}'s view is {w}x{h}, but camera {}'s is {width}x{height}",
            v.id, top.id
        ));
    }
    let png = |image: &DynamicImage| -> std::result::Result<Vec<u8>, String> {
        let mut out = Vec::new();
        image.write_with_encoder(PngEncoder::new(&mut out)).map_err(|e| e.to_string())?;
        Ok(out)
    };
    let mut xml = format!(
        "<?xml version='1.0' encoding='UTF-8'?>\n<image version=\"0.0.5\" w=\"{width}\" h=\"{height}\">\n <stack>\n"
    );
    let mut entries: Vec<(String, Vec<u8>)> = Vec::new();
    for v in &views {
        let src = format!("data/camera{:02}.png", v.id);
        xml += &format!(
            "  <layer name=\"{}\" src=\"{src}\" x=\"0\" y=\"0\" opacity=\"1.0\" visibility=\"visible\" composite-op=\"svg:src-over\"/>\n",
            escape(&layer_name(v.name, v.id))
        );
        entries.push((src, png(&DynamicImage::ImageRgb8(v.image.clone()))?));
    }
    xml += "  <layer name=\"background\" src=\"data/background.png\" x=\"0\" y=\"0\" opacity=\"1.0\" visibility=\"visible\" composite-op=\"svg:src-over\"/>\n </stack>\n</image>\n";
    entries.push((
        "data/background.png".to_owned(),
        png(&DynamicImage::ImageRgb8(RgbImage::new(width, height)))?,
    ));
    // The merged image is the top view: it covers the whole canvas.
    entries.push(("mergedimage.png".to_owned(), png(&DynamicImage::ImageRgb8(top.image.clone()))?));
    // At most 256 pixels on the longer side (as the specification asks), never enlarged.
    let side = width.max(height);
    let thumb = if side <= 256 {
        top.image.clone()
    } else {
        image::imageops::thumbnail(top.image, (width * 256 / side).max(1), (height * 256 / side).max(1))
    };
    entries.push(("Thumbnails/thumbnail.png".to_owned(), png(&DynamicImage::ImageRgb8(thumb))?));

    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let stored = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let deflated = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    let err = |e: zip::result::ZipError| e.to_string();
    // The mimetype first and uncompressed, so `file` and editors recognise the archive.
    zip.start_file("mimetype", stored).map_err(err)?;
    zip.write_all(MIMETYPE.as_bytes()).map_err(|e| e.to_string())?;
    zip.start_file("stack.xml", deflated).map_err(err)?;
    zip.write_all(xml.as_bytes()).map_err(|e| e.to_string())?;
    for (name, bytes) in entries {
        // PNGs are compressed already.
        zip.start_file(name, stored).map_err(err)?;
        zip.write_all(&bytes).map_err(|e| e.to_string())?;
    }
    Ok(zip.finish().map_err(err)?.into_inner())
}

/// `s` escaped for an XML attribute value.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // XML 1.0 allows no other control characters.
            c if c.is_control() && !matches!(c, '\t' | '\n' | '\r') => out.push(' '),
            c => out.push(c),
        }
    }
    out
}
