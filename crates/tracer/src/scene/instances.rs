//! Meshes drawn as instances (docs/design/tracer.md §3.13): one copy of a mesh in its own space
//! and, per instance, where it is placed. The tracer's BVH then holds each mesh's triangles
//! once, whatever the number of copies, and a tree over the instances above them.
//!
//! Where a mesh is *shared* (the copies of a static scene that emit no light), the scene's mesh
//! holds it once, in its own space, after every world-space triangle: each copy's `first`
//! names that one range, and a hit is shaded through its copy ([`Placement`]: positions,
//! normals and tangents moved as flattening would have moved them, the mesh-local triangle's
//! texture coordinates, colours and material). Memory then grows with the unique meshes, not
//! the copies. Otherwise (moving copies, emitters, an animated scene, which posing flattens
//! again) the scene's mesh lists every copy's triangles in world space: instance k's triangle
//! j is the mesh's triangle `first + j`, at the corners `world` gives the local ones. What becomes an instance is
//! chosen where the scene is built: the copies of `EXT_mesh_gpu_instancing`, and nodes that move
//! rigidly within a shutter ([`RigidMotion`]: their transform at the motion steps, interpolated
//! per ray time with the rotation by slerp, as Cycles interpolates its decomposed motion
//! transforms). Deforming (skinned or morphing) meshes are not instances: their vertices move
//! on their own (`motion.rs`).

use super::Mesh;
use super::rig::{Placed, Rig};
use glam::{Affine3A, DVec4, Mat3, Quat, Vec3, Vec4};

/// One unique mesh in its own space, as every instance of it shares it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InstanceMesh {
    /// Vertex positions (local space).
    pub positions: Vec<Vec3>,
    /// Three vertex indices per triangle, in the order (and winding) the scene's mesh holds its
    /// instances' triangles.
    pub triangles: Vec<[u32; 3]>,
    /// The scene's mesh holds this mesh once, in its own space, at every copy's `first`
    /// (rather than each copy's triangles in world space).
    pub shared: bool,
}

impl InstanceMesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The local corners of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|v| self.positions[v as usize])
    }
}

/// One placed copy of an [`InstanceMesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// Index of its mesh in [`SceneInstances::meshes`].
    pub mesh: u32,
    /// Its first triangle in the scene's mesh: its triangle j is the scene's `first + j`.
    pub first: u32,
    /// Local to world, as the scene's mesh was flattened with (for a moving instance, where the
    /// frame's pose has it).
    pub world: Affine3A,
    /// Its transform over the shutter when it moves rigidly within it.
    pub motion: Option<RigidMotion>,
}

/// The scene's instances and the meshes they share.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneInstances {
    /// Unique meshes.
    pub meshes: Vec<InstanceMesh>,
    /// Instances, in the order of their triangles in the scene's mesh (ranges never overlap,
    /// but the copies of a shared mesh all name its one range).
    pub instances: Vec<Instance>,
    /// Where the shared meshes' local triangles and vertices start in the scene's mesh (they
    /// end it); `None` when no mesh is shared.
    pub shared_from: Option<(u32, u32)>,
}

impl SceneInstances {
    /// Checks the instances against the scene's `mesh`: meshes that exist, ranges inside the
    /// mesh, sorted and apart (a shared mesh's copies all at its one range, past
    /// `shared_from`, the rest before it), transforms finite and invertible.
    pub fn validate(&self, mesh: &Mesh) -> Result<(), String> {
        let (world_end, vertex_end) = self.shared_from.unwrap_or((u32::MAX, u32::MAX));
        if self.shared_from.is_some()
            && (world_end as usize > mesh.triangle_count() || vertex_end as usize > mesh.positions.len())
        {
            return Err(format!(
                "the shared meshes start at triangle {world_end}, vertex {vertex_end}: past the mesh"
            ));
        }
        let mut end = 0usize;
        let mut shared_at: Vec<Option<u32>> = vec![None; self.meshes.len()];
        for (k, inst) in self.instances.iter().enumerate() {
            let mesh_k = self
                .meshes
                .get(inst.mesh as usize)
                .ok_or_else(|| format!("instance {k} uses mesh {} of {}", inst.mesh, self.meshes.len()))?;
            let first = inst.first as usize;
            let count = mesh_k.triangle_count();
            let overlap = || format!("instance {k}'s triangles {first}.. overlap or pass the scene's");
            if mesh_k.shared {
                let at = shared_at[inst.mesh as usize].get_or_insert(inst.first);
                let local = first >= world_end as usize && first + count <= mesh.triangle_count();
                if *at != inst.first || !local || (first < end && first != end - count) {
                    return Err(overlap());
                }
                if inst.motion.is_some() {
                    return Err(format!("instance {k} moves but its mesh is shared"));
                }
            } else if first < end || first + count > mesh.triangle_count().min(world_end as usize) {
                return Err(overlap());
            }
            end = first + count;
            if !invertible(&inst.world) {
                return Err(format!("instance {k}'s transform is not finite and invertible"));
            }
        }
        Ok(())
    }

