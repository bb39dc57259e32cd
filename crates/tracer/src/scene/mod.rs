//! A scene as loaded from disk (docs/design/tracer.md §3.1): triangles flattened into world space,
//! materials, cameras, punctual lights and the environment. Loaders: `gltf` (glTF 2.0, .gltf and
//! .glb) and `obj` (OBJ/MTL; a directory or list of OBJ files is one scene). The acceleration
//! structure and light sampling structures are built from a `Scene` by `crate::integrator`.
//! An animated glTF scene keeps its node hierarchy and keyframes (`rig`); [`Scene::at_time`]
//! flattens it again at any time.

pub mod camera_list;
mod environment;
mod gltf;
mod images;
mod instances;
mod mesh;
mod motion;
mod obj;
mod rig;
mod tangents;

pub use instances::{Instance, InstanceMesh, Placement, RigidMotion, SceneInstances, slerp};
pub use mesh::{Mesh, MeshExtras, MeshPart};
pub use motion::{DEFAULT_MOTION_STEPS, MAX_MOTION_STEPS, SceneMotion};
pub use rig::SceneAnimation;
pub(crate) use rig::normal_matrix;

use crate::camera::CameraDesc;
use crate::error::{Result, TracerError};
use crate::material::Material;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A light with no area (`KHR_lights_punctual`). Intensities are radiant (W/sr per channel);
/// the glTF loader converts from candela (÷ 683, docs/design/tracer.md §3.9) and lux (÷ 683).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PunctualLight {
    /// Emits equally in all directions from a point.
    Point {
        /// World-space position.
        position: Vec3,
        /// Radiant intensity, W/sr per RGB channel.
        intensity: Vec3,
    },
    /// A point light restricted to a cone.
    Spot {
        /// World-space position.
        position: Vec3,
        /// Unit direction the cone points along.
        direction: Vec3,
        /// Radiant intensity on the axis, W/sr per RGB channel.
        intensity: Vec3,
        /// Angle from the axis where the falloff starts (radians).
        inner_cone: f32,
        /// Angle from the axis where the light ends (radians).
        outer_cone: f32,
        /// Shape of the falloff between the two.
        falloff: SpotFalloff,
    },
    /// Parallel light from infinitely far away (the sun).
    Directional {
        /// Unit direction the light travels in.
        direction: Vec3,
        /// Irradiance on a surface facing the light, W/m² per RGB channel.
        irradiance: Vec3,
    },
}

/// How a spot light fades between its inner and outer cone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SpotFalloff {
    /// Blender Cycles' falloff: smoothstep((cos θ − cos θo) / ((1 − cos θo) · b)) with
    /// b = 1 − inner/outer (docs/design/tracer.md §3.10); what a Blender-exported scene was lit with.
    #[default]
    Blender,
    /// The glTF specification's recommended falloff: the square of the linear ramp in cos θ
    /// between the outer and inner cone.
    Gltf,
}

/// Whose reading of a glTF file to follow where Blender's importer and the glTF specification
/// differ (docs/cycles.md, "Two readings of one file", lists every difference).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GltfReading {
    /// Blender's importer, as Cycles renders the file: what a file Blender wrote was made to
    /// look like.
    #[default]
    Blender,
    /// The glTF specification.
    Spec,
}

impl GltfReading {
    /// The loader's choice for a file whose `asset.generator` is `generator`: Blender's reading
    /// for files Blender wrote, the specification's for any other.
    pub fn of_generator(generator: &str) -> Self {
        if generator.contains("Blender") { Self::Blender } else { Self::Spec }
    }

    /// The spot-light falloff of this reading.
    pub fn spot_falloff(self) -> SpotFalloff {
        match self {
            Self::Blender => SpotFalloff::Blender,
            Self::Spec => SpotFalloff::Gltf,
        }
    }
}

/// An equirectangular (latitude–longitude) environment image, importance-sampled as a light.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    /// Linear RGB radiance; x spans longitude −180° … 180° with −Z at the centre, y spans
    /// latitude 90° (top) … −90° (the equirectangular camera's convention).
    pub texture: crate::texture::Texture,
    /// Rotation about +Y, radians.
    pub rotation: f32,
    /// Radiance multiplier.
    pub strength: f32,
}

/// Light arriving from infinitely far away where rays leave the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Constant radiance.
    pub color: Vec3,
}

impl Default for Environment {
    fn default() -> Self {
        Self { color: Vec3::ZERO }
    }
}

/// Which of a scene's cameras to use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CameraSelector {
    /// By name (a glTF camera or camera-node name).
    Name(String),
    /// By position in the scene's camera list (0-based; what code passes).
    Index(usize),
    /// By number in the scene's camera list, counted from 1 as a person counts them (what a
    /// command line passes); 0 names no camera.
    Number(usize),
}

