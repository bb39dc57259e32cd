//! Scenes at any time: node hierarchies flattened for a pose, and keyframe animation (glTF 2.0
//! §3.11 and Appendix C).
//!
//! A loader that reads a node hierarchy (glTF) describes the scene as a [`Rig`]: its nodes in
//! depth-first order with their rest transforms, every mesh primitive in its node's local space,
//! and the cameras and lights the nodes carry. [`Rig::flatten`] turns a rig into world-space
//! triangles, cameras and lights for one set of node transforms; it is the only code that does,
//! for static and animated scenes alike. A [`SceneAnimation`] is a rig plus keyframe
//! [`Channel`]s: it flattens the scene at any time by sampling the channels into the animated
//! nodes' translation, rotation and scale. A static scene is flattened once, at load, and keeps
//! no rig.
//!
//! How a channel is sampled between and beyond its keys (glTF Appendix C) is `channel`'s. All the
//! animations of a file play together, from t = 0: exporters such as Blender's write one animation
//! per animated object, all meant to run at once.

mod channel;
mod morph;
mod skin;

pub(in crate::scene) use channel::{Channel, Interpolation, Property};
pub(in crate::scene) use morph::MorphTarget;
pub(crate) use skin::normal_matrix;
pub(in crate::scene) use skin::{Influences, Skin};

use morph::Morphed;

use super::instances::Placement;
use super::{Mesh, MeshExtras, MeshPart, PunctualLight, SpotFalloff};
use crate::camera::{CameraDesc, Projection};
use glam::{Affine3A, Mat3, Quat, Vec2, Vec3, Vec4};
use std::ops::Range;

/// A node's transform relative to its parent, as the file gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::scene) enum Pose {
    /// Translation, rotation (a unit quaternion) and scale, composed as T · R · S.
    Trs {
        /// Translation.
        translation: Vec3,
        /// Rotation.
        rotation: Quat,
        /// Scale.
        scale: Vec3,
    },
    /// A general affine matrix.
    Matrix(Affine3A),
}

impl Pose {
    /// The transform as a matrix.
    pub(in crate::scene) fn affine(&self) -> Affine3A {
        match *self {
            Pose::Trs { translation, rotation, scale } => {
                Affine3A::from_scale_rotation_translation(scale, rotation, translation)
            }
            Pose::Matrix(m) => m,
        }
    }
}

/// One node of a [`Rig`].
#[derive(Clone, Debug)]
pub(in crate::scene) struct RigNode {
    /// How messages name the node ("node 3 ('Cube')").
    pub label: String,
    /// The parent, always earlier in [`Rig::nodes`]; `None` for a root.
    pub parent: Option<usize>,
    /// The transform relative to the parent when no animation applies.
    pub rest: Pose,
    /// The node's mesh primitives (indices into [`Rig::primitives`]).
    pub primitives: Range<usize>,
    /// The camera the node carries.
    pub camera: Option<RigCamera>,
    /// The light the node carries.
    pub light: Option<RigLight>,
    /// The skin (index into [`Rig::skins`]) that deforms the node's primitives.
    pub skin: Option<usize>,
    /// Morph-target weights when no animation sets them (the node's, else its mesh's).
    pub weights: Vec<f32>,
    /// One of the copies `EXT_mesh_gpu_instancing` places (drawn as an instance).
    pub gpu_instance: bool,
}

/// A triangle primitive in its node's local space, indices already a counter-clockwise list.
#[derive(Clone, Debug)]
pub(in crate::scene) struct Primitive {
    /// How messages name the primitive ("mesh 2 ('chair') primitive 0").
    pub label: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals.
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates, set 0.
    pub uvs: Option<Vec<Vec2>>,
    /// Texture coordinates, set 1.
    pub uvs1: Option<Vec<Vec2>>,
    /// Tangents (xyz, w = bitangent sign).
    pub tangents: Option<Vec<Vec4>>,
    /// Vertex colours (linear RGBA, `COLOR_0`).
    pub colors: Option<Vec<Vec4>>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
    /// Material of every triangle.
    pub material: u32,
    /// Joints and weights of every vertex, where the primitive can be skinned.
    pub influences: Option<Influences>,
    /// Morph targets.
    pub targets: Vec<MorphTarget>,
}

