//! The collage composer: what a user does by hand in an image editor (docs/design.md §1, §8),
//! scripted for tests, demos and batch work. A *label image* says which camera each pixel shows:
//! black (0, 0, 0) or alpha 0 is background, and every other exact colour picks a camera, either
//! through an explicit colour → camera map or by the colour's own tag bits. Each labelled pixel
//! then copies that camera's tagged view pixel, so the result is exactly the collage an editor with
//! hard-edged selections would save.
//!
//! ```no_run
//! # use mcc::compose::{LabelMap, compose_files};
//! # use std::path::Path;
//! let map = LabelMap::Colours([([255, 0, 0], 1), ([0, 0, 255], 2)].into_iter().collect());
//! compose_files(Path::new("labels.png"), &map, Path::new("views/"), 5, Path::new("collage.png"))?;
//! # Ok::<(), mcc::MccError>(())
//! ```

use crate::error::{MccError, Result};
use crate::names::find_tagged_views;
use crate::tag::TagCode;
use image::{DynamicImage, Rgb, RgbImage, RgbaImage};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// How label colours name cameras.
#[derive(Clone, Debug, PartialEq)]
pub enum LabelMap {
    /// The colour's own tag bits are the camera id (label with a tagged colour).
    TagBits(TagCode),
    /// An explicit map from exact RGB colour to camera id.
    Colours(HashMap<[u8; 3], u32>),
}

impl LabelMap {
    /// The camera a non-background label colour names, if any.
    pub fn camera(&self, rgb: [u8; 3]) -> Option<u32> {
        match self {
            LabelMap::TagBits(code) => Some(code.decode(rgb)).filter(|&id| id != 0),
            LabelMap::Colours(map) => map.get(&rgb).copied(),
        }
    }
}

/// Composes a collage from `labels` (RGBA: alpha 0 or black is background) and the tagged views
/// (camera id → image, all the labels' size). Refuses label colours that name no camera and
/// cameras without a view, with the count, the reasons and the first few pixels concerned.
pub fn compose(labels: &RgbaImage, map: &LabelMap, views: &BTreeMap<u32, RgbImage>) -> Result<RgbImage> {
    let (w, h) = labels.dimensions();
    for (id, view) in views {
        if view.dimensions() != (w, h) {
            let (vw, vh) = view.dimensions();
            return Err(MccError::input(
                format!("camera {id}'s view"),
                format!("is {vw}x{vh}, but the labels are {w}x{h}"),
            ));
        }
    }
    let mut out = RgbImage::new(w, h);
    let mut bad = BadLabels::default();
    for (x, y, p) in labels.enumerate_pixels() {
        let [r, g, b, a] = p.0;
        if a == 0 || [r, g, b] == [0, 0, 0] {
            continue;
        }
        match map.camera([r, g, b]) {
            None => bad.add(format!("the colour #{r:02x}{g:02x}{b:02x}, which names no camera"), x, y),
            Some(id) => match views.get(&id) {
                None => bad.add(format!("camera {id}, which has no tagged view"), x, y),
                Some(view) => out.put_pixel(x, y, Rgb(view.get_pixel(x, y).0)),
            },
        }
    }
    if bad.count > 0 {
        return Err(MccError::input("label image", bad.to_string()));
    }
    Ok(out)
}

/// Label pixels that name no usable camera: how many, why, and where the first few are.
#[derive(Default)]
struct BadLabels {
    count: usize,
    /// Per reason (colour or camera), its pixel count, in order of first appearance.
    reasons: Vec<(String, usize)>,
    first: Vec<(u32, u32)>,
}

impl BadLabels {
    fn add(&mut self, reason: String, x: u32, y: u32) {
        self.count += 1;
        match self.reasons.iter_mut().find(|(r, _)| *r == reason) {
            Some((_, n)) => *n += 1,
            None => self.reasons.push((reason, 1)),
        }
        if self.first.len() < crate::stray::STRAY_LOCATIONS {
            self.first.push((x, y));
        }
    }
}

impl std::fmt::Display for BadLabels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let reasons: Vec<String> = self.reasons.iter().map(|(r, n)| format!("{n} with {r}")).collect();
        let at: Vec<String> = self.first.iter().map(|(x, y)| format!("({x}, {y})")).collect();
        let more = if self.count > self.first.len() { ", …" } else { "" };
        write!(
            f,
            "{} pixel(s) name no usable camera ({}); first at {}{more}",
            self.count,
            reasons.join("; "),
            at.join(", ")
        )
    }
}

