//! glTF 2.0 loader (.gltf with external or data-URI buffers, and .glb): the default scene's node
//! hierarchy flattened into world space, perspective and orthographic cameras, metallic-roughness
//! materials with their textures (`images`), alpha modes, `KHR_texture_transform`,
//! `KHR_materials_emissive_strength`, `KHR_materials_specular`, `KHR_materials_transmission`,
//! `KHR_materials_ior` (`material`), `KHR_lights_punctual` point, spot and directional lights,
//! and node animations (`channels`: translation, rotation and scale channels).
//!
//! The hierarchy is read into a [`Rig`] (primitives in local space, each mesh once however many
//! nodes instance it) and flattened by [`Rig::flatten`] at t = 0; an animated file keeps the rig
//! and its channels in `Scene::animation` so [`Scene::at_time`] can flatten it at any other time.
//!
//! Every malformed input is a [`TracerError`] naming the file, never a panic; an image that cannot
//! be used is a warning (the material slot is left empty).
//!
//! Light units (docs/design/tracer.md §3.9, §3.10): point and spot intensities are candela,
//! converted to radiant intensity as W/sr = cd / 683; a directional light's lux become irradiance
//! as W/m² = lux / 683, the same photometric conversion (an ideal 555 nm source). Blender's
//! exporter (default lighting mode) writes exactly the inverse: W/(4π) × 683 cd for point and
//! spot lights of W watts, S × 683 lux for a sun of S W/m² (its `lights.py`,
//! `__gather_intensity`), so these reproduce the Blender scene. `range` is ignored: lights fall
//! off by the inverse square law, as physically based renderers do.
//!
//! Two readings ([`GltfReading`](super::GltfReading)): a file written by Blender (its
//! `asset.generator` names Blender) is read as Blender's importer reads it, any other as the
//! specification does (`Scene::reading` carries the choice; `SceneSetup::reading` overrides it).
//! Spot cones follow it: Cycles' smoothstep falloff, which a Blender file was authored with, or
//! the specification's recommended falloff ([`SpotFalloff`](super::SpotFalloff)).

mod accessor;
mod anisotropy;
mod buffers;
mod channels;
mod instancing;
mod material;
mod meshopt;
mod precheck;
#[cfg(test)]
pub(super) mod tests;
mod textures;

use super::rig::{
    Influences, LightKind, MorphTarget, Pose, Primitive, Rig, RigCamera, RigLight, RigNode, Skin,
};
use super::{GltfReading, Scene, SceneAnimation, SpotFalloff, tangents};
use crate::camera::Projection;
use crate::error::{Result, TracerError};
use glam::{Affine3A, Mat4, Quat, Vec2, Vec3, Vec4};
use gltf::mesh::{Mode, Semantic};
pub(crate) use material::apply_reading;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

/// Extensions this loader understands; a file requiring any other is refused.
const HANDLED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_volume",
    "KHR_texture_transform",
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "EXT_texture_webp",
    "EXT_mesh_gpu_instancing",
    // Metadata (authoring information, licences): nothing in it changes the picture.
    "KHR_xmp",
    "KHR_xmp_json_ld",
    "KHR_materials_unlit",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_anisotropy",
];

/// Loads a `.gltf` or `.glb` file (told apart by the GLB magic, not the name).
pub(super) fn load(path: &Path) -> Result<Scene> {
    load_with(path, false)
}

