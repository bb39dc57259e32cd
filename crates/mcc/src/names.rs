//! File names (docs/design/mcc.md §4.3): source views are `frame0005camera03.{exr,png,mcr|txt}`
//! (render, tagged image, rays), rerender rays are `rerender-frame0005.{mcr|txt}`. Frames print
//! with at least 4 digits and cameras with at least 2; readers accept any number of digits, so
//! `frame12345camera100.mcr` round-trips. The ray-file extension only names the usual encoding:
//! readers tell the encoding from the content.

use crate::error::{MccError, Result};
use crate::ray_file::RayFormat;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Extensions a ray file may have.
pub const RAY_EXTENSIONS: [&str; 2] = ["mcr", "txt"];

/// `frame0005camera03`: the stem every file of one source view shares.
pub fn view_stem(frame: u32, camera: u32) -> String {
    format!("frame{frame:04}camera{camera:02}")
}

/// `frame0005camera03.exr`: a source view's linear render.
pub fn view_render_name(frame: u32, camera: u32) -> String {
    format!("{}.exr", view_stem(frame, camera))
}

/// `frame0005camera03.png`: a source view's tagged 8-bit image.
pub fn view_tagged_name(frame: u32, camera: u32) -> String {
    format!("{}.png", view_stem(frame, camera))
}

/// `frame0005camera03.mcr` (or `.txt`): a source view's ray file.
pub fn view_rays_name(frame: u32, camera: u32, format: RayFormat) -> String {
    format!("{}.{}", view_stem(frame, camera), format.extension())
}

/// `rerender-frame0005.mcr` (or `.txt`): the ray file the lens reader uses for a frame.
pub fn rerender_name(frame: u32, format: RayFormat) -> String {
    format!("rerender-frame{frame:04}.{}", format.extension())
}

/// Leading decimal digits of `s` as a number (at least one digit), and the rest.
fn number(s: &str) -> Option<(u32, &str)> {
    let end = s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
    Some((s[..end].parse().ok()?, &s[end..]))
}

/// Splits `frame0005camera03.ext` into (frame, camera, extension).
pub fn parse_view_name(name: &str) -> Option<(u32, u32, &str)> {
    let (frame, rest) = number(name.strip_prefix("frame")?)?;
    let (camera, rest) = number(rest.strip_prefix("camera")?)?;
    Some((frame, camera, rest.strip_prefix('.')?))
}

/// Splits `rerender-frame0005.ext` into (frame, extension).
pub fn parse_rerender_name(name: &str) -> Option<(u32, &str)> {
    let (frame, rest) = number(name.strip_prefix("rerender-frame")?)?;
    Some((frame, rest.strip_prefix('.')?))
}

/// The files of `dir` whose names `parse` accepts, as (parsed key, path). Non-UTF-8 names are
/// not ours and are skipped.
fn scan<K: Ord + Copy>(dir: &Path, parse: impl Fn(&str) -> Option<K>) -> Result<Vec<(K, PathBuf)>> {
    let entries = std::fs::read_dir(dir).map_err(|e| MccError::io(dir, e))?;
    let mut found = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| MccError::io(dir, e))?;
        let name = entry.file_name();
        let Some(key) = name.to_str().and_then(&parse) else { continue };
        found.push((key, entry.path()));
    }
    found.sort();
    Ok(found)
}

/// Refuses two files for one key (e.g. `…camera03.mcr` beside `…camera03.txt`): which one is
/// meant cannot be guessed.
fn unique<K: Ord + Copy>(
    dir: &Path,
    found: Vec<(K, PathBuf)>,
    what: impl Fn(K) -> String,
) -> Result<BTreeMap<K, PathBuf>> {
    let mut map = BTreeMap::new();
    for (key, path) in found {
        if let Some(previous) = map.insert(key, path.clone()) {
            return Err(MccError::Directory {
                path: dir.into(),
                message: format!(
                    "two ray files for {}: {} and {}; remove one",
                    what(key),
                    file_name(&previous),
                    file_name(&path)
                ),
            });
        }
    }
    Ok(map)
}

