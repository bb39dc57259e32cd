//! The seamless blend ([`super::Blend::Seamless`], docs/design/mcc.md §5.8): the column's blend
//! of every camera's ray by distance weights and burp, with the two sources of its tears
//! replaced.
//!
//! * **Rays.** Camera c contributes its smooth field F_c(P) ([`super::field`]: the membrane of its
//!   edge rays) instead of its nearest edge pixel's ray, which jumps where the nearest edge pixel
//!   does (medial axes: between two blobs, inside a ring).
//! * **Weights.** α_c(P) ∝ π_c(P) / d_c(P)², with d_c the distance to c's nearest edge pixel
//!   anywhere, and π_c c's participation: 1 in the regions where c has an edge pixel, 0 in the
//!   others, blurred three times with a box of radius R so that it fades over about 6R pixels
//!   across a region boundary instead of switching there. For two participating cameras this
//!   is the column's formula (α_1 = d_2² / (d_1² + d_2²)); unlike the column's, it stays
//!   continuous while a camera's participation fades out. Near c's own pixels 1/d_c² dominates,
//!   so α_c → 1 at c's edge and the blend meets the camera pixels without a step; no blur or
//!   ease follows (they would pull the weight of an edge's neighbour away from 1).
//!
//! Camera pixels keep their rays bit for bit. Directions are combined by burp exactly as in the
//! column's mode (ascending id, accurate slerp: opposite directions never give NaN), origins by
//! the weighted sum. Cost: one exact distance transform and one membrane solve on 2 × 2 blocks
//! per camera (two when its origins differ), one fade per set of regions, each linear in the
//! pixel count.

use super::field::FieldSolvers;
use super::grid::{Grid, Layout};
use super::nearest::{RegionBoxes, nearest_edges};
use super::smooth::{Blur, Scratch, box_blur};
use super::warning::RemapWarning;
use crate::ray_file::StoredRay;
use crate::regions::Regions;
use crate::slerp::slerp;
use glam::Vec3;
use rayon::prelude::*;

/// What the seamless blend returns: rays, the final weight planes, and its warnings.
pub(crate) struct SeamlessBlend {
    pub rays: Vec<StoredRay>,
    pub weights: Vec<Vec<f32>>,
    pub warnings: Vec<RemapWarning>,
}

/// The box radius of the participation fade on `grid`: three boxes of radius R fade over about
/// 6R pixels, `fade` of the shorter side.
pub(crate) fn fade_radius(fade: f32, grid: Grid) -> usize {
    ((fade * grid.width.min(grid.height) as f32 / 6.0).round() as usize).max(1)
}

/// The seamless blend of `layout` with the merged `sources` and the `regions`; `fade` is the
/// participation fade's width as a fraction of the shorter side.
pub(crate) fn seamless(
    layout: &Layout,
    sources: &[StoredRay],
    regions: &Regions,
    fade: f32,
) -> SeamlessBlend {
    let Layout { grid, cam, edges, cameras } = *layout;
    let region = &regions.index;
    // Which cameras have an edge pixel in which region; regions no camera touches take all.
    let mut participates = vec![vec![false; regions.count()]; cameras];
    let mut background = vec![0usize; regions.count()];
    for (p, &c) in cam.iter().enumerate() {
        if c == 0 {
            background[region[p] as usize] += 1;
        } else if edges[p] {
            participates[c as usize - 1][region[p] as usize] = true;
        }
    }
    let (lists, warnings) = super::weights::participants(&participates, regions, &background, cameras);
    for (r, list) in lists.iter().enumerate() {
        for &k in list {
            participates[k][r] = true;
        }
    }
    // Cameras that take part in the same regions share one faded plane.
    let mut patterns: Vec<&Vec<bool>> = participates.iter().collect();
    patterns.sort();
    patterns.dedup();
    let radius = fade_radius(fade, grid);
    let planes: Vec<Option<Vec<f32>>> =
        patterns.par_iter().map(|pattern| fade_plane(pattern, &background, region, grid, radius)).collect();
    let participation: Vec<Option<&[f32]>> = participates
        .iter()
        .map(|p| planes[patterns.binary_search(&p).expect("a pattern")].as_deref())
        .collect();
    let weights = weight_planes(layout, &participation);
    drop(planes);
    let rays = blend(layout, sources, &weights);
    SeamlessBlend { rays, weights, warnings }
}

