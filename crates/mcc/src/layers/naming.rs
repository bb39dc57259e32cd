//! Which camera a layer is, from its name (docs/layers.md). Tried in this order, ignoring
//! case and surrounding spaces:
//!
//! 1. `background` (the layer `render --layers` writes, and every editor's default name): the
//!    background, as is `0`;
//! 2. a bare id: `3`;
//! 3. the name `render --layers` gives: `left (camera 3)`. Its name and number must agree
//!    where both can be checked: over views (`remap`, `keys`) the number is the views' and a
//!    view's recorded name must be the layer's; a layer whose name and number disagree is
//!    refused, naming both readings. Where the numbers are another render's ([`CameraNames::session`],
//!    the studio numbering its own cameras) the name wins, and a name that is no camera there is
//!    refused rather than read by a number that counts something else;
//! 4. a camera's name, `left`: the names recorded in the views' EXR headers
//!    (`frameFFFFcameraCC.exr` beside the ray files, read only when a layer needs them), or a
//!    table the caller gives;
//! 5. the last `camera` followed by digits: `camera 3`, `Camera #3`, `frame0005camera03.png`
//!    (the name an editor gives a view opened as a layer) and its copies (`… copy`).
//!
//! Anything else names no camera: an error naming the layer, unless an enclosing group names one.

use crate::names::view_render_name;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::OnceLock;

/// What a layer is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The background (id 0).
    Background,
    /// A camera.
    Camera(u32),
}

/// Camera names (lowercase) → the ids carrying them.
type Table = BTreeMap<String, Vec<u32>>;

/// Where camera names come from.
#[derive(Debug)]
enum Names {
    /// No names: only ids.
    None,
    /// A table given by the caller.
    Given(Table),
    /// The views' EXR headers in `dir` for `frame`, read on first need.
    Views { dir: PathBuf, frame: u32, table: OnceLock<Table> },
}

/// The cameras a layered collage may name: the ids that have ray files, and their names.
#[derive(Debug)]
pub struct CameraNames {
    known: Option<BTreeSet<u32>>,
    names: Names,
    /// The ids are not the numbering `NAME (camera N)` layers were written with (the studio's
    /// own cameras): N says nothing, NAME decides.
    foreign_numbers: bool,
}

impl CameraNames {
    /// Ids only; `known` lists the cameras with ray files (`None`: any id).
    pub fn ids(known: Option<BTreeSet<u32>>) -> Self {
        Self { known, names: Names::None, foreign_numbers: false }
    }

    /// Ids and the names in `names` (name, id).
    pub fn with_names(known: Option<BTreeSet<u32>>, names: impl IntoIterator<Item = (String, u32)>) -> Self {
        let mut table = Table::new();
        for (name, id) in names {
            table.entry(name.trim().to_lowercase()).or_default().push(id);
        }
        Self { known, names: Names::Given(table), foreign_numbers: false }
    }

    /// A session's own cameras (name, id), numbered independently of any render: a layer
    /// `NAME (camera N)` (written by `render --layers` with that render's numbering) is the
    /// session's camera NAME whatever N is, and is refused when NAME is none of them.
    pub fn session(names: impl IntoIterator<Item = (String, u32)>) -> Self {
        let names: Vec<(String, u32)> = names.into_iter().collect();
        let known = names.iter().map(|(_, id)| *id).collect();
        Self { foreign_numbers: true, ..Self::with_names(Some(known), names) }
    }

    /// Ids `known`, and the names the views of `frame` in `dir` recorded (the `mcctrace/camera`
    /// attribute of `frameFFFFcameraCC.exr`, read only when a layer's name needs it).
    pub fn from_views(known: BTreeSet<u32>, dir: impl Into<PathBuf>, frame: u32) -> Self {
        Self {
            known: Some(known),
            names: Names::Views { dir: dir.into(), frame, table: OnceLock::new() },
            foreign_numbers: false,
        }
    }

    /// The cameras with ray files (`None`: any id is accepted).
    pub fn known(&self) -> Option<&BTreeSet<u32>> {
        self.known.as_ref()
    }

    fn table(&self) -> Option<&Table> {
        match &self.names {
            Names::None => None,
            Names::Given(table) => Some(table),
            Names::Views { dir, frame, table } => Some(table.get_or_init(|| {
                let mut names = Table::new();
                for &id in self.known.iter().flatten() {
                    if let Some(name) = view_camera_name(&dir.join(view_render_name(*frame, id))) {
                        names.entry(name.trim().to_lowercase()).or_default().push(id);
                    }
                }
                names
            })),
        }
    }

