//! OBJ/MTL loader (placeholder until written).
use super::Scene;
use crate::error::{Result, TracerError};
use std::path::{Path, PathBuf};

pub(super) fn load_dir(path: &Path) -> Result<Scene> {
    Err(TracerError::scene(path, "OBJ loading is not written yet"))
}

pub(super) fn load_files(first: &Path, _paths: &[PathBuf]) -> Result<Scene> {
    Err(TracerError::scene(first, "OBJ loading is not written yet"))
}