impl CameraSelector {
    /// Parses a command-line selector: a whole number is the camera's number, counted from 1
    /// (a camera literally named so wins); anything else is a name.
    pub fn parse(s: &str) -> Self {
        match s.parse::<usize>() {
            Ok(n) => Self::Number(n),
            Err(_) => Self::Name(s.to_owned()),
        }
    }
}

impl std::fmt::Display for CameraSelector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Name(n) => write!(f, "named '{n}'"),
            Self::Index(i) => write!(f, "number {} (index {i})", i + 1),
            Self::Number(0) => write!(f, "number 0: cameras are numbered from 1 (the first is 1)"),
            Self::Number(n) => write!(f, "number {n}"),
        }
    }
}

/// A loaded scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// The file (or directory) the scene came from, for messages.
    pub path: PathBuf,
    /// All triangles, in world space.
    pub mesh: Mesh,
    /// Materials; `mesh.material_ids` index this list.
    pub materials: Vec<Material>,
    /// Cameras the scene carries (glTF), in file order.
    pub cameras: Vec<CameraDesc>,
    /// Punctual lights.
    pub lights: Vec<PunctualLight>,
    /// The environment.
    pub environment: Environment,
    /// What the loader ignored or replaced (unsupported features, missing materials …), each
    /// naming the file: library code never prints, the CLI shows these.
    pub warnings: Vec<String>,
    /// Decoded texture images; materials' `TextureRef`s index this list.
    pub textures: Vec<crate::texture::Texture>,
    /// An environment image replacing `environment.color` where rays leave the scene.
    pub environment_map: Option<EnvironmentMap>,
    /// The reading of a glTF file the scene was loaded with (Blender's for other formats).
    pub reading: GltfReading,
    /// The node hierarchy and keyframes of an animated scene, from which [`Scene::at_time`]
    /// flattens it at any time; `None` for a static scene (and every OBJ scene).
    pub animation: Option<Arc<SceneAnimation>>,
    /// The vertices at the motion steps of a shutter ([`Scene::in_motion`]), when something
    /// moves within it; `None` renders the mesh as it is, at every ray time.
    pub motion: Option<Arc<SceneMotion>>,
    /// The mesh's triangles that the BVH holds as instances of shared meshes (docs/design/
    /// tracer.md §3.13): `EXT_mesh_gpu_instancing` copies, and nodes moving rigidly within the
    /// shutter; `None` when there are none.
    pub instances: Option<Arc<SceneInstances>>,
}

impl Scene {
    /// Follows `reading` from now on: the materials' `KHR_materials_volume` re-read in it (the
    /// spot falloff is the caller's to set, as a flag may override it alone).
    pub fn set_reading(&mut self, reading: GltfReading) {
        self.reading = reading;
        for m in &mut self.materials {
            gltf::apply_reading(m, reading);
        }
    }

    /// Loads a scene: `.gltf`/`.glb`, `.obj`, or a directory whose `.obj` files form one scene.
    /// An animated scene is returned at t = 0 (its channels' values there, glTF clamping a time
    /// before a channel's first key to that key).
    pub fn load(path: &Path) -> Result<Self> {
        let meta = std::fs::metadata(path).map_err(|e| TracerError::io(path, e))?;
        let scene = if meta.is_dir() {
            obj::load_dir(path)?
        } else {
            match extension(path).as_deref() {
                Some("gltf") | Some("glb") => gltf::load(path)?,
                Some("obj") => obj::load_files(path, &[path.to_path_buf()])?,
                _ => {
                    return Err(TracerError::scene(
                        path,
                        "unknown scene format: expected .gltf, .glb, .obj or a directory of .obj files",
                    ));
                }
            }
        };
        scene.validate()?;
        Ok(scene)
    }

    /// Loads several OBJ files as one scene (named after the first).
    pub fn load_obj_files(paths: &[PathBuf]) -> Result<Self> {
        let first = paths.first().ok_or_else(|| TracerError::Settings("no scene files given".into()))?;
        let scene = obj::load_files(first, paths)?;
        scene.validate()?;
        Ok(scene)
    }

    /// The camera `selector` picks, or an error listing the cameras there are.
    pub fn camera(&self, selector: &CameraSelector) -> Result<&CameraDesc> {
        let found = match selector {
            CameraSelector::Name(name) => self.cameras.iter().find(|c| &c.name == name),
            CameraSelector::Index(i) => self.cameras.get(*i),
            CameraSelector::Number(n) => {
                // A camera literally named "2" wins over number 2.
                let by_name = self.cameras.iter().find(|c| c.name == n.to_string());
                by_name.or_else(|| n.checked_sub(1).and_then(|i| self.cameras.get(i)))
            }
        };
        found.ok_or_else(|| TracerError::UnknownCamera {
            path: self.path.clone(),
            wanted: selector.to_string(),
            available: self.describe_cameras(),
        })
    }