    /// What the layer named `name` is, if its name says; an error when a camera name is
    /// ambiguous.
    pub fn resolve(&self, name: &str) -> Result<Option<Role>, String> {
        let lower = name.trim().to_lowercase();
        if lower == "background" {
            return Ok(Some(Role::Background));
        }
        if let Some(id) = parse_id(&lower) {
            return Ok(Some(role(id)));
        }
        if let Some((stem, id)) = lower
            .strip_suffix(')')
            .and_then(|s| s.rsplit_once("(camera "))
            .and_then(|(stem, n)| Some((stem.trim(), parse_id(n)?)))
        {
            return self.resolve_numbered(stem, id).map(|id| Some(role(id)));
        }
        if let Some(ids) = self.table().and_then(|t| t.get(&lower)) {
            return match ids.as_slice() {
                [id] => Ok(Some(role(*id))),
                _ => Err(format!(
                    "the name is shared by cameras {}; rename the layer to one of their ids",
                    list(ids.iter().copied())
                )),
            };
        }
        Ok(last_camera_number(&lower).map(role))
    }

    /// The camera a layer `stem (camera number)` is: the number and the name checked against
    /// each other (module doc, rule 3).
    fn resolve_numbered(&self, stem: &str, number: u32) -> Result<u32, String> {
        let Some(table) = self.table().filter(|_| !stem.is_empty() && number != 0) else {
            return Ok(number);
        };
        let by_name = table.get(stem).map(Vec::as_slice);
        let name_of = |id: u32| table.iter().find(|(_, ids)| ids.contains(&id)).map(|(n, _)| n.as_str());
        let fix_number = |id: u32| match name_of(id) {
            Some(name) => format!("\"{name} (camera {id})\""),
            None => format!("\"camera {id}\""),
        };
        match (by_name, self.foreign_numbers) {
            (Some(ids), _) if ids.contains(&number) => Ok(number),
            (Some([id]), true) => Ok(*id),
            (Some([id]), false) => Err(format!(
                "its name says camera {id} (\"{stem}\") but its number says camera {number}{}; \
                 rename the layer \"{stem} (camera {id})\" if it shows {stem}, or {} if it shows camera \
                 {number}",
                name_of(number).map_or(String::new(), |n| format!(", which the views name \"{n}\"")),
                fix_number(number),
            )),
            (Some(ids), _) => Err(format!(
                "the name is shared by cameras {}; rename the layer to one of their ids",
                list(ids.iter().copied())
            )),
            (None, false) => match name_of(number) {
                None => Ok(number),
                Some(other) => Err(format!(
                    "its name says camera \"{stem}\", which no view records, but its number says \
                     camera {number}, which the views name \"{other}\"; rename the layer {} if it \
                     shows camera {number}, or render {stem}'s view with the others",
                    fix_number(number)
                )),
            },
            (None, true) => Err(format!(
                "its name says camera \"{stem}\", which this session does not have ({}), and its \
                 number {number} counts the cameras of the render that wrote it, not the session's \
                 (here camera {number} is {}); rename the layer to the camera it shows, or start \
                 the session with that camera",
                self.named_list(),
                name_of(number).map_or("none".to_owned(), |n| format!("\"{n}\"")),
            )),
        }
    }

    /// `"left" (1), "right" (2)`: the names known, with their ids.
    fn named_list(&self) -> String {
        let named: Vec<String> = self
            .table()
            .into_iter()
            .flatten()
            .map(|(name, ids)| format!("\"{name}\" ({})", list(ids.iter().copied())))
            .collect();
        if named.is_empty() { "no named cameras".to_owned() } else { named.join(", ") }
    }

    /// The error message for a layer whose name names no camera.
    pub fn unknown_name_message(&self) -> String {
        let names = match self.table() {
            Some(table) if !table.is_empty() => format!(", a camera's name ({})", self.named_list()),
            _ => String::new(),
        };
        format!(
            "names no camera: name each visible layer by its camera id (\"3\", \"camera 3\"){names} \
             or \"background\", or hide it"
        )
    }

    /// The error message for a layer naming camera `id`, which has no ray file.
    pub fn no_rays_message(&self, id: u32) -> String {
        let known = self.known.iter().flatten().copied();
        format!("is camera {id}, which has no ray file (cameras with ray files: {})", list(known))
    }
}

fn role(id: u32) -> Role {
    if id == 0 { Role::Background } else { Role::Camera(id) }
}

