//! What the tracer knows at a hit: the surface geometry (a shading frame from vertex normals
//! or the triangle's own), the material evaluated there (textures, normal map), the alpha
//! test, and the two ray queries (closest hit, occlusion), alpha-tested where the scene needs.

use super::PathTracer;
use crate::bvh::{Hit, Leaving};
use crate::interaction::SurfaceInteraction;
use crate::material::{AlphaMode, Material};
use crate::ray::Ray;
use crate::sampling::Frame;
use crate::scene::Mesh;
use crate::shading::{self, ShadingPoint, TangentFrame};
use glam::{Vec2, Vec3, Vec4};

/// Per-triangle vertex attributes, gathered only for the attributes the scene has.
#[derive(Default)]
pub(super) struct Attributes {
    pub(super) normals: Option<Vec<[Vec3; 3]>>,
    uvs: Option<Vec<[Vec2; 3]>>,
    uvs1: Option<Vec<[Vec2; 3]>>,
    tangents: Option<Vec<[Vec4; 3]>>,
    /// Vertex colours (glTF `COLOR_0`), multiplying base colour and alpha.
    pub(super) colors: Option<Vec<[Vec4; 3]>>,
    /// Vertex normals at each motion step (`[step][triangle]`), when something moves and the
    /// mesh has normals: a moving triangle's are interpolated to the ray's time.
    pub(super) motion_normals: Option<Vec<Vec<[Vec3; 3]>>>,
}

impl Attributes {
    /// The attributes `mesh` has, three per triangle.
    pub(super) fn gather(mesh: &Mesh) -> Self {
        fn gather<T: Copy>(tris: &[[u32; 3]], attr: &[T]) -> Option<Vec<[T; 3]>> {
            (!attr.is_empty()).then(|| tris.iter().map(|t| t.map(|i| attr[i as usize])).collect())
        }
        Self {
            normals: gather(&mesh.triangles, &mesh.normals),
            uvs: gather(&mesh.triangles, &mesh.uvs),
            uvs1: gather(&mesh.triangles, &mesh.uvs1),
            tangents: gather(&mesh.triangles, &mesh.tangents),
            colors: gather(&mesh.triangles, &mesh.colors),
            motion_normals: None,
        }
    }

    /// Adds the vertex normals of every motion step (the mesh's own triangles, `normals` one
    /// list per step).
    pub(super) fn gather_motion(&mut self, mesh: &Mesh, normals: &[Vec<Vec3>]) {
        if self.normals.is_some() && !normals.is_empty() {
            self.motion_normals = Some(
                normals
                    .iter()
                    .map(|n| mesh.triangles.iter().map(|t| t.map(|i| n[i as usize])).collect())
                    .collect(),
            );
        }
    }
}

/// Interpolates a per-triangle attribute with barycentrics `b`.
#[inline]
fn lerp3<T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>>(v: [T; 3], b: [f32; 3]) -> T {
    v[0] * b[0] + v[1] * b[1] + v[2] * b[2]
}

/// Tangent data for materials without a normal map (never read).
const NO_FRAME: TangentFrame = TangentFrame { tangent: None, dpdu: Vec3::X, dpdv: Vec3::Y };

impl PathTracer {
    /// Texture coordinates (sets 0 and 1) on `triangle` at barycentrics `b`.
    #[inline]
    pub(super) fn uvs(&self, triangle: u32, b: [f32; 3]) -> [Vec2; 2] {
        let t = triangle as usize;
        let uv0 = self.attributes.uvs.as_ref().map_or(Vec2::ZERO, |u| lerp3(u[t], b));
        let uv1 = self.attributes.uvs1.as_ref().map_or(uv0, |u| lerp3(u[t], b));
        [uv0, uv1]
    }

