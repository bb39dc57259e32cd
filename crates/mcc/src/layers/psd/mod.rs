//! Photoshop documents (`.psd`, Adobe's "Photoshop File Formats Specification"), as Photoshop,
//! GIMP and Krita save them: the header, then the layer and mask information section, whose
//! layer records (bottom layer first) give each layer's rectangle, channels, blend mode,
//! opacity, clipping, visibility and name (its Unicode `luni` form when present), and whose
//! `lsct` blocks open and close groups; then each layer's channel data, raw, PackBits (RLE) or
//! zlib-compressed (with or without prediction). Only the transparency channel is decoded: a
//! layer's colours play no part. 16-bit documents keep their layers in an `Lr16` block, which is
//! read the same way.
//!
//! Honoured: offsets (layers may reach past the canvas), visibility, opacity and fill opacity
//! (`iOpa`), groups (their visibility and opacity). Refused by name: blend modes other than
//! Normal (Pass Through for groups), clipping masks, enabled layer and vector masks, adjustment
//! and fill layers, 1- and 32-bit depth, bitmap, indexed, duotone and multichannel documents,
//! and the large-document format (PSB). Layer effects are ignored: a layer's own pixels decide.
//!
//! Written here rather than with the `psd` crate (0.3.5), which panics on crafted files (an
//! out-of-bounds slice from an unchecked section length; `unimplemented!` for zlib channels),
//! takes a group's opacity and visibility from its closing divider record instead of its
//! folder record, and does not expose masks or clipping. Every length here is checked against
//! the bytes that remain before it is used, and every size before anything is allocated.

mod channel;

use super::{
    Alpha, BLACK_TOLERANCE, LayerTree, LayeredFile, MAX_LAYERS, Node, NodeKind, check_canvas, check_layer,
};
use crate::error::{MccError, Result};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// A Photoshop document being read.
pub struct Psd {
    path: PathBuf,
    bytes: Vec<u8>,
    tree: LayerTree,
    layers: Vec<PixelLayer>,
    depth: u16,
}

/// Where a pixel layer's transparency is.
struct PixelLayer {
    name: String,
    width: u32,
    height: u32,
    /// The transparency channel's bytes (compression first), if it has one.
    alpha: Option<Range<usize>>,
    /// The colour channels' bytes (RGB or grey documents; empty for CMYK and Lab).
    colour: Vec<Range<usize>>,
}

/// A layer's transparency channel (if any) and colour channels, as byte ranges of the file.
type Channels = (Option<Range<usize>>, Vec<Range<usize>>);

/// A bounds-checked reader over part of the file; errors name the part.
struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
    path: &'a Path,
    part: &'static str,
}

impl<'a> Cursor<'a> {
    fn error(&self, message: impl Into<String>) -> MccError {
        MccError::layered(self.path, self.part, message)
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or_else(|| {
            self.error(format!(
                "needs {n} more bytes at offset {}, but only {} remain (truncated or damaged)",
                self.at,
                self.bytes.len() - self.at
            ))
        })?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }

    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Result<u16> {
        let b = self.take(2)?;
        Ok(u16::from_be_bytes([b[0], b[1]]))
    }

