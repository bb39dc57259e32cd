//! End-to-end tests of the remapper (docs/design/mcc.md §5) on small collages.

use super::*;
use crate::test_util::{Rng, view};

fn views(ids: &[u32], w: u32, h: u32) -> BTreeMap<u32, RayFile> {
    ids.iter().map(|&id| (id, view(id, w, h))).collect()
}

fn bits(r: &StoredRay) -> [u32; 6] {
    bytemuck::cast(*r)
}

/// Random discs of camera ids on background.
fn random_collage(rng: &mut Rng, w: u32, h: u32, ids: &[u32]) -> Collage {
    let mut cells = vec![0u32; (w * h) as usize];
    for &id in ids {
        for _ in 0..1 + rng.below(2) {
            let (cx, cy, r) =
                (rng.below(w) as i64, rng.below(h) as i64, 1 + rng.below(w.max(h) / 3 + 1) as i64);
            for p in 0..(w * h) as usize {
                let (x, y) = ((p as u32 % w) as i64, (p as u32 / w) as i64);
                if (x - cx).pow(2) + (y - cy).pow(2) <= r * r {
                    cells[p] = id;
                }
            }
        }
    }
    Collage::new(w, h, cells).unwrap()
}

fn random_regions(rng: &mut Rng, w: u32, h: u32) -> Regions {
    let n = 1 + rng.below(3);
    let (sx, sy) = (1 + rng.below(w), 1 + rng.below(h));
    let img =
        image::RgbImage::from_fn(w, h, |x, y| image::Rgb([((x / sx + 2 * (y / sy)) % n) as u8 * 60, 0, 0]));
    Regions::from_image(&image::DynamicImage::ImageRgb8(img))
}

#[test]
fn a_collage_of_one_camera_is_that_camera() {
    let (w, h) = (13, 7);
    let files = views(&[1, 4, 9], w, h);
    let collage = Collage::new(w, h, vec![4; (w * h) as usize]).unwrap();
    let out = remap(&collage, &Regions::single(w, h), &files, 5, &RemapConfig::GLASSNER).unwrap();
    let want: Vec<[u32; 6]> = files[&4].rays.iter().map(bits).collect();
    assert_eq!(out.rays.rays.iter().map(bits).collect::<Vec<_>>(), want);
    assert_eq!((out.rays.frame, out.rays.camera_id, out.rays.computed), (5, 0, true));
    assert!(out.warnings.is_empty());
}

#[test]
fn one_camera_with_holes_fills_them_with_its_nearest_edge_rays() {
    // With one camera, every weight is 1 through smoothing, so a hole gets exactly the ray of its
    // nearest edge pixel.
    let (w, h) = (9, 6);
    let files = views(&[3], w, h);
    let ids: Vec<u32> = (0..w * h)
        .map(|p| if (2..6).contains(&(p % w)) && (1..4).contains(&(p / w)) { 0 } else { 3 })
        .collect();
    let collage = Collage::new(w, h, ids).unwrap();
    let out = remap(&collage, &Regions::single(w, h), &files, 0, &RemapConfig::GLASSNER).unwrap();
    // Hole pixel (2, 1): nearest edge pixels at distance 1 are (2, 0) and (1, 1); raster order → (2, 0).
    assert_eq!(bits(out.rays.get(2, 1)), bits(files[&3].get(2, 0)));
    // Hole pixel (5, 3): (6, 3) and (5, 4) are both at distance 1; the smaller row wins.
    assert_eq!(bits(out.rays.get(5, 3)), bits(files[&3].get(6, 3)));
    // Hole pixel (3, 2): the nearest edge pixels are 2 away: (3, 0), (1, 2), (3, 4) → (3, 0).
    assert_eq!(bits(out.rays.get(3, 2)), bits(files[&3].get(3, 0)));
}

