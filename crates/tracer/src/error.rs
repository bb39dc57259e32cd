//! The tracer's error type: every variant names the file (or the setting) and what is wrong.

use std::path::PathBuf;

/// Errors a lens shader reports from its per-frame set-up or tear-down.
pub type LensError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Everything that can go wrong loading a scene, rendering or writing an image.
#[derive(Debug, thiserror::Error)]
pub enum TracerError {
    /// A file could not be read or written. (The OS error is part of the message, not a
    /// separate `source()`, so error chains do not print it twice.)
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        error: std::io::Error,
    },
    /// A scene file is malformed or holds something the tracer cannot use.
    #[error("{}: {message}", path.display())]
    Scene {
        /// The scene file (or the part of a scene) at fault.
        path: PathBuf,
        /// What is wrong, and where in the file.
        message: String,
    },
    /// The requested camera is not in the scene.
    #[error("{}: no camera {wanted}; the scene has {available}", path.display())]
    UnknownCamera {
        /// The scene file.
        path: PathBuf,
        /// The name or index asked for.
        wanted: String,
        /// The cameras the scene does have, listed for the user.
        available: String,
    },
    /// An image file is malformed, unsupported, or could not be encoded.
    #[error("{}: {message}", path.display())]
    Image {
        /// The image file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A render setting is out of range (resolution, sample count, depth …).
    #[error("invalid setting: {0}")]
    Settings(String),
    /// The caller cancelled the work (`render::Progress::cancelled`); nothing was written.
    #[error("cancelled")]
    Cancelled,
    /// Rendering one camera failed (the camera's name, then what went wrong).
    #[error("rendering camera '{camera}': {error}")]
    Render {
        /// The camera's name.
        camera: String,
        /// What went wrong (in the message, not a separate `source()`).
        error: Box<TracerError>,
    },
    /// A lens shader failed in its per-frame set-up or tear-down.
    #[error("lens shader '{shader}': {error}")]
    Lens {
        /// The lens shader's name.
        shader: String,
        /// Its error (in the message, not a separate `source()`).
        error: LensError,
    },
    /// Denoising failed: Intel Open Image Denoise is not installed, or it reported an error.
    #[error("{0}")]
    Denoise(#[from] crate::denoise::DenoiseError),
}

impl TracerError {
    /// Shorthand for a scene error about `path`.
    pub fn scene(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::Scene { path: path.into(), message: message.into() }
    }

    /// Shorthand for an image error about `path`.
    pub fn image(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::Image { path: path.into(), message: message.into() }
    }

    /// Shorthand for an I/O error about `path`.
    pub fn io(path: impl Into<PathBuf>, error: std::io::Error) -> Self {
        Self::Io { path: path.into(), error }
    }
}

/// The tracer's result type.
pub type Result<T, E = TracerError> = std::result::Result<T, E>;