    fn u32(&mut self) -> Result<u32> {
        let b = self.take(4)?;
        Ok(u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn i32(&mut self) -> Result<i32> {
        Ok(self.u32()? as i32)
    }

    fn key(&mut self) -> Result<[u8; 4]> {
        Ok(self.take(4)?.try_into().expect("4 bytes"))
    }

    /// A `u32`-length-prefixed block as its own cursor (same part name).
    fn block(&mut self, part: &'static str) -> Result<Cursor<'a>> {
        let len = self.u32()? as usize;
        let start = self.at;
        let bytes = self.take(len)?;
        Ok(Cursor { bytes: &self.bytes[..start + bytes.len()], at: start, path: self.path, part })
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }
}

/// One layer record, as read.
struct Record {
    name: String,
    top: i32,
    left: i32,
    bottom: i32,
    right: i32,
    /// (channel id, byte length including the compression field).
    channels: Vec<(i16, usize)>,
    blend: [u8; 4],
    opacity: u8,
    clipped: bool,
    hidden: bool,
    fill: u8,
    /// `lsct`: 1 or 2 opens a group (its folder record), 3 closes one.
    section: u32,
    section_blend: Option<[u8; 4]>,
    mask_enabled: bool,
    refused: Option<&'static str>,
}

impl Psd {
    /// Reads the document's structure (not yet its pixels).
    pub fn open(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| MccError::io(path, e))?;
        let (tree, layers, depth) = parse(&bytes, path)?;
        Ok(Self { path: path.to_path_buf(), bytes, tree, layers, depth })
    }
}

/// The blend mode a key names, for messages.
fn blend_name(key: &[u8; 4]) -> String {
    let name = match key {
        b"pass" => "Pass Through",
        b"norm" => "Normal",
        b"diss" => "Dissolve",
        b"dark" => "Darken",
        b"mul " => "Multiply",
        b"idiv" => "Color Burn",
        b"lbrn" => "Linear Burn",
        b"dkCl" => "Darker Color",
        b"lite" => "Lighten",
        b"scrn" => "Screen",
        b"div " => "Color Dodge",
        b"lddg" => "Linear Dodge (Add)",
        b"lgCl" => "Lighter Color",
        b"over" => "Overlay",
        b"sLit" => "Soft Light",
        b"hLit" => "Hard Light",
        b"vLit" => "Vivid Light",
        b"lLit" => "Linear Light",
        b"pLit" => "Pin Light",
        b"hMix" => "Hard Mix",
        b"diff" => "Difference",
        b"smud" => "Exclusion",
        b"fsub" => "Subtract",
        b"fdiv" => "Divide",
        b"hue " => "Hue",
        b"sat " => "Saturation",
        b"colr" => "Color",
        b"lum " => "Luminosity",
        _ => return format!("{:?}", String::from_utf8_lossy(key)),
    };
    name.to_owned()
}

/// Keys of adjustment and fill layers (no pixels of their own).
const ADJUSTMENTS: [&[u8; 4]; 21] = [
    b"SoCo", b"GdFl", b"PtFl", b"brit", b"levl", b"curv", b"expA", b"vibA", b"hue ", b"hue2", b"blnc",
    b"blwh", b"phfl", b"mixr", b"clrL", b"nvrt", b"post", b"thrs", b"grdm", b"selc", b"CgEd",
];

fn parse(bytes: &[u8], path: &Path) -> Result<(LayerTree, Vec<PixelLayer>, u16)> {
    let mut c = Cursor { bytes, at: 0, path, part: "header" };
    if c.take(4).ok() != Some(b"8BPS") {
        return Err(c.error("no 8BPS signature: not a Photoshop document"));
    }
    match c.u16()? {
        1 => {}
        2 => return Err(c.error("large-document format (PSB) is not supported; save as PSD")),
        v => return Err(c.error(format!("version {v} is unknown (1 is PSD)"))),
    }
    c.take(6)?;
    let _channels = c.u16()?;
    let height = c.u32()?;
    let width = c.u32()?;
    let (width, height) = check_canvas(path, "header", width.into(), height.into())?;
    let depth = c.u16()?;
    if depth != 8 && depth != 16 {
        return Err(
            c.error(format!("{depth}-bit channels are not supported; save with 8 or 16 bits per channel"))
        );
    }
    let mode = c.u16()?;
    match mode {
        1 | 3 | 4 | 9 => {}
        mode => {
            let name = match mode {
                0 => "bitmap",
                2 => "indexed colour",
                7 => "multichannel",
                8 => "duotone",
                _ => "unknown",
            };
            return Err(c.error(format!("{name} colour mode ({mode}) is not supported; save as RGB")));
        }
    }
    c.part = "colour mode data";
    c.block("colour mode data")?;
    c.part = "image resources";
    c.block("image resources")?;
    c.part = "layer and mask information";
    let mut section = c.block("layer and mask information")?;
    if section.remaining() == 0 {
        return Err(section.error("the document has no layers (a flattened image); save it with its layers"));
    }
    let mut info = section.block("layer info")?;
    if info.remaining() == 0 {
        // 16- and 32-bit documents keep their layers in a tagged block after the global mask.
        section.block("global layer mask info")?;
        section.part = "additional layer information";
        while section.remaining() >= 12 {
            let _signature = section.key()?;
            let key = section.key()?;
            let block = section.block("additional layer information")?;
            if &key == b"Lr16" || &key == b"Lr32" || &key == b"Layr" {
                info = Cursor { part: "layer info", ..block };
                break;
            }
        }
    }
    if info.remaining() == 0 {
        return Err(info.error("the document has no layers (a flattened image); save it with its layers"));
    }
    let count = (info.u16()? as i16).unsigned_abs() as usize;
    if count > MAX_LAYERS {
        return Err(info.error(format!("{count} layer records; at most {MAX_LAYERS} are accepted")));
    }
    info.part = "layer records";
    let mut records = Vec::with_capacity(count);
    for _ in 0..count {
        records.push(read_record(&mut info)?);
    }
    // The channel data follows, record by record, channel by channel.
    info.part = "channel image data";
    let colour_channels = match mode {
        1 => 1,
        3 => 3,
        _ => 0,
    };
    let mut channels = Vec::with_capacity(count);
    for r in &records {
        let (mut alpha, mut colour) = (None, Vec::new());
        for &(id, len) in &r.channels {
            let start = info.at;
            info.take(len)?;
            if id == -1 {
                alpha = Some(start..start + len);
            } else if (0..colour_channels).contains(&id) {
                colour.push(start..start + len);
            }
        }
        channels.push((alpha, colour));
    }
    build_tree(path, width, height, records, channels).map(|(tree, layers)| (tree, layers, depth))
}

fn read_record(c: &mut Cursor<'_>) -> Result<Record> {
    let (top, left, bottom, right) = (c.i32()?, c.i32()?, c.i32()?, c.i32()?);
    let n = c.u16()? as usize;
    if n > 56 {
        return Err(c.error(format!("a layer record claims {n} channels; a document has at most 56")));
    }
    let mut channels = Vec::with_capacity(n);
    for _ in 0..n {
        let id = c.u16()? as i16;
        let len = c.u32()? as usize;
        if len < 2 {
            return Err(c.error(format!("channel {id} claims {len} bytes, less than its compression field")));
        }
        channels.push((id, len));
    }
    if c.take(4)? != b"8BIM" {
        return Err(c.error("a layer record's blend-mode signature is not 8BIM"));
    }
    let blend = c.key()?;
    let opacity = c.u8()?;
    let clipped = c.u8()? != 0;
    let flags = c.u8()?;
    c.u8()?;
    let mut extra = c.block("layer records")?;
    let mut mask = extra.block("layer records")?;
    // A layer mask's flags (after its rectangle and default colour): bit 1 disables it.
    let mask_enabled = mask.remaining() >= 18 && {
        mask.take(17)?;
        mask.u8()? & 2 == 0
    };
    extra.block("layer records")?; // blending ranges
    let name_len = extra.u8()? as usize;
    let name = extra.take(name_len)?;
    // Latin-1 → Unicode (the Pascal name predates Unicode; `luni` below replaces it).
    let mut name: String = name.iter().map(|&b| b as char).collect();
    extra.take((4 - (1 + name_len) % 4) % 4)?;
    let mut record = Record {
        name: String::new(),
        top,
        left,
        bottom,
        right,
        channels,
        blend,
        opacity,
        clipped,
        hidden: flags & 2 != 0,
        fill: 255,
        section: 0,
        section_blend: None,
        mask_enabled,
        refused: None,
    };
    while extra.remaining() >= 12 {
        let signature = extra.key()?;
        if &signature != b"8BIM" && &signature != b"8B64" {
            return Err(extra.error("an additional-information block lacks its 8BIM signature"));
        }
        let key = extra.key()?;
        let mut block = extra.block("layer records")?;
        match &key {
            b"luni" => {
                let chars = block.u32()? as usize;
                let units = block.take(chars.saturating_mul(2))?;
                let units: Vec<u16> =
                    units.chunks_exact(2).map(|u| u16::from_be_bytes([u[0], u[1]])).collect();
                name = String::from_utf16_lossy(&units).trim_end_matches('\0').to_owned();
            }
            b"lsct" | b"lsdk" => {
                record.section = block.u32()?;
                if block.remaining() >= 8 {
                    block.take(4)?;
                    record.section_blend = Some(block.key()?);
                }
            }
            b"iOpa" => record.fill = block.u8()?,
            b"vmsk" | b"vsms" => record.refused = Some("a vector mask"),
            k if ADJUSTMENTS.contains(&k) => record.refused = Some("an adjustment or fill layer"),
            _ => {}
        }
    }
    record.name = name;
    Ok(record)
}

/// Layer records (bottom first) → the tree (top first), refusing what is not supported.
fn build_tree(
    path: &Path,
    width: u32,
    height: u32,
    records: Vec<Record>,
    channels: Vec<Channels>,
) -> Result<(LayerTree, Vec<PixelLayer>)> {
    // Open groups, innermost last: (its node, its children so far).
    let mut stack: Vec<(Node, Vec<Node>)> = Vec::new();
    let mut top: Vec<Node> = Vec::new();
    let mut layers = Vec::new();
    for (r, (alpha, colour)) in records.into_iter().zip(channels).rev() {
        let entry = format!("layer {:?}", r.name);
        let refuse = |what: String| {
            MccError::layered(path, &entry, format!("{what} is not supported; {}", fix(&what)))
        };
        let opacity = r.opacity as f32 / 255.0 * (r.fill as f32 / 255.0);
        let node = match r.section {
            1 | 2 => {
                let blend = r.section_blend.unwrap_or(r.blend);
                if &blend != b"pass" && &blend != b"norm" {
                    return Err(refuse(format!("the group's blend mode {}", blend_name(&blend))));
                }
                let group =
                    Node { name: r.name, visible: !r.hidden, opacity, kind: NodeKind::Group(Vec::new()) };
                stack.push((group, Vec::new()));
                continue;
            }
            3 => {
                let Some((mut group, children)) = stack.pop() else {
                    return Err(MccError::layered(
                        path,
                        "layer records",
                        "a group closes that was never opened",
                    ));
                };
                group.kind = NodeKind::Group(children);
                group
            }
            _ => {
                if let Some(what) = r.refused {
                    return Err(refuse(what.to_owned()));
                }
                if &r.blend != b"norm" {
                    return Err(refuse(format!("blend mode {}", blend_name(&r.blend))));
                }
                if r.clipped {
                    return Err(refuse("a clipping mask".to_owned()));
                }
                if r.mask_enabled && r.channels.iter().any(|&(id, _)| id == -2 || id == -3) {
                    return Err(refuse("a layer mask".to_owned()));
                }
                let (w, h) = (r.right as i64 - r.left as i64, r.bottom as i64 - r.top as i64);
                if w < 0 || h < 0 {
                    return Err(MccError::layered(
                        path,
                        &entry,
                        format!(
                            "its rectangle ({}, {}) to ({}, {}) has a negative size",
                            r.left, r.top, r.right, r.bottom
                        ),
                    ));
                }
                check_layer(path, &entry, r.left.into(), r.top.into(), w as u64, h as u64)?;
                layers.push(PixelLayer {
                    name: r.name.clone(),
                    width: w as u32,
                    height: h as u32,
                    alpha,
                    colour,
                });
                let kind = NodeKind::Layer { x: r.left.into(), y: r.top.into(), index: layers.len() - 1 };
                Node { name: r.name, visible: !r.hidden, opacity, kind }
            }
        };
        match stack.last_mut() {
            Some((_, children)) => children.push(node),
            None => top.push(node),
        }
    }
    if let Some((group, _)) = stack.last() {
        return Err(MccError::layered(
            path,
            format!("group {:?}", group.name),
            "never closes (damaged layer records)",
        ));
    }
    Ok((LayerTree { width, height, nodes: top }, layers))
}

/// How to get rid of an unsupported feature, for the message.
fn fix(what: &str) -> &'static str {
    if what.contains("blend mode") {
        "set it to Normal: only a layer's alpha decides which pixels it takes"
    } else if what.contains("mask") {
        "apply or delete the mask (or the clipping) and save again"
    } else {
        "delete the layer or merge it down and save again"
    }
}

impl LayeredFile for Psd {
    fn path(&self) -> &Path {
        &self.path
    }

