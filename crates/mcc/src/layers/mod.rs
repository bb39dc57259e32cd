//! Layered collages (docs/layers.md, cut in an editor that keeps layers): a layer *is* a
//! camera, so no tag bits are needed. Each visible layer names its camera ([`naming`]); the
//! layers are taken top to bottom and a pixel belongs to the topmost layer whose alpha there,
//! times its opacity and its groups', is at least ½ — hard edges by rule, so a soft brush or a
//! feathered selection just works — else to the background. A layer named `background` takes
//! its pixels for the background.
//!
//! A top-level group named `regions` is not part of the collage: its direct children are the
//! regions (same rule; pixels under none of them form one more region). A layered file given
//! as the region image is read the same way, every top-level layer or group a region.
//!
//! One reader per format, each a [`LayeredFile`]: [`openraster`] (a zip archive with an XML
//! layer stack; also the writer of `render --layers`) and [`psd`]. Both parse the structure
//! first and decode one layer's alpha at a time, so memory stays at one layer plus the result.
//! [`open_collage`] tells the format from the file's first bytes (then its extension) and reads
//! tagged images ([`Collage::load`]) exactly as before.

pub mod naming;
pub mod openraster;
pub mod psd;

#[cfg(test)]
mod tests;

use crate::collage::{Collage, CollageOptions};
use crate::error::{MccError, Result};
use crate::regions::{RegionInfo, Regions};
use crate::stray::StrayReport;
pub use naming::{CameraNames, Role};
use std::io::Read;
use std::path::{Path, PathBuf};

/// The most layers and groups a layered file may hold.
pub const MAX_LAYERS: usize = 4096;
/// The deepest nesting of groups accepted.
pub const MAX_DEPTH: usize = 64;
/// The most pixels one layer may have (layers may reach past the canvas): 2^27, as a ray file.
pub const MAX_LAYER_PIXELS: u64 = crate::ray_file::MAX_PIXELS;
/// The largest canvas side accepted (a collage has its views' size: a ray file's limit).
pub const MAX_SIDE: u32 = crate::ray_file::MAX_SIDE;
/// The farthest a layer may be offset from the canvas, in pixels, either way.
pub const MAX_OFFSET: i64 = 1 << 20;
/// A layer's alpha at full coverage (8-bit alpha is widened ×257, so 255 → 65535).
pub const OPAQUE: u16 = u16::MAX;

/// A layered file's structure: the canvas and its layer tree, topmost first.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerTree {
    /// Canvas width in pixels.
    pub width: u32,
    /// Canvas height in pixels.
    pub height: u32,
    /// The top-level layers and groups, topmost first.
    pub nodes: Vec<Node>,
}

/// A layer or a group.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Its name in the editor.
    pub name: String,
    /// False when hidden (a hidden group hides everything in it).
    pub visible: bool,
    /// Opacity in [0, 1] (multiplied into its layers' alpha, and its children's).
    pub opacity: f32,
    /// A layer or a group.
    pub kind: NodeKind,
}

/// What a [`Node`] is.
#[derive(Clone, Debug, PartialEq)]
pub enum NodeKind {
    /// A pixel layer; its alpha comes from [`LayeredFile::alpha`] with this index.
    Layer {
        /// Offset of its left column on the canvas.
        x: i64,
        /// Offset of its top row on the canvas.
        y: i64,
        /// Its index for [`LayeredFile::alpha`].
        index: usize,
    },
    /// A group of layers, topmost first.
    Group(Vec<Node>),
}

/// One layer's coverage: alpha per pixel, 0 … [`OPAQUE`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Alpha {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Alpha per pixel, row-major; `None` when the layer has no alpha (opaque everywhere).
    pub values: Option<Vec<u16>>,
}

/// A layered file being read: its structure, and each layer's alpha on demand.
pub trait LayeredFile {
    /// The file, for messages.
    fn path(&self) -> &Path;
    /// The canvas and the layer tree.
    fn tree(&self) -> &LayerTree;
    /// Decodes layer `index`'s alpha; errors name the file and the entry.
    fn alpha(&mut self, index: usize) -> Result<Alpha>;
    /// True when layer `index` shows a picture rather than black where it is at least half
    /// opaque (a layer named `background` must not: GIMP names the first view it opens so).
    fn holds_picture(&mut self, index: usize) -> Result<bool>;
}

/// The brightest channel value (of 255) a background layer may have and still count as black
/// (editors' colour management may move black by a unit or two).
pub const BLACK_TOLERANCE: u8 = 8;

