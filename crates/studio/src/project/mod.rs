//! The studio's project folder (docs/studio.md, "Project folder"): what a save writes, laid out
//! as the batch commands read it, and how a session is opened from a scene, an existing collage
//! or a saved project.
//!
//! ```text
//! studio.json                      scene, resolution, settings, frame, every key's cameras
//! collage.png, collage-regions.png the current key (tagged, as `remap`/`rerender` read it)
//! keys/frameFFFF.png (+ -regions)  every key, as `keys --key F=keys/frameFFFF.png` reads it
//! views/frameFFFFcameraCC.{exr,png,mcr}  every key's views (`render --tag --lens-writer`)
//! final/rerender-frameFFFF.{exr,png,mcr} the last "render final" (as `rerender` writes it)
//! ```
//!
//! Unsaved changes left when the studio stops go to `PROJECT.autosave/`, a project folder of the
//! same layout beside it ([`autosave`]).

pub mod autosave;
mod final_render;
mod save;

pub use final_render::start_final;
pub use save::{key_collage, save};

use crate::camera::StudioCamera;
use crate::config::Config;
use crate::engine::Shared;
use crate::error::{Result, StudioError};
use crate::maps::Maps;
use crate::session::{Key, MAX_CAMERAS, Session};
use crate::source::SceneSource;
use mcc::layers::CameraNames;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The project file's name.
pub const PROJECT_FILE: &str = "studio.json";
/// The project file's format version.
pub const VERSION: u32 = 1;

/// One key as the project file records it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct KeyFile {
    /// The key's frame.
    pub frame: u32,
    /// Its collage, relative to the project folder.
    pub collage: PathBuf,
    /// Its cameras, edited ones included.
    pub cameras: Vec<StudioCamera>,
}

/// The project file (`studio.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProjectFile {
    /// Format version.
    pub version: u32,
    /// The scene file (absolute).
    pub scene: PathBuf,
    /// The scene cameras the session started with (all when empty).
    pub scene_cameras: Vec<String>,
    /// Collage width and height.
    pub res: [u32; 2],
    /// The key being edited.
    pub frame: u32,
    /// The seamless blend (`--seamless`).
    pub seamless: bool,
    /// The views' samples per pixel.
    pub view_spp: u32,
    /// Every key.
    pub keys: Vec<KeyFile>,
}

impl ProjectFile {
    /// Reads and checks `dir/studio.json`.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(PROJECT_FILE);
        let text = std::fs::read_to_string(&path).map_err(|e| StudioError::io(&path, e))?;
        let bad = |message: String| StudioError::Project { path: path.clone(), message };
        let file: Self =
            serde_json::from_str(&text).map_err(|e| bad(format!("not a studio project file: {e}")))?;
        if file.version != VERSION {
            return Err(bad(format!("version {} (this studio reads {VERSION})", file.version)));
        }
        check_res(file.res).map_err(|e| bad(e.to_string()))?;
        if !file.keys.iter().any(|k| k.frame == file.frame) {
            return Err(bad(format!("frame {} has no key", file.frame)));
        }
        for key in &file.keys {
            check_cameras(&key.cameras).map_err(|e| bad(format!("key at frame {}: {e}", key.frame)))?;
            if key.collage.is_absolute()
                || key.collage.components().any(|c| c == std::path::Component::ParentDir)
            {
                return Err(bad(format!(
                    "key at frame {}: its collage must lie inside the project",
                    key.frame
                )));
            }
        }
        Ok(file)
    }
}

/// Refuses an empty or huge collage size.
pub fn check_res(res: [u32; 2]) -> Result<()> {
    let [w, h] = res;
    if w == 0 || h == 0 || w > 4096 || h > 4096 {
        return Err(StudioError::request(format!("resolution {w}x{h}: each side must be 1 to 4096 pixels")));
    }
    Ok(())
}

fn check_cameras(cameras: &[StudioCamera]) -> Result<()> {
    if cameras.is_empty() || cameras.len() > MAX_CAMERAS {
        return Err(StudioError::request(format!("1 to {MAX_CAMERAS} cameras, not {}", cameras.len())));
    }
    for (i, c) in cameras.iter().enumerate() {
        if c.index != i as u32 + 1 {
            return Err(StudioError::request(format!(
                "camera '{}' has index {}, expected {}",
                c.name,
                c.index,
                i + 1
            )));
        }
        c.desc()?;
    }
    Ok(())
}

