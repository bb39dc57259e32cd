//! `mcctrace merge`: the bands `render --tile` / `rerender --tile` wrote assembled into the EXR
//! and PNG one run would have written (docs/farm.md, `tracer::job::merge_bands`).

use anyhow::bail;
use clap::Args;
use std::path::PathBuf;
use tracer::job::{band_files, merge_bands};

/// Arguments of `mcctrace merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Band files (NAME.tileIofN.exr), in any order; none: every NAME.tileIofN.exr beside --out.
    #[arg(value_name = "BAND")]
    pub bands: Vec<PathBuf>,
    /// The whole image to write (NAME.exr; its PNG preview goes beside it).
    #[arg(long, value_name = "FILE.exr")]
    pub out: PathBuf,
    /// No summary.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(a: MergeArgs) -> anyhow::Result<()> {
    if !a.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!("--out {}: give an .exr file", a.out.display());
    }
    let bands = if a.bands.is_empty() { band_files(&a.out)? } else { a.bands };
    let merged = merge_bands(&bands, &a.out)?;
    if !a.quiet {
        eprintln!(
            "merge: {} bands -> {} ({}x{}) and {}",
            merged.bands,
            merged.exr.display(),
            merged.size.x,
            merged.size.y,
            merged.png.display()
        );
    }
    Ok(())
}