    /// The surface geometry at `hit`; with `FLAT` (a mesh without vertex normals), the
    /// triangle's own frame without looking for vertex normals.
    #[inline(always)]
    pub(super) fn surface<const FLAT: bool>(&self, hit: &Hit) -> SurfaceInteraction {
        if self.bvh.is_moving(hit.slot) {
            return self.moving_surface::<FLAT>(hit);
        }
        let tri = &self.bvh.triangle_at(hit.slot, hit.time);
        let (p, p_error) = crate::triangle::hit_point(tri, hit.barycentrics);
        let t = hit.triangle as usize;
        let geometric = self.geometric_frames[t];
        let n_geom = geometric.z;
        // A smooth hit's frame is built here even when no BSDF will need it (the path's last
        // hit, a normal-mapped material): building it only at the BSDF was slower on the café
        // (docs/performance.md, ledger: "shading frame only where a BSDF needs it").
        let shading = match &self.attributes.normals {
            _ if FLAT => geometric,
            Some(normals) => {
                let [n0, n1, n2] = normals[t];
                // A zero vertex normal marks a part without normals: shade it flat.
                if n0 == Vec3::ZERO || n1 == Vec3::ZERO || n2 == Vec3::ZERO {
                    geometric
                } else {
                    Frame::from_z(lerp3(normals[t], hit.barycentrics).normalize_or(n_geom))
                }
            }
            None => geometric,
        };
        SurfaceInteraction {
            p,
            p_error,
            n_geom,
            shading,
            triangle: hit.triangle,
            material: self.material_ids[t],
        }
    }

    /// [`PathTracer::surface`] of a triangle that moves within the shutter: its corners, frame
    /// and vertex normals at the ray's time.
    #[cold]
    fn moving_surface<const FLAT: bool>(&self, hit: &Hit) -> SurfaceInteraction {
        let tri = self.bvh.triangle_at(hit.slot, hit.time);
        let (p, p_error) = crate::triangle::hit_point(&tri, hit.barycentrics);
        let t = hit.triangle as usize;
        let [v0, v1, v2] = tri.map(Vec3::from_array);
        let geometric = Frame::from_z((v1 - v0).cross(v2 - v0).normalize_or(Vec3::Z));
        let n_geom = geometric.z;
        let shading = match (&self.attributes.normals, &self.attributes.motion_normals) {
            _ if FLAT => geometric,
            // A rigidly moving copy's normals turn with it: those at the shutter's opening,
            // by the (inverse transpose of the) motion from there.
            (Some(normals), Some(steps))
                if !normals[t].contains(&Vec3::ZERO)
                    && let Some(m) = self.bvh.rigid_motion(hit.slot, hit.time) =>
            {
                let cofactor = crate::scene::normal_matrix(glam::Mat3::from(m.matrix3));
                let n = cofactor * lerp3(steps[0][t], hit.barycentrics);
                Frame::from_z(n.normalize_or(n_geom))
            }
            (Some(normals), Some(steps)) if !normals[t].contains(&Vec3::ZERO) => {
                let (k, f) = self.bvh.motion_step(hit.time);
                let (a, b) = (steps[k][t], steps[k + 1][t]);
                let at: [Vec3; 3] = std::array::from_fn(|i| a[i] * (1.0 - f) + b[i] * f);
                Frame::from_z(lerp3(at, hit.barycentrics).normalize_or(n_geom))
            }
            _ => geometric,
        };
        SurfaceInteraction {
            p,
            p_error,
            n_geom,
            shading,
            triangle: hit.triangle,
            material: self.material_ids[t],
        }
    }

    /// The material evaluated at `si` (textures, normal map, vertex colour). `UNTEXTURED`: the
    /// scene has none of these (the Lambert-only path).
    #[inline(always)]
    pub(super) fn shade<const UNTEXTURED: bool>(
        &self,
        material: &Material,
        si: &SurfaceInteraction,
        b: [f32; 3],
    ) -> ShadingPoint {
        // An anisotropic material needs its tangent frame even without textures.
        let mut sp = if UNTEXTURED || (material.textures.is_empty() && material.anisotropy.is_none()) {
            ShadingPoint::of(material, si.shading.z)
        } else {
            let uv = self.uvs(si.triangle, b);
            let t = &material.textures;
            let frame = if t.normal.is_some() || t.coat_normal.is_some() || material.anisotropy.is_some() {
                self.tangent_frame(si.triangle, b)
            } else {
                NO_FRAME
            };
            shading::evaluate(material, &self.textures, uv, si.shading.z, &frame)
        };
        if !UNTEXTURED && let Some(c) = self.vertex_color(si.triangle, b) {
            sp.base_color *= c.truncate();
            sp.alpha = (sp.alpha * c.w).clamp(0.0, 1.0);
        }
        sp
    }