/// The kinds of collage file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// A tagged image (PNG, TIFF …: [`Collage::load`]).
    Image,
    /// An OpenRaster archive (`.ora`).
    OpenRaster,
    /// A Photoshop document (`.psd`).
    Psd,
}

impl Format {
    /// The format of the file at `path`: by its first bytes (zip or `8BPS`), else by its
    /// extension (so a damaged `.ora` is reported as a bad archive, not as an undecodable image).
    pub fn of(path: &Path) -> Result<Self> {
        let mut head = [0u8; 4];
        let mut file = std::fs::File::open(path).map_err(|e| MccError::io(path, e))?;
        let n = file.read(&mut head).map_err(|e| MccError::io(path, e))?;
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        Ok(match (&head[..n], ext.as_deref()) {
            (b"PK\x03\x04", _) | (_, Some("ora")) => Self::OpenRaster,
            (b"8BPS", _) | (_, Some("psd" | "psb")) => Self::Psd,
            _ => Self::Image,
        })
    }

    /// Opens a layered file of this format (`None` for [`Format::Image`]).
    fn open(self, path: &Path) -> Result<Option<Box<dyn LayeredFile>>> {
        Ok(match self {
            Self::Image => None,
            Self::OpenRaster => Some(Box::new(openraster::OpenRaster::open(path)?)),
            Self::Psd => Some(Box::new(psd::Psd::open(path)?)),
        })
    }
}

/// Where a collage's regions came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RegionSource {
    /// No region image: one region.
    None,
    /// A region image file (given, or found beside the collage).
    File(PathBuf),
    /// The collage's own `regions` group.
    Group,
}

/// A collage file read with its regions.
#[derive(Clone, Debug)]
pub struct OpenedCollage {
    /// One camera id per pixel.
    pub collage: Collage,
    /// Stray pixels treated as background (tagged images only; empty otherwise).
    pub strays: StrayReport,
    /// The region of every pixel.
    pub regions: Regions,
    /// Where the regions came from.
    pub regions_from: RegionSource,
    /// What the user should know about the layers (e.g. a layer too transparent to take any
    /// pixel), without failing.
    pub notes: Vec<String>,
}

/// Reads the collage at `path`, whatever its format, and its regions: `regions` if given (an
/// image or a layered file), else the collage's `regions` group, else
/// `<collage-stem>-regions.png` beside it, else one region. `cameras` says which ids have ray
/// files and how layer names map to ids. Refuses a `regions` group together with a region image.
pub fn open_collage(
    path: &Path,
    regions: Option<&Path>,
    cameras: &CameraNames,
    options: CollageOptions,
) -> Result<OpenedCollage> {
    let Some(mut file) = Format::of(path)?.open(path)? else {
        let (collage, strays) = Collage::load(path, cameras.known(), options)?;
        let (regions, used) = load_regions_or_find(path, regions, collage.width, collage.height)?;
        let regions_from = used.map_or(RegionSource::None, RegionSource::File);
        return Ok(OpenedCollage { collage, strays, regions, regions_from, notes: Vec::new() });
    };
    let (width, height) = (file.tree().width, file.tree().height);
    let (group, nodes): (Vec<&Node>, Vec<&Node>) =
        file.tree().nodes.iter().partition(|n| is_regions_group(n));
    let nodes: Vec<Node> = nodes.into_iter().cloned().collect();
    let group: Option<Vec<Node>> = match group.as_slice() {
        [] => None,
        [one] => match &one.kind {
            NodeKind::Group(children) => Some(if one.visible { children.clone() } else { Vec::new() }),
            NodeKind::Layer { .. } => unreachable!("is_regions_group takes groups only"),
        },
        _ => {
            return Err(MccError::layered(path, "layer stack", "has two groups named \"regions\"; keep one"));
        }
    };
    let mut notes = Vec::new();
    let labels = paint(
        file.as_mut(),
        &nodes,
        &|node, inherited| camera_label(path, cameras, node, inherited),
        &mut notes,
    )?;
    let ids: Vec<u32> = labels.into_iter().map(|l| if l == UNCLAIMED { 0 } else { l }).collect();
    let collage = Collage::new(width, height, ids)?;
    let beside = Regions::beside(path);
    let (regions, regions_from) = match (group, regions) {
        (Some(_), Some(explicit)) => {
            return Err(MccError::layered(
                path,
                "group \"regions\"",
                format!("the collage has its own regions, and {} was given too; use one", explicit.display()),
            ));
        }
        (Some(_), None) if beside.is_file() => {
            return Err(MccError::layered(
                path,
                "group \"regions\"",
                format!(
                    "the collage has its own regions, and {} lies beside it; remove or rename one",
                    beside.display()
                ),
            ));
        }
        (Some(children), None) => {
            (regions_from_nodes(file.as_mut(), &children, &mut notes)?, RegionSource::Group)
        }
        (None, explicit) => {
            let (r, used) = load_regions_or_find(path, explicit, width, height)?;
            (r, used.map_or(RegionSource::None, RegionSource::File))
        }
    };
    Ok(OpenedCollage { collage, strays: StrayReport::default(), regions, regions_from, notes })
}