    /// The scene's cameras listed for a message, numbered from 1 as a selector counts them:
    /// "2 cameras: 1 'left', 2 'right'".
    pub fn describe_cameras(&self) -> String {
        if self.cameras.is_empty() {
            return "no cameras (give one with --look-from/--look-at or a camera-list file)".to_owned();
        }
        let list: Vec<String> =
            self.cameras.iter().zip(1..).map(|(c, n)| format!("{n} '{}'", c.name)).collect();
        format!("{} camera{}: {}", list.len(), if list.len() == 1 { "" } else { "s" }, list.join(", "))
    }

    /// The scene at `seconds`: every animated node's translation, rotation and scale sampled
    /// there (clamped to each channel's keys), and the meshes, cameras and lights on those nodes
    /// and below them moved with them. Materials, textures, the environment and the warnings
    /// carry over unchanged, and so do cameras added after the file's own (a camera-list
    /// file's). A static scene is returned as it is. The error names the file, the time and
    /// what an animated transform broke (a light left without a direction by a zero scale …).
    pub fn at_time(&self, seconds: f32) -> Result<Scene> {
        let Some(animation) = &self.animation else { return Ok(self.clone()) };
        if seconds.is_nan() {
            return Err(TracerError::Settings(format!("{}: the time to render is NaN", self.path.display())));
        }
        let at = |m: String| TracerError::scene(&self.path, format!("at t = {seconds} s: {m}"));
        let flat = animation.flatten_at(seconds).map_err(at)?;
        let mut cameras = flat.cameras;
        cameras.extend(self.cameras.iter().skip(animation.camera_count()).cloned());
        let instances = instances::gpu_instances(animation.rig(), &flat.placed).finish().map(Arc::new);
        let scene = Scene {
            path: self.path.clone(),
            mesh: flat.mesh,
            materials: self.materials.clone(),
            cameras,
            lights: flat.lights,
            environment: self.environment,
            warnings: self.warnings.clone(),
            textures: self.textures.clone(),
            environment_map: self.environment_map.clone(),
            reading: self.reading,
            animation: Some(Arc::clone(animation)),
            motion: None,
            instances,
        };
        scene.validate_geometry().map_err(|e| match e {
            TracerError::Scene { path, message } => {
                TracerError::scene(path, format!("at t = {seconds} s: {message}"))
            }
            e => e,
        })?;
        Ok(scene)
    }

    /// How long the scene's animation runs: the end of its longest channel in seconds (0 for a
    /// static scene).
    pub fn duration(&self) -> f32 {
        self.animation.as_ref().map_or(0.0, |a| a.duration())
    }

    /// Checks the whole scene for values the tracer cannot use (NaN vertices, bad indices,
    /// out-of-range materials) and names the first problem.
    pub fn validate(&self) -> Result<()> {
        self.validate_geometry()?;
        for m in &self.materials {
            m.validate().map_err(|msg| TracerError::scene(&self.path, msg))?;
        }
        for t in &self.textures {
            if t.texels.len() != t.width as usize * t.height as usize
                || t.texels.iter().any(|v| !v.is_finite())
            {
                return Err(TracerError::scene(&self.path, format!("texture '{}' is malformed", t.name)));
            }
        }
        let texture_count = self.textures.len();
        for m in &self.materials {
            let t = &m.textures;
            let refs = t.all();
            if let Some(r) =
                refs.iter().flatten().find(|r| r.texture as usize >= texture_count || r.uv_set > 1)
            {
                return Err(TracerError::scene(
                    &self.path,
                    format!(
                        "material '{}' refers to texture {} (set {}) of {texture_count}",
                        m.name, r.texture, r.uv_set
                    ),
                ));
            }
        }
        if !self.environment.color.is_finite() || self.environment.color.min_element() < 0.0 {
            return Err(TracerError::scene(&self.path, "environment colour must be finite and non-negative"));
        }
        Ok(())
    }