    /// Bytes the meshes and instances take.
    pub fn bytes(&self) -> usize {
        let meshes: usize = self
            .meshes
            .iter()
            .map(|m| std::mem::size_of_val(&m.positions[..]) + std::mem::size_of_val(&m.triangles[..]))
            .sum();
        let motion: usize =
            self.instances.iter().filter_map(|i| i.motion.as_ref()).map(RigidMotion::bytes).sum();
        meshes + std::mem::size_of_val(&self.instances[..]) + motion
    }

    /// The number of instances that move within the shutter.
    pub fn moving_count(&self) -> usize {
        self.instances.iter().filter(|i| i.motion.is_some()).count()
    }
}

/// Collects instances, each unique mesh once (a node's primitives, wound as its transform
/// has them).
pub(in crate::scene) struct Builder<'a> {
    rig: &'a Rig,
    /// Per mesh: its node's primitive range and whether it was re-wound.
    keys: Vec<(usize, usize, bool)>,
    out: SceneInstances,
}

impl<'a> Builder<'a> {
    /// No instances yet.
    pub(in crate::scene) fn new(rig: &'a Rig) -> Self {
        Self { rig, keys: Vec::new(), out: SceneInstances::default() }
    }

    /// Adds the node `p` placed as an instance at `world` (moving as `motion`); false (nothing
    /// added) when its transform is not invertible or its primitives do not give its triangles.
    pub(in crate::scene) fn add(&mut self, p: &Placed, world: Affine3A, motion: Option<RigidMotion>) -> bool {
        let Some(node) = self.rig.nodes.get(p.node) else { return false };
        let Some(prims) = self.rig.primitives.get(node.primitives.clone()) else { return false };
        if !p.rigid || p.count == 0 || !invertible(&world) {
            return false;
        }
        let key = (node.primitives.start, node.primitives.end, p.mirrored);
        let mesh = match self.keys.iter().position(|k| *k == key) {
            Some(m) => m,
            None => {
                let mut mesh = InstanceMesh::default();
                for prim in prims {
                    let base = mesh.positions.len() as u32;
                    mesh.positions.extend_from_slice(&prim.positions);
                    // Re-wound as `Rig::flatten` re-winds a mirrored node's triangles.
                    mesh.triangles.extend(prim.indices.chunks_exact(3).map(|t| {
                        let [a, b, c] = [t[0], t[1], t[2]].map(|v| base + v);
                        if p.mirrored { [a, c, b] } else { [a, b, c] }
                    }));
                }
                if mesh.triangle_count() != p.count as usize {
                    return false;
                }
                self.keys.push(key);
                self.out.meshes.push(mesh);
                self.out.meshes.len() - 1
            }
        };
        self.out.instances.push(Instance { mesh: mesh as u32, first: p.first, world, motion });
        true
    }

    /// The instances, `None` when there are none.
    pub(in crate::scene) fn finish(self) -> Option<SceneInstances> {
        let mut out = self.out;
        out.instances.sort_by_key(|i| i.first);
        (!out.instances.is_empty()).then_some(out)
    }