/// The regions of a `width × height` collage from `explicit` (an image or a layered file), else
/// from the image beside `collage`, else one region ([`Regions::find`]'s rule).
fn load_regions_or_find(
    collage: &Path,
    explicit: Option<&Path>,
    width: u32,
    height: u32,
) -> Result<(Regions, Option<PathBuf>)> {
    match explicit {
        Some(path) => Ok((load_regions(path, width, height)?, Some(path.to_path_buf()))),
        None => Regions::find(collage, None, width, height),
    }
}

/// Reads a region image at `path`, an image ([`Regions::load`]) or a layered file whose
/// top-level layers and groups are the regions; it must be `width × height`.
pub fn load_regions(path: &Path, width: u32, height: u32) -> Result<Regions> {
    let Some(mut file) = Format::of(path)?.open(path)? else {
        return Regions::load(path, width, height);
    };
    let tree = file.tree();
    if (tree.width, tree.height) != (width, height) {
        return Err(MccError::SizeMismatch {
            path: path.into(),
            what: "the region image".into(),
            found: (tree.width, tree.height),
            expected_from: "the collage".into(),
            expected: (width, height),
        });
    }
    let nodes = tree.nodes.clone();
    regions_from_nodes(file.as_mut(), &nodes, &mut Vec::new())
}

fn is_regions_group(node: &Node) -> bool {
    matches!(node.kind, NodeKind::Group(_)) && node.name.trim().eq_ignore_ascii_case("regions")
}

/// What a layer paints, from the node and the label its groups pass down (see [`camera_label`]).
type LabelFn<'a> = dyn Fn(&Node, Option<u32>) -> Result<Option<u32>> + 'a;

/// A pixel no layer has taken yet.
const UNCLAIMED: u32 = u32::MAX;

/// The label a layer paints: its camera (0 for the background), from its own name, else from
/// the nearest enclosing group whose name names one (`inherited`).
fn camera_label(
    path: &Path,
    cameras: &CameraNames,
    node: &Node,
    inherited: Option<u32>,
) -> Result<Option<u32>> {
    let what = if matches!(node.kind, NodeKind::Group(_)) { "group" } else { "layer" };
    let entry = format!("{what} {:?}", node.name);
    match cameras.resolve(&node.name).map_err(|message| MccError::layered(path, &entry, message))? {
        Some(Role::Background) => Ok(Some(0)),
        Some(Role::Camera(id)) => {
            if let Some(known) = cameras.known()
                && !known.contains(&id)
            {
                return Err(MccError::layered(path, entry, cameras.no_rays_message(id)));
            }
            Ok(Some(id))
        }
        None if inherited.is_some() || what == "group" => Ok(inherited),
        None => Err(MccError::layered(path, entry, cameras.unknown_name_message())),
    }
}

/// Labels a region layer: its top-level node's index + 1 (0 is "under no region layer").
fn regions_from_nodes(
    file: &mut dyn LayeredFile,
    nodes: &[Node],
    notes: &mut Vec<String>,
) -> Result<Regions> {
    let (width, height) = (file.tree().width, file.tree().height);
    let mut labels = vec![UNCLAIMED; width as usize * height as usize];
    let mut painter = Painter::new(file, &mut labels, notes);
    for (k, node) in nodes.iter().enumerate() {
        painter.paint(node, 1.0, Some(k as u32 + 1), &|_, inherited| Ok(inherited), 0)?;
    }
    // Dense region numbers in raster order of first pixel, as a region image's.
    let mut number = vec![u32::MAX; nodes.len() + 1];
    let mut info = Vec::new();
    let mut index = Vec::with_capacity(labels.len());
    for (k, &label) in labels.iter().enumerate() {
        let label = if label == UNCLAIMED { 0 } else { label } as usize;
        if number[label] == u32::MAX {
            number[label] = info.len() as u32;
            let layer = match label {
                0 => "under no region layer".to_owned(),
                l => format!("layer {:?}", nodes[l - 1].name),
            };
            let first = (k as u32 % width, k as u32 / width);
            info.push(RegionInfo { colour: [0, 0, 0, 0], first, layer: Some(layer) });
        }
        index.push(number[label]);
    }
    Ok(Regions { width, height, index, info })
}