/// The vertex attributes a frame transforms: the primitive's own, or morphed ones.
#[derive(Clone, Copy)]
struct Attributes<'a> {
    positions: &'a [Vec3],
    normals: Option<&'a [Vec3]>,
    tangents: Option<&'a [Vec4]>,
}

/// A camera on a node: it looks down the node's −Z with +Y up.
#[derive(Clone, Debug)]
pub(in crate::scene) struct RigCamera {
    /// The camera's name in the scene's camera list.
    pub name: String,
    /// Its projection.
    pub projection: Projection,
}

/// A punctual light on a node, intensities already radiometric (see the glTF loader).
#[derive(Clone, Debug)]
pub(in crate::scene) struct RigLight {
    /// How messages name the light ("light 0 ('sun')").
    pub label: String,
    /// What kind of light, with its node-independent parameters.
    pub kind: LightKind,
}

/// The node-independent part of a [`PunctualLight`].
#[derive(Clone, Copy, Debug)]
pub(in crate::scene) enum LightKind {
    /// A point light of this radiant intensity (W/sr).
    Point { intensity: Vec3 },
    /// A spot light shining down the node's −Z.
    Spot { intensity: Vec3, inner_cone: f32, outer_cone: f32, falloff: SpotFalloff },
    /// A directional light shining down the node's −Z.
    Directional { irradiance: Vec3 },
}

/// A node hierarchy with its geometry, cameras and lights in local space.
#[derive(Clone, Debug, Default)]
pub(in crate::scene) struct Rig {
    /// Nodes in depth-first order, parents before children (the order cameras and lights are
    /// listed in).
    pub nodes: Vec<RigNode>,
    /// Mesh primitives; a mesh several nodes instance is stored once.
    pub primitives: Vec<Primitive>,
    /// Skins the nodes refer to.
    pub skins: Vec<Skin>,
}

/// What [`Rig::flatten`] produces: the scene's world-space part.
#[derive(Clone, Debug, Default)]
pub(in crate::scene) struct Flat {
    /// All triangles in world space.
    pub mesh: Mesh,
    /// Cameras in node order.
    pub cameras: Vec<CameraDesc>,
    /// Lights in node order.
    pub lights: Vec<PunctualLight>,
    /// Every node that drew triangles, with where they went.
    pub placed: Vec<Placed>,
}

/// Where [`Rig::flatten`] put one node's triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(in crate::scene) struct Placed {
    /// The node.
    pub node: usize,
    /// Its world transform.
    pub world: Affine3A,
    /// Its first triangle in the flattened mesh.
    pub first: u32,
    /// How many triangles it drew.
    pub count: u32,
    /// Its transform mirrors (the triangles were re-wound).
    pub mirrored: bool,
    /// Its triangles are its primitives' moved by `world` alone (no skin, no morph targets).
    pub rigid: bool,
}

/// Reused buffers for one primitive's transformed attributes.
#[derive(Default)]
struct Scratch {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    tangents: Vec<Vec4>,
    indices: Vec<u32>,
}

