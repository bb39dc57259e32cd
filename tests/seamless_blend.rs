//! The seamless blend end to end (docs/design/mcc.md §5.8), through the `mcctrace remap` command
//! line: views and a collage written as files, remapped in both blends, the rays read back.
//!
//! - Camera pixels keep their view's rays bit for bit in both blends.
//! - The collage has a region boundary that the column's blend tears along and two pieces of
//!   one camera: the seam ratio of the seamless rays stays at the bounds (p99 ≤ 3,
//!   maximum ≤ 20), the column's does not.
//! - The two views face each other: no ray is NaN or of zero length.

use crate::common::{Scratch, mcctrace};
use glam::{Quat, Vec3};
use mcc::ray_file::{RayFile, RayFormat, StoredRay};
use mcc::remap::SeamRatios;
use mcc::{Collage, TagCode};

const W: u32 = 200;
const H: u32 = 120;

/// Camera `id`'s view: a pinhole at its own eye turned by `yaw` about the vertical.
fn view(id: u32, yaw: f32) -> RayFile {
    let (turn, eye) = (Quat::from_rotation_y(yaw), Vec3::new(id as f32, 0.0, 0.0));
    let rays = (0..W * H)
        .map(|p| {
            let (x, y) = ((p % W) as f32 + 0.5 - W as f32 / 2.0, H as f32 / 2.0 - (p / W) as f32 - 0.5);
            StoredRay::new(eye, turn * Vec3::new(x / W as f32, y / W as f32, -1.0).normalize())
        })
        .collect();
    RayFile::new(W, H, 0, id, rays).unwrap()
}

/// Camera 1 in two pieces (top left, bottom middle), camera 2 on the right; 0 elsewhere.
fn label(x: u32, y: u32) -> u32 {
    match (x, y) {
        (0..40, 0..50) | (80..110, 95..) => 1,
        (170.., _) => 2,
        _ => 0,
    }
}

fn bits(r: &StoredRay) -> [u32; 6] {
    let [a, b] = [r.origin, r.direction].map(|v| v.to_array().map(f32::to_bits));
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}

#[test]
fn camera_pixels_exact_and_no_seams() {
    let dir = Scratch::new("seamless-blend");
    // Camera 2 faces camera 1 (nearly opposite directions meet in the blend).
    let views = [view(1, 0.0), view(2, 3.0)];
    for (k, v) in views.iter().enumerate() {
        v.write(
            &dir.path(&mcc::names::view_rays_name(0, k as u32 + 1, RayFormat::Binary)),
            RayFormat::Binary,
        )
        .unwrap();
    }
    let code = TagCode::default();
    let collage = mcc::image::RgbImage::from_fn(W, H, |x, y| {
        mcc::image::Rgb(match label(x, y) {
            0 => [0, 0, 0],
            id => code.encode([90, 120, 150], id).unwrap(),
        })
    });
    collage.save(dir.path("cut.png")).unwrap();
    // A region boundary across the middle: camera 1's nearest edge pixel in the region flips
    // from its top piece to its bottom piece there.
    let regions = mcc::image::RgbImage::from_fn(W, H, |_, y| mcc::image::Rgb([(y >= 60) as u8 * 200, 0, 0]));
    regions.save(dir.path("cut-regions.png")).unwrap();
    let ids: Vec<u32> = (0..W * H).map(|p| label(p % W, p / W)).collect();
    let mut figures = Vec::new();
    for (name, flag) in [("glassner", None), ("seamless", Some("--seamless"))] {
        let out = dir.s(&format!("{name}.mcr"));
        let (cut, rays) = (dir.s("cut.png"), dir.s("."));
        let mut args = vec!["remap", "--collage", &cut];
        args.extend(["--rays", &rays, "--frame", "0", "--out", &out, "--quiet"]);
        args.extend(flag);
        mcctrace(&args).unwrap();
        let got = RayFile::read(std::path::Path::new(&out)).unwrap();
        for (p, (r, &id)) in got.rays.iter().zip(&ids).enumerate() {
            if id != 0 {
                let want = &views[id as usize - 1].rays[p];
                assert_eq!(bits(r), bits(want), "{name}: camera pixel {p}");
            } else {
                assert!(r.defect().is_none(), "{name}: background pixel {p}: {r:?}");
            }
        }
        let collage = Collage::new(W, H, ids.clone()).unwrap();
        figures.push(SeamRatios::measure(&got.rays, &collage.ids, W as usize).unwrap().summary);
    }
    let [glassner, seamless] = [figures[0], figures[1]];
    assert!(glassner.max > 20.0, "the column's blend has seams here: {glassner}");
    assert!(seamless.p99 <= 3.0 && seamless.max <= 20.0, "{seamless}");
}