    /// The instances with every mesh that `emits` no light shared: `mesh` (flattened with
    /// every copy in world space) loses its copies' triangles and vertices and gains each
    /// shared mesh once, in its own space, at its end; its copies' `first` name that range.
    pub(in crate::scene) fn finish_shared(
        self,
        mesh: Mesh,
        emits: impl Fn(u32) -> bool,
    ) -> (Mesh, Option<SceneInstances>) {
        let (rig, keys) = (self.rig, self.keys.clone());
        let Some(mut out) = self.finish() else { return (mesh, None) };
        let counts: Vec<usize> = out.meshes.iter().map(InstanceMesh::triangle_count).collect();
        let count = |m: u32| counts[m as usize];
        // An emitting mesh's copies each stay lights of their own: none of them is shared.
        let mut shared = vec![true; out.meshes.len()];
        for i in &out.instances {
            let range = i.first as usize..i.first as usize + count(i.mesh);
            shared[i.mesh as usize] &= !mesh.material_ids[range].iter().any(|&m| emits(m));
        }
        out.meshes.iter_mut().zip(shared).for_each(|(m, s)| m.shared = s);
        if !out.meshes.iter().any(|m| m.shared) {
            return (mesh, Some(out));
        }
        let mut dropped = vec![false; mesh.triangle_count()];
        for i in out.instances.iter().filter(|i| out.meshes[i.mesh as usize].shared) {
            dropped[i.first as usize..i.first as usize + count(i.mesh)].fill(true);
        }
        // What is left keeps its order; `new_index[t]`: where world triangle t went.
        let mut new_index = Vec::with_capacity(mesh.triangle_count());
        let mut kept = 0u32;
        for &d in &dropped {
            new_index.push(kept);
            kept += u32::from(!d);
        }
        let mut world = mesh.without(&dropped);
        let shared_from = (world.triangle_count() as u32, world.positions.len() as u32);
        let mut local_first = vec![u32::MAX; out.meshes.len()];
        for (m, key) in keys.iter().enumerate().filter(|(m, _)| out.meshes[*m].shared) {
            local_first[m] = world.triangle_count() as u32;
            let pushed = rig.push_local(key.0..key.1, key.2, &mut world);
            debug_assert!(
                pushed.is_ok() && world.triangle_count() as u32 - local_first[m] == count(m as u32) as u32
            );
        }
        for i in &mut out.instances {
            i.first = match out.meshes[i.mesh as usize].shared {
                true => local_first[i.mesh as usize],
                false => new_index[i.first as usize],
            };
        }
        out.instances.sort_by_key(|i| i.first);
        out.shared_from = Some(shared_from);
        (world, Some(out))
    }
}

/// How a copy's placement moves its mesh's vertex attributes into world space, as flattening
/// moves a node's: positions by the transform, normals by its cofactor matrix (the inverse
/// transpose up to a positive scale, finite for singular transforms), tangents by its linear
/// part, the bitangent sign flipped where it mirrors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// The linear part of the transform.
    pub linear: Mat3,
    /// Its cofactor matrix, signed by its determinant so that mirrored normals still point
    /// out of the re-wound front face.
    pub cofactor: Mat3,
    /// The transform mirrors (its triangles were re-wound).
    pub mirrored: bool,
}

impl Placement {
    /// The placement by `world`.
    pub fn new(world: &Affine3A) -> Self {
        let linear = Mat3::from(world.matrix3);
        Self { linear, cofactor: super::normal_matrix(linear), mirrored: linear.determinant() < 0.0 }
    }

    /// A vertex normal in world space (unit, or zero for none).
    #[inline(always)]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        (self.cofactor * n).normalize_or_zero()
    }

    /// A vertex tangent in world space (unit xyz and the bitangent sign, or zero for none).
    #[inline(always)]
    pub fn tangent(&self, t: Vec4) -> Vec4 {
        let handedness = if self.mirrored { -1.0 } else { 1.0 };
        let xyz = (self.linear * t.truncate()).normalize_or_zero();
        let w = if t.w < 0.0 { -handedness } else { handedness };
        if xyz == Vec3::ZERO { Vec4::ZERO } else { xyz.extend(w) }
    }
}

