//! End-to-end tests of the remapper (SPEC §5) on small collages.

use super::*;
use crate::test_util::{Rng, scratch_dir};
use glam::Vec3;

/// A pinhole-like view: camera `id` at its own position, looking along its own axis.
fn view(id: u32, w: u32, h: u32) -> RayFile {
    let eye = Vec3::new(id as f32, -(id as f32) * 0.5, 2.0 * id as f32);
    let forward = if id.is_multiple_of(2) { Vec3::Z } else { -Vec3::Z }; // even and odd cameras face each other
    let rays = (0..w * h)
        .map(|p| {
            let (x, y) = ((p % w) as f32 + 0.5, (p / w) as f32 + 0.5);
            let d = forward + Vec3::new(x / w as f32 - 0.5, 0.5 - y / h as f32, 0.0) * 0.8;
            StoredRay::new(eye, d.normalize())
        })
        .collect();
    RayFile::new(w, h, 5, id, rays).unwrap()
}

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
        let config = if case % 2 == 0 { RemapConfig::GLASSNER } else { RemapConfig::UNSMOOTHED };
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
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| remap(&collage, &regions, &files, 0, &RemapConfig::GLASSNER).unwrap())
    };
    let (one, three) = (run(1), run(3));
    assert_eq!(
        one.rays.rays.iter().map(bits).collect::<Vec<_>>(),
        three.rays.rays.iter().map(bits).collect::<Vec<_>>()
    );
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
fn remaps_from_files_and_writes_debug_pictures() {
    let dir = scratch_dir("remap-files");
    let (w, h) = (20, 12);
    let code = crate::TagCode::default();
    for id in [1, 2] {
        view(id, w, h)
            .write(
                &dir.join(crate::names::view_rays_name(7, id, crate::RayFormat::Binary)),
                crate::RayFormat::Binary,
            )
            .unwrap();
    }
    let img = image::RgbImage::from_fn(w, h, |x, y| {
        image::Rgb(match x {
            0..4 => code.encode([10, 20, 30], 1).unwrap(),
            15.. => code.encode([0, 0, 0], 2).unwrap(),
            _ if y == 0 && x == 8 => [100, 100, 100], // a stray
            _ => [0, 0, 0],
        })
    });
    let collage_path = dir.join("cut.png");
    crate::png::write_png(&collage_path, &image::DynamicImage::ImageRgb8(img)).unwrap();
    let mut inputs = RemapInputs {
        collage: &collage_path,
        regions: None,
        rays_dir: &dir,
        frame: 7,
        collage_options: Default::default(),
    };
    let err = remap_files(&inputs, &RemapConfig::GLASSNER).unwrap_err().to_string();
    assert!(err.contains("cut.png") && err.contains("(8, 0)"), "{err}");
    inputs.collage_options.strays = crate::StrayPolicy::Background;
    let config = RemapConfig { debug: true, ..RemapConfig::GLASSNER };
    let out = remap_files(&inputs, &config).unwrap();
    assert!(matches!(&out.warnings[..], [RemapWarning::StraysIgnored(r)] if r.count == 1));
    assert_eq!(bits(out.rays.get(0, 0)), bits(view(1, w, h).get(0, 0)));
    let written = out.debug.unwrap().write_pngs(&dir, 7).unwrap();
    assert_eq!(written.len(), 6);
    assert!(dir.join("debug-frame0007-seams.png").is_file());
    assert!(written.iter().all(|p| p.is_file()));
    assert!(dir.join("debug-frame0007-camera02-weights.png").is_file());
    let err = remap_files(&RemapInputs { frame: 8, ..inputs }, &config).unwrap_err().to_string();
    assert!(err.contains("no ray files for frame 8"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
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
    let config = RemapConfig { debug: true, ..RemapConfig::GLASSNER };
    let out = remap(&collage, &Regions::single(w, h), &files, 0, &config).unwrap();
    assert!(out.rays.rays.iter().all(|r| r.defect().is_none()));
    let dbg = out.debug.unwrap();
    for p in 0..(w * h) as usize {
        let sum: f32 = dbg.weights.iter().map(|plane| plane[p]).sum();
        assert!(sum.is_finite() && (sum - 1.0).abs() < 1e-5, "pixel {p}: {sum}");
    }
}
