//! Skinning (glTF 2.0 §3.7.3): a mesh whose vertices follow joints. Each vertex is moved by the
//! weighted sum of its joints' matrices, joint world × inverse bind; the skinned node's own
//! transform is ignored, as the specification requires and Blender's armature deformation does.

use glam::{Affine3A, Mat3, Mat3A, Vec3, Vec4};

/// A skin: the joints (rig nodes) and their inverse bind matrices.
#[derive(Clone, Debug)]
pub(in crate::scene) struct Skin {
    /// How messages name it ("skin 0 ('Armature')").
    pub label: String,
    /// The rig node of each joint.
    pub joints: Vec<usize>,
    /// Each joint's inverse bind matrix (identity where the file gives none).
    pub inverse_bind: Vec<Affine3A>,
}

/// Each vertex's joints and weights: `sets` groups of four (`JOINTS_n` / `WEIGHTS_n`), the
/// weights normalised to sum 1 as the specification requires.
#[derive(Clone, Debug, PartialEq)]
pub(in crate::scene) struct Influences {
    /// Groups of four influences per vertex.
    sets: usize,
    /// Joint indices into the skin's joint list, `4 × sets` per vertex.
    joints: Vec<u16>,
    /// Weights, `4 × sets` per vertex; all zero where the file gives a vertex no weight.
    weights: Vec<f32>,
    /// The largest joint index used (checked against the skin when flattening).
    max_joint: u16,
}

impl Influences {
    /// Interleaves the sets and normalises each vertex's weights; the message names the set.
    pub(in crate::scene) fn new(
        sets: Vec<(Vec<[u16; 4]>, Vec<Vec4>)>,
        vertices: usize,
    ) -> Result<Self, String> {
        for (k, (j, w)) in sets.iter().enumerate() {
            if j.len() != vertices || w.len() != vertices {
                return Err(format!(
                    "JOINTS_{k} has {} and WEIGHTS_{k} {} entries for {vertices} vertices",
                    j.len(),
                    w.len()
                ));
            }
        }
        let n = sets.len();
        let mut joints = Vec::with_capacity(vertices * 4 * n);
        let mut weights = Vec::with_capacity(vertices * 4 * n);
        for v in 0..vertices {
            let start = weights.len();
            for (j, w) in &sets {
                joints.extend_from_slice(&j[v]);
                weights.extend_from_slice(&w[v].to_array());
            }
            let vw = &mut weights[start..];
            if let Some(bad) = vw.iter().find(|w| !w.is_finite() || **w < 0.0) {
                return Err(format!(
                    "vertex {v} has the weight {bad}; weights must be finite and not negative"
                ));
            }
            let sum: f32 = vw.iter().sum();
            if sum > 0.0 {
                vw.iter_mut().for_each(|w| *w /= sum);
            }
        }
        let max_joint =
            joints.iter().zip(&weights).filter(|(_, w)| **w > 0.0).map(|(j, _)| *j).max().unwrap_or(0);
        Ok(Self { sets: n, joints, weights, max_joint })
    }

    /// The largest joint index a vertex depends on.
    pub(in crate::scene) fn max_joint(&self) -> u16 {
        self.max_joint
    }

    /// Vertex `v`'s blended matrix over `matrices` (one per joint), or `fallback` for a vertex
    /// without weight (it stays where its node puts it, as in Blender).
    #[inline]
    pub(in crate::scene) fn matrix(&self, v: usize, matrices: &[Affine3A], fallback: &Affine3A) -> Affine3A {
        let span = v * 4 * self.sets..(v + 1) * 4 * self.sets;
        let (mut linear, mut translation, mut any) = (Mat3A::ZERO, Vec3::ZERO.into(), false);
        for (&j, &w) in self.joints[span.clone()].iter().zip(&self.weights[span]) {
            if w > 0.0 {
                let m = &matrices[j as usize];
                linear += m.matrix3 * w;
                translation += m.translation * w;
                any = true;
            }
        }
        if any { Affine3A { matrix3: linear, translation } } else { *fallback }
    }
}

/// The cofactor matrix of `m` signed by its determinant: it transforms normals as the inverse
/// transpose does, up to scale, and stays finite for singular matrices.
#[inline]
pub(crate) fn normal_matrix(m: Mat3) -> Mat3 {
    let c = Mat3::from_cols(m.y_axis.cross(m.z_axis), m.z_axis.cross(m.x_axis), m.x_axis.cross(m.y_axis));
    c * m.determinant().signum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn weights_are_normalised_and_blend_joint_matrices() {
        let sets = vec![
            (vec![[0, 1, 0, 0], [1, 0, 0, 0]], vec![Vec4::new(1.0, 3.0, 0.0, 0.0), Vec4::ZERO]),
            (vec![[0, 0, 0, 2], [0, 0, 0, 0]], vec![Vec4::new(0.0, 0.0, 0.0, 4.0), Vec4::ZERO]),
        ];
        let inf = Influences::new(sets, 2).unwrap();
        assert_eq!(inf.max_joint(), 2);
        let m = [
            Affine3A::from_translation(Vec3::X),
            Affine3A::from_translation(Vec3::Y * 2.0),
            Affine3A::from_rotation_translation(Quat::from_rotation_z(1.0), Vec3::Z),
        ];
        let fallback = Affine3A::from_translation(Vec3::splat(9.0));
        let blended = inf.matrix(0, &m, &fallback);
        let want_t = (Vec3::X * 1.0 + Vec3::Y * 2.0 * 3.0 + Vec3::Z * 4.0) / 8.0;
        assert!((Vec3::from(blended.translation) - want_t).length() < 1e-6);
        let want_l = (Mat3::IDENTITY * 4.0 + Mat3::from_quat(Quat::from_rotation_z(1.0)) * 4.0) / 8.0;
        assert!(Mat3::from(blended.matrix3).abs_diff_eq(want_l, 1e-6));
        // A vertex without weight stays where its node puts it.
        assert_eq!(inf.matrix(1, &m, &fallback), fallback);
    }

    #[test]
    fn bad_weights_and_counts_are_refused() {
        let bad = vec![(vec![[0; 4]], vec![Vec4::new(-1.0, 0.0, 0.0, 0.0)])];
        assert!(Influences::new(bad, 1).unwrap_err().contains("weight -1"));
        let short = vec![(vec![[0; 4]], vec![Vec4::X])];
        assert!(Influences::new(short, 2).unwrap_err().contains("2 vertices"));
    }

    #[test]
    fn normal_matrix_is_the_inverse_transpose_up_to_scale() {
        let m = Mat3::from_cols_array(&[2.0, 0.3, 0.0, -0.1, 1.0, 0.2, 0.0, 0.4, 0.5]);
        let want = m.inverse().transpose();
        let got = normal_matrix(m);
        let n = Vec3::new(0.3, -0.5, 0.8);
        assert!((got * n).normalize().abs_diff_eq((want * n).normalize(), 1e-6));
    }
}