/// [`load`], keeping the node hierarchy in `Scene::animation` even when nothing is animated
/// if `keep_rig` (so a test can time flattening a static scene again).
pub(super) fn load_with(path: &Path, keep_rig: bool) -> Result<Scene> {
    let bytes = std::fs::read(path).map_err(|e| TracerError::io(path, e))?;
    let err = |m: String| TracerError::scene(path, m);
    let (json, bin) = if bytes.starts_with(b"glTF") {
        buffers::split_glb(&bytes).map_err(|m| err(format!("malformed GLB: {m}")))?
    } else {
        (&bytes[..], None)
    };
    // Tolerate what some writers add although the spec forbids it: a UTF-8 byte-order mark, and
    // NUL instead of space padding at the end of a GLB JSON chunk.
    let json = json.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(json);
    let end = json.iter().rposition(|&b| b != 0 && !b.is_ascii_whitespace()).map_or(0, |i| i + 1);
    let mut root: gltf::json::Root = gltf::json::deserialize::from_slice(&json[..end])
        .map_err(|e| err(format!("malformed glTF JSON: {e}")))?;
    // The same JSON untyped, for what the gltf crate drops (a normalTexture's extensions).
    let mut raw: serde_json::Value =
        serde_json::from_slice(&json[..end]).map_err(|e| err(format!("malformed glTF JSON: {e}")))?;
    if textures::use_webp_sources(&mut raw) {
        root = serde_json::from_value(raw.clone()).map_err(|e| err(format!("malformed glTF JSON: {e}")))?;
    }
    if !root.asset.version.starts_with("2.") {
        return Err(err(format!("glTF version {} is not supported (only 2.x)", root.asset.version)));
    }
    if let Some(ext) = root.extensions_required.iter().find(|e| !HANDLED_EXTENSIONS.contains(&e.as_str())) {
        return Err(err(format!("the file requires extension {ext}, which mcctrace does not support")));
    }
    // The gltf crate's validator refuses required extensions it does not parse itself (e.g.
    // KHR_materials_specular); they were checked above, so it need not see the list.
    root.extensions_required.clear();
    channels::check_indices(&root).map_err(err)?;
    precheck::check(&root).map_err(err)?;
    let unbounded = fill_position_bounds(&mut root);
    let base = path.parent().unwrap_or(Path::new("."));
    // Compressed views are decoded into buffers of their own before the document is built, so
    // that everything after reads them as plain views.
    let compressed = meshopt::Views::read(&raw).map_err(err)?;
    let decoded = if compressed.is_empty() {
        None
    } else {
        let mut buffers = buffers::load(&root.buffers, base, bin, &compressed.fallback).map_err(err)?;
        compressed.decode(&mut root, &mut buffers).map_err(err)?;
        Some(buffers)
    };
    let doc = gltf::Document::from_json(root).map_err(|e| match e {
        gltf::Error::Validation(errors) => err(precheck::describe_validation(&errors)),
        other => err(other.to_string()),
    })?;
    let buffers = match decoded {
        Some(buffers) => buffers,
        None => buffers::load(&doc.as_json().buffers, base, bin, &[]).map_err(err)?,
    };

    let mut scene = Scene { path: path.to_owned(), ..Scene::default() };
    if unbounded > 0 {
        let msg = format!("{unbounded} POSITION accessor(s) lack the min/max glTF requires; not needed here");
        scene.warnings.push(format!("{}: {msg}", path.display()));
    }
    for ext in doc.extensions_used().filter(|e| !HANDLED_EXTENSIONS.contains(e)) {
        scene.warnings.push(format!("{}: extension {ext} is not supported; ignored", path.display()));
    }
    let mut textures = textures::TextureLoader::new(&doc, &buffers, base, path);
    let raw_materials = raw.get("materials").and_then(serde_json::Value::as_array);
    // Blender-exported files keep the falloff and the glass Cycles rendered them with (module docs).
    let generator = doc.as_json().asset.generator.as_deref().unwrap_or("");
    let reading = GltfReading::of_generator(generator);
    for m in doc.materials() {
        let raw_material = m.index().and_then(|i| raw_materials.and_then(|a| a.get(i)));
        let converted = material::convert(&m, raw_material, &mut textures, reading).map_err(err)?;
        scene.materials.push(converted);
    }
    scene.warnings.append(&mut textures.warnings);
    scene.textures = textures.textures;
    scene.reading = reading;
    let spot_falloff = scene.reading.spot_falloff();
    let mut loader = Loader {
        path,
        buffers: &buffers,
        scene,
        default_material: None,
        spot_falloff,
        rig: Rig::default(),
        mesh_primitives: vec![None; doc.meshes().len()],
        rig_node_of: vec![None; doc.nodes().len()],
        cameras: 0,
        quantized: doc.extensions_used().any(|e| e == "KHR_mesh_quantization"),
        raw_nodes: raw.get("nodes").and_then(serde_json::Value::as_array),
    };
    loader.traverse(&doc)?;
    loader.skins(&doc)?;
    let Loader { mut scene, rig, rig_node_of, .. } = loader;
    let (channels, warnings) = channels::read(&doc, &buffers, &rig, &rig_node_of).map_err(err)?;
    scene.warnings.extend(warnings.into_iter().map(|w| format!("{}: {w}", path.display())));
    let animated = !channels.is_empty();
    // Static or not, the scene is flattened by the same code: at t = 0, where a static scene's
    // nodes are at rest and an animated one's take their channels' values (glTF clamps a time
    // before the first key to it).
    let animation = SceneAnimation::new(rig, channels).map_err(err)?;
    let flat = animation.flatten_at(0.0).map_err(err)?;
    scene.cameras = flat.cameras;
    scene.lights = flat.lights;
    let instances = super::instances::gpu_instances(animation.rig(), &flat.placed);
    if animated || keep_rig {
        // Posing flattens the scene again, every copy in world space.
        scene.instances = instances.finish().map(Arc::new);
        scene.mesh = flat.mesh;
        scene.animation = Some(Arc::new(animation));
    } else {
        let emits =
            |m: u32| scene.materials.get(m as usize).is_some_and(crate::material::Material::is_emissive);
        let (mesh, instances) = instances.finish_shared(flat.mesh, emits);
        scene.mesh = mesh;
        scene.instances = instances.map(Arc::new);
    }
    Ok(scene)
}

