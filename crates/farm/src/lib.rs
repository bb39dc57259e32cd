//! Render-farm jobs of a whole MCC shot (docs/farm.md, "Schedulers"; the shot's stages are
//! docs/design/workflow.md §8's keyframe workflow): the source views of every key frame, `keys` (remap and
//! in-between), the output frames in chunks, and a check of every frame, as Slurm batch scripts
//! ([`slurm`]) or an Open Job Description template ([`openjd`]). Both are written from one
//! [`Shot`] and its [`Plan`]: the `mcctrace` command line of every task. A big still
//! ([`Still`], docs/farm.md "Big stills") is one `render` or `rerender` cut into bands, then
//! merged, written by the same two writers.
//!
//! Nothing here renders: the generated tasks run the `mcctrace` binary. Nothing here prints or
//! parses arguments either; the command line is `mcctrace farm`.

pub mod openjd;
mod quote;
pub mod shot;
pub mod slurm;
pub mod still;
mod yaml;

pub use shot::{FrameSpan, Key, NodeSize, Pass, Plan, Resources, Shot, StageResources, ViewTask};
pub use still::{Still, StillStage};

use std::path::PathBuf;

/// Everything that can go wrong writing or submitting a shot's jobs.
#[derive(Debug, thiserror::Error)]
pub enum FarmError {
    /// The shot description is inconsistent; `flag` names the command-line flag to fix.
    #[error("{flag}: {message}")]
    Shot {
        /// The flag (or argument) at fault, like `--chunk`.
        flag: &'static str,
        /// What is wrong with it.
        message: String,
    },
    /// A file could not be written or a folder created.
    #[error("{}: {message}", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// `sbatch` refused a script or could not be run.
    #[error("submitting {}: {message}", script.display())]
    Submit {
        /// The batch script.
        script: PathBuf,
        /// What `sbatch` said.
        message: String,
    },
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, FarmError>;

/// A shot error naming `flag`.
pub(crate) fn bad(flag: &'static str, message: impl Into<String>) -> FarmError {
    FarmError::Shot { flag, message: message.into() }
}

/// Writes `text` to `path` atomically (executable when `executable`), creating its folder.
pub(crate) fn write_file(path: &std::path::Path, text: &str, executable: bool) -> Result<()> {
    let fail = |e: &dyn std::fmt::Display| FarmError::Write { path: path.to_owned(), message: e.to_string() };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| fail(&e))?;
    }
    tracer::atomic::write_atomically(path, |w| std::io::Write::write_all(w, text.as_bytes()))
        .map_err(|e| fail(&e))?;
    if executable {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).map_err(|e| fail(&e))?;
    }
    Ok(())
}