/// Paints `nodes` top to bottom into a label plane (see [`Painter`]); unclaimed pixels stay
/// [`UNCLAIMED`].
fn paint(
    file: &mut dyn LayeredFile,
    nodes: &[Node],
    label: &LabelFn<'_>,
    notes: &mut Vec<String>,
) -> Result<Vec<u32>> {
    let (width, height) = (file.tree().width as usize, file.tree().height as usize);
    let mut labels = vec![UNCLAIMED; width * height];
    let mut painter = Painter::new(file, &mut labels, notes);
    for node in nodes {
        painter.paint(node, 1.0, None, label, 0)?;
    }
    Ok(labels)
}

/// The top-to-bottom walk: each visible layer claims the still unclaimed pixels where its alpha
/// times its opacity (and its groups') is at least ½. A visible layer that claims none is noted,
/// with the layers above that cover it: it changes nothing, which the user did not mean.
struct Painter<'a> {
    file: &'a mut dyn LayeredFile,
    labels: &'a mut [u32],
    /// Which layer (its number in `names`) claimed each pixel; meaningful where `labels` is not
    /// [`UNCLAIMED`].
    owners: Vec<u16>,
    /// The names of the layers painted so far, in order.
    names: Vec<String>,
    notes: &'a mut Vec<String>,
}

impl<'a> Painter<'a> {
    fn new(file: &'a mut dyn LayeredFile, labels: &'a mut [u32], notes: &'a mut Vec<String>) -> Self {
        let owners = vec![0; labels.len()];
        Self { file, labels, owners, names: Vec::new(), notes }
    }

    fn paint(
        &mut self,
        node: &Node,
        opacity: f32,
        inherited: Option<u32>,
        label: &LabelFn<'_>,
        depth: usize,
    ) -> Result<()> {
        if !node.visible {
            return Ok(());
        }
        let opacity = opacity * node.opacity;
        // Names are checked for every visible layer, even below a canvas already full, so a
        // misnamed layer is reported whatever lies above it.
        let own = label(node, inherited)?;
        match &node.kind {
            NodeKind::Group(children) => {
                if depth >= MAX_DEPTH {
                    return Err(MccError::layered(
                        self.file.path(),
                        format!("group {:?}", node.name),
                        format!("groups nest deeper than {MAX_DEPTH} levels"),
                    ));
                }
                for child in children {
                    self.paint(child, opacity, own, label, depth + 1)?;
                }
            }
            &NodeKind::Layer { x, y, index } => {
                let Some(value) = own else { unreachable!("a layer's label is known or an error") };
                let Some(threshold) = threshold(opacity) else {
                    self.notes.push(format!(
                        "layer {:?} is visible, but at {:.0} % opacity no pixel of it reaches alpha ½: \
                         it takes no pixel",
                        node.name,
                        opacity * 100.0
                    ));
                    return Ok(());
                };
                if value == 0 && self.file.holds_picture(index)? {
                    return Err(MccError::layered(
                        self.file.path(),
                        format!("layer {:?}", node.name),
                        "is named as the background, but it holds a picture, not black (an editor \
                         names the first image it opens \"Background\"): rename it after its camera \
                         (\"camera 2\", or the view's file name)",
                    ));
                }
                // Claimed even under a full canvas: a layer that takes nothing is worth a note.
                self.claim(node, x, y, index, threshold, value)?;
            }
        }
        Ok(())
    }

