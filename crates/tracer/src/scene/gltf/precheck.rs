//! Checks of the raw glTF JSON before the gltf crate's validator sees it (docs/design.md §3.1, §8:
//! every malformed input is an error naming the file and the problem, never a panic).
//!
//! Why before: the validator (gltf-json 1.4) indexes `accessors[POSITION]` unchecked and panics
//! on a dangling POSITION index; it reports a camera without its projection object only as
//! `cameras[0]: Missing data`; and it refuses a view-less accessor without saying how large it
//! claimed to be. Everything else it finds is reworded by [`describe_validation`].

use gltf::json::Root;
use gltf::json::camera::Type;
use gltf::json::validation::{Checked, Error};
use gltf::mesh::Semantic;

/// Largest element count accepted for an accessor without a buffer view (all zeros plus sparse
/// substitutions): such a count is not bounded by any buffer, so a hostile file could ask for
/// terabytes. Shared with the accessor reader.
pub(super) const MAX_VIEWLESS_COUNT: usize = 1 << 26;

/// The Draco mesh-compression extension, whose accessors carry no data of their own.
const DRACO: &str = "KHR_draco_mesh_compression";

/// Refuses, with a message naming the object, what the gltf crate's validator would panic on
/// or report unclearly.
pub(super) fn check(root: &Root) -> Result<(), String> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                let name = match semantic {
                    Checked::Valid(Semantic::Positions) => "POSITION".to_owned(),
                    Checked::Valid(s) => s.to_string(),
                    Checked::Invalid => "(invalid semantic)".to_owned(),
                };
                if index.value() >= root.accessors.len() {
                    return Err(format!(
                        "meshes[{m}].primitives[{p}].attributes.{name}: Index out of range: accessor {} \
                         does not exist (the file has {})",
                        index.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    for (i, camera) in root.cameras.iter().enumerate() {
        let complete = match camera.type_ {
            Checked::Valid(Type::Perspective) => camera.perspective.is_some(),
            Checked::Valid(Type::Orthographic) => camera.orthographic.is_some(),
            Checked::Invalid => true, // the validator names the bad `type`
        };
        if !complete {
            let name = camera.name.as_deref().unwrap_or("");
            return Err(format!("camera {i} ('{name}') lacks the projection object its type names"));
        }
    }
    for (i, accessor) in root.accessors.iter().enumerate() {
        if accessor.buffer_view.is_some() {
            continue; // bounded by its buffer, checked when read
        }
        let count = accessor.count.0;
        if count > MAX_VIEWLESS_COUNT as u64 {
            return Err(format!(
                "accessor {i}: count {count} without a buffer view is implausibly large (at most \
                 {MAX_VIEWLESS_COUNT})"
            ));
        }
        if accessor.sparse.is_none() && root.extensions_used.iter().any(|e| e == DRACO) {
            // Draco files leave the accessors their compressed data replaces without a view:
            // the file's geometry is in a form this loader cannot decode.
            return Err(format!(
                "accessor {i} has no data of its own: its mesh is compressed with Draco ({DRACO}, \
                 listed in extensionsUsed), which mcctrace cannot decode (it has no Draco decoder); \
                 export the file without Draco mesh compression"
            ));
        }
        if accessor.sparse.is_none() {
            return Err(format!(
                "accessor {i} has neither a bufferView nor sparse values; all-zero accessors are not \
                 supported"
            ));
        }
    }
    Ok(())
}

/// The gltf crate's validation errors as one message: `path: problem; path: problem`.
pub(super) fn describe_validation(errors: &[(gltf::json::Path, Error)]) -> String {
    let problems: Vec<String> = errors
        .iter()
        .map(|(path, error)| {
            let what = match error {
                Error::IndexOutOfBounds => "Index out of range (no such object)",
                Error::Invalid => "invalid value",
                Error::Missing => "required data is missing",
                Error::Oversize => "size exceeds the system's limits",
                Error::Unsupported => "unsupported extension",
            };
            format!("{path}: {what}")
        })
        .collect();
    format!("invalid glTF: {}", problems.join("; "))
}