#[test]
fn camera_pixels_are_bit_exact_and_background_rays_valid() {
    let mut rng = Rng::new(99);
    for case in 0..60 {
        let (w, h) = (1 + rng.below(30), 1 + rng.below(20));
        let ids: Vec<u32> = (1..=1 + rng.below(5)).map(|k| k * 3 - 1).collect();
        let collage = random_collage(&mut rng, w, h, &ids);
        if collage.cameras().is_empty() {
            continue;
        }
        let regions = random_regions(&mut rng, w, h);
        let files = views(&ids, w, h);
        let config = [RemapConfig::GLASSNER, RemapConfig::UNSMOOTHED, RemapConfig::SEAMLESS][case % 3];
        let out = remap(&collage, &regions, &files, 1, &config).unwrap();
        for (p, (&id, r)) in collage.ids.iter().zip(&out.rays.rays).enumerate() {
            if id != 0 {
                assert_eq!(bits(r), bits(&files[&id].rays[p]), "case {case} pixel {p}");
            } else {
                assert!(r.defect().is_none(), "case {case} pixel {p}: {r:?}");
            }
        }
    }
}

#[test]
fn weights_interpolate_towards_each_camera() {
    // Camera 1 on the left third, camera 2 on the right third, background between.
    let (w, h) = (30, 5);
    let ids: Vec<u32> = (0..w * h)
        .map(|p| {
            if p % w < 10 {
                1
            } else if p % w >= 20 {
                2
            } else {
                0
            }
        })
        .collect();
    let collage = Collage::new(w, h, ids).unwrap();
    let files = views(&[1, 2], w, h);
    for preset in [RemapConfig::UNSMOOTHED, RemapConfig::GLASSNER] {
        let config = RemapConfig { debug: true, ..preset };
        let out = remap(&collage, &Regions::single(w, h), &files, 0, &config).unwrap();
        let dbg = out.debug.unwrap();
        let y = 2usize;
        let alpha1: Vec<f32> = (10..20).map(|x| dbg.weights[0][y * w as usize + x]).collect();
        assert!(alpha1.windows(2).all(|p| p[0] >= p[1]), "{alpha1:?}: falls away from camera 1");
        assert!(alpha1[0] > 0.75 && alpha1[9] < 0.25, "{alpha1:?}");
        for x in 10..20 {
            let p = y * w as usize + x;
            assert!((dbg.weights[0][p] + dbg.weights[1][p] - 1.0).abs() < 1e-6);
        }
        // Symmetric layout, symmetric weights.
        for x in 10..20 {
            let (a, b) = (dbg.weights[0][y * w as usize + x], dbg.weights[1][y * w as usize + 29 - x]);
            assert!((a - b).abs() < 1e-5, "{x}: {a} vs {b}");
        }
        assert_eq!(dbg.dominant[y * w as usize + 12], 0);
        assert_eq!(dbg.dominant[y * w as usize + 17], 1);
    }
}

#[test]
fn regions_without_cameras_warn_and_blend_everything() {
    let (w, h) = (12, 4);
    let ids: Vec<u32> = (0..w * h)
        .map(|p| match p % w {
            0 => 1,
            5 => 2,
            _ => 0,
        })
        .collect();
    let collage = Collage::new(w, h, ids).unwrap();
    // Region 1 is columns 8.. : no camera there.
    let img =
        image::RgbImage::from_fn(w, h, |x, _| image::Rgb(if x < 8 { [0, 0, 0] } else { [255, 255, 255] }));
    let regions = Regions::from_image(&image::DynamicImage::ImageRgb8(img));
    let out = remap(&collage, &regions, &views(&[1, 2], w, h), 0, &RemapConfig::GLASSNER).unwrap();
    assert_eq!(out.warnings.len(), 1);
    let msg = out.warnings[0].to_string();
    assert!(
        msg.contains("region 1") && msg.contains("#ffffff") && msg.contains("(8, 0)") && msg.contains("16"),
        "{msg}"
    );
}

#[test]
fn same_result_for_any_thread_count() {
    let mut rng = Rng::new(5);
    let (w, h) = (64, 48);
    let ids = [1, 2, 3, 5, 8];
    let collage = random_collage(&mut rng, w, h, &ids);
    let regions = random_regions(&mut rng, w, h);
    let files = views(&ids, w, h);
    for preset in [RemapConfig::GLASSNER, RemapConfig::SEAMLESS] {
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| remap(&collage, &regions, &files, 0, &preset).unwrap())
        };
        let (one, three) = (run(1), run(3));
        assert_eq!(
            one.rays.rays.iter().map(bits).collect::<Vec<_>>(),
            three.rays.rays.iter().map(bits).collect::<Vec<_>>(),
            "{:?}",
            preset.blend
        );
    }
}