impl Rig {
    /// Flattens the hierarchy with each node's transform relative to its parent taken from
    /// `locals` (one per node) and its morph weights from `weights` where that has them (else
    /// the node's own); the message names the node, primitive or light at fault.
    pub(in crate::scene) fn flatten(
        &self,
        locals: &[Affine3A],
        weights: &[Option<Vec<f32>>],
    ) -> Result<Flat, String> {
        if locals.len() != self.nodes.len() {
            return Err(format!("{} node transforms for {} nodes", locals.len(), self.nodes.len()));
        }
        let mut flat = Flat::default();
        let primitives = |n: &RigNode| {
            self.primitives.get(n.primitives.clone()).ok_or_else(|| {
                format!("{}: primitives {:?} of {}", n.label, n.primitives, self.primitives.len())
            })
        };
        let (mut vertices, mut triangles) = (0, 0);
        for node in &self.nodes {
            for p in primitives(node)? {
                vertices += p.positions.len();
                triangles += p.indices.len() / 3;
            }
        }
        flat.mesh.positions.reserve(vertices);
        flat.mesh.triangles.reserve(triangles);
        flat.mesh.material_ids.reserve(triangles);
        // Every world transform first: a skinned mesh needs its joints', wherever they are.
        let mut worlds: Vec<Affine3A> = Vec::with_capacity(self.nodes.len());
        for (node, local) in self.nodes.iter().zip(locals) {
            let world = match node.parent {
                None => *local,
                Some(p) => {
                    let parent =
                        worlds.get(p).ok_or_else(|| format!("{}: parent {p} comes later", node.label))?;
                    *parent * *local
                }
            };
            if !world.is_finite() {
                return Err(format!("{} has a non-finite transform", node.label));
            }
            worlds.push(world);
        }
        let mut scratch = Scratch::default();
        let mut joint_buf: Vec<Affine3A> = Vec::new();
        let mut morphed = Morphed::default();
        for (i, (node, world)) in self.nodes.iter().zip(&worlds).enumerate() {
            let node_weights = weights.get(i).and_then(Option::as_deref).unwrap_or(&node.weights);
            if !node.primitives.is_empty() {
                let frame = Frame::new(world);
                let joints = match node.skin {
                    Some(s) => Some(self.joint_matrices(s, &worlds, &mut joint_buf)?),
                    None => None,
                };
                let first = flat.mesh.triangle_count() as u32;
                let mut rigid = true;
                for prim in primitives(node)? {
                    rigid &= prim.targets.is_empty() && (joints.is_none() || prim.influences.is_none());
                    let mut attrs = Attributes {
                        positions: &prim.positions,
                        normals: prim.normals.as_deref(),
                        tangents: prim.tangents.as_deref(),
                    };
                    if !prim.targets.is_empty() {
                        let [p, n, t] = morphed
                            .apply(
                                &prim.targets,
                                node_weights,
                                attrs.positions,
                                attrs.normals,
                                attrs.tangents,
                            )
                            .map_err(|m| format!("{}: {m}", prim.label))?;
                        if p {
                            attrs.positions = &morphed.positions;
                        }
                        if n {
                            attrs.normals = Some(&morphed.normals);
                        }
                        if t {
                            attrs.tangents = Some(&morphed.tangents);
                        }
                    }
                    let pushed = match (joints, &prim.influences) {
                        (Some(matrices), Some(influences)) => frame.push_skinned(
                            prim,
                            attrs,
                            influences,
                            matrices,
                            &mut flat.mesh,
                            &mut scratch,
                        ),
                        _ => frame.push(prim, attrs, &mut flat.mesh, &mut scratch),
                    };
                    pushed.map_err(|m| format!("{}: {m}", prim.label))?;
                }
                let count = flat.mesh.triangle_count() as u32 - first;
                let mirrored = frame.place.mirrored;
                flat.placed.push(Placed { node: i, world: *world, first, count, mirrored, rigid });
            }
            if let Some(camera) = &node.camera {
                let projection = camera.projection;
                flat.cameras.push(CameraDesc {
                    name: camera.name.clone(),
                    world_from_camera: *world,
                    projection,
                });
            }
            if let Some(light) = &node.light {
                flat.lights.push(light.place(world)?);
            }
        }
        Ok(flat)
    }

    /// Appends the primitives `prims` in their own space to `mesh` (re-wound when `mirrored`,
    /// as flattening re-winds a mirrored node's): a shared instance mesh, whose copies' hits
    /// move its attributes as [`Frame::push`] would have (`instances::Placement`).
    pub(in crate::scene) fn push_local(
        &self,
        prims: std::ops::Range<usize>,
        mirrored: bool,
        mesh: &mut Mesh,
    ) -> Result<(), String> {
        let prims = self.primitives.get(prims).ok_or("no such primitives")?;
        let mut indices = Vec::new();
        for prim in prims {
            indices.clear();
            indices.extend_from_slice(&prim.indices);
            if mirrored {
                indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
            }
            let part = MeshPart {
                positions: &prim.positions,
                normals: prim.normals.as_deref(),
                uvs: prim.uvs.as_deref(),
                indices: Some(&indices),
                material: prim.material,
            };
            let extras = MeshExtras {
                uvs1: prim.uvs1.as_deref(),
                tangents: prim.tangents.as_deref(),
                colors: prim.colors.as_deref(),
            };
            mesh.push_with(part, extras)?;
        }
        Ok(())
    }

