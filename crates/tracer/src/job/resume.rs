//! Safe resume (docs/farm.md, "Bands and resume"): an output already on disk counts as finished
//! only when its files exist, read back whole, have the size asked for and record in their
//! header the same settings as this run. Anything else is rendered again, and the reason is
//! said, so a farm task re-run after a crash, a kill or a changed setting never keeps a stale or
//! damaged frame.

use super::{COUNT_KEYS, DENOISER_KEY};
use crate::image_io::{read_exr, read_png8};
use glam::UVec2;
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

/// Why an output on disk is not a finished render of this run's settings.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Stale {
    /// A file is not there.
    Missing(PathBuf),
    /// A file does not read back whole.
    Damaged {
        /// The file.
        path: PathBuf,
        /// What reading it said.
        reason: String,
    },
    /// The image has another size than this run's.
    Size {
        /// The file's size.
        was: UVec2,
        /// This run's.
        now: UVec2,
    },
    /// Settings in the header differ from this run's: (key without `mcctrace/`, the file's
    /// value, this run's), `None` where one side has no such setting.
    Settings(Vec<(String, Option<String>, Option<String>)>),
}

impl fmt::Display for Stale {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Missing(path) => write!(f, "{} is missing", path.display()),
            Self::Damaged { path, reason } => write!(f, "{} is damaged: {reason}", path.display()),
            Self::Size { was, now } => write!(f, "size {}x{} ≠ {}x{}", was.x, was.y, now.x, now.y),
            Self::Settings(changes) => {
                let shown = |v: &Option<String>| v.clone().unwrap_or_else(|| "(none)".to_owned());
                let words: Vec<String> = changes
                    .iter()
                    .map(|(key, was, now)| format!("{key} {} ≠ {}", shown(was), shown(now)))
                    .collect();
                write!(f, "{}", words.join(", "))
            }
        }
    }
}

/// A file written beside a render that a finished render also needs (a workflow's own output,
/// like the MCC lens writer's rays), and how to tell that it reads back whole and as this run
/// would write it (`Err`: what is wrong).
pub struct Companion<'a> {
    /// The file.
    pub path: &'a Path,
    /// Reads it back and checks it.
    pub check: &'a dyn Fn(&Path) -> Result<(), String>,
}

/// Whether `exr` (and `png`, when given) is a finished render of size `size` with the header
/// settings `settings` (as [`super::RenderInfo::settings`] lists them; the counts in
/// [`COUNT_KEYS`] are not compared): `Ok` to skip it, else why it must be rendered again. In
/// [`Stale::Size`] and [`Stale::Settings`], the file's value comes first.
pub fn check_finished(
    exr: &Path,
    png: Option<&Path>,
    settings: &[(&str, String)],
    size: UVec2,
) -> Result<(), Stale> {
    check_finished_with(exr, png, settings, size, &[])
}

