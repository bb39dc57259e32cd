//! The MCC error type (docs/design.md §8: "every error names the file and what is wrong with it").
//! Each variant carries the file (or, for data handed over in memory, what the data is) and a
//! message a user can act on; nothing in this crate prints or panics on bad input.

use crate::collage::StrayReport;
use std::path::PathBuf;
use tracer::TracerError;

/// Everything that can go wrong in the MCC stages.
#[derive(Debug, thiserror::Error)]
pub enum MccError {
    /// A file or directory could not be read. (The OS error is part of the message, not a
    /// separate `source()`, so error chains do not print it twice, as with `TracerError::Io`.)
    #[error("{}: {error}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What the operating system said.
        error: std::io::Error,
    },
    /// A ray file is malformed as a whole (header, size, length, encoding).
    #[error("{}: {message}", path.display())]
    RayFile {
        /// The ray file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// One record of a ray file is wrong (the first offending one is reported).
    #[error("{}: {record}: {message}", path.display())]
    RayRecord {
        /// The ray file.
        path: PathBuf,
        /// Where: `line 17 (pixel (3, 4))` for text, `record 12 (pixel (0, 1))` for binary.
        record: String,
        /// What is wrong with it.
        message: String,
    },
    /// An image could not be decoded, or has a pixel format that cannot carry what it must.
    #[error("{}: {message}", path.display())]
    Image {
        /// The image file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A collage has non-background pixels that name no usable camera.
    #[error("{}: {report}", path.display())]
    StrayPixels {
        /// The collage file.
        path: PathBuf,
        /// How many, which ids, and where the first few are (boxed: the error stays small).
        report: Box<StrayReport>,
    },
    /// A layered collage (OpenRaster, PSD) is malformed or uses what this reader does not
    /// support; `entry` says where: an archive entry (`stack.xml`, `data/layer1.png`), a layer
    /// (`layer "left (camera 1)"`) or a part of the file (`layer records`).
    #[error("{}: {entry}: {message}", path.display())]
    Layered {
        /// The layered file.
        path: PathBuf,
        /// The entry, layer or part at fault.
        entry: String,
        /// What is wrong with it.
        message: String,
    },
    /// A collage file holds no camera pixels: there is nothing to remap from.
    #[error("{}: has no camera pixels: there is nothing to remap from", path.display())]
    EmptyCollage {
        /// The collage file.
        path: PathBuf,
    },
    /// Two inputs that must have the same resolution do not.
    #[error("{}: {what} is {}x{}, but {expected_from} is {}x{}", path.display(), found.0, found.1, expected.0, expected.1)]
    SizeMismatch {
        /// The file whose size is wrong.
        path: PathBuf,
        /// What that file is (e.g. "the region image").
        what: String,
        /// Its size (width, height).
        found: (u32, u32),
        /// What it must match (e.g. "the collage").
        expected_from: String,
        /// The size it must have.
        expected: (u32, u32),
    },
    /// A directory does not hold the files a frame needs, or holds ambiguous ones.
    #[error("{}: {message}", path.display())]
    Directory {
        /// The directory.
        path: PathBuf,
        /// What is missing or ambiguous.
        message: String,
    },
    /// A camera id or tag width outside what the tag code can represent.
    #[error("tag code: {0}")]
    Tag(String),
    /// A setting is out of range (remapper configuration, label map …).
    #[error("invalid setting: {0}")]
    Settings(String),
    /// In-memory inputs that do not fit together (no file to name: `what` says which data).
    #[error("{what}: {message}")]
    Input {
        /// The data at fault, e.g. "camera 3's rays".
        what: String,
        /// What is wrong with it.
        message: String,
    },
    /// The camera gave no ray for a pixel centre the lens writer must record.
    #[error(
        "lens writer, frame {frame}, camera {camera}: pixel ({i}, {j}) has no eye ray at its centre \
         (the camera or an earlier lens shader dropped it; a ray file needs one ray per pixel, so \
         crop the film to the camera's image, e.g. inside a fisheye's circle)"
    )]
    DroppedRay {
        /// Frame number.
        frame: u32,
        /// Camera number.
        camera: u32,
        /// Pixel column.
        i: u32,
        /// Pixel row.
        j: u32,
    },
    /// The camera gave an invalid ray (non-finite, non-unit) for a pixel centre.
    #[error("lens writer, frame {frame}, camera {camera}: pixel ({i}, {j}): {message}")]
    BadRay {
        /// Frame number.
        frame: u32,
        /// Camera number.
        camera: u32,
        /// Pixel column.
        i: u32,
        /// Pixel row.
        j: u32,
        /// What is wrong with the ray.
        message: String,
    },
    /// A step of a job failed: `doing` says which (the frame, the key), `source` why.
    #[error("{doing}")]
    Step {
        /// The step, e.g. "frame 3: reading its rays".
        doing: String,
        /// What went wrong in it.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The tracer failed: writing an output (its atomic writer names the file) or rendering
    /// (the error names the camera), or the caller cancelled a render.
    #[error(transparent)]
    Tracer(#[from] TracerError),
}

impl MccError {
    /// Shorthand for an I/O error about `path`.
    pub fn io(path: impl Into<PathBuf>, error: std::io::Error) -> Self {
        Self::Io { path: path.into(), error }
    }

    /// Shorthand for an image error about `path`.
    pub fn image(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::Image { path: path.into(), message: message.into() }
    }

    /// Shorthand for an error about `entry` of the layered file at `path`.
    pub fn layered(path: impl Into<PathBuf>, entry: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Layered { path: path.into(), entry: entry.into(), message: message.into() }
    }

    /// Shorthand for a whole-file ray-file error about `path`.
    pub fn ray_file(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::RayFile { path: path.into(), message: message.into() }
    }

    /// This error as the failure of the step `doing` of a job.
    pub fn during(self, doing: impl Into<String>) -> Self {
        Self::step(doing, self)
    }

    /// The step `doing` of a job failed with `error`.
    pub fn step(doing: impl Into<String>, error: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self::Step { doing: doing.into(), source: Box::new(error) }
    }

    /// Shorthand for an error about in-memory data.
    pub fn input(what: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Input { what: what.into(), message: message.into() }
    }
}

/// The crate's result type.
pub type Result<T, E = MccError> = std::result::Result<T, E>;