    fn tree(&self) -> &LayerTree {
        &self.tree
    }

    fn alpha(&mut self, index: usize) -> Result<Alpha> {
        let layer = &self.layers[index];
        let (width, height) = (layer.width, layer.height);
        let Some(range) = layer.alpha.clone() else {
            return Ok(Alpha { width, height, values: None });
        };
        let entry = format!("layer {:?}: transparency channel", layer.name);
        let values = channel::decode_channel(
            &self.bytes[range],
            width as usize,
            height as usize,
            self.depth,
            &self.path,
            &entry,
        )?;
        Ok(Alpha { width, height, values: Some(values) })
    }

    fn holds_picture(&mut self, index: usize) -> Result<bool> {
        let alpha = self.alpha(index)?;
        let layer = &self.layers[index];
        let (w, h) = (layer.width as usize, layer.height as usize);
        let limit = BLACK_TOLERANCE as u16 * 257 + 256;
        for (k, range) in layer.colour.iter().enumerate() {
            let entry = format!("layer {:?}: colour channel {k}", layer.name);
            let values =
                channel::decode_channel(&self.bytes[range.clone()], w, h, self.depth, &self.path, &entry)?;
            let opaque = |i: usize| alpha.values.as_ref().is_none_or(|a| a[i] >= 1 << 15);
            if values.iter().enumerate().any(|(i, &v)| v > limit && opaque(i)) {
                return Ok(true);
            }
        }
        Ok(false)
    }
}
