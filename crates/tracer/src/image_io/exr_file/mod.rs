//! OpenEXR: linear f32 renders with AOV layers and string metadata.
//!
//! Written files are single-part, scan-line, f32, ZIP-compressed (zlib, 16 lines per block).
//! ZIP rather than PIZ: both are lossless, and PIZ's wavelet is built for f16 data; on f32 renders
//! it is larger and slower to read and write (docs/performance.md, ledger: "EXR: ZIP over PIZ").
//! The reader takes whatever the exr crate reads: scan-line or tiled (largest mip level), any
//! compression, f16/f32/u32 channels (all converted to f32), single- or multi-part files (a
//! part's name prefixes its channels: `part.R`).

use super::{MAX_PIXELS, MAX_SAMPLES, check_dimensions};
use crate::atomic::write_atomically;
use crate::error::{Result, TracerError};
use crate::image::{GrayImage, RgbImage};
use exr::meta::MetaData;
use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Blocks, Compression, Encoding, FlatSamples, Image, Layer,
    LayerAttributes, LineOrder, ReadChannels, ReadLayers, SmallVec, Text, Vec2, WritableImage,
};
use glam::Vec3;
use std::collections::BTreeMap;
use std::io::{BufReader, Seek};
use std::path::Path;

/// One extra image (AOV) stored beside the beauty image in [`write_exr`].
#[derive(Clone, Copy, Debug)]
pub enum Aov<'a> {
    /// A colour AOV (albedo, normal, variance …), stored as channels `name.R`, `name.G`, `name.B`.
    Rgb {
        /// Layer name: ASCII letters, digits, `_`, `-`, inner `.`.
        name: &'a str,
        /// The pixels; same size as the beauty image.
        image: &'a RgbImage,
    },
    /// A single-channel AOV (depth …), stored as channel `name.Y`.
    Gray {
        /// Layer name: ASCII letters, digits, `_`, `-`, inner `.`.
        name: &'a str,
        /// The pixels; same size as the beauty image.
        image: &'a GrayImage,
    },
}

/// A named layer read from an OpenEXR file.
#[derive(Clone, Debug, PartialEq)]
pub enum ExrLayer {
    /// Channels `name.R`, `name.G`, `name.B`.
    Rgb(RgbImage),
    /// A single channel: `name.Y`, or any channel not part of an R/G/B triple (`A`, `Z`, `foo.A`),
    /// then named by its full channel name.
    Gray(GrayImage),
}

/// What [`read_exr`] found in a file.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// The beauty image: channels `R`, `G`, `B` (a file with only `Y` gives grey R = G = B).
    pub rgb: RgbImage,
    /// Every other layer, by name (see [`ExrLayer`] for how channels become layers).
    pub layers: BTreeMap<String, ExrLayer>,
    /// String attributes of the header(s): ours, plus e.g. Mitsuba's `generatedBy` or `software`.
    pub metadata: BTreeMap<String, String>,
}

impl ExrImage {
    /// The colour layer `name`, if the file has one.
    pub fn rgb_layer(&self, name: &str) -> Option<&RgbImage> {
        match self.layers.get(name) {
            Some(ExrLayer::Rgb(image)) => Some(image),
            _ => None,
        }
    }

    /// The single-channel layer `name`, if the file has one.
    pub fn gray_layer(&self, name: &str) -> Option<&GrayImage> {
        match self.layers.get(name) {
            Some(ExrLayer::Gray(image)) => Some(image),
            _ => None,
        }
    }
}

/// Header attribute names the OpenEXR standard (and the exr crate) give a meaning and a type;
/// metadata keys may not reuse them, or they would not read back as plain strings.
#[rustfmt::skip]
const RESERVED_KEYS: &[&str] = &[
    "tiles", "name", "type", "version", "chunkCount", "maxSamplesPerPixel", "channels", "compression",
    "dataWindow", "displayWindow", "lineOrder", "pixelAspectRatio", "screenWindowCenter",
    "screenWindowWidth", "whiteLuminance", "adoptedNeutral", "renderingTransform", "lookModTransform",
    "xDensity", "owner", "comments", "capDate", "utcOffset", "longitude", "latitude", "altitude",
    "focus", "expTime", "aperture", "isoSpeed", "envmap", "keyCode", "timeCode", "wrapmodes",
    "framesPerSecond", "multiView", "worldToCamera", "worldToNDC", "deepImageState",
    "originalDataWindow", "dwaCompressionLevel", "preview", "view", "chromaticities", "near", "far",
    "fieldOfViewHorizontal", "fieldOfViewVertical", "software",
];