/// [`check_finished`], and every companion file there ([`Stale::Missing`]) and passing its
/// check ([`Stale::Damaged`] with what the check said).
pub fn check_finished_with(
    exr: &Path,
    png: Option<&Path>,
    settings: &[(&str, String)],
    size: UVec2,
    companions: &[Companion<'_>],
) -> Result<(), Stale> {
    for path in std::iter::once(exr).chain(png).chain(companions.iter().map(|c| c.path)) {
        if !path.is_file() {
            return Err(Stale::Missing(path.to_path_buf()));
        }
    }
    let damaged = |path: &Path, e: crate::TracerError| Stale::Damaged {
        path: path.to_path_buf(),
        reason: e.to_string(),
    };
    let image = read_exr(exr).map_err(|e| damaged(exr, e))?;
    let was = UVec2::new(image.rgb.width, image.rgb.height);
    if was != size {
        return Err(Stale::Size { was, now: size });
    }
    let header = image.metadata.into_iter().filter(|(k, _)| k.starts_with("mcctrace/"));
    let run = settings.iter().map(|(k, v)| (k.to_string(), v.clone()));
    compare_settings(header, run)?;
    if let Some(png) = png {
        let preview = read_png8(png).map_err(|e| damaged(png, e))?;
        if UVec2::new(preview.width, preview.height) != size {
            return Err(Stale::Damaged {
                path: png.to_path_buf(),
                reason: format!("{}x{} pixels, its EXR {}x{}", preview.width, preview.height, size.x, size.y),
            });
        }
    }
    for c in companions {
        (c.check)(c.path).map_err(|reason| Stale::Damaged { path: c.path.to_path_buf(), reason })?;
    }
    Ok(())
}

/// The resume rule's comparison of settings: those `recorded` with a finished output against
/// this run's, both ways (a key only one side has differs), the counts in [`COUNT_KEYS`] aside;
/// [`Stale::Settings`] lists every difference, the recorded value first, keys without their
/// `mcctrace/` prefix.
pub fn compare_settings(
    recorded: impl IntoIterator<Item = (String, String)>,
    run: impl IntoIterator<Item = (String, String)>,
) -> Result<(), Stale> {
    let settings = |pairs: &mut dyn Iterator<Item = (String, String)>| -> BTreeMap<String, String> {
        pairs.filter(|(k, _)| !COUNT_KEYS.contains(&k.as_str()) && k != DENOISER_KEY).collect()
    };
    let file = settings(&mut recorded.into_iter());
    let run = settings(&mut run.into_iter());
    let mut keys: Vec<&String> = file.keys().chain(run.keys()).collect();
    keys.sort();
    keys.dedup();
    let changes: Vec<_> = keys
        .into_iter()
        .filter(|k| file.get(*k) != run.get(*k))
        .map(|k| (k.trim_start_matches("mcctrace/").to_owned(), file.get(k).cloned(), run.get(k).cloned()))
        .collect();
    if changes.is_empty() { Ok(()) } else { Err(Stale::Settings(changes)) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::RgbImage;
    use crate::image_io::{write_exr, write_png_srgb};
    use glam::Vec3;

    /// Finished only when both files are there, whole, of the size and settings asked for;
    /// otherwise the reason names the file or every differing setting, the file's value first.
    #[test]
    fn finished_means_whole_same_size_and_same_settings() {
        let dir = std::env::temp_dir().join(format!("mcctrace-resume-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (exr, png) = (dir.join("f.exr"), dir.join("f.png"));
        let size = UVec2::new(4, 3);
        let image = RgbImage { width: 4, height: 3, pixels: vec![Vec3::splat(0.5); 12] };
        let settings = vec![("mcctrace/spp", "64".to_owned()), ("mcctrace/seed", "1".to_owned())];
        let check = |settings: &[(&str, String)], size| check_finished(&exr, Some(&png), settings, size);
        assert_eq!(check(&settings, size), Err(Stale::Missing(exr.clone())));
        let mut header = settings.clone();
        header.push(("mcctrace/seconds", "1.5".to_owned()));
        write_exr(&exr, &image, &[], &header).unwrap();
        assert_eq!(check(&settings, size), Err(Stale::Missing(png.clone())));
        write_png_srgb(&png, &image).unwrap();
        assert_eq!(check(&settings, size), Ok(()), "the seconds are not a setting");
        assert_eq!(check(&settings, UVec2::new(4, 4)).unwrap_err().to_string(), "size 4x3 ≠ 4x4");
        let other = vec![("mcctrace/spp", "128".to_owned()), ("mcctrace/crop", "2".to_owned())];
        assert_eq!(
            check(&other, size).unwrap_err().to_string(),
            "crop (none) ≠ 2, seed 1 ≠ (none), spp 64 ≠ 128"
        );
        // A companion file must be there, and pass its check, for the render to count.
        let rays = dir.join("f.rays");
        let whole = |p: &Path| match std::fs::read(p) {
            Ok(b) if b == b"whole" => Ok(()),
            _ => Err("not whole".to_owned()),
        };
        let with = |c: &[Companion]| check_finished_with(&exr, Some(&png), &settings, size, c);
        assert_eq!(with(&[Companion { path: &rays, check: &whole }]), Err(Stale::Missing(rays.clone())));
        std::fs::write(&rays, b"half").unwrap();
        assert_eq!(
            with(&[Companion { path: &rays, check: &whole }]).unwrap_err().to_string(),
            format!("{} is damaged: not whole", rays.display())
        );
        std::fs::write(&rays, b"whole").unwrap();
        assert_eq!(with(&[Companion { path: &rays, check: &whole }]), Ok(()));
        let bytes = std::fs::read(&exr).unwrap();
        std::fs::write(&exr, &bytes[..bytes.len() / 2]).unwrap();
        let err = check(&settings, size).unwrap_err();
        assert!(matches!(&err, Stale::Damaged { path, .. } if *path == exr), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