    /// Skin `s`'s joint matrices (joint world × inverse bind) into `out`.
    fn joint_matrices<'o>(
        &self,
        s: usize,
        worlds: &[Affine3A],
        out: &'o mut Vec<Affine3A>,
    ) -> Result<&'o [Affine3A], String> {
        let skin = self.skins.get(s).ok_or_else(|| format!("skin {s} of {}", self.skins.len()))?;
        out.clear();
        for (&j, ibm) in skin.joints.iter().zip(&skin.inverse_bind) {
            let world =
                worlds.get(j).ok_or_else(|| format!("{}: joint node {j} of {}", skin.label, worlds.len()))?;
            out.push(*world * *ibm);
        }
        Ok(out)
    }

    /// How many cameras the nodes carry.
    fn camera_count(&self) -> usize {
        self.nodes.iter().filter(|n| n.camera.is_some()).count()
    }
}

/// A node's world transform prepared for transforming attributes.
struct Frame<'a> {
    world: &'a Affine3A,
    /// How its attributes move (a mirroring transform turns counter-clockwise into clockwise).
    place: Placement,
}

impl<'a> Frame<'a> {
    fn new(world: &'a Affine3A) -> Self {
        Self { world, place: Placement::new(world) }
    }

    /// Appends skinned `prim` to `mesh`: each vertex moved by its joints' blended matrix; the
    /// node's own transform applies only to a vertex without weight.
    fn push_skinned(
        &self,
        prim: &Primitive,
        attrs: Attributes<'_>,
        influences: &Influences,
        joints: &[Affine3A],
        mesh: &mut Mesh,
        s: &mut Scratch,
    ) -> Result<(), String> {
        if usize::from(influences.max_joint()) >= joints.len() {
            return Err(format!(
                "a vertex uses joint {} but its skin has {}",
                influences.max_joint(),
                joints.len()
            ));
        }
        let n = prim.positions.len();
        for (what, len) in [
            ("NORMAL", prim.normals.as_ref().map(Vec::len)),
            ("TANGENT", prim.tangents.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&l| l != n) {
                return Err(format!("{what} has {len} entries for {n} positions"));
            }
        }
        s.positions.clear();
        s.normals.clear();
        s.tangents.clear();
        for (v, &p) in attrs.positions.iter().enumerate() {
            let m = influences.matrix(v, joints, self.world);
            s.positions.push(m.transform_point3(p));
            let linear = Mat3::from(m.matrix3);
            if let Some(ns) = attrs.normals {
                s.normals.push((skin::normal_matrix(linear) * ns[v]).normalize_or_zero());
            }
            if let Some(ts) = attrs.tangents {
                let t = ts[v];
                let xyz = (linear * t.truncate()).normalize_or_zero();
                let w = if (t.w < 0.0) == (linear.determinant() < 0.0) { 1.0 } else { -1.0 };
                s.tangents.push(if xyz == Vec3::ZERO { Vec4::ZERO } else { xyz.extend(w) });
            }
        }
        let part = MeshPart {
            positions: &s.positions,
            normals: attrs.normals.map(|_| &s.normals[..]),
            uvs: prim.uvs.as_deref(),
            indices: Some(&prim.indices),
            material: prim.material,
        };
        let extras = MeshExtras {
            uvs1: prim.uvs1.as_deref(),
            tangents: attrs.tangents.map(|_| &s.tangents[..]),
            colors: prim.colors.as_deref(),
        };
        mesh.push_with(part, extras)
    }