fn file_name(path: &Path) -> String {
    path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

/// The ray files of frame `frame` in `dir` (either extension), as camera id → path.
/// An empty map is not an error here: callers say what they needed.
pub fn find_view_rays(dir: &Path, frame: u32) -> Result<BTreeMap<u32, PathBuf>> {
    let found = scan(dir, |name| {
        let (f, camera, ext) = parse_view_name(name)?;
        (f == frame && RAY_EXTENSIONS.contains(&ext)).then_some(camera)
    })?;
    unique(dir, found, |camera| format!("frame {frame}, camera {camera}"))
}

/// The tagged view images (`frameFFFFcameraCC.png`) of frame `frame` in `dir`, as camera → path.
pub fn find_tagged_views(dir: &Path, frame: u32) -> Result<BTreeMap<u32, PathBuf>> {
    let found = scan(dir, |name| {
        let (f, camera, ext) = parse_view_name(name)?;
        (f == frame && ext.eq_ignore_ascii_case("png")).then_some(camera)
    })?;
    unique(dir, found, |camera| format!("frame {frame}, camera {camera}"))
}

/// The rerender ray file of frame `frame` in `dir` (either extension), if there is one.
pub fn rerender_rays_if_any(dir: &Path, frame: u32) -> Result<Option<PathBuf>> {
    let found = scan(dir, |name| {
        let (f, ext) = parse_rerender_name(name)?;
        (f == frame && RAY_EXTENSIONS.contains(&ext)).then_some(f)
    })?;
    Ok(unique(dir, found, |f| format!("frame {f}"))?.remove(&frame))
}

/// The rerender ray file of frame `frame` in `dir` (either extension); its absence is an error.
pub fn find_rerender_rays(dir: &Path, frame: u32) -> Result<PathBuf> {
    rerender_rays_if_any(dir, frame)?.ok_or_else(|| MccError::Directory {
        path: dir.into(),
        message: format!(
            "no rerender ray file for frame {frame} ({})",
            rerender_name(frame, RayFormat::Binary)
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::scratch_dir;

    #[test]
    fn names_follow_the_spec() {
        assert_eq!(view_render_name(5, 3), "frame0005camera03.exr");
        assert_eq!(view_tagged_name(5, 3), "frame0005camera03.png");
        assert_eq!(view_rays_name(5, 3, RayFormat::Binary), "frame0005camera03.mcr");
        assert_eq!(view_rays_name(5, 3, RayFormat::Text), "frame0005camera03.txt");
        assert_eq!(rerender_name(5, RayFormat::Binary), "rerender-frame0005.mcr");
        assert_eq!(view_stem(12345, 100), "frame12345camera100");
        assert_eq!(parse_view_name("frame0005camera03.mcr"), Some((5, 3, "mcr")));
        assert_eq!(parse_view_name("frame12345camera100.txt"), Some((12345, 100, "txt")));
        assert_eq!(parse_rerender_name("rerender-frame0150.txt"), Some((150, "txt")));
        for bad in ["frame0005camera03", "framecamera03.mcr", "frame0005.mcr", "xframe0005camera03.mcr"] {
            assert_eq!(parse_view_name(bad), None, "{bad}");
        }
    }

    #[test]
    fn finds_the_rays_of_a_frame() {
        let dir = scratch_dir("names");
        for name in [
            "frame0005camera01.mcr",
            "frame0005camera02.txt",
            "frame0005camera02.png",
            "frame0006camera01.mcr",
            "frame0005camera10.mcr",
            "notes.txt",
            "rerender-frame0005.txt",
        ] {
            std::fs::write(dir.join(name), b"").unwrap();
        }
        let found = find_view_rays(&dir, 5).unwrap();
        assert_eq!(found.keys().copied().collect::<Vec<_>>(), [1, 2, 10]);
        assert!(found[&2].ends_with("frame0005camera02.txt"));
        assert_eq!(find_tagged_views(&dir, 5).unwrap().len(), 1);
        assert!(find_rerender_rays(&dir, 5).unwrap().ends_with("rerender-frame0005.txt"));
        let err = find_rerender_rays(&dir, 6).unwrap_err().to_string();
        assert!(err.contains("rerender-frame0006.mcr"), "{err}");
        std::fs::write(dir.join("frame0005camera01.txt"), b"").unwrap();
        let err = find_view_rays(&dir, 5).unwrap_err().to_string();
        assert!(err.contains("two ray files") && err.contains("camera 1"), "{err}");
        assert!(find_view_rays(&dir.join("missing"), 5).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
