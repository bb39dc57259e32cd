//! Stray pixels of a collage (docs/design/mcc.md §4.5): non-background pixels whose tag names no
//! camera with a ray file, counted, the first few located, and the likely cause told (an
//! antialiased edge, the wrong tag width, an untagged, resampled or JPEG picture, a view without
//! its ray file) in the caller's own terms ([`StrayHints`]). A leaf: the error type carries the
//! report, and the collage and composer readers fill it.

use std::collections::BTreeMap;
use std::fmt;

/// How many stray pixels a report locates.
pub const STRAY_LOCATIONS: usize = 8;

/// What to do with stray pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StrayPolicy {
    /// Refuse the collage (the default: a stray is usually a mistake worth fixing).
    #[default]
    Refuse,
    /// Treat strays as background (they are still reported).
    Background,
}

/// The names, in the caller's terms, of the settings a stray report points to (a command line
/// gives its flags), so this crate's messages name what the user can actually change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StrayHints {
    /// What treats strays as background ([`StrayPolicy::Background`]), e.g. `--ignore-strays`.
    pub ignore: &'static str,
    /// What sets the tag width (`crate::tag::TagCode`), e.g. `--tag-bits`.
    pub tag_bits: &'static str,
    /// What makes tagged views to cut a collage from, e.g. `render --tag`.
    pub tagged_views: &'static str,
    /// What makes the views as one layered file (no tags needed), e.g. `render --layers`.
    pub layered_views: &'static str,
}

impl Default for StrayHints {
    fn default() -> Self {
        Self {
            ignore: "the stray policy Background",
            tag_bits: "the tag width",
            tagged_views: "the tagger",
            layered_views: "the OpenRaster writer",
        }
    }
}

/// How many ids with no ray file a report lists by name (the rest are counted): an untagged
/// picture decodes to every id there is, and a list of 61 helps nobody.
pub const LISTED_IDS: usize = 4;

/// An unknown id with at least this many pixels is a solid block (a view without its ray file),
/// not the noise an antialiased edge makes.
pub const SOLID_BLOCK: usize = 64;

/// Stray pixels found in a collage.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StrayReport {
    /// Number of stray pixels.
    pub count: usize,
    /// How many of them decode to id 0.
    pub zero_id: usize,
    /// Ids without a ray file, with their pixel counts.
    pub unknown_ids: BTreeMap<u32, usize>,
    /// The first few stray pixels in raster order, as (x, y).
    pub first: Vec<(u32, u32)>,
    /// Non-background pixels in all (strays included): when nearly all are strays, the tag
    /// width is the likely cause.
    pub foreground: usize,
    /// The policy the collage was read with (a report of ignored strays suggests no remedy).
    pub policy: StrayPolicy,
    /// How to name the settings the report suggests.
    pub hints: StrayHints,
    /// Another tag width (bits per channel) at which nearly every non-background pixel names a
    /// camera with a ray file: the views' tag width, when the one given was wrong.
    pub fitting_bits: Option<u8>,
    /// The collage is a JPEG, whose lossy compression rewrites the tag bits.
    pub jpeg: bool,
    /// The collage's size, and the views' when known and different: a collage with strays
    /// and another size than its views was resampled.
    pub resized: Option<((u32, u32), (u32, u32))>,
}

impl StrayReport {
    /// True when the collage had no stray pixel.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Counts a stray pixel at (x, y) decoding to `id`.
    pub(crate) fn add(&mut self, x: u32, y: u32, id: u32) {
        self.count += 1;
        if id == 0 {
            self.zero_id += 1;
        } else {
            *self.unknown_ids.entry(id).or_default() += 1;
        }
        if self.first.len() < STRAY_LOCATIONS {
            self.first.push((x, y));
        }
    }
}

impl Default for StrayReport {
    fn default() -> Self {
        Self::new(StrayPolicy::default(), StrayHints::default())
    }
}

impl StrayReport {
    /// An empty report for a collage read with the stray policy `policy`, naming settings as
    /// `hints` says.
    pub fn new(policy: StrayPolicy, hints: StrayHints) -> Self {
        Self {
            count: 0,
            zero_id: 0,
            unknown_ids: BTreeMap::new(),
            first: Vec::new(),
            foreground: 0,
            policy,
            hints,
            fitting_bits: None,
            jpeg: false,
            resized: None,
        }
    }

    /// True when the pixels carry no tags at all: nearly all are strays and no other tag width
    /// reads them (an untagged picture, a JPEG, a resampled collage).
    pub fn untagged(&self) -> bool {
        self.nearly_all() && self.fitting_bits.is_none()
    }