/// The faded participation π of the cameras that take part in the regions `participates` marks
/// (`region`: every pixel's region; `background`: each region's background pixel count), three
/// box blurs of `radius`; `None` where that is every region with background (π = 1 throughout:
/// nothing to fade).
fn fade_plane(
    participates: &[bool],
    background: &[usize],
    region: &[u32],
    grid: Grid,
    radius: usize,
) -> Option<Vec<f32>> {
    if participates.iter().zip(background).all(|(&p, &b)| p || b == 0) {
        return None;
    }
    let mut plane: Vec<f32> = region.iter().map(|&r| participates[r as usize] as u32 as f32).collect();
    let mut other = vec![0f32; plane.len()];
    let everywhere = vec![true; plane.len()];
    let mut scratch = Scratch::default();
    for _ in 0..3 {
        box_blur(Blur { src: &plane, dst: &mut other, background: &everywhere, grid, radius }, &mut scratch);
        std::mem::swap(&mut plane, &mut other);
    }
    Some(plane)
}

/// The weight planes: 1 / 0 at camera pixels, α_k ∝ π_k / d_k² at background pixels (π_k:
/// camera k's `participation`, 1 throughout where `None`).
fn weight_planes(layout: &Layout, participation: &[Option<&[f32]>]) -> Vec<Vec<f32>> {
    let Layout { grid, cam, cameras, .. } = *layout;
    let width = grid.width;
    // Distances to each camera's nearest edge pixel anywhere: one region, no region logic.
    let whole = vec![0u32; cam.len()];
    let boxes = RegionBoxes::new(layout, &whole, 1);
    let nearest = nearest_edges(layout, &whole, &boxes);
    drop(whole);
    let mut planes = vec![vec![0f32; cam.len()]; cameras];
    let rows = grid.rows_mut(&mut planes);
    rows.into_par_iter().enumerate().for_each_init(
        || vec![0f64; cameras],
        |v, (y, mut row)| {
            #[allow(clippy::needless_range_loop)] // `row[k][x]` reaches across planes
            for x in 0..width {
                let p = y * width + x;
                if cam[p] != 0 {
                    row[cam[p] as usize - 1][x] = 1.0;
                    continue;
                }
                let mut sum = 0.0f64;
                for k in 0..cameras {
                    let pi = participation[k].map_or(1.0, |plane| plane[p] as f64);
                    let (e, w) = (nearest.planes[k][p], width as u32);
                    let (dx, dy) = ((e % w) as f64 - x as f64, (e / w) as f64 - y as f64);
                    v[k] = pi / (dx * dx + dy * dy);
                    sum += v[k];
                }
                // Some camera participates in every region, and its π is > 0 on all of it.
                let inverse = if sum > 0.0 { 1.0 / sum } else { 0.0 };
                for k in 0..cameras {
                    row[k][x] = (v[k] * inverse) as f32;
                }
            }
        },
    );
    planes
}

