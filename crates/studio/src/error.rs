//! The studio's typed error (docs/studio.md): every failure names the file, flag or message
//! field at fault.

use std::path::PathBuf;

/// A studio failure.
#[derive(Debug, thiserror::Error)]
pub enum StudioError {
    /// The tracer failed (scene, render, image file).
    #[error(transparent)]
    Tracer(#[from] tracer::TracerError),
    /// The collage machinery failed (remap, ray file, collage file).
    #[error(transparent)]
    Mcc(#[from] mcc::MccError),
    /// A file or folder could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A project file is not what the studio writes.
    #[error("{path}: {message}")]
    Project {
        /// The project file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A message from the page (or a setting) asks for something impossible.
    #[error("{0}")]
    Request(String),
    /// The server could not start.
    #[error("server: {0}")]
    Server(String),
    /// The work was cancelled by newer work.
    #[error("cancelled")]
    Cancelled,
}

impl StudioError {
    /// An I/O failure on `path`.
    pub fn io(path: impl Into<PathBuf>, e: impl std::fmt::Display) -> Self {
        Self::Io { path: path.into(), message: e.to_string() }
    }

    /// A refused request, saying why.
    pub fn request(message: impl Into<String>) -> Self {
        Self::Request(message.into())
    }

    /// Whether this is a cancellation (a render stopped for newer work), not a failure.
    pub fn is_cancelled(&self) -> bool {
        matches!(
            self,
            Self::Cancelled
                | Self::Tracer(tracer::TracerError::Cancelled)
                | Self::Mcc(mcc::MccError::Tracer(tracer::TracerError::Cancelled))
        )
    }
}

/// The studio's result type.
pub type Result<T, E = StudioError> = std::result::Result<T, E>;