    /// The ids with no ray file, the most frequent [`LISTED_IDS`] by name: "5 ×200, 7 ×3 and
    /// 58 more".
    fn listed_ids(&self) -> String {
        let mut by_count: Vec<(&u32, &usize)> = self.unknown_ids.iter().collect();
        by_count.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let ids: Vec<String> = by_count.iter().take(LISTED_IDS).map(|(id, n)| format!("{id} ×{n}")).collect();
        let more = by_count.len().saturating_sub(LISTED_IDS);
        if more > 0 { format!("{} and {more} more", ids.join(", ")) } else { ids.join(", ") }
    }

    /// True when nearly every non-background pixel is a stray (at least 90 %, of a collage
    /// with some size): the views were tagged with another tag width than the one given.
    pub fn nearly_all(&self) -> bool {
        self.foreground >= 16 && self.count * 10 >= self.foreground * 9
    }

    /// The unknown ids with a solid block of pixels ([`SOLID_BLOCK`] or more).
    pub fn solid_ids(&self) -> Vec<u32> {
        self.unknown_ids.iter().filter(|&(_, &n)| n >= SOLID_BLOCK).map(|(&id, _)| id).collect()
    }
}

impl fmt::Display for StrayReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if self.zero_id > 0 {
            parts.push(format!("{} with id 0", self.zero_id));
        }
        if !self.unknown_ids.is_empty() {
            parts.push(format!("ids with no ray file: {}", self.listed_ids()));
        }
        if self.untagged() || self.resized.is_some() {
            // No tags at all, or a resampled collage: which ids the noise decodes to, or where,
            // says nothing useful.
            let cause = match (self.jpeg, self.resized) {
                (true, _) => "the collage is a JPEG, whose lossy compression rewrites the low bits that \
                              carry the camera tags"
                    .to_owned(),
                (false, Some(((w, h), (vw, vh)))) => format!(
                    "the collage is {w}x{h} but the views are {vw}x{vh}: it was resampled, which rewrites \
                     the low bits that carry the camera tags"
                ),
                (false, None) => "its pixels carry no camera tags: it was not cut from tagged views, or \
                                  lost their tags on the way (resampled, colour-managed, saved lossy)"
                    .to_owned(),
            };
            return write!(
                f,
                "{} of {} non-background pixels name no camera with a ray file ({}): {cause}.\n\
                 Cut the collage from the tagged PNGs of {} with hard-edged selections and save it as \
                 PNG, or keep it layered (.ora or .psd, as {} writes it: no tags needed)",
                self.count,
                self.foreground,
                parts.join("; "),
                self.hints.tagged_views,
                self.hints.layered_views
            );
        }
        write!(f, "{} non-background pixel(s) carry no usable camera id (", self.count)?;
        write!(f, "{}); first at ", parts.join("; "))?;
        let at: Vec<String> = self.first.iter().map(|(x, y)| format!("({x}, {y})")).collect();
        write!(f, "{}", at.join(", "))?;
        if self.count > self.first.len() {
            write!(f, ", …")?;
        }
        // The likely cause, by the shape of the report.
        let solid = self.solid_ids();
        if let (true, Some(bits)) = (self.nearly_all(), self.fitting_bits) {
            write!(
                f,
                ": nearly every non-background pixel ({} of {}) decodes to no usable camera, but at {bits} \
                 bits per channel they name cameras with ray files, so the views were tagged with {bits}: \
                 give {} {bits}, as when they were rendered",
                self.count, self.foreground, self.hints.tag_bits
            )?;
        } else if !solid.is_empty() {
            let mut ids: Vec<String> = solid.iter().take(LISTED_IDS).map(u32::to_string).collect();
            if solid.len() > LISTED_IDS {
                ids.push(format!("… ({} cameras)", solid.len()));
            }
            write!(
                f,
                ": camera(s) {} cover whole areas but have no ray file for this frame: render their \
                 views with the lens writer into the rays folder (or check the frame number)",
                ids.join(", ")
            )?;
            if self.count > solid.iter().map(|id| self.unknown_ids[id]).sum::<usize>() {
                write!(f, "; the other strays are probably an antialiased selection edge")?;
            }
        } else {
            write!(
                f,
                ": probably an antialiased selection edge — cut the collage with hard-edged selections"
            )?;
        }
        if self.policy == StrayPolicy::Refuse {
            write!(f, ", or give {} to treat such pixels as background", self.hints.ignore)?;
        }
        Ok(())
    }
}