/// Burp of the cameras' fields (from the merged `sources`) with the `weights`, from the highest
/// camera index down (the column's order), one camera's field in memory at a time.
fn blend(layout: &Layout, sources: &[StoredRay], weights: &[Vec<f32>]) -> Vec<StoredRay> {
    let cam = layout.cam;
    // Per background pixel: Σ α·origin, β = Σ α, and the burp so far.
    let mut origin = vec![Vec3::ZERO; cam.len()];
    let mut beta = vec![0f32; cam.len()];
    let mut direction: Vec<Option<Vec3>> = vec![None; cam.len()];
    let mut solvers = FieldSolvers::new(layout.grid);
    for k in (0..weights.len()).rev() {
        let plane = &weights[k];
        let c = k as u32 + 1;
        if !cam.iter().zip(plane).any(|(&id, &a)| id == 0 && a > 0.0) {
            continue;
        }
        let field = solvers.field(layout, c, sources);
        origin.par_iter_mut().zip(beta.par_iter_mut()).zip(direction.par_iter_mut()).enumerate().for_each(
            |(p, ((o, b), d))| {
                let a = plane[p];
                if cam[p] != 0 || a.is_nan() || a <= 0.0 {
                    return;
                }
                *o += a * field.origin(p);
                *b += a;
                let f = field.direction(p);
                *d = Some(match *d {
                    None => f,
                    Some(r) => slerp(r, f, (a / *b).min(1.0)),
                });
            },
        );
    }
    (0..cam.len())
        .into_par_iter()
        .map(|p| {
            if cam[p] != 0 {
                return sources[p];
            }
            match direction[p] {
                Some(d) => StoredRay::new(origin[p] / beta[p], d),
                // Unreachable (every background pixel has a positive weight); a valid ray anyway.
                None => StoredRay::new(Vec3::ZERO, Vec3::Z),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::collage::Collage;
    use crate::ray_file::{RayFile, StoredRay};
    use crate::regions::Regions;
    use crate::remap::{RemapConfig, SeamSummary, remap};
    use glam::{Quat, Vec3};
    use std::collections::BTreeMap;

    /// A pinhole view of camera `id` at the origin, turned by `yaw` about the vertical (a field of
    /// view of about 0.9 rad across `w`).
    fn turned(id: u32, yaw: f32, w: u32, h: u32) -> RayFile {
        let turn = Quat::from_rotation_y(yaw);
        let rays = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 + 0.5 - w as f32 / 2.0, h as f32 / 2.0 - (p / w) as f32 - 0.5);
                StoredRay::new(Vec3::ZERO, turn * Vec3::new(x / w as f32, y / w as f32, -1.0).normalize())
            })
            .collect();
        RayFile::new(w, h, 0, id, rays).unwrap()
    }

    /// Both blends' seam figures on a collage labelled by `label(x, y)`, with regions
    /// `region(x, y)` (a colour per region), views yawed by `yaws[id - 1]`.
    fn both(
        w: u32,
        h: u32,
        yaws: &[f32],
        label: impl Fn(u32, u32) -> u32,
        region: impl Fn(u32, u32) -> u8,
    ) -> [SeamSummary; 2] {
        let ids = (0..w * h).map(|p| label(p % w, p / w)).collect();
        let collage = Collage::new(w, h, ids).unwrap();
        let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb([region(x, y), 0, 0]));
        let regions = Regions::from_image(&image::DynamicImage::ImageRgb8(img));
        let files: BTreeMap<u32, RayFile> = yaws
            .iter()
            .enumerate()
            .map(|(k, &yaw)| (k as u32 + 1, turned(k as u32 + 1, yaw, w, h)))
            .collect();
        [RemapConfig::GLASSNER, RemapConfig::SEAMLESS].map(|preset| {
            let out = remap(&collage, &regions, &files, 0, &RemapConfig { report: true, ..preset }).unwrap();
            for (p, (&id, r)) in collage.ids.iter().zip(&out.rays.rays).enumerate() {
                if id != 0 {
                    assert_eq!(r, &files[&id].rays[p], "camera pixels keep their rays");
                }
            }
            out.seams.unwrap()
        })
    }

    #[test]
    fn no_tear_at_a_region_boundary() {
        // The column's figure 11 with a twist: camera 1 on the left, camera 2 top right and
        // again bottom middle, camera 3 bottom right, and a region boundary across the middle.
        // Below it camera 2's nearest edge pixel in the region is on its lower piece, above it on
        // its upper piece: the column's ray jumps at the boundary, and its blurs smooth only the
        // weights. Camera 3 takes part only below: the seamless blend fades it in.
        let (w, h) = (160, 120);
        let label = |x: u32, y: u32| match (x, y) {
            (0..24, _) => 1,
            (136.., 0..40) | (60..80, 100..) => 2,
            (136.., 80..) => 3,
            _ => 0,
        };
        let [glassner, seamless] = both(w, h, &[0.0, -0.2, -0.4], label, |_, y| (y >= 60) as u8 * 100);
        println!("glassner {glassner}\nseamless {seamless}");
        // A step of over 0.2 rad between rows 59 and 60, many times those around it.
        assert!(glassner.worst.1 == 59 && glassner.worst_step > 0.2, "the column's blend tears: {glassner}");
        assert!(glassner.max > 12.0, "{glassner}");
        assert!(seamless.p99 < 3.0 && seamless.max < 6.0 && seamless.worst_step < 0.05, "{seamless}");
    }

    #[test]
    fn no_jump_at_a_medial_axis() {
        // Two blobs of camera 1 and a strip of camera 2 below: between the blobs the column's
        // nearest edge pixel of camera 1 jumps from one blob to the other; inside a ring of
        // camera 1 likewise. The membrane of camera 1's edge rays does not.
        let (w, h) = (160, 120);
        let blobs = |x: u32, y: u32| {
            let d = |cx: f32, cy: f32| (x as f32 - cx).hypot(y as f32 - cy);
            if d(35.0, 50.0) < 25.0 || d(125.0, 50.0) < 20.0 { 1 } else { (y >= 105) as u32 * 2 }
        };
        let [glassner, seamless] = both(w, h, &[0.0, -0.8], blobs, |_, _| 0);
        println!("blobs: glassner {glassner}\nseamless {seamless}");
        assert!(glassner.max > 20.0, "the column's blend jumps: {glassner}");
        assert!(seamless.p99 < 3.0 && seamless.max < 6.0, "{seamless}");
        let ring = |x: u32, y: u32| {
            let r = (x as f32 - 80.0).hypot(y as f32 - 60.0);
            if (20.0..38.0).contains(&r) { 1 } else { (y >= 112) as u32 * 2 }
        };
        let [glassner, seamless] = both(w, h, &[0.0, -0.8], ring, |_, _| 0);
        println!("ring: glassner {glassner}\nseamless {seamless}");
        assert!(glassner.max > 20.0, "the column's blend jumps: {glassner}");
        assert!(seamless.p99 < 3.0 && seamless.max < 6.0, "{seamless}");
    }
}
