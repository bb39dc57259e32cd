//! Step 5 of the remapper (docs/design.md §5.5): rays. A camera pixel of camera c gets exactly
//! R_c(p), bit for bit. A background pixel P gets the origin Σ_c α_c·A_c(e_c(P)) and the direction
//! by *burp* (Glassner's "bilinear uniform repeated" interpolation): order the cameras with α > 0
//! by ascending id, p_0 … p_{n−1} their directions D_c(e_c(P)); r_{n−1} = p_{n−1};
//! r_k = slerp(r_{k+1}, p_k, α_k / β_k) with β_k = Σ_{j≥k} α_j; the direction is r_0.
//! Each step is the accurate [`crate::slerp::slerp`], so nearly opposite eye rays stay exact
//! and no step yields NaN; α_k / β_k ≤ 1 because β_k ≥ α_k.

use super::nearest::NearestEdges;
use crate::ray_file::StoredRay;
use crate::slerp::slerp;
use glam::Vec3;
use rayon::prelude::*;

/// Burp of unit `directions` with `weights` (same order, ascending camera id); entries with a
/// weight ≤ 0 take no part. `None` when no weight is positive.
pub fn burp(directions: &[Vec3], weights: &[f32]) -> Option<Vec3> {
    let mut r: Option<Vec3> = None;
    let mut beta = 0.0f32;
    for (&p, &a) in directions.iter().zip(weights).rev() {
        if a.is_nan() || a <= 0.0 {
            continue;
        }
        beta += a;
        r = Some(match r {
            None => p,
            Some(r) => slerp(r, p, (a / beta).min(1.0)),
        });
    }
    r
}

/// The remapped rays of every pixel, and (when `dominant` is asked for) the camera index with
/// the largest weight per pixel (ties to the smallest id). Rows run in parallel; each pixel's
/// result depends only on its own inputs.
pub(crate) fn remapped_rays(
    cam: &[u32],
    sources: &[StoredRay],
    nearest: &NearestEdges,
    planes: &[Vec<f32>],
    width: usize,
    dominant: bool,
) -> (Vec<StoredRay>, Option<Vec<u32>>) {
    let mut rays = vec![StoredRay::default(); cam.len()];
    rays.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let p = y * width + x;
            if cam[p] != 0 {
                *out = sources[p];
                continue;
            }
            let mut origin = Vec3::ZERO;
            let mut direction: Option<Vec3> = None;
            let mut beta = 0.0f32;
            // Burp runs from the highest id down; origins accumulate alongside.
            for k in (0..planes.len()).rev() {
                let a = planes[k][p];
                if a.is_nan() || a <= 0.0 {
                    continue;
                }
                let source = &sources[nearest.planes[k][p] as usize];
                origin += a * source.origin;
                beta += a;
                direction = Some(match direction {
                    None => source.direction,
                    Some(r) => slerp(r, source.direction, (a / beta).min(1.0)),
                });
            }
            *out = match direction {
                Some(d) => StoredRay::new(origin / beta, d),
                // Unreachable after renormalisation; still a valid ray rather than a panic.
                None => sources[nearest.planes[0][p] as usize],
            };
        }
    });
    (rays, dominant.then(|| self::dominant(cam, planes)))
}

/// The camera index with the largest weight at every pixel (ties to the smallest id; a camera
/// pixel's own camera).
pub(crate) fn dominant(cam: &[u32], planes: &[Vec<f32>]) -> Vec<u32> {
    (0..cam.len())
        .into_par_iter()
        .map(|p| {
            if cam[p] != 0 {
                return cam[p] - 1;
            }
            let mut best = 0;
            for k in 1..planes.len() {
                if planes[k][p] > planes[best][p] {
                    best = k;
                }
            }
            best as u32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slerp::angle_between;
    use crate::test_util::Rng;

    #[test]
    fn two_cameras_is_slerp() {
        let mut rng = Rng::new(6);
        for _ in 0..500 {
            let (a, b) = (rng.direction(), rng.direction());
            let w = rng.unit();
            let got = burp(&[a, b], &[w, 1.0 - w]).unwrap();
            // r_1 = b, r_0 = slerp(b, a, α_0 / (α_0 + α_1)).
            let want = slerp(b, a, w / (w + (1.0 - w)));
            assert!((got - want).length() < 1e-6);
        }
        assert_eq!(burp(&[Vec3::X, Vec3::Y], &[0.0, 1.0]), Some(Vec3::Y));
        assert_eq!(burp(&[Vec3::X, Vec3::Y], &[1.0, 0.0]), Some(Vec3::X));
        assert_eq!(burp(&[Vec3::X], &[0.0]), None);
    }

    #[test]
    fn always_unit_even_for_nearly_opposite_directions() {
        let mut rng = Rng::new(7);
        for n in 1..40 {
            let base = rng.direction();
            let dirs: Vec<Vec3> = (0..n)
                .map(|k| {
                    // Alternate nearly-opposite and random directions.
                    let jitter = rng.direction() * 1e-6;
                    if k % 3 == 0 {
                        (-base + jitter).normalize()
                    } else if k % 3 == 1 {
                        base
                    } else {
                        rng.direction()
                    }
                })
                .collect();
            let weights: Vec<f32> = (0..n).map(|_| rng.unit()).collect();
            let sum: f32 = weights.iter().sum();
            let weights: Vec<f32> = weights.iter().map(|w| w / sum).collect();
            let d = burp(&dirs, &weights).unwrap();
            assert!(d.is_finite() && (d.length() - 1.0).abs() < 1e-6, "{n}: {d}");
        }
        // Exactly opposite pair with equal weights: a quarter turn on the documented circle.
        let d = burp(&[Vec3::Z, -Vec3::Z], &[0.5, 0.5]).unwrap();
        assert!((angle_between(d, Vec3::Z) - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
    }

    #[test]
    fn equal_directions_stay_put_and_weights_pull() {
        let d = burp(&[Vec3::X; 5], &[0.2; 5]).unwrap();
        assert_eq!(d, Vec3::X);
        // A dominant weight pulls the result close to its direction: the last step covers 98 % of
        // the quarter turn from the (Y, Z) midpoint to X.
        let d = burp(&[Vec3::X, Vec3::Y, Vec3::Z], &[0.98, 0.01, 0.01]).unwrap();
        assert!((angle_between(d, Vec3::X) - 0.02 * std::f32::consts::FRAC_PI_2).abs() < 1e-5);
        assert!((d.y - d.z).abs() < 1e-6);
    }
}