    /// The part of [`Scene::validate`] that node transforms affect: the mesh (its material ids
    /// included) and the lights.
    fn validate_geometry(&self) -> Result<()> {
        self.mesh.validate(self.materials.len()).map_err(|m| TracerError::scene(&self.path, m))?;
        if let Some(motion) = &self.motion {
            motion.validate(&self.mesh).map_err(|m| TracerError::scene(&self.path, m))?;
        }
        if let Some(instances) = &self.instances {
            instances.validate(&self.mesh).map_err(|m| TracerError::scene(&self.path, m))?;
        }
        for (i, light) in self.lights.iter().enumerate() {
            let ok = match *light {
                PunctualLight::Point { position, intensity } => {
                    position.is_finite() && intensity.is_finite() && intensity.min_element() >= 0.0
                }
                PunctualLight::Spot { position, direction, intensity, inner_cone, outer_cone, .. } => {
                    position.is_finite()
                        && direction.is_normalized()
                        && intensity.is_finite()
                        && intensity.min_element() >= 0.0
                        && inner_cone >= 0.0
                        && inner_cone <= outer_cone
                        && outer_cone > 0.0
                        && outer_cone <= std::f32::consts::FRAC_PI_2
                }
                PunctualLight::Directional { direction, irradiance } => {
                    direction.is_normalized() && irradiance.is_finite() && irradiance.min_element() >= 0.0
                }
            };
            if !ok {
                return Err(TracerError::scene(
                    &self.path,
                    format!("light {i} has a non-finite, negative or out-of-range value: {light:?}"),
                ));
            }
        }
        Ok(())
    }

    /// True when something gives light: a punctual light, a surface of an emissive material,
    /// a constant environment or an environment image that is not black. Without any, every
    /// picture of the scene is black.
    pub fn has_light(&self) -> bool {
        let punctual = self.lights.iter().any(|l| match *l {
            PunctualLight::Point { intensity, .. } | PunctualLight::Spot { intensity, .. } => {
                intensity.max_element() > 0.0
            }
            PunctualLight::Directional { irradiance, .. } => irradiance.max_element() > 0.0,
        });
        let environment = self.environment.color.max_element() > 0.0
            || self.environment_map.as_ref().is_some_and(|m| {
                m.strength > 0.0 && m.texture.texels.iter().any(|t| t.truncate().max_element() > 0.0)
            });
        let emissive: Vec<bool> = self.materials.iter().map(Material::is_emissive).collect();
        let surfaces = emissive.contains(&true)
            && self.mesh.material_ids.iter().any(|&m| emissive.get(m as usize).copied().unwrap_or(false));
        punctual || environment || surfaces
    }

    /// Axis-aligned bounds of all vertices (min, max), every copy of a shared mesh where it
    /// is placed; `None` for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let Some(instances) = self.instances.as_deref().filter(|i| i.shared_from.is_some()) else {
            return self.mesh.bounds();
        };
        let world_vertices = instances.shared_from.map_or(0, |(_, v)| v as usize);
        let copies = instances.instances.iter().filter(|i| instances.meshes[i.mesh as usize].shared);
        let placed = copies.flat_map(|i| {
            instances.meshes[i.mesh as usize].positions.iter().map(|&p| i.world.transform_point3(p))
        });
        let mut points = self.mesh.positions[..world_vertices].iter().copied().chain(placed);
        let first = points.next()?;
        Some(points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// The number of triangles drawn: every copy of a shared mesh counted.
    pub fn drawn_triangle_count(&self) -> usize {
        let shared = self.instances.as_deref().filter(|i| i.shared_from.is_some());
        let extra = shared.map_or(0, |s| {
            let per_mesh: Vec<usize> = s.meshes.iter().map(InstanceMesh::triangle_count).collect();
            let copies: usize = s
                .instances
                .iter()
                .filter(|i| s.meshes[i.mesh as usize].shared)
                .map(|i| per_mesh[i.mesh as usize])
                .sum();
            let once: usize = s.meshes.iter().filter(|m| m.shared).map(InstanceMesh::triangle_count).sum();
            copies - once
        });
        self.mesh.triangle_count() + extra
    }

    /// The same scene with every copy of a shared mesh in the mesh in world space (as an
    /// animated scene's copies are): what the scene was before its copies were shared, for
    /// comparing the two.
    pub fn with_copies_flattened(&self) -> Scene {
        let Some(instances) = self.instances.as_deref().filter(|i| i.shared_from.is_some()) else {
            return self.clone();
        };
        let (mesh, instances) = instances::unshare(&self.mesh, instances);
        Scene { mesh, instances: Some(Arc::new(instances)), ..self.clone() }
    }

    /// Bytes the scene's geometry takes: the mesh's vertex, triangle and material arrays and
    /// the instances' meshes and placements.
    pub fn geometry_bytes(&self) -> usize {
        self.mesh.bytes() + self.instances.as_deref().map_or(0, SceneInstances::bytes)
    }
}

fn extension(path: &Path) -> Option<String> {
    path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase())
}