    /// Claims the pixels of layer `index` whose alpha is at least `threshold`.
    fn claim(&mut self, node: &Node, x: i64, y: i64, index: usize, threshold: u16, value: u32) -> Result<()> {
        let alpha = self.file.alpha(index)?;
        let tree = self.file.tree();
        let (cw, ch) = (tree.width as i64, tree.height as i64);
        let (x0, x1) = (x.max(0), (x + alpha.width as i64).min(cw));
        let (y0, y1) = (y.max(0), (y + alpha.height as i64).min(ch));
        if x0 >= x1 || y0 >= y1 {
            if alpha.width > 0 && alpha.height > 0 {
                self.notes.push(format!(
                    "layer {:?} ({}x{} at ({x}, {y})) lies wholly outside the {cw}x{ch} canvas: it takes no pixel",
                    node.name, alpha.width, alpha.height
                ));
            }
            return Ok(());
        }
        // MAX_LAYERS bounds the layers, so their numbers fit.
        let me = self.names.len() as u16;
        self.names.push(node.name.clone());
        let (mut claimed, mut covering) = (0usize, 0usize);
        // The layers above holding the pixels this one would take (noted if it takes none).
        let mut above = std::collections::BTreeSet::new();
        for cy in y0..y1 {
            let row = (cy * cw) as usize;
            let src_row = ((cy - y) * alpha.width as i64) as usize;
            for cx in x0..x1 {
                let a = alpha.values.as_ref().map_or(OPAQUE, |v| v[src_row + (cx - x) as usize]);
                if a < threshold {
                    continue;
                }
                covering += 1;
                let k = row + cx as usize;
                if self.labels[k] == UNCLAIMED {
                    self.labels[k] = value;
                    self.owners[k] = me;
                    claimed += 1;
                } else if claimed == 0 {
                    above.insert(self.owners[k]);
                }
            }
        }
        if claimed == 0 {
            let why = if covering == 0 {
                "none of its pixels is at least half opaque".to_owned()
            } else {
                let names: Vec<String> =
                    above.iter().map(|&o| format!("{:?}", self.names[o as usize])).collect();
                let shown = if names.len() > 3 {
                    format!("{} and {} more", names[..3].join(", "), names.len() - 3)
                } else {
                    names.join(", ")
                };
                format!("the layers above it ({shown}) cover every pixel it would take")
            };
            self.notes.push(format!("layer {:?} is visible, but {why}: it takes no pixel", node.name));
        }
        Ok(())
    }
}

/// The least alpha (0 … 65535) that, times `opacity`, is at least ½ (a/65535 · opacity ≥ ½);
/// `None` when even full alpha is not.
pub fn threshold(opacity: f32) -> Option<u16> {
    let opacity = f64::from(opacity);
    let half = f64::from(OPAQUE) / 2.0;
    // `None` also for a NaN opacity (no comparison holds).
    if (opacity * f64::from(OPAQUE)).partial_cmp(&half).is_none_or(|o| o.is_lt()) {
        return None;
    }
    // The quotient is within an ulp of the answer; step to the exact least integer.
    let mut t = (half / opacity).ceil().clamp(0.0, f64::from(OPAQUE)) as u32;
    while t > 0 && f64::from(t - 1) * opacity >= half {
        t -= 1;
    }
    while f64::from(t) * opacity < half {
        t += 1;
    }
    Some(t as u16)
}

/// Reads at most `limit` bytes of `reader` into memory; more is an error naming `path` and
/// `entry` (the limit holds whatever sizes the file declares: a zip bomb stops at it).
pub(crate) fn read_limited(
    reader: impl Read,
    limit: u64,
    path: &Path,
    entry: &str,
    why: &str,
) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    reader
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| MccError::layered(path, entry, format!("cannot read it: {e}")))?;
    if bytes.len() as u64 > limit {
        return Err(MccError::layered(
            path,
            entry,
            format!(
                "decompresses to more than {limit} bytes, more than {why} can need (damaged, or a zip bomb)"
            ),
        ));
    }
    Ok(bytes)
}

/// Refuses a canvas of no pixels or past the collage limits; `entry` names where it was read.
pub(crate) fn check_canvas(path: &Path, entry: &str, width: u64, height: u64) -> Result<(u32, u32)> {
    if width == 0 || height == 0 || width > MAX_SIDE as u64 || height > MAX_SIDE as u64 {
        return Err(MccError::layered(
            path,
            entry,
            format!("the canvas is {width}x{height}; each side must be 1 to {MAX_SIDE} pixels"),
        ));
    }
    if width * height > crate::ray_file::MAX_PIXELS {
        return Err(MccError::layered(
            path,
            entry,
            format!(
                "the canvas is {width}x{height}, more than the {} pixels a collage may have",
                crate::ray_file::MAX_PIXELS
            ),
        ));
    }
    Ok((width as u32, height as u32))
}

/// Refuses a layer larger than [`MAX_LAYER_PIXELS`] or offset past [`MAX_OFFSET`].
pub(crate) fn check_layer(path: &Path, entry: &str, x: i64, y: i64, width: u64, height: u64) -> Result<()> {
    if width * height > MAX_LAYER_PIXELS {
        return Err(MccError::layered(
            path,
            entry,
            format!(
                "the layer is {width}x{height}, more than the {MAX_LAYER_PIXELS} pixels a layer may have"
            ),
        ));
    }
    if x.abs() > MAX_OFFSET || y.abs() > MAX_OFFSET {
        return Err(MccError::layered(
            path,
            entry,
            format!("the layer is offset to ({x}, {y}), more than {MAX_OFFSET} pixels from the canvas"),
        ));
    }
    Ok(())
}