#[test]
fn bad_inputs_are_errors() {
    let (w, h) = (6, 4);
    let collage = Collage::new(w, h, (0..24).map(|p| (p % 3 == 0) as u32 * 2).collect()).unwrap();
    let files = views(&[1], w, h);
    let err =
        remap(&collage, &Regions::single(w, h), &files, 0, &RemapConfig::GLASSNER).unwrap_err().to_string();
    assert!(err.contains("camera 2") && err.contains("no ray file"), "{err}");
    let files = views(&[2], w + 1, h);
    let err =
        remap(&collage, &Regions::single(w, h), &files, 0, &RemapConfig::GLASSNER).unwrap_err().to_string();
    assert!(err.contains("7x4") && err.contains("6x4"), "{err}");
    let files = views(&[2], w, h);
    assert!(remap(&collage, &Regions::single(w, h + 1), &files, 0, &RemapConfig::GLASSNER).is_err());
    let bad = RemapConfig { ease_control: 1.0, ..RemapConfig::GLASSNER };
    assert!(remap(&collage, &Regions::single(w, h), &files, 0, &bad).is_err());
    let empty = Collage::new(w, h, vec![0; 24]).unwrap();
    assert!(remap(&empty, &Regions::single(w, h), &files, 0, &RemapConfig::GLASSNER).is_err());
}

#[test]
fn sixty_three_cameras_give_finite_unit_rays() {
    // One small blob per camera, scattered: every background pixel blends up to 63 cameras.
    let (w, h) = (64, 40);
    let mut ids = vec![0u32; (w * h) as usize];
    for id in 1..=63u32 {
        let (x, y) = ((id * 37) % (w - 2) + 1, (id * 23) % (h - 2) + 1);
        ids[(y * w + x) as usize] = id;
        ids[(y * w + x + 1) as usize] = id;
    }
    let collage = Collage::new(w, h, ids).unwrap();
    let files: BTreeMap<u32, RayFile> = (1..=63).map(|id| (id, view(id, w, h))).collect();
    // Even and odd cameras face each other: burp meets nearly opposite directions.
    for preset in [RemapConfig::GLASSNER, RemapConfig::SEAMLESS] {
        let config = RemapConfig { debug: true, ..preset };
        let out = remap(&collage, &Regions::single(w, h), &files, 0, &config).unwrap();
        assert!(out.rays.rays.iter().all(|r| r.defect().is_none()), "{:?}", preset.blend);
        let dbg = out.debug.unwrap();
        for p in 0..(w * h) as usize {
            let sum: f32 = dbg.weights.iter().map(|plane| plane[p]).sum();
            assert!(sum.is_finite() && (sum - 1.0).abs() < 1e-5, "{:?} pixel {p}: {sum}", preset.blend);
        }
    }
}

/// FNV-1a over the bits of every ray: a fingerprint of a remap's exact output.
fn fingerprint(rays: &[StoredRay]) -> u64 {
    rays.iter()
        .flat_map(bits)
        .flat_map(u32::to_le_bytes)
        .fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

#[test]
fn the_columns_blend_is_unchanged_bit_for_bit() {
    // The default blend's output on a fixed collage with regions, three cameras (two facing each
    // other) and holes, recorded from the remapper before the seamless blend existed (commit
    // c39ba49): the default must stay bit-identical (docs/design/mcc.md §5.8).
    let mut rng = Rng::new(2028);
    let (w, h) = (48, 32);
    let ids = [1, 2, 4];
    let collage = random_collage(&mut rng, w, h, &ids);
    let regions = random_regions(&mut rng, w, h);
    let files = views(&ids, w, h);
    let out = remap(&collage, &regions, &files, 0, &RemapConfig::GLASSNER).unwrap();
    assert_eq!(collage.ids.iter().filter(|&&id| id == 0).count(), EXPECTED_BACKGROUND);
    assert_eq!(fingerprint(&out.rays.rays), EXPECTED_FINGERPRINT);
}

/// Recorded with the remapper at commit c39ba49 (see the test).
const EXPECTED_BACKGROUND: usize = 936;
const EXPECTED_FINGERPRINT: u64 = 0x5280_2cde_2506_79ae;