/// [`compose`] from files: the labels at `labels`, the tagged views `frameFFFFcameraCC.png` of
/// frame `frame` in `views_dir` (only the cameras the labels use are read), the collage written
/// to `output` atomically.
pub fn compose_files(
    labels: &Path,
    map: &LabelMap,
    views_dir: &Path,
    frame: u32,
    output: &Path,
) -> Result<()> {
    let label_image = crate::png::read_image(labels)?;
    let rgba = match &label_image {
        DynamicImage::ImageRgb8(_) | DynamicImage::ImageRgba8(_) => label_image.to_rgba8(),
        _ => {
            return Err(MccError::image(
                labels,
                format!(
                    "label images must be 8-bit RGB or RGBA (exact colours), not {:?}",
                    label_image.color()
                ),
            ));
        }
    };
    let available = find_tagged_views(views_dir, frame)?;
    let mut wanted: Vec<u32> = Vec::new();
    let mut last = None;
    for p in rgba.pixels() {
        let [r, g, b, a] = p.0;
        if a == 0 || [r, g, b] == [0, 0, 0] || last == Some([r, g, b]) {
            continue;
        }
        last = Some([r, g, b]);
        if let Some(id) = map.camera([r, g, b])
            && !wanted.contains(&id)
        {
            wanted.push(id);
        }
    }
    let mut views = BTreeMap::new();
    for id in wanted {
        if let Some(path) = available.get(&id) {
            let view = crate::png::read_image(path)?;
            if (view.width(), view.height()) != rgba.dimensions() {
                return Err(MccError::SizeMismatch {
                    path: path.clone(),
                    what: format!("camera {id}'s tagged view"),
                    found: (view.width(), view.height()),
                    expected_from: labels.display().to_string(),
                    expected: rgba.dimensions(),
                });
            }
            views.insert(id, view.to_rgb8());
        }
    }
    let collage = compose(&rgba, map, &views).map_err(|e| match e {
        MccError::Input { message, .. } => MccError::image(labels, message),
        other => other,
    })?;
    crate::png::write_png(output, &DynamicImage::ImageRgb8(collage))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collage::Collage;
    use crate::names::view_tagged_name;
    use crate::test_util::scratch_dir;
    use image::Rgba;

    #[test]
    fn composes_a_collage_that_decodes_to_the_labels() {
        let dir = scratch_dir("compose");
        let code = TagCode::default();
        let (w, h) = (9, 5);
        for id in [1, 2, 7] {
            let mut view = RgbImage::from_fn(w, h, |x, y| Rgb([x as u8 * 20, y as u8 * 40, id as u8 * 30]));
            code.tag_rgb(&mut view, id).unwrap();
            crate::png::write_png(&dir.join(view_tagged_name(5, id)), &DynamicImage::ImageRgb8(view))
                .unwrap();
        }
        let labels = RgbaImage::from_fn(w, h, |x, y| match (x / 3, y) {
            (0, _) => Rgba([255, 0, 0, 255]),
            (1, 0) => Rgba([255, 0, 0, 0]), // transparent: background
            (2, _) => Rgba([0, 0, 255, 255]),
            _ => Rgba([0, 0, 0, 255]),
        });
        let label_path = dir.join("labels.png");
        crate::png::write_png(&label_path, &DynamicImage::ImageRgba8(labels)).unwrap();
        let map = LabelMap::Colours([([255, 0, 0], 7), ([0, 0, 255], 2)].into_iter().collect());
        let out = dir.join("collage.png");
        compose_files(&label_path, &map, &dir, 5, &out).unwrap();
        let (collage, _) = Collage::load(&out, None, Default::default()).unwrap();
        for y in 0..h {
            for x in 0..w {
                let want = match x / 3 {
                    0 => 7,
                    2 => 2,
                    _ => 0,
                };
                assert_eq!(collage.id(x, y), want, "({x}, {y})");
            }
        }
        // The copied pixels are the views' own.
        let img = crate::png::read_image(&out).unwrap().to_rgb8();
        assert_eq!(img.get_pixel(0, 1).0, code.encode([0, 40, 210], 7).unwrap());
        // Tag-bit labels: a colour tagged with camera 1.
        let tagged = RgbaImage::from_fn(w, h, |_, _| {
            Rgba({
                let [r, g, b] = code.encode([128, 128, 128], 1).unwrap();
                [r, g, b, 255]
            })
        });
        crate::png::write_png(&label_path, &DynamicImage::ImageRgba8(tagged)).unwrap();
        compose_files(&label_path, &LabelMap::TagBits(code), &dir, 5, &out).unwrap();
        let (collage, _) = Collage::load(&out, None, Default::default()).unwrap();
        assert!(collage.ids.iter().all(|&id| id == 1));
        // Errors name the pixel and the camera.
        let map = LabelMap::Colours([([255, 0, 0], 3)].into_iter().collect());
        let bad = RgbaImage::from_pixel(w, h, Rgba([255, 0, 0, 255]));
        crate::png::write_png(&label_path, &DynamicImage::ImageRgba8(bad)).unwrap();
        let err = compose_files(&label_path, &map, &dir, 5, &out).unwrap_err().to_string();
        assert!(err.contains("labels.png") && err.contains("camera 3") && err.contains("(0, 0)"), "{err}");
        let err = compose_files(&label_path, &LabelMap::Colours(HashMap::new()), &dir, 5, &out)
            .unwrap_err()
            .to_string();
        assert!(err.contains("#ff0000"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_label_pixels_are_counted_and_located() {
        let map = LabelMap::Colours([([255, 0, 0], 1), ([0, 0, 255], 4)].into_iter().collect());
        let views = BTreeMap::from([(1, RgbImage::new(6, 4))]);
        // Column 5 an unknown colour (4 pixels), row 3 camera 4 without a view (5 pixels).
        let labels = RgbaImage::from_fn(6, 4, |x, y| match (x, y) {
            (5, _) => Rgba([9, 9, 9, 255]),
            (_, 3) => Rgba([0, 0, 255, 255]),
            _ => Rgba([255, 0, 0, 255]),
        });
        let err = compose(&labels, &map, &views).unwrap_err().to_string();
        for want in [
            "9 pixel(s) name no usable camera",
            "4 with the colour #090909, which names no camera",
            "5 with camera 4, which has no tagged view",
            "first at (5, 0), (5, 1), (5, 2), (0, 3), (1, 3), (2, 3), (3, 3), (4, 3), …",
        ] {
            assert!(err.contains(want), "{err:?} lacks {want:?}");
        }
    }
}
