//! `mcctrace remap`: the lens remapper (docs/design/mcc.md §5): a collage and the views' ray files
//! in, one ray per pixel out.

use crate::args::RayFormatArg;
use crate::setup::collage::{CollageInputArgs, remap};
use clap::Args;
use std::path::{Path, PathBuf};

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

/// A warning when `out`'s extension is not the one of `format` (.mcr or .txt): the file would
/// be read by its content, but a ray file named `.png` misleads whoever finds it.
pub fn extension_warning(out: &Path, format: mcc::RayFormat) -> Option<String> {
    let want = format.extension();
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("");
    (!ext.eq_ignore_ascii_case(want)).then(|| {
        let (kind, other) = match format {
            mcc::RayFormat::Binary => ("binary", "--ray-format text writes .txt"),
            mcc::RayFormat::Text => ("text", "--ray-format binary writes .mcr"),
        };
        format!("--out {}: writes a {kind} ray file, whose extension is .{want} ({other})", out.display())
    })
}

pub fn run(a: RemapArgs) -> anyhow::Result<()> {
    if let Some(w) = extension_warning(&a.out, a.ray_format.into()) {
        eprintln!("warning: {w}");
    }
    let remapped = remap(&a.input.job(a.frame)?, a.quiet)?;
    remapped.write_rays(&a.out, a.ray_format.into())?;
    if !a.quiet {
        eprintln!("rays -> {}", a.out.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warns_when_the_extension_disagrees_with_the_format() {
        assert_eq!(extension_warning(Path::new("a/rerender-frame0000.mcr"), mcc::RayFormat::Binary), None);
        assert_eq!(extension_warning(Path::new("r.TXT"), mcc::RayFormat::Text), None);
        let w = extension_warning(Path::new("e.png"), mcc::RayFormat::Binary).unwrap();
        assert!(w.contains("--out e.png") && w.contains("binary ray file") && w.contains(".mcr"), "{w}");
        let w = extension_warning(Path::new("rays.mcr"), mcc::RayFormat::Text).unwrap();
        assert!(w.contains("text ray file") && w.contains(".txt"), "{w}");
        assert!(extension_warning(Path::new("rays"), mcc::RayFormat::Binary).is_some());
    }
}