    /// Appends `prim` transformed into world space to `mesh`.
    fn push(
        &self,
        prim: &Primitive,
        attrs: Attributes<'_>,
        mesh: &mut Mesh,
        s: &mut Scratch,
    ) -> Result<(), String> {
        s.positions.clear();
        s.positions.extend(attrs.positions.iter().map(|&p| self.world.transform_point3(p)));
        let normals = attrs.normals.map(|ns| {
            s.normals.clear();
            s.normals.extend(ns.iter().map(|&n| self.place.normal(n)));
            &s.normals[..]
        });
        // Tangents are directions on the surface: they transform like positions' differences.
        // A mirroring transform flips the handedness of the tangent frame, so w flips too.
        let tangents = attrs.tangents.map(|ts| {
            s.tangents.clear();
            s.tangents.extend(ts.iter().map(|&t| self.place.tangent(t)));
            &s.tangents[..]
        });
        let indices = if self.place.mirrored {
            s.indices.clear();
            s.indices.extend_from_slice(&prim.indices);
            s.indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
            &s.indices[..]
        } else {
            &prim.indices[..]
        };
        let part = MeshPart {
            positions: &s.positions,
            normals,
            uvs: prim.uvs.as_deref(),
            indices: Some(indices),
            material: prim.material,
        };
        let extras = MeshExtras { uvs1: prim.uvs1.as_deref(), tangents, colors: prim.colors.as_deref() };
        mesh.push_with(part, extras)
    }
}

impl RigLight {
    /// The light placed by its node's world transform.
    fn place(&self, world: &Affine3A) -> Result<PunctualLight, String> {
        let position = Vec3::from(world.translation);
        // Spot and directional lights shine along their node's local −Z.
        let direction = || {
            let n = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
            if n == Vec3::ZERO || !n.is_finite() {
                return Err(format!(
                    "{}: its node's transform is singular, so the light has no direction",
                    self.label
                ));
            }
            Ok(n)
        };
        Ok(match self.kind {
            LightKind::Point { intensity } => PunctualLight::Point { position, intensity },
            LightKind::Spot { intensity, inner_cone, outer_cone, falloff } => PunctualLight::Spot {
                position,
                direction: direction()?,
                intensity,
                inner_cone,
                outer_cone,
                falloff,
            },
            LightKind::Directional { irradiance } => {
                PunctualLight::Directional { direction: direction()?, irradiance }
            }
        })
    }
}

/// A node some channel animates: its rest TRS and the channel (if any) of each property.
#[derive(Clone, Debug)]
struct Animated {
    node: usize,
    rest: (Vec3, Quat, Vec3),
    /// Channel indices by [`Property::slot`]: translation, rotation, scale, then each group of
    /// four morph weights.
    channels: Vec<Option<usize>>,
}

/// A scene's node hierarchy and its keyframe animation: everything needed to flatten the scene
/// again at another time without re-reading the file ([`Scene::at_time`](super::Scene::at_time)).
#[derive(Clone)]
pub struct SceneAnimation {
    rig: Rig,
    channels: Vec<Channel>,
    /// Each node's rest transform relative to its parent.
    rest: Vec<Affine3A>,
    animated: Vec<Animated>,
    duration: f32,
}

impl std::fmt::Debug for SceneAnimation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneAnimation")
            .field("nodes", &self.rig.nodes.len())
            .field("primitives", &self.rig.primitives.len())
            .field("channels", &self.channels.len())
            .field("animated_nodes", &self.animated.len())
            .field("duration", &self.duration)
            .finish()
    }
}

