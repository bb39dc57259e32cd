//! Saving (docs/studio.md, "Project folder"): every key's views through the batch `render`'s
//! own job (`mcc::job::ViewRender`: EXR, tagged PNG, the lens writer's ray file), its collage
//! cut from those tagged views, its region image, then the project file — each file written
//! atomically, saves one at a time, so the last save wins whole.

use super::{KeyFile, PROJECT_FILE, ProjectFile, VERSION};
use crate::engine::Shared;
use crate::engine::pictures::region_image;
use crate::error::{Result, StudioError};
use crate::session::Key;
use glam::UVec2;
use image::{DynamicImage, Rgb, RgbImage};
use mcc::TagCode;
use mcc::job::ViewRender;
use mcc::names::{view_render_name, view_tagged_name};
use mcc::ray_file::RayFormat;
use std::path::{Path, PathBuf};
use tracer::job::{CameraRender, Provenance, Quality};
use tracer::render::NoProgress;

/// The folder of the views.
pub const VIEWS: &str = "views";
/// The folder of the keys' collages.
pub const KEYS: &str = "keys";

/// `keys/frameFFFF.png`.
pub fn key_collage(frame: u32) -> PathBuf {
    Path::new(KEYS).join(format!("frame{frame:04}.png"))
}

/// Writes the project folder; returns it. Its views render on the studio's render threads. The
/// session is saved then: an autosave beside the project is obsolete and goes.
pub fn save(shared: &Shared) -> Result<PathBuf> {
    let edits = save_into(shared, &shared.project)?;
    shared.saved_edits.fetch_max(edits, std::sync::atomic::Ordering::SeqCst);
    let autosave = super::autosave::autosave_dir(&shared.project);
    if autosave.join(PROJECT_FILE).is_file() && shared.autosave_offered().is_none() {
        std::fs::remove_dir_all(&autosave).map_err(|e| StudioError::io(&autosave, e))?;
    }
    Ok(shared.project.clone())
}

/// Writes the session as a project folder into `dir`; returns the session's `edits` it holds.
pub(super) fn save_into(shared: &Shared, dir: &Path) -> Result<u64> {
    // A second tab's save waits here, outside the pool, not on one of its render threads.
    let _one_at_a_time = shared.save_lock.lock().unwrap_or_else(|e| e.into_inner());
    shared.pool.install(|| save_on_pool(shared, dir))
}

fn save_on_pool(shared: &Shared, dir: &Path) -> Result<u64> {
    let (keys, res, frame, seamless, edits) = {
        let s = shared.session();
        (s.keys.clone(), s.res, s.frame, s.seamless, s.edits)
    };
    let views = dir.join(VIEWS);
    std::fs::create_dir_all(&views).map_err(|e| StudioError::io(&views, e))?;
    std::fs::create_dir_all(dir.join(KEYS)).map_err(|e| StudioError::io(dir.join(KEYS), e))?;
    let mut key_files = Vec::new();
    for (&f, key) in &keys {
        write_views(shared, f, key, res, &views)?;
        let collage = cut_collage(key, f, res, &views)?;
        let regions = DynamicImage::ImageRgb8(region_image(res[0], res[1], &key.maps.regions));
        let path = dir.join(key_collage(f));
        mcc::png::write_png(&path, &collage)?;
        mcc::png::write_png(&mcc::Regions::beside(&path), &regions)?;
        if f == frame {
            let current = dir.join("collage.png");
            mcc::png::write_png(&current, &collage)?;
            mcc::png::write_png(&mcc::Regions::beside(&current), &regions)?;
        }
        key_files.push(KeyFile { frame: f, collage: key_collage(f), cameras: key.cameras.clone() });
    }
    let scene = std::fs::canonicalize(&shared.source.path).unwrap_or_else(|_| shared.source.path.clone());
    let file = ProjectFile {
        version: VERSION,
        scene,
        scene_cameras: shared.source.names.clone(),
        res,
        frame,
        seamless,
        view_spp: shared.settings.view_spp,
        keys: key_files,
    };
    let text = serde_json::to_string_pretty(&file).expect("a project file serialises");
    let path = dir.join(PROJECT_FILE);
    tracer::atomic::write_atomically(&path, |w| std::io::Write::write_all(w, text.as_bytes()))?;
    Ok(edits)
}

/// Renders and writes the views of `key` that are not on disk with their current pose.
fn write_views(shared: &Shared, frame: u32, key: &Key, res: [u32; 2], views: &Path) -> Result<()> {
    let quality = Quality::DEFAULT.with_spp(shared.settings.view_spp);
    let mut prepared = None;
    for cam in &key.cameras {
        let stamp = views.join(format!("{}.pose", mcc::names::view_stem(frame, cam.index)));
        let pose = serde_json::to_string(&(cam, quality.spp, res)).expect("a camera serialises");
        let exr = views.join(view_render_name(frame, cam.index));
        if std::fs::read_to_string(&stamp).is_ok_and(|s| s == pose) && exr.is_file() {
            continue;
        }
        if prepared.is_none() {
            prepared = Some(shared.source.tracer(frame, &quality)?);
        }
        let path_tracer = prepared.as_deref().expect("set above");
        let desc = cam.desc()?;
        let camera = desc.build(UVec2::new(res[0], res[1]))?;
        let job = ViewRender {
            render: CameraRender {
                tracer: path_tracer,
                camera: camera.as_ref(),
                name: &cam.name,
                camera_id: cam.index,
                frame,
                shutter: (0.0, 0.0),
                quality,
            },
            scene: &shared.source.path,
            exr: &exr,
            rays: Some(RayFormat::Binary),
            tag: Some(TagCode::default()),
            provenance: Provenance { projection: Some(desc.projection), ..Provenance::default() },
            setup: Some(&shared.source.setup),
            band: None,
        };
        job.run(&NoProgress)?;
        tracer::atomic::write_atomically(&stamp, |w| std::io::Write::write_all(w, pose.as_bytes()))?;
    }
    Ok(())
}

/// The key's collage: each painted pixel from its camera's tagged view, background black —
/// what cutting the tagged views in an editor gives.
fn cut_collage(key: &Key, frame: u32, res: [u32; 2], views: &Path) -> Result<DynamicImage> {
    let [w, h] = res;
    let mut tagged = std::collections::BTreeMap::new();
    for &label in &key.maps.labels {
        if label != 0 && !tagged.contains_key(&label) {
            let path = views.join(view_tagged_name(frame, label as u32));
            tagged.insert(label, mcc::png::read_image(&path)?.to_rgb8());
        }
    }
    let image = RgbImage::from_fn(w, h, |x, y| match key.maps.labels[(y * w + x) as usize] {
        0 => Rgb([0, 0, 0]),
        k => *tagged[&k].get_pixel(x, y),
    });
    Ok(DynamicImage::ImageRgb8(image))
}
