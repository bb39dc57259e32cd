//! A small glTF 2.0 writer shared by the generators: one binary buffer, buffer views on 4-byte
//! boundaries, accessors with exact bounds, and the document's arrays collected in order.
//! JSON objects are `serde_json` maps (sorted keys), so equal input gives byte-identical output.

use anyhow::{Context, Result};
use glam::{Mat3, Quat, Vec2, Vec3, Vec4};
use serde_json::{Value, json};
use std::collections::BTreeSet;
use std::path::Path;

/// `bufferView.target` for vertex attributes.
pub const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` for indices.
pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The document under construction.
#[derive(Default)]
pub struct GltfBuilder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    pub meshes: Vec<Value>,
    pub nodes: Vec<Value>,
    pub materials: Vec<Value>,
    pub cameras: Vec<Value>,
    pub lights: Vec<Value>,
    images: Vec<Value>,
    samplers: Vec<Value>,
    textures: Vec<Value>,
    extensions_used: BTreeSet<String>,
}

/// Appends `value` to `list` and returns its index.
fn push(list: &mut Vec<Value>, value: Value) -> usize {
    list.push(value);
    list.len() - 1
}

impl GltfBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    /// Declares an extension in `extensionsUsed`.
    pub fn use_extension(&mut self, name: &str) {
        self.extensions_used.insert(name.to_owned());
    }

    /// Appends `data` as a buffer view starting on a 4-byte boundary (glTF requires accessor
    /// offsets to be multiples of their component size; 4 serves every type) and returns its index.
    pub fn push_view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let mut view = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bin.extend_from_slice(data);
        push(&mut self.views, view)
    }

    /// A VEC3 float accessor; with `bounds` it carries `min`/`max` (required for POSITION).
    pub fn vec3_accessor(&mut self, values: &[Vec3], bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER));
        let mut acc =
            json!({ "bufferView": view, "componentType": 5126, "count": values.len(), "type": "VEC3" });
        if bounds {
            let (lo, hi) = values
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
            // f32 → f64 is exact, so the bounds equal the stored floats bit for bit.
            acc["min"] = json!(lo.to_array().map(f64::from));
            acc["max"] = json!(hi.to_array().map(f64::from));
        }
        push(&mut self.accessors, acc)
    }

    /// A VEC2 float accessor (texture coordinates).
    pub fn vec2_accessor(&mut self, values: &[Vec2]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER));
        push(
            &mut self.accessors,
            json!({ "bufferView": view, "componentType": 5126, "count": values.len(), "type": "VEC2" }),
        )
    }

    /// A VEC4 float accessor (tangents).
    pub fn vec4_accessor(&mut self, values: &[Vec4]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER));
        push(
            &mut self.accessors,
            json!({ "bufferView": view, "componentType": 5126, "count": values.len(), "type": "VEC4" }),
        )
    }

    /// An index accessor: unsigned short when every vertex index fits, else unsigned int.
    pub fn index_accessor(&mut self, indices: &[u32], vertex_count: usize) -> usize {
        let wide = vertex_count > usize::from(u16::MAX);
        let bytes: Vec<u8> = indices
            .iter()
            .flat_map(|&i| if wide { i.to_le_bytes().to_vec() } else { (i as u16).to_le_bytes().to_vec() })
            .collect();
        let view = self.push_view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        push(
            &mut self.accessors,
            json!({ "bufferView": view, "componentType": if wide { 5125 } else { 5123 }, "count": indices.len(), "type": "SCALAR" }),
        )
    }

    pub fn add_mesh(&mut self, mesh: Value) -> usize {
        push(&mut self.meshes, mesh)
    }

    pub fn add_node(&mut self, node: Value) -> usize {
        push(&mut self.nodes, node)
    }

    pub fn add_material(&mut self, material: Value) -> usize {
        push(&mut self.materials, material)
    }

    pub fn add_camera(&mut self, camera: Value) -> usize {
        push(&mut self.cameras, camera)
    }

    /// A `KHR_lights_punctual` light (declares the extension).
    pub fn add_light(&mut self, light: Value) -> usize {
        self.use_extension("KHR_lights_punctual");
        push(&mut self.lights, light)
    }

    /// An external image (a file beside the .gltf).
    pub fn add_image(&mut self, uri: &str, name: &str) -> usize {
        push(&mut self.images, json!({ "uri": uri, "mimeType": "image/png", "name": name }))
    }

    pub fn add_sampler(&mut self, sampler: Value) -> usize {
        push(&mut self.samplers, sampler)
    }

    pub fn add_texture(&mut self, image: usize, sampler: usize) -> usize {
        push(&mut self.textures, json!({ "source": image, "sampler": sampler }))
    }

    /// The finished document (every node a root of scene 0, unless `roots` says otherwise) and
    /// its buffer, which the document names `buffer_uri`.
    pub fn finish(self, scene_name: &str, roots: Option<Vec<usize>>, buffer_uri: &str) -> (Value, Vec<u8>) {
        let roots = roots.unwrap_or_else(|| (0..self.nodes.len()).collect());
        let mut gltf = json!({
            "asset": { "version": "2.0", "generator": "mcctrace-scenegen (crates/scenegen)" },
            "extensionsUsed": self.extensions_used.iter().collect::<Vec<_>>(),
            "scene": 0,
            "scenes": [{ "name": scene_name, "nodes": roots }],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{ "uri": buffer_uri, "byteLength": self.bin.len() }],
        });
        let optional = [
            ("cameras", self.cameras),
            ("images", self.images),
            ("samplers", self.samplers),
            ("textures", self.textures),
        ];
        for (key, list) in optional {
            if !list.is_empty() {
                gltf[key] = Value::Array(list);
            }
        }
        if self.extensions_used.is_empty() {
            gltf.as_object_mut().expect("an object").remove("extensionsUsed");
        }
        if !self.lights.is_empty() {
            gltf["extensions"] = json!({ "KHR_lights_punctual": { "lights": self.lights } });
        }
        (gltf, self.bin)
    }
}

/// The node rotation that turns a glTF camera or spot light (which looks down its local −Z, with
/// local +Y up) to look from `eye` at `target` with `up` as the image's up direction.
pub fn look_at_rotation(eye: Vec3, target: Vec3, up: Vec3) -> Quat {
    let forward = (target - eye).normalize();
    let right = forward.cross(up).normalize();
    let true_up = right.cross(forward);
    Quat::from_mat3(&Mat3::from_cols(right, true_up, -forward)).normalize()
}

/// A quaternion as glTF's `[x, y, z, w]`, in f64 for JSON.
pub fn quat_json(q: Quat) -> Value {
    json!(q.to_array().map(f64::from))
}

/// A vector as a JSON array of f64 (exact for f32 input).
pub fn vec3_json(v: Vec3) -> Value {
    json!(v.to_array().map(f64::from))
}

/// Writes `gltf` pretty-printed with a final newline.
pub fn write_json(path: &Path, gltf: &Value) -> Result<()> {
    write_atomic(path, (serde_json::to_string_pretty(gltf)? + "\n").as_bytes())
}

/// Writes through a temporary file and a rename, so an interrupted run leaves no half file.
pub fn write_atomic(path: &Path, data: &[u8]) -> Result<()> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, data).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("renaming to {}", path.display()))
}
