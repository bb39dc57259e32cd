//! All of a scene's triangles in one world-space triangle list, with optional per-vertex
//! normals and texture coordinates. Parts with and without normals can be mixed: a vertex normal
//! of zero means "none", and triangles with any such vertex are shaded flat.

use glam::{Vec2, Vec3, Vec4};

/// World-space triangles with per-vertex attributes and a material per triangle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, or empty when no part has any (zero = none for that vertex).
    pub normals: Vec<Vec3>,
    /// Per-vertex texture coordinates (set 0), or empty when no part has any.
    pub uvs: Vec<Vec2>,
    /// Per-vertex texture coordinates (set 1), or empty when no part has any.
    pub uvs1: Vec<Vec2>,
    /// Per-vertex tangents (xyz, w = ±1 bitangent sign, glTF `TANGENT`), or empty; zero = none.
    pub tangents: Vec<Vec4>,
    /// Per-vertex colours (linear RGBA, glTF `COLOR_0`) multiplying the base colour and alpha,
    /// or empty when no part has any; parts without are padded with white (no change).
    pub colors: Vec<Vec4>,
    /// Vertex indices, three per triangle, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
    /// Material index per triangle.
    pub material_ids: Vec<u32>,
}

/// Less common vertex attributes of a part (see [`Mesh::push_with`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct MeshExtras<'a> {
    /// Texture coordinates, set 1.
    pub uvs1: Option<&'a [Vec2]>,
    /// Tangents (xyz, w = bitangent sign), already in world space.
    pub tangents: Option<&'a [Vec4]>,
    /// Vertex colours (linear RGBA).
    pub colors: Option<&'a [Vec4]>,
}

/// One piece of geometry to add to a [`Mesh`], already in world space.
#[derive(Clone, Copy, Debug)]
pub struct MeshPart<'a> {
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Per-vertex normals, if the part has them.
    pub normals: Option<&'a [Vec3]>,
    /// Per-vertex texture coordinates, if the part has them.
    pub uvs: Option<&'a [Vec2]>,
    /// Triangle indices into `positions` (a multiple of three), or `None` for a non-indexed
    /// list where every three consecutive vertices make a triangle.
    pub indices: Option<&'a [u32]>,
    /// Material of every triangle of the part.
    pub material: u32,
}