    /// The interpolated vertex colour at barycentrics `b` of `triangle`, when the mesh has
    /// colours.
    #[inline]
    fn vertex_color(&self, triangle: u32, b: [f32; 3]) -> Option<Vec4> {
        self.attributes.colors.as_ref().map(|c| lerp3(c[triangle as usize], b))
    }

    /// Tangent data for normal mapping and anisotropy: vertex tangents if the mesh has them, and the
    /// triangle's ∂p/∂u, ∂p/∂v from its texture coordinates.
    fn tangent_frame(&self, triangle: u32, b: [f32; 3]) -> TangentFrame {
        let t = triangle as usize;
        let tangent = self.attributes.tangents.as_ref().and_then(|ts| {
            let v = ts[t];
            (v.iter().all(|x| x.truncate() != Vec3::ZERO)).then(|| lerp3(v, b))
        });
        let [p0, p1, p2] = {
            let [a, b, c] = self.bvh.triangle_corners_by_id(triangle);
            [a, b, c]
        };
        let [uv0, uv1, uv2] = self.attributes.uvs.as_ref().map_or([Vec2::ZERO, Vec2::X, Vec2::Y], |u| u[t]);
        let (d1, d2) = (uv1 - uv0, uv2 - uv0);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let det = d1.x * d2.y - d1.y * d2.x;
        let (dpdu, dpdv) = if det.abs() > 1e-12 {
            let inv = 1.0 / det;
            ((d2.y * e1 - d1.y * e2) * inv, (d1.x * e2 - d2.x * e1) * inv)
        } else {
            (e1, e2)
        };
        TangentFrame { tangent, dpdu, dpdv }
    }

    /// Whether the alpha test lets a ray through (false) or stops it (true) at barycentrics
    /// `b` of `triangle`. Masked surfaces compare alpha with the cut-off; blended ones are
    /// hit with probability alpha, decided by a hash of the ray and the point (deterministic).
    /// Unlit surfaces stop camera rays alone (`camera`), as Blender's import makes them.
    #[inline]
    fn alpha_accepts(&self, tested: &[bool], triangle: u32, b: [f32; 3], ray: &Ray, camera: bool) -> bool {
        if !tested[triangle as usize] {
            return true;
        }
        let material = &self.materials[self.material_ids[triangle as usize] as usize];
        if material.unlit && !camera {
            return false;
        }
        let mut alpha = shading::alpha(material, &self.textures, self.uvs(triangle, b));
        if let Some(c) = self.vertex_color(triangle, b) {
            alpha *= c.w;
        }
        match material.alpha_mode {
            AlphaMode::Opaque => true,
            AlphaMode::Mask { cutoff } => alpha >= cutoff,
            AlphaMode::Blend => {
                let bits = [ray.origin.x, ray.origin.y, ray.origin.z, ray.direction.x, b[0], b[1]];
                let h =
                    bits.iter().fold(triangle ^ 0x68bc_21eb, |h, x| crate::sampler::hash(h ^ x.to_bits()));
                ((h >> 8) as f32 / (1u32 << 24) as f32) < alpha
            }
        }
    }

    /// The closest hit along `ray` (skipping `leaving`), alpha-tested with `ALPHA`; `camera`:
    /// the ray comes from the camera (unlit surfaces stop it).
    #[inline]
    pub(super) fn closest_hit<const ALPHA: bool>(
        &self,
        ray: &Ray,
        leaving: Leaving,
        camera: bool,
    ) -> Option<Hit> {
        match (ALPHA, &self.alpha_tested) {
            (true, Some(tested)) => self.bvh.intersect_from(ray, f32::INFINITY, leaving, |t, b| {
                self.alpha_accepts(tested, t, b, ray, camera)
            }),
            _ => self.bvh.intersect_from(ray, f32::INFINITY, leaving, |_, _| true),
        }
    }

    /// Whether anything blocks `ray` before `t_max` (skipping `leaving`), alpha-tested with `ALPHA`.
    #[inline]
    pub(super) fn occluded<const ALPHA: bool>(&self, ray: &Ray, t_max: f32, leaving: Leaving) -> bool {
        match (ALPHA, &self.alpha_tested) {
            (true, Some(tested)) => self
                .bvh
                .occluded_from(ray, t_max, leaving, |t, b| self.alpha_accepts(tested, t, b, ray, false)),
            _ => self.bvh.occluded_from(ray, t_max, leaving, |_, _| true),
        }
    }
}
