//! `mcctrace remap`: the lens remapper (docs/design.md §5): a collage and the views' ray files
//! in, one ray per pixel out.

use crate::args::RayFormatArg;
use crate::setup::collage::{CollageInputArgs, remap};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `mcctrace remap`.
#[derive(Args, Debug)]
pub struct RemapArgs {
    #[command(flatten)]
    pub input: CollageInputArgs,
    /// Frame of the views.
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// The remapped ray file to write (rerender-frameFFFF.mcr by convention).
    #[arg(long)]
    pub out: PathBuf,
    /// Encoding of the ray file.
    #[arg(long, value_enum, default_value = "binary")]
    pub ray_format: RayFormatArg,
    /// No summary.
    #[arg(long, short)]
    pub quiet: bool,
}

pub fn run(a: RemapArgs) -> anyhow::Result<()> {
    let remapped = remap(&a.input.job(a.frame)?, a.quiet)?;
    remapped.write_rays(&a.out, a.ray_format.into())?;
    if !a.quiet {
        eprintln!("rays -> {}", a.out.display());
    }
    Ok(())
}