impl Mesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Appends a part; returns a message when its indices or attribute counts are inconsistent.
    pub fn push(&mut self, part: MeshPart<'_>) -> Result<(), String> {
        self.push_with(part, MeshExtras::default())
    }

    /// Appends a part with its second texture-coordinate set and tangents.
    pub fn push_with(&mut self, part: MeshPart<'_>, extras: MeshExtras<'_>) -> Result<(), String> {
        let n = part.positions.len();
        if let Some(uvs1) = extras.uvs1
            && uvs1.len() != n
        {
            return Err(format!("{} second texture coordinates for {} vertices", uvs1.len(), n));
        }
        if let Some(tangents) = extras.tangents
            && tangents.len() != n
        {
            return Err(format!("{} tangents for {} vertices", tangents.len(), n));
        }
        if let Some(colors) = extras.colors
            && colors.len() != n
        {
            return Err(format!("{} vertex colours for {} vertices", colors.len(), n));
        }
        if let Some(normals) = part.normals
            && normals.len() != n
        {
            return Err(format!("{} normals for {} vertices", normals.len(), n));
        }
        if let Some(uvs) = part.uvs
            && uvs.len() != n
        {
            return Err(format!("{} texture coordinates for {} vertices", uvs.len(), n));
        }
        let count = part.indices.map_or(n, <[u32]>::len);
        if !count.is_multiple_of(3) {
            return Err(format!("{count} indices is not a whole number of triangles"));
        }
        if let Some(indices) = part.indices
            && let Some(&bad) = indices.iter().find(|&&i| i as usize >= n)
        {
            return Err(format!("index {bad} out of range for {n} vertices"));
        }
        let base =
            u32::try_from(self.positions.len()).map_err(|_| "scene exceeds 2^32 vertices".to_owned())?;
        if u32::try_from(self.positions.len() + n).is_err() {
            return Err("scene exceeds 2^32 vertices".to_owned());
        }

        // Attributes the mesh has but this part lacks (or the reverse) are padded with zeros.
        let had = self.positions.len();
        self.positions.extend_from_slice(part.positions);
        Self::extend_attr(&mut self.normals, had, part.normals, n);
        Self::extend_attr(&mut self.uvs, had, part.uvs, n);
        Self::extend_attr(&mut self.uvs1, had, extras.uvs1, n);
        Self::extend_attr(&mut self.tangents, had, extras.tangents, n);
        Self::extend_attr_with(&mut self.colors, had, extras.colors, n, Vec4::ONE);

        let tris = count / 3;
        self.triangles.reserve(tris);
        match part.indices {
            Some(indices) => self
                .triangles
                .extend(indices.chunks_exact(3).map(|c| [base + c[0], base + c[1], base + c[2]])),
            None => self
                .triangles
                .extend((0..tris as u32).map(|t| [base + 3 * t, base + 3 * t + 1, base + 3 * t + 2])),
        }
        self.material_ids.extend(std::iter::repeat_n(part.material, tris));
        Ok(())
    }

    fn extend_attr<T: Copy + Default>(dst: &mut Vec<T>, had: usize, src: Option<&[T]>, n: usize) {
        Self::extend_attr_with(dst, had, src, n, T::default());
    }

    /// [`Mesh::extend_attr`] padding with `fill` (what "none" means for the attribute).
    fn extend_attr_with<T: Copy>(dst: &mut Vec<T>, had: usize, src: Option<&[T]>, n: usize, fill: T) {
        match src {
            Some(values) => {
                if dst.len() < had {
                    dst.resize(had, fill);
                }
                dst.extend_from_slice(values);
            }
            None if !dst.is_empty() => dst.resize(had + n, fill),
            None => {}
        }
    }

    /// Checks indices, attribute counts, finiteness and material ids; returns what is wrong.
    pub fn validate(&self, material_count: usize) -> Result<(), String> {
        let n = self.positions.len();
        if let Some((i, p)) = self.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(format!("vertex {i} has a non-finite position {p}"));
        }
        if !self.normals.is_empty() && self.normals.len() != n {
            return Err(format!("{} normals for {n} vertices", self.normals.len()));
        }
        if let Some((i, _)) = self.normals.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!("vertex {i} has a non-finite normal"));
        }
        if !self.uvs.is_empty() && self.uvs.len() != n {
            return Err(format!("{} texture coordinates for {n} vertices", self.uvs.len()));
        }
        if let Some((i, _)) = self.uvs.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!("vertex {i} has non-finite texture coordinates"));
        }
        for (what, len) in [
            ("second texture coordinates", self.uvs1.len()),
            ("tangents", self.tangents.len()),
            ("vertex colours", self.colors.len()),
        ] {
            if len != 0 && len != n {
                return Err(format!("{len} {what} for {n} vertices"));
            }
        }
        if let Some((i, _)) = self.uvs1.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!("vertex {i} has non-finite second texture coordinates"));
        }
        if let Some((i, _)) = self.tangents.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!("vertex {i} has a non-finite tangent"));
        }
        if let Some((i, c)) =
            self.colors.iter().enumerate().find(|(_, c)| !c.is_finite() || c.min_element() < 0.0)
        {
            return Err(format!("vertex {i} has a non-finite or negative colour {c}"));
        }
        if self.material_ids.len() != self.triangles.len() {
            return Err(format!(
                "{} material ids for {} triangles",
                self.material_ids.len(),
                self.triangles.len()
            ));
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri.iter().any(|&i| i as usize >= n) {
                return Err(format!("triangle {t} indexes a vertex past the {n} there are"));
            }
        }
        if let Some((t, m)) =
            self.material_ids.iter().enumerate().find(|(_, m)| **m as usize >= material_count)
        {
            return Err(format!("triangle {t} uses material {m} of {material_count}"));
        }
        Ok(())
    }

    /// Axis-aligned bounds (min, max) of the vertices, or `None` when there are none.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(self.positions.iter().fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
    }

    /// The mesh without the triangles `dropped` flags (one flag per triangle) and the vertices
    /// only they use; what is left keeps its order.
    pub fn without(self, dropped: &[bool]) -> Mesh {
        let mut used = vec![false; self.positions.len()];
        for (t, _) in self.triangles.iter().zip(dropped).filter(|(_, d)| !**d) {
            t.iter().for_each(|&v| used[v as usize] = true);
        }
        let mut new_vertex = vec![u32::MAX; self.positions.len()];
        let mut next = 0u32;
        for (v, &u) in used.iter().enumerate() {
            if u {
                new_vertex[v] = next;
                next += 1;
            }
        }
        fn keep<T: Copy>(attr: Vec<T>, used: &[bool]) -> Vec<T> {
            attr.into_iter().zip(used).filter(|(_, u)| **u).map(|(x, _)| x).collect()
        }
        let kept = |t: usize| !dropped[t];
        Mesh {
            positions: keep(self.positions, &used),
            normals: keep(self.normals, &used),
            uvs: keep(self.uvs, &used),
            uvs1: keep(self.uvs1, &used),
            tangents: keep(self.tangents, &used),
            colors: keep(self.colors, &used),
            triangles: (0..self.triangles.len())
                .filter(|&t| kept(t))
                .map(|t| self.triangles[t].map(|v| new_vertex[v as usize]))
                .collect(),
            material_ids: (0..self.material_ids.len())
                .filter(|&t| kept(t))
                .map(|t| self.material_ids[t])
                .collect(),
        }
    }

    /// Bytes its arrays take.
    pub fn bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.positions[..])
            + size_of_val(&self.normals[..])
            + size_of_val(&self.uvs[..])
            + size_of_val(&self.uvs1[..])
            + size_of_val(&self.tangents[..])
            + size_of_val(&self.colors[..])
            + size_of_val(&self.triangles[..])
            + size_of_val(&self.material_ids[..])
    }

    /// The three corners of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mixing_parts_with_and_without_normals_pads_with_zero() {
        let mut m = Mesh::default();
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        m.push(MeshPart { positions: &p, normals: None, uvs: None, indices: None, material: 0 }).unwrap();
        let n = [Vec3::Z; 3];
        m.push(MeshPart {
            positions: &p,
            normals: Some(&n),
            uvs: None,
            indices: Some(&[0, 1, 2]),
            material: 1,
        })
        .unwrap();
        assert_eq!(m.normals, vec![Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, Vec3::Z, Vec3::Z, Vec3::Z]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(m.material_ids, vec![0, 1]);
        assert!(m.uvs.is_empty());
        m.validate(2).unwrap();
        assert!(m.validate(1).is_err());
    }

    #[test]
    fn bad_parts_are_refused() {
        let mut m = Mesh::default();
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let part = |indices| MeshPart { positions: &p, normals: None, uvs: None, indices, material: 0 };
        assert!(m.push(part(Some(&[0, 1, 3]))).unwrap_err().contains("out of range"));
        assert!(m.push(part(Some(&[0, 1]))).unwrap_err().contains("whole number"));
        let mut nan = Mesh::default();
        let q = [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y];
        nan.push(MeshPart { positions: &q, normals: None, uvs: None, indices: None, material: 0 }).unwrap();
        assert!(nan.validate(1).unwrap_err().contains("vertex 1"));
    }
}