/// State while walking the node hierarchy into a [`Rig`].
struct Loader<'a> {
    path: &'a Path,
    buffers: &'a [Vec<u8>],
    /// Materials and warnings so far.
    scene: Scene,
    /// Index of glTF's default material once a primitive without a material needed it.
    default_material: Option<u32>,
    /// How spot lights fade (by the file's generator).
    spot_falloff: SpotFalloff,
    /// The hierarchy being built.
    rig: Rig,
    /// Each glTF mesh's primitives in `rig` once read: a mesh instanced by several nodes is
    /// read (and warned about) once.
    mesh_primitives: Vec<Option<Range<usize>>>,
    /// Each glTF node's index in `rig`, if the rendered scene holds it.
    rig_node_of: Vec<Option<usize>>,
    /// Cameras met so far (names unnamed ones).
    cameras: usize,
    /// The file declares `KHR_mesh_quantization`: vertex attributes may be integers.
    quantized: bool,
    /// The nodes' untyped JSON, for extensions the gltf crate does not parse (instancing).
    raw_nodes: Option<&'a Vec<serde_json::Value>>,
}

impl Loader<'_> {
    fn error(&self, message: String) -> TracerError {
        TracerError::scene(self.path, message)
    }

    fn warn(&mut self, message: String) {
        self.scene.warnings.push(format!("{}: {message}", self.path.display()));
    }

    /// Visits the default scene (else scene 0, else every root node) depth first, parents before
    /// children, in file order: the rig's nodes, and so cameras and lights, are in this order.
    fn traverse(&mut self, doc: &gltf::Document) -> Result<()> {
        let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(scene) => scene.nodes().collect(),
            None => {
                let mut is_child = vec![false; doc.nodes().len()];
                for child in doc.nodes().flat_map(|n| n.children()) {
                    if let Some(c) = is_child.get_mut(child.index()) {
                        *c = true;
                    }
                }
                doc.nodes().filter(|n| !is_child.get(n.index()).copied().unwrap_or(false)).collect()
            }
        };
        // An explicit stack: a hostile file's deep hierarchy cannot overflow the thread's stack.
        let mut stack: Vec<(gltf::Node, Option<usize>)> =
            roots.into_iter().rev().map(|n| (n, None)).collect();
        while let Some((node, parent)) = stack.pop() {
            let label = node_label(&node);
            let index = self.rig.nodes.len();
            match self.rig_node_of.get_mut(node.index()) {
                Some(seen @ None) => *seen = Some(index),
                _ => {
                    return Err(self.error(format!(
                        "{label} is reached twice in the node hierarchy (a cycle or a second parent); glTF nodes must form trees"
                    )));
                }
            }
            let primitives = match node.mesh() {
                Some(mesh) => self.mesh(&mesh)?,
                None => 0..0,
            };
            // Morph weights: the node's, else its mesh's, else zero, one per target.
            let targets =
                self.rig.primitives[primitives.clone()].iter().map(|p| p.targets.len()).max().unwrap_or(0);
            let mesh_weights = node.mesh().and_then(|m| m.weights().map(<[f32]>::to_vec));
            let mut weights = node.weights().map(<[f32]>::to_vec).or(mesh_weights).unwrap_or_default();
            weights.resize(targets, 0.0);
            // Resolved into the rig's skins once every joint has its rig node (`skins`).
            let skin = node.skin().map(|s| s.index());
            let camera = match node.camera() {
                Some(camera) => Some(self.camera(doc, &node, &camera)?),
                None => None,
            };
            let light = match node.light() {
                Some(light) => Some(self.light(&light)?),
                None => None,
            };
            let rest = rest_pose(&node);
            let raw_node = self.raw_nodes.and_then(|n| n.get(node.index()));
            let instances = match raw_node {
                Some(raw) => instancing::instances(raw, doc, self.buffers, self.quantized)
                    .map_err(|m| self.error(format!("{label}: {m}")))?,
                None => None,
            };
            match instances {
                // The node carries the mesh's instances as leaves; itself it draws nothing.
                Some(poses) => {
                    self.rig.nodes.push(RigNode {
                        label: label.clone(),
                        parent,
                        rest,
                        primitives: 0..0,
                        camera,
                        light,
                        skin: None,
                        weights: Vec::new(),
                        gpu_instance: false,
                    });
                    for (i, pose) in poses.into_iter().enumerate() {
                        self.rig.nodes.push(RigNode {
                            label: format!("{label} instance {i}"),
                            parent: Some(index),
                            rest: pose,
                            primitives: primitives.clone(),
                            camera: None,
                            light: None,
                            skin,
                            weights: weights.clone(),
                            gpu_instance: true,
                        });
                    }
                }
                None => self.rig.nodes.push(RigNode {
                    label,
                    parent,
                    rest,
                    primitives,
                    camera,
                    light,
                    skin,
                    weights,
                    gpu_instance: false,
                }),
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, Some(index))));
        }
        Ok(())
    }

    /// Reads a mesh's triangle primitives into the rig (once per mesh); returns their indices.
    fn mesh(&mut self, mesh: &gltf::Mesh) -> Result<Range<usize>> {
        if let Some(Some(done)) = self.mesh_primitives.get(mesh.index()) {
            return Ok(done.clone());
        }
        let start = self.rig.primitives.len();
        for prim in mesh.primitives() {
            let what =
                format!("mesh {} ('{}') primitive {}", mesh.index(), mesh.name().unwrap_or(""), prim.index());
            let path = self.path;
            let fail = |m: String| TracerError::scene(path, format!("{what}: {m}"));
            let mode = prim.mode();
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                self.warn(format!("{what}: {mode:?} primitives are not rendered; skipped"));
                continue;
            }
            let Some(pos_accessor) = prim.get(&Semantic::Positions) else {
                self.warn(format!("{what}: no POSITION attribute; skipped"));
                continue;
            };
            let q = self.quantized;
            let (position_types, unit_types) =
                if q { (accessor::QUANTIZED, accessor::UNIT) } else { (accessor::FLOAT, accessor::FLOAT) };
            let positions =
                accessor::read_vec3(&pos_accessor, self.buffers, "POSITION", position_types).map_err(fail)?;
            let normals = match prim.get(&Semantic::Normals) {
                Some(a) => Some(accessor::read_vec3(&a, self.buffers, "NORMAL", unit_types).map_err(fail)?),
                None => None,
            };
            let uvs = match prim.get(&Semantic::TexCoords(0)) {
                Some(a) => Some(accessor::read_uv(&a, self.buffers, "TEXCOORD_0", q).map_err(fail)?),
                None => None,
            };
            let uvs1 = match prim.get(&Semantic::TexCoords(1)) {
                Some(a) => Some(accessor::read_uv(&a, self.buffers, "TEXCOORD_1", q).map_err(fail)?),
                None => None,
            };
            let tangents = match prim.get(&Semantic::Tangents) {
                Some(a) => Some(accessor::read_vec4(&a, self.buffers, "TANGENT", unit_types).map_err(fail)?),
                None => None,
            };
            let influences = self.influences(&prim, positions.len()).map_err(fail)?;
            let targets = self.targets(&prim).map_err(fail)?;
            // Blender's importer multiplies base colour (and alpha, unless opaque) by COLOR_0
            // whenever a primitive has it, as the specification says; the other sets it ignores.
            let colors = match prim.get(&Semantic::Colors(0)) {
                Some(a) => Some(accessor::read_color(&a, self.buffers, "COLOR_0").map_err(fail)?),
                None => None,
            };
            let mut indices = match prim.indices() {
                Some(a) => accessor::read_indices(&a, self.buffers).map_err(fail)?,
                None => {
                    let n =
                        u32::try_from(positions.len()).map_err(|_| fail("more than 2^32 vertices".into()))?;
                    (0..n).collect()
                }
            };
            indices = match mode {
                Mode::TriangleStrip => strip_to_list(&indices),
                Mode::TriangleFan => fan_to_list(&indices),
                _ => indices,
            };
            let material = match prim.material().index() {
                Some(i) => i as u32,
                None => self.default_material(),
            };
            self.check_texture_coordinates(&what, material, [uvs.is_some(), uvs1.is_some()]);
            let tangents = match tangents {
                None => {
                    self.generated_tangents(material, &positions, normals.as_deref(), [&uvs, &uvs1], &indices)
                }
                given => given,
            };
            // Counts and indices are checked when the primitive is flattened (`Mesh::push_with`).
            self.rig.primitives.push(Primitive {
                label: what,
                positions,
                normals,
                uvs,
                uvs1,
                tangents,
                colors,
                indices,
                material,
                influences,
                targets,
            });
        }
        let range = start..self.rig.primitives.len();
        if let Some(slot) = self.mesh_primitives.get_mut(mesh.index()) {
            *slot = Some(range.clone());
        }
        Ok(range)
    }

    /// A primitive's morph targets: `POSITION`, `NORMAL` and `TANGENT` deltas (floats, or
    /// normalised integers with `KHR_mesh_quantization`).
    fn targets(&self, prim: &gltf::Primitive) -> Result<Vec<MorphTarget>, String> {
        let types = if self.quantized { accessor::QUANTIZED } else { accessor::FLOAT };
        let read = |a: Option<gltf::Accessor>, what: String| match a {
            Some(a) => accessor::read_vec3(&a, self.buffers, &what, types).map(Some),
            None => Ok(None),
        };
        prim.morph_targets()
            .enumerate()
            .map(|(i, t)| {
                Ok(MorphTarget {
                    positions: read(t.positions(), format!("target {i} POSITION"))?,
                    normals: read(t.normals(), format!("target {i} NORMAL"))?,
                    tangents: read(t.tangents(), format!("target {i} TANGENT"))?,
                })
            })
            .collect()
    }

    /// A primitive's `JOINTS_n` / `WEIGHTS_n` sets, in order until the first missing pair.
    fn influences(&self, prim: &gltf::Primitive, vertices: usize) -> Result<Option<Influences>, String> {
        let mut sets = Vec::new();
        for k in 0.. {
            let (joints, weights) = (prim.get(&Semantic::Joints(k)), prim.get(&Semantic::Weights(k)));
            let (Some(j), Some(w)) = (joints, weights) else {
                if prim.get(&Semantic::Joints(k)).is_some() != prim.get(&Semantic::Weights(k)).is_some() {
                    return Err(format!("JOINTS_{k} and WEIGHTS_{k} must come together"));
                }
                break;
            };
            sets.push((
                accessor::read_joints(&j, self.buffers, &format!("JOINTS_{k}"))?,
                accessor::read_weights(&w, self.buffers, &format!("WEIGHTS_{k}"))?,
            ));
        }
        if sets.is_empty() {
            return Ok(None);
        }
        Influences::new(sets, vertices).map(Some)
    }

    /// The file's skins as rig skins, and each skinned node pointed at its own; a joint outside
    /// the rendered hierarchy is an error naming the skin.
    fn skins(&mut self, doc: &gltf::Document) -> Result<()> {
        let mut rig_skin_of = vec![None; doc.skins().len()];
        for node in 0..self.rig.nodes.len() {
            let Some(s) = self.rig.nodes[node].skin else { continue };
            if let Some(Some(done)) = rig_skin_of.get(s) {
                self.rig.nodes[node].skin = Some(*done);
                continue;
            }
            let skin = doc.skins().nth(s).ok_or_else(|| self.error(format!("skin {s} does not exist")))?;
            let label = format!("skin {s} ('{}')", skin.name().unwrap_or(""));
            let mut joints = Vec::new();
            for j in skin.joints() {
                let rig = self.rig_node_of.get(j.index()).copied().flatten().ok_or_else(|| {
                    self.error(format!(
                        "{label}: joint {} is not in the rendered scene's hierarchy",
                        node_label(&j)
                    ))
                })?;
                joints.push(rig);
            }
            let inverse_bind = match skin.inverse_bind_matrices() {
                Some(a) => {
                    let m = accessor::read_mat4(&a, self.buffers)
                        .map_err(|m| self.error(format!("{label}: {m}")))?;
                    if m.len() < joints.len() {
                        return Err(self.error(format!(
                            "{label}: {} inverse bind matrices for {} joints",
                            m.len(),
                            joints.len()
                        )));
                    }
                    m.iter().map(|m| Affine3A::from_mat4(*m)).collect()
                }
                None => vec![Affine3A::IDENTITY; joints.len()],
            };
            self.rig.skins.push(Skin { label, joints, inverse_bind });
            let index = self.rig.skins.len() - 1;
            rig_skin_of[s] = Some(index);
            self.rig.nodes[node].skin = Some(index);
        }
        Ok(())
    }

    /// Warns when `material`'s textures read a coordinate set the primitive lacks (the tracer
    /// then reads set 0 instead of set 1, and without set 0 a single texel).
    fn check_texture_coordinates(&mut self, what: &str, material: u32, has: [bool; 2]) {
        let Some(m) = self.scene.materials.get(material as usize) else { return };
        let t = &m.textures;
        let refs = t.all();
        let used = |set: u32| refs.iter().flatten().any(|r| r.uv_set == set);
        let name = m.name.clone();
        if (used(0) || (used(1) && !has[1])) && !has[0] {
            self.warn(format!(
                "{what}: material '{name}' has textures but the primitive has no texture coordinates; \
                 they read a single texel"
            ));
        } else if used(1) && !has[1] {
            self.warn(format!(
                "{what}: material '{name}' reads TEXCOORD_1, which the primitive lacks; TEXCOORD_0 is used"
            ));
        }
    }

    /// glTF's default material (spec §3.9.2), added to the scene the first time it is needed.
    /// MikkTSpace tangents for a primitive without `TANGENT` whose material `material` is
    /// anisotropic, from the coordinate set its anisotropy texture uses (else set 0), as
    /// Blender's Tangent node makes them; `None` for every other primitive (it pays nothing), and
    /// for one whose counts or indices are wrong (flattening reports them).
    fn generated_tangents(
        &self,
        material: u32,
        positions: &[Vec3],
        normals: Option<&[Vec3]>,
        uvs: [&Option<Vec<Vec2>>; 2],
        indices: &[u32],
    ) -> Option<Vec<Vec4>> {
        let m = self.scene.materials.get(material as usize)?;
        m.anisotropy?;
        let set = m.textures.anisotropy.map_or(0, |t| t.uv_set.min(1)) as usize;
        let uvs = uvs[set].as_deref()?;
        let n = positions.len();
        let fits = uvs.len() == n
            && normals.is_none_or(|v| v.len() == n)
            && indices.len().is_multiple_of(3)
            && indices.iter().all(|&i| (i as usize) < n);
        fits.then(|| tangents::mikktspace(positions, normals, uvs, indices))
    }

    fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.scene.materials.push(material::gltf_default());
            (self.scene.materials.len() - 1) as u32
        })
    }

    fn camera(
        &mut self,
        doc: &gltf::Document,
        node: &gltf::Node,
        camera: &gltf::Camera,
    ) -> Result<RigCamera> {
        use gltf::json::camera::Type;
        use gltf::json::validation::Checked;
        let name = [node.name(), camera.name()]
            .into_iter()
            .flatten()
            .find(|n| !n.is_empty())
            .map_or_else(|| format!("camera{}", self.cameras), str::to_owned);
        self.cameras += 1;
        // Read from the JSON: the gltf crate's `projection()` panics when `type` names an object
        // the camera lacks, which its validator lets through. The aspect ratio is ignored: the
        // resolution is the renderer's choice (as in Blender).
        let json = doc.as_json().cameras.get(camera.index());
        let projection = match json.map(|c| (c.type_, &c.perspective, &c.orthographic)) {
            Some((Checked::Valid(Type::Perspective), Some(p), _)) => {
                Projection::Perspective { fov_y: p.yfov }
            }
            Some((Checked::Valid(Type::Orthographic), _, Some(o))) => {
                Projection::Orthographic { half_height: o.ymag }
            }
            _ => {
                return Err(self.error(format!(
                    "camera {} ('{name}') lacks the projection object its type names",
                    camera.index()
                )));
            }
        };
        Ok(RigCamera { name, projection })
    }

    /// The light's node-independent part; its node places and aims it (`RigLight::place`).
    fn light(&mut self, light: &gltf::khr_lights_punctual::Light) -> Result<RigLight> {
        use gltf::khr_lights_punctual::Kind;
        let label = format!("light {} ('{}')", light.index(), light.name().unwrap_or(""));
        let color = Vec3::from(light.color());
        let intensity = light.intensity();
        if !(intensity.is_finite() && intensity >= 0.0 && color.is_finite() && color.min_element() >= 0.0) {
            return Err(self.error(format!(
                "{label}: intensity {intensity} and color {color} must be finite and non-negative"
            )));
        }
        // Units: module docs. `range` is ignored on purpose (inverse-square falloff).
        let radiant = color * (intensity / 683.0);
        let kind = match light.kind() {
            Kind::Point => LightKind::Point { intensity: radiant },
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                let (inner, outer) = (inner_cone_angle, outer_cone_angle);
                let half_pi = std::f32::consts::FRAC_PI_2;
                if !(outer.is_finite() && outer > 0.0 && outer <= half_pi) {
                    return Err(self.error(format!("{label}: outerConeAngle {outer} must be in (0, π/2]")));
                }
                if !(inner.is_finite() && inner >= 0.0 && inner <= outer) {
                    return Err(self.error(format!(
                        "{label}: innerConeAngle {inner} must be in [0, outerConeAngle = {outer}]"
                    )));
                }
                LightKind::Spot {
                    intensity: radiant,
                    inner_cone: inner,
                    outer_cone: outer,
                    falloff: self.spot_falloff,
                }
            }
            Kind::Directional => LightKind::Directional { irradiance: radiant },
        };
        Ok(RigLight { label, kind })
    }
}

