//! Where renders go and what is said about them (docs/design.md §4.3 names, §8): the output paths
//! of `render`, the one-line summary of a finished render, and its warning about samples that
//! came out NaN or infinite.

use anyhow::{Context, bail};
use std::path::{Path, PathBuf};
use tracer::render::Rendered;

use mcc::job::View;

/// Where each view's EXR goes: `out` itself for one view and an .exr path, else the view names
/// `frameFFFFcameraCC.exr` in the directory `out` (created if missing).
pub fn output_paths(out: &Path, views: &[View], frame: u32) -> anyhow::Result<Vec<PathBuf>> {
    let is_file = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if is_file {
        if views.len() != 1 {
            bail!(
                "--out {} names one file but {} cameras were given: give a directory",
                out.display(),
                views.len()
            );
        }
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        return Ok(vec![out.to_path_buf()]);
    }
    if out.extension().is_some() && !out.is_dir() {
        bail!("--out {}: expected an .exr file or a directory", out.display());
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    Ok(views.iter().map(|v| out.join(mcc::names::view_render_name(frame, v.id))).collect())
}

/// Creates the parent directory of `path` if it has one.
pub fn create_parent(path: &Path) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    Ok(())
}

/// One line about a finished render of `name` at `spp` written to `out`.
pub fn summary(name: &str, spp: u32, r: &Rendered, out: &Path) -> String {
    let s = &r.stats;
    format!(
        "{name}: {}x{} at {} spp in {:.2} s ({:.2} M samples/s, {:.1} M rays/s) -> {}",
        r.images.image.width,
        r.images.image.height,
        spp,
        s.seconds,
        s.samples as f64 / s.seconds / 1e6,
        s.rays as f64 / s.seconds / 1e6,
        out.display()
    )
}

/// Warns (even when quiet: the image is damaged) about samples recorded as black because they
/// came out NaN or infinite.
pub fn warn_nonfinite(name: &str, r: &Rendered) {
    if r.stats.nonfinite_samples > 0 {
        eprintln!(
            "warning: camera '{name}': {} samples were NaN or infinite and were recorded as black",
            r.stats.nonfinite_samples
        );
    }
}
