//! Geometry in motion within one frame's shutter (docs/design/tracer.md §3.12): the scene's vertices
//! at the motion steps, evenly spaced from the shutter's opening to its closing, as Cycles
//! stores a deforming mesh (`motion_steps`). A ray at time t sees each moving vertex linearly
//! interpolated between the two steps around t (Cycles' motion triangles); the tracer's BVH
//! keeps the triangles that move apart from the rest, so static geometry is traced as without
//! a shutter.

use super::{Mesh, Scene};
use crate::error::{Result, TracerError};
use glam::Vec3;
use std::sync::Arc;

/// Motion steps unless told otherwise: the shutter's opening, middle and closing (Cycles'
/// default, `motion_steps` 1, gives 2^1 + 1 = 3).
pub const DEFAULT_MOTION_STEPS: usize = 3;

/// The most motion steps a shutter takes (Cycles' limit of `motion_steps` 7 gives 129).
pub const MAX_MOTION_STEPS: usize = 129;

/// A scene's vertex positions (and normals) at evenly spaced times over a shutter.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneMotion {
    /// Ray time (frames) of the first step: the shutter's opening.
    pub open: f32,
    /// Ray time (frames) of the last step: the shutter's closing.
    pub close: f32,
    /// Per step, every vertex's position (each as long as the mesh's positions).
    pub positions: Vec<Vec<Vec3>>,
    /// Per step, every vertex's normal; empty when the mesh has no normals.
    pub normals: Vec<Vec<Vec3>>,
}

impl SceneMotion {
    /// Checks the steps against `mesh`: at least two, as many normals as positions, every value
    /// finite, open < close; the message says what is wrong.
    pub fn validate(&self, mesh: &Mesh) -> std::result::Result<(), String> {
        let steps = self.positions.len();
        if !(2..=MAX_MOTION_STEPS).contains(&steps) {
            return Err(format!("{steps} motion steps: need 2 ..= {MAX_MOTION_STEPS}"));
        }
        if !(self.open.is_finite() && self.close.is_finite() && self.open < self.close) {
            return Err(format!(
                "motion steps from {} to {}: need finite times, open < close",
                self.open, self.close
            ));
        }
        let n = mesh.positions.len();
        if let Some(k) = self.positions.iter().position(|p| p.len() != n) {
            return Err(format!(
                "motion step {k} has {} positions for {n} vertices",
                self.positions[k].len()
            ));
        }
        if !self.normals.is_empty()
            && (self.normals.len() != steps || self.normals.iter().any(|s| s.len() != mesh.normals.len()))
        {
            return Err("motion steps' normals do not match the mesh's".to_owned());
        }
        if let Some(k) = self.positions.iter().position(|s| s.iter().any(|p| !p.is_finite())) {
            return Err(format!("motion step {k} has a non-finite vertex position"));
        }
        if self.normals.iter().any(|s| s.iter().any(|v| !v.is_finite())) {
            return Err("a motion step has a non-finite vertex normal".to_owned());
        }
        Ok(())
    }

    /// How many steps.
    pub fn steps(&self) -> usize {
        self.positions.len()
    }

    /// The triangles of `mesh` that move: a corner differs at some step from the mesh's own
    /// position (bit for bit; a vertex that no animation moves keeps its bits at every step).
    pub fn moving_triangles(&self, mesh: &Mesh) -> Vec<bool> {
        let moved: Vec<bool> = (0..mesh.positions.len())
            .map(|v| self.positions.iter().any(|s| s[v] != mesh.positions[v]))
            .collect();
        mesh.triangles.iter().map(|t| t.iter().any(|&v| moved[v as usize])).collect()
    }
}

impl Scene {
    /// The scene (posed at its frame) with its geometry at `steps` evenly spaced times over the
    /// shutter from `seconds.0` to `seconds.1` (scene time), which rays see at times `frames.0`
    /// to `frames.1` (frames): [`Scene::motion`] is set when some vertex moves within it, and
    /// left `None` otherwise (a static scene, or a shutter where nothing moves, renders as
    /// without one). An animation whose triangles change within the shutter (a node's scale
    /// turning it inside out) keeps the frame's pose, with a warning. The error names the file
    /// and the time at which posing failed.
    pub fn in_motion(mut self, seconds: (f32, f32), frames: (f32, f32), steps: usize) -> Result<Scene> {
        self.motion = None;
        let Some(animation) = self.animation.clone() else { return Ok(self) };
        if !(seconds.0 < seconds.1 && frames.0 < frames.1) {
            return Ok(self);
        }
        if !(2..=MAX_MOTION_STEPS).contains(&steps) {
            return Err(TracerError::Settings(format!(
                "{steps} motion steps: need 2 ..= {MAX_MOTION_STEPS}"
            )));
        }
        let mut motion =
            SceneMotion { open: frames.0, close: frames.1, positions: Vec::new(), normals: Vec::new() };
        let mut placed = Vec::with_capacity(steps);
        for k in 0..steps {
            // In f64, so that the first and last step land on the shutter's ends exactly.
            let f = k as f64 / (steps - 1) as f64;
            let t = (seconds.0 as f64 + (seconds.1 as f64 - seconds.0 as f64) * f) as f32;
            let flat = animation.flatten_at(t).map_err(|m| {
                TracerError::scene(&self.path, format!("at t = {t} s (motion step {k}): {m}"))
            })?;
            if flat.mesh.triangles != self.mesh.triangles
                || flat.mesh.positions.len() != self.mesh.positions.len()
            {
                self.warnings.push(format!(
                    "{}: the triangles change within the shutter at t = {t} s (a transform turns a mesh inside \
                     out), so the geometry is drawn without motion blur",
                    self.path.display()
                ));
                return Ok(self);
            }
            placed.push(flat.placed);
            motion.positions.push(flat.mesh.positions);
            if !self.mesh.normals.is_empty() {
                motion.normals.push(flat.mesh.normals);
            }
        }
        motion.validate(&self.mesh).map_err(|m| TracerError::scene(&self.path, m))?;
        let moving = motion.moving_triangles(&self.mesh);
        if moving.contains(&true) {
            self.instances = self.rigid_instances(&animation, &placed, frames, &moving).map(Arc::new);
            self.motion = Some(Arc::new(motion));
        }
        Ok(self)
    }