/// Gives POSITION accessors without `min`/`max` placeholder bounds so the gltf crate's
/// validator accepts them: the bounds are a hint the tracer never reads, and refusing an
/// otherwise sound file over them would help nobody. Returns how many were filled.
fn fill_position_bounds(root: &mut gltf::json::Root) -> usize {
    use gltf::json::validation::Checked;
    let positions: Vec<usize> = root
        .meshes
        .iter()
        .flat_map(|m| &m.primitives)
        .filter_map(|p| p.attributes.get(&Checked::Valid(Semantic::Positions)))
        .map(|i| i.value())
        .collect();
    let mut filled = 0;
    for i in positions {
        if let Some(a) = root.accessors.get_mut(i).filter(|a| a.min.is_none() || a.max.is_none()) {
            a.min.get_or_insert_with(|| serde_json::json!([0.0, 0.0, 0.0]));
            a.max.get_or_insert_with(|| serde_json::json!([0.0, 0.0, 0.0]));
            filled += 1;
        }
    }
    filled
}

fn node_label(node: &gltf::Node) -> String {
    match node.name() {
        Some(name) => format!("node {} ('{name}')", node.index()),
        None => format!("node {}", node.index()),
    }
}

/// A node's transform relative to its parent when no animation applies.
fn rest_pose(node: &gltf::Node) -> Pose {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            Pose::Matrix(Affine3A::from_mat4(Mat4::from_cols_array_2d(&matrix)))
        }
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            // Exporters write unit quaternions to float precision only; renormalise. A zero
            // quaternion has no rotation to recover and yields NaN, reported when flattening.
            let q = Quat::from_array(rotation);
            Pose::Trs { translation: translation.into(), rotation: q / q.length(), scale: scale.into() }
        }
    }
}

/// Triangle strip to list, keeping every triangle counter-clockwise (glTF spec §3.7.2.1).
fn strip_to_list(strip: &[u32]) -> Vec<u32> {
    strip
        .windows(3)
        .enumerate()
        .flat_map(|(i, w)| if i % 2 == 0 { [w[0], w[1], w[2]] } else { [w[0], w[2], w[1]] })
        .collect()
}

/// Triangle fan to list (glTF spec §3.7.2.1: triangle i is (p[i+1], p[i+2], p[0])).
fn fan_to_list(fan: &[u32]) -> Vec<u32> {
    match fan.split_first() {
        Some((&centre, rest)) => rest.windows(2).flat_map(|w| [w[0], w[1], centre]).collect(),
        None => Vec::new(),
    }
}
