//! glTF 2.0 loader (placeholder until written).
use super::Scene;
use crate::error::{Result, TracerError};
use std::path::Path;

pub(super) fn load(path: &Path) -> Result<Scene> {
    Err(TracerError::scene(path, "glTF loading is not written yet"))
}