/// Writes `rgb` (channels R, G, B), the `aovs` and the string `metadata` to one OpenEXR file,
/// linear f32 stored as given (NaN and ∞ too), ZIP-compressed, atomically. Metadata values are
/// string attributes (UTF-8); the header's `software` attribute names mcctrace.
pub fn write_exr(path: &Path, rgb: &RgbImage, aovs: &[Aov<'_>], metadata: &[(&str, String)]) -> Result<()> {
    let bad = |message: String| TracerError::image(path, message);
    check_dimensions(rgb.width, rgb.height, rgb.pixels.len(), 1, "the image").map_err(bad)?;
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    channels.extend(rgb_channels("", rgb));
    let mut names = Vec::new();
    for aov in aovs {
        let (name, width, height, len) = match aov {
            Aov::Rgb { name, image } => (*name, image.width, image.height, image.pixels.len()),
            Aov::Gray { name, image } => (*name, image.width, image.height, image.pixels.len()),
        };
        check_layer_name(name).map_err(bad)?;
        if names.contains(&name) {
            return Err(bad(format!("two AOVs are named '{name}'")));
        }
        names.push(name);
        check_dimensions(width, height, len, 1, &format!("AOV '{name}'")).map_err(bad)?;
        if (width, height) != (rgb.width, rgb.height) {
            return Err(bad(format!(
                "AOV '{name}' is {width} × {height} but the image is {} × {}",
                rgb.width, rgb.height
            )));
        }
        match aov {
            Aov::Rgb { image, .. } => channels.extend(rgb_channels(&format!("{name}."), image)),
            Aov::Gray { image, .. } => channels.push(AnyChannel::new(
                Text::from_slice_unchecked(format!("{name}.Y").as_bytes()),
                FlatSamples::F32(image.pixels.clone()),
            )),
        }
    }
    let mut attributes = LayerAttributes {
        software_name: Some(Text::from_slice_unchecked(
            concat!("mcctrace ", env!("CARGO_PKG_VERSION")).as_bytes(),
        )),
        ..LayerAttributes::default()
    };
    for (key, value) in metadata {
        if key.is_empty() || key.len() > 255 || key.contains('\0') {
            return Err(bad(format!("metadata key {key:?} must be 1 to 255 bytes without NUL")));
        }
        if RESERVED_KEYS.contains(key) {
            return Err(bad(format!(
                "metadata key '{key}' is a standard OpenEXR attribute; use another name"
            )));
        }
        // OpenEXR strings are bytes; we store UTF-8 as OpenEXR's C++ library does.
        let old = attributes.other.insert(
            Text::from_slice_unchecked(key.as_bytes()),
            AttributeValue::Text(Text::from_slice_unchecked(value.as_bytes())),
        );
        if old.is_some() {
            return Err(bad(format!("metadata key '{key}' is given twice")));
        }
    }
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let size = Vec2(rgb.width as usize, rgb.height as usize);
    let image = Image::from_layer(Layer::new(size, attributes, encoding, AnyChannels::sort(channels)));
    write_atomically(path, |w| image.write().to_buffered(w).map_err(exr_to_io))
}

/// Reads an OpenEXR file: the beauty image, every other layer and the string metadata.
///
/// Channels are grouped into layers by the prefix before their last `.`: `p.R`, `p.G`, `p.B`
/// make colour layer `p` (unprefixed: the beauty image); `p.Y` is single-channel layer `p`
/// (unless colour layer `p` exists); any other channel (`A`, `Z`, `p.A` …) is a single-channel
/// layer named by its full name. A file without `R`, `G`, `B` but with `Y` gives a grey beauty
/// image; one with neither is refused, listing its channels. The data window is read as the
/// image (a display window of another size is ignored).
pub fn read_exr(path: &Path) -> Result<ExrImage> {
    let bad = |message: String| TracerError::image(path, message);
    let file = std::fs::File::open(path).map_err(|e| TracerError::io(path, e))?;
    let mut reader = BufReader::new(file);
    let meta = MetaData::read_from_buffered(&mut reader, false)
        .map_err(|e| bad(format!("not a readable OpenEXR header: {}", exr_message(&e))))?;
    check_headers(&meta).map_err(bad)?;
    reader.rewind().map_err(|e| TracerError::io(path, e))?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(reader)
        .map_err(|e| bad(format!("malformed or unsupported OpenEXR file: {}", exr_message(&e))))?;

    let mut metadata = BTreeMap::new();
    let mut channels: BTreeMap<String, (u32, u32, Vec<f32>)> = BTreeMap::new();
    collect_text(&image.attributes.other, &mut metadata);
    for layer in &image.layer_data {
        collect_layer_text(&layer.attributes, &mut metadata);
        let prefix = match &layer.attributes.layer_name {
            Some(name) if !name.bytes().is_empty() => format!("{}.", text_to_string(name)),
            _ => String::new(),
        };
        // check_headers bounded the size, so these casts cannot truncate.
        let (width, height) = (layer.size.width() as u32, layer.size.height() as u32);
        for channel in &layer.channel_data.list {
            let name = format!("{prefix}{}", text_to_string(&channel.name));
            let samples: Vec<f32> = channel.sample_data.values_as_f32().collect();
            if samples.len() != width as usize * height as usize {
                return Err(bad(format!(
                    "channel '{name}' holds {} samples, not {width} × {height}",
                    samples.len()
                )));
            }
            if channels.insert(name.clone(), (width, height, samples)).is_some() {
                return Err(bad(format!("channel '{name}' appears twice")));
            }
        }
    }
    let (rgb, layers) = group_layers(channels).map_err(bad)?;
    Ok(ExrImage { rgb, layers, metadata })
}

/// Reads only the beauty image (channels `R`, `G`, `B`) of an OpenEXR file.
pub fn read_exr_rgb(path: &Path) -> Result<RgbImage> {
    read_exr(path).map(|image| image.rgb)
}

/// Refuses what the reader does not take, from the header alone, before pixels are allocated.
fn check_headers(meta: &MetaData) -> Result<(), String> {
    let mut samples = 0u64;
    for header in &meta.headers {
        if header.deep {
            return Err("deep data is not supported".into());
        }
        let (width, height) = (header.layer_size.width() as u64, header.layer_size.height() as u64);
        if width == 0 || height == 0 || width * height > MAX_PIXELS {
            return Err(format!(
                "header claims {width} × {height} pixels; this reader accepts 1 to {MAX_PIXELS} pixels"
            ));
        }
        for channel in &header.channels.list {
            if channel.sampling != Vec2(1, 1) {
                return Err(format!("channel '{}' is subsampled, which is not supported", channel.name));
            }
        }
        samples += width * height * header.channels.list.len() as u64;
        if samples > MAX_SAMPLES {
            return Err(format!("header claims more than {MAX_SAMPLES} channel samples in all"));
        }
    }
    if meta.headers.is_empty() {
        return Err("the file has no header".into());
    }
    Ok(())
}

/// Groups full channel names into the beauty image and named layers (rules in [`read_exr`]).
fn group_layers(
    mut channels: BTreeMap<String, (u32, u32, Vec<f32>)>,
) -> Result<(RgbImage, BTreeMap<String, ExrLayer>), String> {
    let found = channels.keys().cloned().collect::<Vec<_>>().join(", ");
    let mut prefixes: Vec<String> = channels.keys().map(|name| split_channel(name).0.to_string()).collect();
    prefixes.dedup();
    let mut beauty = None;
    let mut layers = BTreeMap::new();
    for prefix in prefixes {
        let full = |c: &str| if prefix.is_empty() { c.to_string() } else { format!("{prefix}.{c}") };
        let (r, g, b) = (full("R"), full("G"), full("B"));
        if channels.contains_key(&r) && channels.contains_key(&g) && channels.contains_key(&b) {
            let [r, g, b] = [&r, &g, &b].map(|name| channels.remove(name).expect("present"));
            if (r.0, r.1) != (g.0, g.1) || (r.0, r.1) != (b.0, b.1) {
                return Err(format!("the R, G, B channels of layer '{prefix}' differ in size"));
            }
            let pixels = (0..r.2.len()).map(|i| Vec3::new(r.2[i], g.2[i], b.2[i])).collect();
            let image = RgbImage { width: r.0, height: r.1, pixels };
            if prefix.is_empty() {
                beauty = Some(image);
            } else {
                layers.insert(prefix, ExrLayer::Rgb(image));
            }
        }
    }
    if beauty.is_none() {
        match channels.remove("Y") {
            Some((width, height, y)) => {
                beauty = Some(RgbImage { width, height, pixels: y.into_iter().map(Vec3::splat).collect() })
            }
            None => return Err(format!("no beauty channels R, G, B (or Y); the file has: {found}")),
        }
    }
    for (name, (width, height, pixels)) in channels {
        let (prefix, channel) = split_channel(&name);
        // `depth.Y` is layer `depth`, unless a colour layer `depth` exists too.
        let short = channel == "Y" && !prefix.is_empty() && !layers.contains_key(prefix);
        let layer_name = if short { prefix.to_string() } else { name.clone() };
        if layers.insert(layer_name.clone(), ExrLayer::Gray(GrayImage { width, height, pixels })).is_some() {
            return Err(format!("layer name '{layer_name}' is ambiguous"));
        }
    }
    Ok((beauty.expect("set above"), layers))
}

/// Channels `{prefix}R`, `{prefix}G`, `{prefix}B` holding `image` as f32.
fn rgb_channels(prefix: &str, image: &RgbImage) -> [AnyChannel<FlatSamples>; 3] {
    std::array::from_fn(|c| {
        let name = format!("{prefix}{}", ["R", "G", "B"][c]);
        let samples = image.pixels.iter().map(|p| p[c]).collect();
        AnyChannel::new(Text::from_slice_unchecked(name.as_bytes()), FlatSamples::F32(samples))
    })
}

/// `albedo.R` → (`albedo`, `R`); `R` → (``, `R`).
fn split_channel(name: &str) -> (&str, &str) {
    name.rsplit_once('.').unwrap_or(("", name))
}

/// Layer names we write: non-empty ASCII letters, digits, `_` and `-`, with inner dots allowed.
fn check_layer_name(name: &str) -> Result<(), String> {
    let ok_chars = name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-' || b == b'.');
    if name.is_empty() || name.len() > 200 || !ok_chars || name.starts_with('.') || name.ends_with('.') {
        return Err(format!(
            "AOV name {name:?}: use 1 to 200 ASCII letters, digits, '_', '-' (and inner '.')"
        ));
    }
    Ok(())
}

/// Adds the string-valued attributes of `attributes` to `out`.
fn collect_text(
    attributes: &std::collections::HashMap<Text, AttributeValue>,
    out: &mut BTreeMap<String, String>,
) {
    for (key, value) in attributes {
        if let AttributeValue::Text(text) = value {
            out.insert(text_to_string(key), text_to_string(text));
        }
    }
}

/// A layer's custom string attributes plus the standard ones the exr crate parses into fields.
fn collect_layer_text(attributes: &LayerAttributes, out: &mut BTreeMap<String, String>) {
    collect_text(&attributes.other, out);
    let standard = [
        ("software", &attributes.software_name),
        ("owner", &attributes.owner),
        ("comments", &attributes.comments),
        ("capDate", &attributes.capture_date),
        ("renderingTransform", &attributes.rendering_transform_name),
        ("lookModTransform", &attributes.look_modification_transform_name),
        ("view", &attributes.view_name),
    ];
    for (key, value) in standard {
        if let Some(text) = value {
            out.insert(key.to_string(), text_to_string(text));
        }
    }
}

/// OpenEXR text is bytes: UTF-8 by convention (and as we write it), else read as Latin-1.
fn text_to_string(text: &Text) -> String {
    match std::str::from_utf8(text.bytes()) {
        Ok(s) => s.to_string(),
        Err(_) => text.bytes().iter().map(|&b| b as char).collect(),
    }
}

/// The exr crate's message, with its wording for an early end of file made plain.
fn exr_message(error: &exr::error::Error) -> String {
    match error {
        exr::error::Error::Invalid(m) if m == "reference to missing bytes" => {
            "the file ends before its data does (truncated, or an offset points past the end)".into()
        }
        other => other.to_string(),
    }
}

/// Encoder errors surface as I/O errors of the atomic write, which names the file.
fn exr_to_io(error: exr::error::Error) -> std::io::Error {
    match error {
        exr::error::Error::Io(e) => e,
        other => std::io::Error::other(format!("OpenEXR encoder: {other}")),
    }
}

#[cfg(test)]
mod tests;