/// The label map of a collage file (a tagged image, or a layered OpenRaster or PSD file cut in
/// an editor, its layers named after `cameras` or their numbers; a layer `NAME (camera N)` that
/// `render --layers` wrote is the session's camera NAME, since N is that render's numbering) and
/// its region map (the
/// file's `regions` group, else the region image beside it, if any): read by the batch
/// remapper's own reader, `mcc::layers::open_collage`.
/// `res` is the size the collage must have (`None`: its own, checked like `--res`).
pub fn read_collage(path: &Path, res: Option<[u32; 2]>, cameras: &[StudioCamera]) -> Result<Maps> {
    let names = CameraNames::session(cameras.iter().map(|c| (c.name.clone(), c.index)));
    let opened = mcc::layers::open_collage(path, None, &names, mcc::CollageOptions::default())?;
    let collage = opened.collage;
    let [w, h] = match res {
        Some(res) => res,
        None => {
            let own = [collage.width, collage.height];
            check_res(own)
                .map_err(|e| StudioError::Project { path: path.to_path_buf(), message: e.to_string() })?;
            own
        }
    };
    collage.check_size(path, w, h, "the studio's resolution (--res)")?;
    let labels = collage
        .ids
        .iter()
        .map(|&id| {
            u8::try_from(id).ok().filter(|&l| (l as usize) <= cameras.len()).ok_or_else(|| {
                StudioError::Project {
                    path: path.to_path_buf(),
                    message: format!("uses camera {id}, but the session has {} cameras", cameras.len()),
                }
            })
        })
        .collect::<Result<Vec<u8>>>()?;
    let regions = opened
        .regions
        .index
        .iter()
        .map(|&r| {
            u8::try_from(r).ok().filter(|&r| r < 255).ok_or_else(|| StudioError::Project {
                path: path.to_path_buf(),
                message: "more than 255 regions".into(),
            })
        })
        .collect::<Result<Vec<u8>>>()?;
    Ok(Maps::with(w, h, labels, regions))
}

/// The session `config` asks for: a new one on its scene (from its collage, if given), or the
/// project saved in its folder.
pub fn open_session(config: &Config) -> Result<Shared> {
    let project = config.project.clone();
    let (session, source) = match &config.scene {
        Some(scene) => {
            if let Some(res) = config.res {
                check_res(res)?;
            }
            let source = SceneSource::load(scene.clone(), config.cameras.clone())?;
            let cameras = source.cameras(config.frame)?;
            check_cameras(&cameras)?;
            // Without `--res` a collage keeps its own size (issue 41).
            let maps = match &config.collage {
                Some(path) => read_collage(path, config.res, &cameras)?,
                None => {
                    let [w, h] = config.res.unwrap_or(Config::DEFAULT_RES);
                    Maps::new(w, h)
                }
            };
            let res = [maps.width, maps.height];
            (Session::new(res, config.frame, Key { cameras, maps }), source)
        }
        None => open_project(&project)?,
    };
    let engine = crate::engine::EngineSettings { ..config.engine };
    let shared = Shared::new(session, source, engine, project)?;
    autosave::offer(&shared);
    Ok(shared)
}

/// Opens the project saved in `dir`.
pub(crate) fn open_project(dir: &Path) -> Result<(Session, SceneSource)> {
    let file = ProjectFile::read(dir)?;
    let source = SceneSource::load(file.scene.clone(), file.scene_cameras.clone())?;
    let mut keys = std::collections::BTreeMap::new();
    for key in &file.keys {
        let maps = read_collage(&dir.join(&key.collage), Some(file.res), &key.cameras)?;
        keys.insert(key.frame, Key { cameras: key.cameras.clone(), maps });
    }
    let mut session = Session::new(file.res, file.frame, keys.remove(&file.frame).expect("checked"));
    session.keys.extend(keys);
    session.seamless = file.seamless;
    Ok((session, source))
}