/// `mesh` with every copy of its shared meshes in world space again (each after the world
/// triangles, in instance order), and no shared mesh: what flattening the copies gives, bit
/// for bit but for the triangles' order.
pub(in crate::scene) fn unshare(mesh: &Mesh, instances: &SceneInstances) -> (Mesh, SceneInstances) {
    let Some((world_end, vertex_end)) = instances.shared_from else {
        return (mesh.clone(), instances.clone());
    };
    let mut out = mesh.clone();
    out.triangles.truncate(world_end as usize);
    out.material_ids.truncate(world_end as usize);
    let v = vertex_end as usize;
    out.positions.truncate(v);
    out.normals.truncate(v);
    out.uvs.truncate(v);
    out.uvs1.truncate(v);
    out.tangents.truncate(v);
    out.colors.truncate(v);
    let mut result =
        SceneInstances { meshes: instances.meshes.clone(), instances: Vec::new(), shared_from: None };
    result.meshes.iter_mut().for_each(|m| m.shared = false);
    for inst in &instances.instances {
        let local = &instances.meshes[inst.mesh as usize];
        let first = out.triangle_count() as u32;
        if local.shared {
            push_placed(
                &mut out,
                mesh,
                inst.first as usize..inst.first as usize + local.triangle_count(),
                &inst.world,
            );
            result.instances.push(Instance { first, ..inst.clone() });
        } else {
            result.instances.push(inst.clone());
        }
    }
    result.instances.sort_by_key(|i| i.first);
    (out, result)
}

/// Appends `src`'s triangles `range` (and the vertices they use, a contiguous run) to `out`,
/// moved by `world` as flattening moves a node's.
fn push_placed(out: &mut Mesh, src: &Mesh, range: std::ops::Range<usize>, world: &Affine3A) {
    let place = Placement::new(world);
    let used = src.triangles[range.clone()].iter().flatten().copied();
    let (lo, hi) = used.fold((u32::MAX, 0), |(lo, hi), v| (lo.min(v), hi.max(v + 1)));
    let (lo, hi) = (lo.min(hi) as usize, hi as usize);
    let base = out.positions.len();
    extend(&mut out.normals, &src.normals, (base, lo, hi), Vec3::ZERO, |n| place.normal(n));
    extend(&mut out.tangents, &src.tangents, (base, lo, hi), Vec4::ZERO, |t| place.tangent(t));
    extend(&mut out.uvs, &src.uvs, (base, lo, hi), glam::Vec2::ZERO, |x| x);
    extend(&mut out.uvs1, &src.uvs1, (base, lo, hi), glam::Vec2::ZERO, |x| x);
    extend(&mut out.colors, &src.colors, (base, lo, hi), Vec4::ONE, |x| x);
    out.positions.extend(src.positions[lo..hi].iter().map(|&p| world.transform_point3(p)));
    let shift = |v: u32| (v as usize - lo + base) as u32;
    out.triangles.extend(src.triangles[range.clone()].iter().map(|t| t.map(shift)));
    out.material_ids.extend_from_slice(&src.material_ids[range]);
}

/// An attribute `all` has (not empty): `dst` padded with `fill` to `base` vertices, then
/// `all`'s vertices `lo..hi` mapped by `f`.
fn extend<T: Copy>(
    dst: &mut Vec<T>,
    all: &[T],
    (base, lo, hi): (usize, usize, usize),
    fill: T,
    f: impl Fn(T) -> T,
) {
    if !all.is_empty() {
        dst.resize(base, fill);
        dst.extend(all[lo..hi].iter().map(|&x| f(x)));
    }
}

/// The copies `EXT_mesh_gpu_instancing` placed among `placed` (one flattening of `rig`), to
/// finish with or without sharing their meshes.
pub(in crate::scene) fn gpu_instances<'a>(rig: &'a Rig, placed: &[Placed]) -> Builder<'a> {
    let mut builder = Builder::new(rig);
    for p in placed.iter().filter(|p| rig.nodes.get(p.node).is_some_and(|n| n.gpu_instance)) {
        builder.add(p, p.world, None);
    }
    builder
}

/// True when `m` is finite and has a finite inverse that is not singular.
pub(crate) fn invertible(m: &Affine3A) -> bool {
    let det = m.matrix3.determinant();
    m.is_finite() && det.is_normal() && m.inverse().is_finite()
}

/// A rigid motion (translation, rotation, scale; no shear) sampled at evenly spaced steps over a
/// shutter, interpolated per ray time: translation and scale linearly, the rotation by a slerp
/// along the shorter arc between consecutive steps (Cycles' decomposed motion transforms).
#[derive(Clone, Debug, PartialEq)]
pub struct RigidMotion {
    /// Ray time (frames) of the first step.
    open: f32,
    /// Ray time (frames) of the last step.
    close: f32,
    /// Steps per unit of ray time after the first.
    rate: f32,
    translations: Vec<Vec3>,
    scales: Vec<Vec3>,
    /// Per step, the rotation; consecutive ones on the same hemisphere (dot ≥ 0).
    rotations: Vec<Quat>,
    /// Per pair of steps, the slerp's unit vector ⟂ to the first rotation and its angle.
    arcs: Vec<(Vec4, f32)>,
}

