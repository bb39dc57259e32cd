//! When the ray files `keys` writes are finished (docs/farm.md, "Resume"): a record beside them,
//! [`RECORD_NAME`], of what they were made from (every setting, and a SHA-256 of every input
//! file: the collages, their region images, the views' ray files), written after the last of
//! them. A re-run is skipped when the record holds the same settings and inputs (compared by
//! `tracer::job::compare_settings`, the rule frames and views follow) and every ray file is
//! there and reads back whole; anything else is made again, and the reason said.

use crate::error::{MccError, Result};
use crate::ray_file::RayFile;
use std::io::Read;
use std::path::{Path, PathBuf};
use tracer::job::{Stale, compare_settings};

/// The record's file name, in the folder of ray files.
pub const RECORD_NAME: &str = "keys-record.txt";

/// What a folder of ray files made by `keys` was made from, and the files it holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeysRecord {
    /// The record's file.
    pub path: PathBuf,
    /// The settings, then `input PATH` → the file's SHA-256, in order.
    pub entries: Vec<(String, String)>,
    /// The ray files the run writes.
    pub outputs: Vec<PathBuf>,
}

/// The SHA-256 of a file's bytes, in hex.
pub fn file_sha256(path: &Path) -> Result<String> {
    use sha2::{Digest, Sha256};
    let mut file = std::fs::File::open(path).map_err(|e| MccError::io(path, e))?;
    let mut hash = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = file.read(&mut buf).map_err(|e| MccError::io(path, e))?;
        if n == 0 {
            break;
        }
        hash.update(&buf[..n]);
    }
    Ok(hash.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

/// A record line's text: tabs and line breaks escaped, so each entry is one `key\tvalue` line.
fn line_text(s: &str) -> String {
    s.replace('\\', "\\\\").replace('\t', "\\t").replace('\n', "\\n")
}

impl KeysRecord {
    /// The record of a run writing `outputs` into `dir` with `settings`, from the files `inputs`
    /// (each hashed now).
    pub fn new(
        dir: &Path,
        settings: Vec<(String, String)>,
        inputs: &[PathBuf],
        outputs: Vec<PathBuf>,
    ) -> Result<Self> {
        let mut entries: Vec<(String, String)> =
            settings.into_iter().map(|(k, v)| (line_text(&k), line_text(&v))).collect();
        for input in inputs {
            entries.push((line_text(&format!("input {}", input.display())), file_sha256(input)?));
        }
        Ok(Self { path: dir.join(RECORD_NAME), entries, outputs })
    }

    /// `Ok` when the folder holds this run's finished output: the record there, with the same
    /// settings and inputs, and every ray file there and whole; else why not.
    pub fn check(&self) -> std::result::Result<(), Stale> {
        let text = std::fs::read_to_string(&self.path).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => Stale::Missing(self.path.clone()),
            _ => Stale::Damaged { path: self.path.clone(), reason: e.to_string() },
        })?;
        let mut recorded = Vec::new();
        for line in text.lines() {
            let (k, v) = line.split_once('\t').ok_or_else(|| Stale::Damaged {
                path: self.path.clone(),
                reason: format!("{line:?} is not KEY<tab>VALUE"),
            })?;
            recorded.push((k.to_owned(), v.to_owned()));
        }
        compare_settings(recorded, self.entries.iter().cloned())?;
        for out in &self.outputs {
            if !out.is_file() {
                return Err(Stale::Missing(out.clone()));
            }
            RayFile::read(out).map_err(|e| Stale::Damaged { path: out.clone(), reason: e.to_string() })?;
        }
        Ok(())
    }

    /// Writes the record (atomically): call it once every ray file is written.
    pub fn write(&self) -> Result<()> {
        let text: String = self.entries.iter().map(|(k, v)| format!("{k}\t{v}\n")).collect();
        tracer::atomic::write_atomically(&self.path, |w| std::io::Write::write_all(w, text.as_bytes()))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray_file::{RayFormat, StoredRay};
    use glam::Vec3;

    /// Finished only with the record there and the same, and every output whole; otherwise the
    /// reason names the file or the setting, the recorded value first.
    #[test]
    fn finished_means_same_record_and_whole_outputs() {
        let dir = crate::test_util::scratch_dir("keys-record");
        let input = dir.join("collage 0.png");
        std::fs::write(&input, b"collage").unwrap();
        let out = dir.join("rerender-frame0000.mcr");
        let settings =
            |mode: &str| vec![("mode".to_owned(), mode.to_owned()), ("path".to_owned(), "a\tb".into())];
        let record = |mode: &str| {
            KeysRecord::new(&dir, settings(mode), std::slice::from_ref(&input), vec![out.clone()]).unwrap()
        };
        let smooth = record("smooth");
        assert_eq!(smooth.check(), Err(Stale::Missing(dir.join(RECORD_NAME))));
        let rays = RayFile::new(2, 1, 0, 0, vec![StoredRay::new(Vec3::ZERO, Vec3::Z); 2]).unwrap();
        rays.write(&out, RayFormat::Binary).unwrap();
        smooth.write().unwrap();
        assert_eq!(smooth.check(), Ok(()));
        assert_eq!(record("linear").check().unwrap_err().to_string(), "mode smooth ≠ linear");
        std::fs::write(&input, b"collage, edited").unwrap();
        let err = record("smooth").check().unwrap_err().to_string();
        assert!(err.starts_with(&format!("input {} ", input.display())), "{err}");
        std::fs::write(&input, b"collage").unwrap();
        std::fs::write(&out, b"half a ray file").unwrap();
        assert!(matches!(smooth.check(), Err(Stale::Damaged { path, .. }) if path == out));
        std::fs::remove_file(&out).unwrap();
        assert_eq!(smooth.check(), Err(Stale::Missing(out.clone())));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
