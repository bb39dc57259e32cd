//! `EXT_mesh_gpu_instancing`: a node drawing its mesh once per instance, each instance placed by
//! its own translation, rotation and scale (applied before the node's own transform). The
//! instances become leaf nodes of the rig under the instancing node, so they move with it and
//! its animation.

use super::super::rig::Pose;
use super::accessor;
use glam::{Quat, Vec3};
use gltf::accessor::DataType;
use serde_json::Value;

/// Element types of `TRANSLATION` and `SCALE` (floats, or integers with `KHR_mesh_quantization`).
fn vector_types(quantized: bool) -> &'static [(DataType, bool)] {
    if quantized { accessor::QUANTIZED } else { accessor::FLOAT }
}

/// The instances' poses of a node whose raw JSON carries the extension, `None` without it.
pub(super) fn instances(
    node: &Value,
    doc: &gltf::Document,
    buffers: &[Vec<u8>],
    quantized: bool,
) -> Result<Option<Vec<Pose>>, String> {
    let Some(ext) = node.pointer("/extensions/EXT_mesh_gpu_instancing") else { return Ok(None) };
    let attributes = ext
        .get("attributes")
        .and_then(Value::as_object)
        .ok_or("EXT_mesh_gpu_instancing has no attributes")?;
    let get = |name: &str| -> Result<Option<gltf::Accessor>, String> {
        let Some(index) = attributes.get(name) else { return Ok(None) };
        let index = index
            .as_u64()
            .ok_or_else(|| format!("EXT_mesh_gpu_instancing {name} is not an accessor index"))?;
        doc.accessors()
            .nth(index as usize)
            .map(Some)
            .ok_or_else(|| format!("EXT_mesh_gpu_instancing {name}: accessor {index} does not exist"))
    };
    let what = |name: &str| format!("EXT_mesh_gpu_instancing {name}");
    let translations = match get("TRANSLATION")? {
        Some(a) => Some(accessor::read_vec3(&a, buffers, &what("TRANSLATION"), vector_types(quantized))?),
        None => None,
    };
    let rotations = match get("ROTATION")? {
        Some(a) => Some(accessor::read_rotations(&a, buffers)?),
        None => None,
    };
    let scales = match get("SCALE")? {
        Some(a) => Some(accessor::read_vec3(&a, buffers, &what("SCALE"), vector_types(quantized))?),
        None => None,
    };
    let counts: Vec<usize> = [
        translations.as_ref().map(Vec::len),
        rotations.as_ref().map(Vec::len),
        scales.as_ref().map(Vec::len),
    ]
    .into_iter()
    .flatten()
    .collect();
    let Some(&count) = counts.first() else {
        return Err("EXT_mesh_gpu_instancing names none of TRANSLATION, ROTATION and SCALE".to_owned());
    };
    if counts.iter().any(|&c| c != count) {
        return Err(format!("EXT_mesh_gpu_instancing attributes have different counts {counts:?}"));
    }
    Ok(Some(
        (0..count)
            .map(|i| {
                let q = rotations.as_ref().map_or(Quat::IDENTITY, |r| Quat::from_vec4(r[i]));
                Pose::Trs {
                    translation: translations.as_ref().map_or(Vec3::ZERO, |t| t[i]),
                    // Renormalised as node rotations are (a zero quaternion is reported when flattening).
                    rotation: q / q.length(),
                    scale: scales.as_ref().map_or(Vec3::ONE, |s| s[i]),
                }
            })
            .collect(),
    ))
}