impl RigidMotion {
    /// The motion through `steps` (≥ 2 transforms, the first at `open`, the last at `close`),
    /// or `None` when one does not split into translation, rotation and scale (a shear, a
    /// singular or mirroring-changing transform): such a node's triangles move as a deforming
    /// mesh's do.
    pub fn from_steps(open: f32, close: f32, steps: &[Affine3A]) -> Option<Self> {
        if steps.len() < 2 || !(open < close) {
            return None;
        }
        let (mut translations, mut rotations, mut scales) = (Vec::new(), Vec::<Quat>::new(), Vec::new());
        for m in steps {
            let (s, r, t) = m.to_scale_rotation_translation();
            if !(s.is_finite() && r.is_finite() && t.is_finite() && invertible(m)) {
                return None;
            }
            // The decomposition must give the matrix back: no shear (a non-uniformly scaled
            // parent of a rotated child) hidden in it.
            let back = Affine3A::from_scale_rotation_translation(s, r, t);
            let size = m.matrix3.x_axis.abs().max(m.matrix3.y_axis.abs()).max(m.matrix3.z_axis.abs());
            let err = (back.matrix3.x_axis - m.matrix3.x_axis)
                .abs()
                .max((back.matrix3.y_axis - m.matrix3.y_axis).abs())
                .max((back.matrix3.z_axis - m.matrix3.z_axis).abs());
            if err.max_element() > 1e-5 * size.max_element() {
                return None;
            }
            // A scale that changes sign between steps would pass through zero.
            if scales.last().is_some_and(|&p: &Vec3| (p * s).min_element() <= 0.0) {
                return None;
            }
            let r = r.normalize();
            let r = match rotations.last() {
                Some(&p) if p.dot(r) < 0.0 => -r,
                _ => r,
            };
            translations.push(t);
            rotations.push(r);
            scales.push(s);
        }
        let arcs = rotations.windows(2).map(|w| arc(w[0], w[1])).collect();
        let rate = (steps.len() - 1) as f32 / (close - open);
        Some(Self { open, close, rate, translations, scales, rotations, arcs })
    }

    /// How many steps.
    pub fn steps(&self) -> usize {
        self.rotations.len()
    }

    /// The step before `time` and the fraction to the next; times outside the shutter hold
    /// its ends (a NaN time holds the first step).
    #[inline]
    fn step_at(&self, time: f32) -> (usize, f32) {
        let last = (self.steps() - 1) as f32;
        let x = ((time - self.open) * self.rate).clamp(0.0, last);
        let x = if x.is_nan() { 0.0 } else { x };
        let k = (x as usize).min(self.steps() - 2);
        (k, x - k as f32)
    }

    /// The transform at ray time `time`.
    #[inline]
    pub fn at(&self, time: f32) -> Affine3A {
        let (k, f) = self.step_at(time);
        let t = self.translations[k].lerp(self.translations[k + 1], f);
        let s = self.scales[k].lerp(self.scales[k + 1], f);
        let (u, theta) = self.arcs[k];
        let r = rotate(self.rotations[k], u, theta, f);
        Affine3A::from_scale_rotation_translation(s, r, t)
    }

    /// The angle (radians, between the quaternions: half the turn) from step `k` to step
    /// `k + 1`, for bounding the motion.
    pub(crate) fn arc_angle(&self, k: usize) -> f32 {
        self.arcs[k].1
    }

    /// The ray time of step `k`.
    pub(crate) fn step_time(&self, k: usize) -> f32 {
        if k + 1 == self.steps() { self.close } else { self.open + k as f32 / self.rate }
    }

    /// The largest scale factor at any step (and so at any time).
    pub(crate) fn largest_scale(&self) -> f32 {
        self.scales.iter().map(|s| s.abs().max_element()).fold(0.0, f32::max)
    }

    /// Bytes it takes.
    pub(crate) fn bytes(&self) -> usize {
        std::mem::size_of::<Self>() + self.steps() * (2 * 12 + 16 + 20)
    }
}

