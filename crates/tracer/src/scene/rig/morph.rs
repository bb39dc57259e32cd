//! Morph targets (glTF 2.0 §3.7.2.2): a primitive's attributes displaced by the weighted sum of
//! its targets' deltas, applied before skinning as the specification orders it.

use glam::{Vec3, Vec4};

/// One morph target's displacements (each as long as the primitive's vertices, where given).
#[derive(Clone, Debug, Default, PartialEq)]
pub(in crate::scene) struct MorphTarget {
    /// `POSITION` deltas.
    pub positions: Option<Vec<Vec3>>,
    /// `NORMAL` deltas.
    pub normals: Option<Vec<Vec3>>,
    /// `TANGENT` deltas (xyz; the handedness stays the base's).
    pub tangents: Option<Vec<Vec3>>,
}

/// A primitive's attributes after its targets at `weights`: positions, normals, tangents.
#[derive(Default)]
pub(in crate::scene) struct Morphed {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub tangents: Vec<Vec4>,
    /// Scratch: the base tangents' xyz and their displaced values, reused across primitives.
    tangent_base: Vec<Vec3>,
    tangent_moved: Vec<Vec3>,
}

/// `base` plus Σ wᵢ·Δᵢ over the targets that displace it, into `out`; false (and `out`
/// untouched) when no target with a non-zero weight does, so the caller keeps `base` and its bits.
fn displace<'t>(
    base: &[Vec3],
    deltas: impl Iterator<Item = (f32, Option<&'t Vec<Vec3>>)>,
    out: &mut Vec<Vec3>,
) -> Result<bool, String> {
    let mut any = false;
    for (w, d) in deltas {
        let Some(d) = d.filter(|_| w != 0.0) else { continue };
        if d.len() != base.len() {
            return Err(format!("a morph target has {} deltas for {} vertices", d.len(), base.len()));
        }
        if !any {
            out.clear();
            out.extend_from_slice(base);
            any = true;
        }
        out.iter_mut().zip(d).for_each(|(o, d)| *o += *d * w);
    }
    Ok(any)
}

impl Morphed {
    /// Applies `targets` at `weights` (missing weights count as 0) to the base attributes;
    /// returns which of positions, normals and tangents were displaced (the rest stay the base's).
    pub(in crate::scene) fn apply(
        &mut self,
        targets: &[MorphTarget],
        weights: &[f32],
        positions: &[Vec3],
        normals: Option<&[Vec3]>,
        tangents: Option<&[Vec4]>,
    ) -> Result<[bool; 3], String> {
        let w = |i: usize| weights.get(i).copied().unwrap_or(0.0);
        let p = displace(
            positions,
            targets.iter().enumerate().map(|(i, t)| (w(i), t.positions.as_ref())),
            &mut self.positions,
        )?;
        // Displaced normals are no longer unit length; the frame transform renormalises.
        let n = match normals {
            Some(base) => displace(
                base,
                targets.iter().enumerate().map(|(i, t)| (w(i), t.normals.as_ref())),
                &mut self.normals,
            )?,
            None => false,
        };
        let t = match tangents {
            Some(base) => {
                self.tangent_base.clear();
                self.tangent_base.extend(base.iter().map(|t| t.truncate()));
                let deltas = targets.iter().enumerate().map(|(i, t)| (w(i), t.tangents.as_ref()));
                let moved = displace(&self.tangent_base, deltas, &mut self.tangent_moved)?;
                if moved {
                    self.tangents.clear();
                    self.tangents.extend(self.tangent_moved.iter().zip(base).map(|(v, b)| v.extend(b.w)));
                }
                moved
            }
            None => false,
        };
        Ok([p, n, t])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_add_their_weighted_deltas() {
        let base = [Vec3::ZERO, Vec3::X];
        let targets = [
            MorphTarget { positions: Some(vec![Vec3::Y, Vec3::Y]), ..MorphTarget::default() },
            MorphTarget {
                positions: Some(vec![Vec3::Z, Vec3::ZERO]),
                normals: Some(vec![Vec3::X; 2]),
                ..MorphTarget::default()
            },
        ];
        let mut m = Morphed::default();
        let normals = [Vec3::Z, Vec3::Z];
        let moved = m.apply(&targets, &[0.5, 2.0], &base, Some(&normals), None).unwrap();
        assert_eq!(moved, [true, true, false]);
        assert_eq!(m.positions, [Vec3::new(0.0, 0.5, 2.0), Vec3::new(1.0, 0.5, 0.0)]);
        assert_eq!(m.normals, [Vec3::new(2.0, 0.0, 1.0); 2]);
        // Zero weights displace nothing: the base keeps its bits.
        assert_eq!(m.apply(&targets, &[0.0], &base, Some(&normals), None).unwrap(), [false; 3]);
        let short = [MorphTarget { positions: Some(vec![Vec3::Y]), ..MorphTarget::default() }];
        assert!(m.apply(&short, &[1.0], &base, None, None).unwrap_err().contains("1 deltas for 2 vertices"));
    }
}