    /// The instances of the scene in motion: nodes that move rigidly within the shutter, their
    /// transforms at the steps (`placed`, one flattening per step) interpolated per ray time,
    /// and the `EXT_mesh_gpu_instancing` copies that stay still, where the frame has them. A
    /// node is left to the moving triangles (`moving`) when it deforms, emits light (which is
    /// lit where the frame has it) or its transform does not split into translation, rotation
    /// and scale.
    fn rigid_instances(
        &self,
        animation: &super::SceneAnimation,
        placed: &[Vec<super::rig::Placed>],
        frames: (f32, f32),
        moving: &[bool],
    ) -> Option<super::SceneInstances> {
        let rig = animation.rig();
        let mut builder = super::instances::Builder::new(rig);
        let still = |first: u32| self.instances.as_ref()?.instances.iter().find(|i| i.first == first);
        let emissive = |t: usize| {
            self.materials.get(self.mesh.material_ids[t] as usize).is_some_and(|m| m.is_emissive())
        };
        for (i, p) in placed[0].iter().enumerate() {
            let range = p.first as usize..(p.first + p.count) as usize;
            let same = placed
                .iter()
                .all(|s| s.get(i).is_some_and(|q| (q.node, q.first, q.count) == (p.node, p.first, p.count)));
            let moves =
                same && p.rigid && moving[range.clone()].contains(&true) && !range.clone().any(emissive);
            let worlds: Vec<glam::Affine3A> = placed.iter().map(|s| s[i.min(s.len() - 1)].world).collect();
            let motion =
                if moves { super::RigidMotion::from_steps(frames.0, frames.1, &worlds) } else { None };
            match (motion, still(p.first)) {
                (Some(m), _) => {
                    builder.add(p, worlds[0], Some(m));
                }
                (None, Some(copy)) if !moving[range].contains(&true) => {
                    builder.add(p, copy.world, None);
                }
                _ => {}
            }
        }
        builder.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::MeshPart;

    fn quad() -> Mesh {
        let mut m = Mesh::default();
        let p = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(5.0, 0.0, 0.0),
            Vec3::new(6.0, 0.0, 0.0),
            Vec3::new(5.0, 1.0, 0.0),
        ];
        m.push(MeshPart { positions: &p, normals: None, uvs: None, indices: None, material: 0 }).unwrap();
        m
    }

    #[test]
    fn only_triangles_with_a_moved_corner_move() {
        let mesh = quad();
        let mut later = mesh.positions.clone();
        later[4].y += 0.5;
        let motion = SceneMotion {
            open: 0.0,
            close: 0.5,
            positions: vec![mesh.positions.clone(), later],
            normals: vec![],
        };
        motion.validate(&mesh).unwrap();
        assert_eq!(motion.moving_triangles(&mesh), [false, true]);
        let short = SceneMotion { positions: vec![mesh.positions.clone()], ..motion.clone() };
        assert!(short.validate(&mesh).unwrap_err().contains("1 motion steps"));
        let backwards = SceneMotion { open: 1.0, close: 0.5, ..motion.clone() };
        assert!(backwards.validate(&mesh).unwrap_err().contains("open < close"));
        let mut nan = motion.clone();
        nan.positions[1][0].x = f32::NAN;
        assert!(nan.validate(&mesh).unwrap_err().contains("step 1"));
    }

    #[test]
    fn a_static_scene_has_no_motion() {
        let scene = Scene { mesh: quad(), ..Scene::default() };
        let moved = scene.clone().in_motion((0.0, 0.25), (0.0, 0.5), 3).unwrap();
        assert!(moved.motion.is_none());
        assert_eq!(moved.mesh, scene.mesh);
    }
}