/// `s` as a decimal id, when it is nothing but digits.
fn parse_id(s: &str) -> Option<u32> {
    (!s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())).then(|| s.parse().ok()).flatten()
}

/// The number after the last `camera` that is followed (after spaces, `#`, `_` or `-`) by
/// digits.
fn last_camera_number(lower: &str) -> Option<u32> {
    lower.rmatch_indices("camera").find_map(|(at, word)| {
        let rest = lower[at + word.len()..].trim_start_matches([' ', '#', '_', '-']);
        let digits = &rest[..rest.find(|c: char| !c.is_ascii_digit()).unwrap_or(rest.len())];
        parse_id(digits)
    })
}

/// `1, 2, 3`, or `none`.
fn list(ids: impl Iterator<Item = u32>) -> String {
    let all: Vec<String> = ids.map(|id| id.to_string()).collect();
    if all.is_empty() { "none".to_owned() } else { all.join(", ") }
}

/// The `mcctrace/camera` attribute of the EXR at `path` (headers only), if there is one.
fn view_camera_name(path: &std::path::Path) -> Option<String> {
    use exr::meta::attribute::AttributeValue;
    let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
    meta.headers.iter().find_map(|h| {
        match h.own_attributes.other.iter().find(|(k, _)| **k == *"mcctrace/camera") {
            Some((_, AttributeValue::Text(t))) => Some(t.to_string()),
            _ => None,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_resolve_in_order() {
        let names = CameraNames::with_names(
            Some([1, 2, 3].into()),
            [("left".into(), 1), ("camera2".into(), 1), ("twin".into(), 2), ("Twin".into(), 3)],
        );
        let r = |n: &str| names.resolve(n);
        assert_eq!(r(" Background "), Ok(Some(Role::Background)));
        assert_eq!(r("0"), Ok(Some(Role::Background)));
        assert_eq!(r("12"), Ok(Some(Role::Camera(12))));
        assert_eq!(r("left (camera 1)"), Ok(Some(Role::Camera(1))));
        assert_eq!(r("(camera 3)"), Ok(Some(Role::Camera(3))));
        // Name and number disagree: refused, naming both readings and the fix.
        let err = r("left (camera 3)").unwrap_err();
        assert!(
            err.contains("camera 1 (\"left\")")
                && err.contains("camera 3")
                && err.contains("\"left (camera 1)\""),
            "{err}"
        );
        let err = r("wide (camera 1)").unwrap_err();
        assert!(
            err.contains("\"wide\", which no view records")
                && err.contains(" (camera 1)\" if it shows camera 1"),
            "{err}"
        );
        // A shared name: the number picks among its cameras.
        assert_eq!(r("twin (camera 3)"), Ok(Some(Role::Camera(3))));
        assert_eq!(r("LEFT"), Ok(Some(Role::Camera(1))));
        // A camera's own name wins over the camera-number pattern it happens to contain.
        assert_eq!(r("camera2"), Ok(Some(Role::Camera(1))));
        assert_eq!(r("Camera #4"), Ok(Some(Role::Camera(4))));
        assert_eq!(r("frame0005camera03.png copy"), Ok(Some(Role::Camera(3))));
        assert_eq!(r("camera2 (camera 1)"), Ok(Some(Role::Camera(1))));
        assert_eq!(r("Layer 1"), Ok(None));
        assert_eq!(r("camera"), Ok(None));
        assert!(r("twin").unwrap_err().contains("2, 3"));
        assert!(names.unknown_name_message().contains("\"left\" (1)"));
        assert_eq!(CameraNames::ids(None).resolve("left"), Ok(None));
        assert_eq!(CameraNames::ids(None).resolve("wide (camera 1)"), Ok(Some(Role::Camera(1))));
    }

    #[test]
    fn a_session_reads_numbered_layers_by_name() {
        let names = CameraNames::session([("left".into(), 1), ("right".into(), 2), ("wide".into(), 3)]);
        assert_eq!(names.resolve("right (camera 1)"), Ok(Some(Role::Camera(2))));
        assert_eq!(names.resolve("wide (camera 2)"), Ok(Some(Role::Camera(3))));
        assert_eq!(names.resolve("camera 2"), Ok(Some(Role::Camera(2))));
        let err = names.resolve("cornell (camera 1)").unwrap_err();
        assert!(
            err.contains("\"cornell\", which this session does not have") && err.contains("\"left\""),
            "{err}"
        );
    }
}