impl SceneAnimation {
    /// `channels` on `rig`; where two animate the same property of a node, the first wins (the
    /// loader warns). An animated node given as a matrix is split into translation, rotation and
    /// scale; the message says which node cannot be (a singular matrix).
    pub(in crate::scene) fn new(rig: Rig, channels: Vec<Channel>) -> Result<Self, String> {
        let rest: Vec<Affine3A> = rig.nodes.iter().map(|n| n.rest.affine()).collect();
        let mut animated: Vec<Animated> = Vec::new();
        let mut slot_of = vec![None; rig.nodes.len()];
        for (c, channel) in channels.iter().enumerate() {
            let node = rig
                .nodes
                .get(channel.node)
                .ok_or_else(|| format!("a channel animates node {} of {}", channel.node, rig.nodes.len()))?;
            let a = match slot_of[channel.node] {
                Some(a) => a,
                None => {
                    let trs = match node.rest {
                        Pose::Trs { translation, rotation, scale } => (translation, rotation, scale),
                        Pose::Matrix(m) => {
                            let (s, r, t) = m.to_scale_rotation_translation();
                            if !(s.is_finite() && r.is_finite() && t.is_finite() && s.cmpne(Vec3::ZERO).all())
                            {
                                return Err(format!(
                                    "{} is animated but its matrix is singular, so it has no translation, \
                                     rotation and scale to animate",
                                    node.label
                                ));
                            }
                            (t, r, s)
                        }
                    };
                    animated.push(Animated { node: channel.node, rest: trs, channels: vec![None; 3] });
                    slot_of[channel.node] = Some(animated.len() - 1);
                    animated.len() - 1
                }
            };
            let slots = &mut animated[a].channels;
            let slot = channel.property.slot();
            if slots.len() <= slot {
                slots.resize(slot + 1, None);
            }
            slots[slot].get_or_insert(c);
        }
        let duration = channels.iter().map(Channel::end).fold(0.0, f32::max);
        Ok(Self { rig, channels, rest, animated, duration })
    }

    /// The node hierarchy.
    pub(in crate::scene) fn rig(&self) -> &Rig {
        &self.rig
    }

    /// The end of the longest channel, in seconds (0 when nothing is animated).
    pub fn duration(&self) -> f32 {
        self.duration
    }

    /// How many keyframe channels (node translation, rotation or scale) the scene has.
    pub fn channel_count(&self) -> usize {
        self.channels.len()
    }

    /// How many cameras the file's nodes carry (the first entries of the scene's camera list).
    pub(in crate::scene) fn camera_count(&self) -> usize {
        self.rig.camera_count()
    }

    /// Node `node`'s translation, rotation and scale relative to its parent at `t` seconds, if
    /// some channel animates it.
    #[cfg(test)]
    pub(in crate::scene) fn node_trs(&self, node: usize, t: f32) -> Option<(Vec3, Quat, Vec3)> {
        self.animated.iter().find(|a| a.node == node).map(|a| self.trs(a, t))
    }

    fn trs(&self, a: &Animated, t: f32) -> (Vec3, Quat, Vec3) {
        let (mut translation, mut rotation, mut scale) = a.rest;
        let sample = |slot: usize| a.channels[slot].map(|c| self.channels[c].sample(t));
        if let Some(v) = sample(Property::Translation.slot()) {
            translation = v.truncate();
        }
        if let Some(v) = sample(Property::Rotation.slot()) {
            rotation = Quat::from_vec4(v);
        }
        if let Some(v) = sample(Property::Scale.slot()) {
            scale = v.truncate();
        }
        (translation, rotation, scale)
    }

    /// The scene's world-space part at `t` seconds (see [`Rig::flatten`]).
    pub(in crate::scene) fn flatten_at(&self, t: f32) -> Result<Flat, String> {
        let mut locals = self.rest.clone();
        let mut weights: Vec<Option<Vec<f32>>> = Vec::new();
        for a in &self.animated {
            if a.channels[..3].iter().any(Option::is_some) {
                let (translation, rotation, scale) = self.trs(a, t);
                locals[a.node] = Affine3A::from_scale_rotation_translation(scale, rotation, translation);
            }
            if a.channels.len() > 3 {
                let mut w = self.rig.nodes[a.node].weights.clone();
                for (g, c) in a.channels[3..].iter().enumerate() {
                    let Some(c) = c else { continue };
                    let v = self.channels[*c].sample(t).to_array();
                    for (slot, value) in w.iter_mut().skip(4 * g).zip(v) {
                        *slot = value;
                    }
                }
                weights.resize(self.rig.nodes.len(), None);
                weights[a.node] = Some(w);
            }
        }
        self.rig.flatten(&locals, &weights)
    }
}