/// The slerp's unit vector u ⟂ `a` in the plane of `a` and `b` (a, b unit quaternions with
/// a · b ≥ 0), and the angle θ between them, so that slerp(a, b, f) = a·cos(fθ) + u·sin(fθ).
/// θ = 2·atan2(|a − b|, |a + b|) keeps its precision near 0 and π where acos(a · b) does not;
/// arithmetic in f64. Equal inputs (or ones too close to tell a plane) give u = 0: the
/// rotation holds still.
fn arc(a: Quat, b: Quat) -> (Vec4, f32) {
    let (a, b): (DVec4, DVec4) = (Vec4::from(a).as_dvec4(), Vec4::from(b).as_dvec4());
    let theta = 2.0 * (a - b).length().atan2((a + b).length());
    let perp = b - a * a.dot(b);
    let len = perp.length();
    let u = if len > 0.0 && len.is_finite() { (perp / len).as_vec4() } else { Vec4::ZERO };
    (u, theta as f32)
}

/// a·cos(fθ) + u·sin(fθ), renormalised.
#[inline]
fn rotate(a: Quat, u: Vec4, theta: f32, f: f32) -> Quat {
    let (s, c) = (f * theta).sin_cos();
    Quat::from_vec4(Vec4::from(a) * c + u * s).normalize()
}

/// Spherical linear interpolation of unit quaternions `a` to `b` (along the shorter arc) at
/// `f` in [0, 1]: the robust form this module interpolates rotations with.
pub fn slerp(a: Quat, b: Quat, f: f32) -> Quat {
    let b = if a.dot(b) < 0.0 { -b } else { b };
    let (u, theta) = arc(a, b);
    rotate(a, u, theta, f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    /// NOTES.md's cases: unit length ± 1e-6, angle f·θ ± 1e-5, never NaN, at θ from 0 to π
    /// (a turn of up to 2π, which the quaternions' shorter arc takes as its complement).
    #[test]
    fn slerp_is_accurate_at_every_angle() {
        let a = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        for turn in [0.0f32, 1e-7, 1e-3, PI / 2.0, PI - 1e-3, PI - 1e-6, PI] {
            let b = a * Quat::from_rotation_y(turn);
            for f in [0.0f32, 0.25, 0.5, 0.9, 1.0] {
                let q = slerp(a, b, f);
                assert!(q.is_finite(), "turn {turn} f {f}");
                assert!((q.length() - 1.0).abs() < 1e-6, "turn {turn} f {f}: |q| = {}", q.length());
                let rel = a.inverse() * q;
                let angle = 2.0 * rel.xyz().length().atan2(rel.w.abs());
                assert!((angle - f * turn).abs() < 1e-5, "turn {turn} f {f}: {angle} for {}", f * turn);
            }
        }
        // Exactly opposite quaternions are the same rotation: no turn, no NaN.
        let q = slerp(a, -a, 0.5);
        assert!((q.dot(a).abs() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_rigid_motion_passes_its_steps_and_turns_along_the_arc() {
        let m = |turn: f32, x: f32| {
            Affine3A::from_scale_rotation_translation(
                Vec3::splat(2.0),
                Quat::from_rotation_z(turn),
                Vec3::X * x,
            )
        };
        let motion = RigidMotion::from_steps(1.0, 2.0, &[m(0.0, 0.0), m(PI / 2.0, 1.0), m(PI, 2.0)]).unwrap();
        for (time, turn, x) in [(1.0, 0.0, 0.0), (1.25, PI / 4.0, 0.5), (1.5, PI / 2.0, 1.0), (2.0, PI, 2.0)]
        {
            let got = motion.at(time);
            let want = m(turn, x);
            assert!(got.abs_diff_eq(want, 1e-5), "{time}: {got:?} against {want:?}");
            // On the arc, the transformed point keeps its distance from the centre.
            let p = got.transform_point3(Vec3::X) - Vec3::X * x;
            assert!((p.length() - 2.0).abs() < 1e-5);
        }
        assert_eq!(motion.at(5.0), motion.at(2.0), "held after the shutter");
        assert_eq!(motion.at(f32::NAN), motion.at(1.0));
        let shear = Affine3A::from_cols_array(&[1.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        assert!(
            RigidMotion::from_steps(0.0, 1.0, &[m(0.0, 0.0), shear]).is_none(),
            "a shear is no rigid motion"
        );
        let mirrored = Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        assert!(RigidMotion::from_steps(0.0, 1.0, &[Affine3A::IDENTITY, mirrored]).is_none());
    }
}
