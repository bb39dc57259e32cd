//! The vertex attributes a scene has, three per triangle (mesh order), and their values
//! interpolated at a hit.

use crate::scene::Mesh;
use glam::{Vec2, Vec3, Vec4};

/// Per-triangle vertex attributes, gathered only for the attributes the scene has.
#[derive(Default)]
pub(super) struct Attributes {
    pub(super) normals: Option<Vec<[Vec3; 3]>>,
    pub(super) uvs: Option<Vec<[Vec2; 3]>>,
    uvs1: Option<Vec<[Vec2; 3]>>,
    pub(super) tangents: Option<Vec<[Vec4; 3]>>,
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

    /// Bytes the gathered attributes take.
    pub(super) fn bytes(&self) -> usize {
        fn of<T>(v: &Option<Vec<T>>) -> usize {
            v.as_ref().map_or(0, |v| std::mem::size_of_val(&v[..]))
        }
        let motion =
            self.motion_normals.iter().flatten().map(|s| std::mem::size_of_val(&s[..])).sum::<usize>();
        of(&self.normals) + of(&self.uvs) + of(&self.uvs1) + of(&self.tangents) + of(&self.colors) + motion
    }

    /// Texture coordinates (sets 0 and 1) on `triangle` at barycentrics `b`.
    #[inline]
    pub(super) fn uvs(&self, triangle: u32, b: [f32; 3]) -> [Vec2; 2] {
        let t = triangle as usize;
        let uv0 = self.uvs.as_ref().map_or(Vec2::ZERO, |u| lerp3(u[t], b));
        let uv1 = self.uvs1.as_ref().map_or(uv0, |u| lerp3(u[t], b));
        [uv0, uv1]
    }

    /// The interpolated vertex colour at barycentrics `b` of `triangle`, when the mesh has
    /// colours.
    #[inline]
    pub(super) fn vertex_color(&self, triangle: u32, b: [f32; 3]) -> Option<Vec4> {
        self.colors.as_ref().map(|c| lerp3(c[triangle as usize], b))
    }
}

/// Interpolates a per-triangle attribute with barycentrics `b`.
#[inline]
pub(super) fn lerp3<T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>>(
    v: [T; 3],
    b: [f32; 3],
) -> T {
    v[0] * b[0] + v[1] * b[1] + v[2] * b[2]
}
