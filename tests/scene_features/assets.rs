//! glTF files, PNGs and meshes written by hand into a temporary folder: the assets every test here builds.

use glam::{Quat, Vec2, Vec3, Vec4};
use std::f32::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

/// A temporary folder, removed on drop.
pub(crate) struct TempDir(PathBuf);

impl TempDir {
    pub(crate) fn new(tag: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("mcctrace-features-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    pub(crate) fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    pub(crate) fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// An 8-bit RGBA PNG.
pub(crate) fn png(dir: &TempDir, name: &str, width: u32, height: u32, rgba: &[[u8; 4]]) {
    let bytes: Vec<u8> = rgba.iter().flatten().copied().collect();
    tracer::image_io::write_png_rgba8(&dir.path(name), width, height, &bytes).unwrap();
}

pub(crate) fn num(v: f32) -> String {
    assert!(v.is_finite());
    format!("{v}")
}

pub(crate) fn arr(v: &[f32]) -> String {
    format!("[{}]", v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", "))
}

/// A glTF file written by hand: JSON objects as strings, one external binary buffer.
#[derive(Default)]
pub(crate) struct Gltf {
    pub(crate) generator: String,
    pub(crate) bin: Vec<u8>,
    pub(crate) views: Vec<String>,
    pub(crate) accessors: Vec<String>,
    pub(crate) images: Vec<String>,
    pub(crate) samplers: Vec<String>,
    pub(crate) textures: Vec<String>,
    pub(crate) materials: Vec<String>,
    pub(crate) meshes: Vec<String>,
    pub(crate) nodes: Vec<String>,
    pub(crate) cameras: Vec<String>,
    pub(crate) lights: Vec<String>,
}

/// A mesh primitive's data.
#[derive(Default)]
pub(crate) struct Prim {
    pub(crate) positions: Vec<Vec3>,
    pub(crate) normals: Vec<Vec3>,
    pub(crate) uv0: Vec<Vec2>,
    pub(crate) uv1: Vec<Vec2>,
    pub(crate) tangents: Vec<Vec4>,
    pub(crate) indices: Vec<u32>,
}

pub(crate) fn push<T>(list: &mut Vec<T>, item: T) -> usize {
    list.push(item);
    list.len() - 1
}

impl Gltf {
    pub(crate) fn new(generator: &str) -> Self {
        Self { generator: generator.to_owned(), ..Self::default() }
    }

    pub(crate) fn accessor(
        &mut self,
        bytes: Vec<u8>,
        component: u32,
        ty: &str,
        count: usize,
        bounds: &str,
    ) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let view =
            format!(r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}}}"#, self.bin.len(), bytes.len());
        self.bin.extend(bytes);
        let v = push(&mut self.views, view);
        let a = format!(
            r#"{{"bufferView": {v}, "componentType": {component}, "type": "{ty}", "count": {count}{bounds}}}"#
        );
        push(&mut self.accessors, a)
    }

    pub(crate) fn floats(&mut self, values: &[f32], ty: &str, count: usize, bounds: &str) -> usize {
        self.accessor(values.iter().flat_map(|f| f.to_le_bytes()).collect(), 5126, ty, count, bounds)
    }

    pub(crate) fn primitive(&mut self, p: &Prim, material: usize) -> String {
        let lo = p.positions.iter().fold(Vec3::splat(f32::MAX), |a, b| a.min(*b));
        let hi = p.positions.iter().fold(Vec3::splat(f32::MIN), |a, b| a.max(*b));
        let bounds = format!(r#", "min": {}, "max": {}"#, arr(&lo.to_array()), arr(&hi.to_array()));
        let flat3: Vec<f32> = p.positions.iter().flat_map(|v| v.to_array()).collect();
        let mut attributes =
            format!(r#""POSITION": {}"#, self.floats(&flat3, "VEC3", p.positions.len(), &bounds));
        if !p.normals.is_empty() {
            let flat: Vec<f32> = p.normals.iter().flat_map(|v| v.to_array()).collect();
            write!(attributes, r#", "NORMAL": {}"#, self.floats(&flat, "VEC3", p.normals.len(), "")).unwrap();
        }
        for (set, uvs) in [(0, &p.uv0), (1, &p.uv1)] {
            if !uvs.is_empty() {
                let flat: Vec<f32> = uvs.iter().flat_map(|v| v.to_array()).collect();
                write!(attributes, r#", "TEXCOORD_{set}": {}"#, self.floats(&flat, "VEC2", uvs.len(), ""))
                    .unwrap();
            }
        }
        if !p.tangents.is_empty() {
            let flat: Vec<f32> = p.tangents.iter().flat_map(|v| v.to_array()).collect();
            write!(attributes, r#", "TANGENT": {}"#, self.floats(&flat, "VEC4", p.tangents.len(), ""))
                .unwrap();
        }
        let bytes = p.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.accessor(bytes, 5125, "SCALAR", p.indices.len(), "");
        format!(r#"{{"attributes": {{{attributes}}}, "indices": {indices}, "material": {material}}}"#)
    }

    /// A mesh of `prims` on a new node with extra node JSON (`, "translation": …`).
    pub(crate) fn mesh_node(&mut self, prims: &[(&Prim, usize)], node_extra: &str) -> usize {
        let list: Vec<String> = prims.iter().map(|(p, m)| self.primitive(p, *m)).collect();
        let mesh = push(&mut self.meshes, format!(r#"{{"primitives": [{}]}}"#, list.join(", ")));
        push(&mut self.nodes, format!(r#"{{"mesh": {mesh}{node_extra}}}"#))
    }

    pub(crate) fn material(&mut self, json: &str) -> usize {
        push(&mut self.materials, json.to_owned())
    }

    /// A texture of the image file `uri` with sampler JSON `sampler` (or none).
    pub(crate) fn texture(&mut self, uri: &str, sampler: Option<&str>) -> usize {
        let image = push(&mut self.images, format!(r#"{{"uri": "{uri}"}}"#));
        match sampler {
            Some(s) => {
                let s = push(&mut self.samplers, s.to_owned());
                push(&mut self.textures, format!(r#"{{"source": {image}, "sampler": {s}}}"#))
            }
            None => push(&mut self.textures, format!(r#"{{"source": {image}}}"#)),
        }
    }

    /// A light shining along `direction` (spot, directional) from `position`.
    pub(crate) fn light(&mut self, json: &str, position: Vec3, direction: Vec3) -> usize {
        let l = push(&mut self.lights, json.to_owned());
        let q = Quat::from_rotation_arc(Vec3::NEG_Z, direction.normalize());
        let node = format!(
            r#"{{"translation": {}, "rotation": {}, "extensions": {{"KHR_lights_punctual": {{"light": {l}}}}}}}"#,
            arr(&position.to_array()),
            arr(&q.to_array())
        );
        push(&mut self.nodes, node)
    }

    pub(crate) fn write(&self, dir: &TempDir, name: &str) -> PathBuf {
        let bin_name = format!("{name}.bin");
        std::fs::write(dir.path(&bin_name), &self.bin).unwrap();
        let list = |v: &[String]| format!("[{}]", v.join(", "));
        let nodes: Vec<String> = (0..self.nodes.len()).map(|i| i.to_string()).collect();
        let mut json = format!(
            r#"{{"asset": {{"version": "2.0", "generator": "{}"}},
"extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength", "KHR_lights_punctual",
                   "KHR_texture_transform", "KHR_materials_transmission", "KHR_materials_ior",
                   "KHR_materials_volume"],
"scene": 0, "scenes": [{{"nodes": [{}]}}],
"buffers": [{{"uri": "{bin_name}", "byteLength": {}}}],
"bufferViews": {}, "accessors": {}, "meshes": {}, "nodes": {}, "materials": {}"#,
            self.generator,
            nodes.join(", "),
            self.bin.len(),
            list(&self.views),
            list(&self.accessors),
            list(&self.meshes),
            list(&self.nodes),
            list(&self.materials),
        );
        for (key, v) in [("images", &self.images), ("samplers", &self.samplers), ("textures", &self.textures)]
        {
            if !v.is_empty() {
                write!(json, r#", "{key}": {}"#, list(v)).unwrap();
            }
        }
        if !self.cameras.is_empty() {
            write!(json, r#", "cameras": {}"#, list(&self.cameras)).unwrap();
        }
        if !self.lights.is_empty() {
            write!(
                json,
                r#", "extensions": {{"KHR_lights_punctual": {{"lights": {}}}}}"#,
                list(&self.lights)
            )
            .unwrap();
        }
        json.push('}');
        dir.write(&format!("{name}.gltf"), json)
    }
}

/// A rectangle p(s, t) = centre + (2s − 1)·a + (2t − 1)·b with texture coordinates (s, t) (so
/// +b runs down the image), wound so its front faces `facing`.
pub(crate) fn quad(centre: Vec3, a: Vec3, b: Vec3, facing: Vec3) -> Prim {
    let st = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
    let positions = st.iter().map(|s| centre + (2.0 * s.x - 1.0) * a + (2.0 * s.y - 1.0) * b).collect();
    let indices = if a.cross(b).dot(facing) > 0.0 { vec![0, 1, 2, 0, 2, 3] } else { vec![0, 2, 1, 0, 3, 2] };
    Prim { positions, normals: vec![facing.normalize(); 4], uv0: st.to_vec(), indices, ..Prim::default() }
}

/// A UV sphere with exact vertex normals, triangles facing outwards.
pub(crate) fn sphere(centre: Vec3, radius: f32, stacks: u32, slices: u32) -> Prim {
    let mut p = Prim::default();
    for i in 0..=stacks {
        let theta = PI * i as f32 / stacks as f32;
        for j in 0..=slices {
            let phi = 2.0 * PI * j as f32 / slices as f32;
            let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            p.positions.push(centre + radius * n);
            p.normals.push(n);
        }
    }
    let at = |i: u32, j: u32| i * (slices + 1) + j;
    for i in 0..stacks {
        for j in 0..slices {
            for [a, b, c] in
                [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]]
            {
                let [pa, pb, pc] = [a, b, c].map(|k| p.positions[k as usize]);
                let n = (pb - pa).cross(pc - pa);
                if n.length() < 1e-9 {
                    continue; // the poles' degenerate triangles
                }
                let outward = n.dot((pa + pb + pc) / 3.0 - centre) > 0.0;
                p.indices.extend(if outward { [a, b, c] } else { [a, c, b] });
            }
        }
    }
    p
}

/// A Lambertian material (`KHR_materials_specular` 0, as Blender writes walls).
pub(crate) fn lambert(name: &str, rho: Vec3) -> String {
    format!(
        r#"{{"name": "{name}", "doubleSided": true, "pbrMetallicRoughness": {{"baseColorFactor": [{}, {}, {}, 1],
           "metallicFactor": 0, "roughnessFactor": 1}}, "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}}}}"#,
        rho.x, rho.y, rho.z
    )
}
