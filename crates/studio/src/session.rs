//! A studio session's editable state (docs/studio.md, "Engine"): the keys (one collage per
//! frame, each with its cameras, label and region maps and their history), the current frame,
//! the remapper's settings and the canvas's view. Messages edit it here; the preview engine
//! works from snapshots of it.

use crate::camera::StudioCamera;
use crate::error::{Result, StudioError};
use crate::maps::{Maps, Undone};
use crate::protocol::{Layer, Outbound, ViewMode};
use base64::Engine as _;
use base64::engine::general_purpose::STANDARD as BASE64;
use serde_json::json;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Most cameras one key may hold (label bytes 1 … 254; 255 means "keep" in a patch).
pub const MAX_CAMERAS: usize = 254;

/// One keyframe's collage: its cameras and maps.
#[derive(Clone, Debug)]
pub struct Key {
    /// The cameras, by tag number (index k at position k − 1).
    pub cameras: Vec<StudioCamera>,
    /// The label and region maps.
    pub maps: Maps,
}

impl Key {
    /// The camera with tag number `index`.
    pub fn camera(&self, index: u32) -> Result<&StudioCamera> {
        self.cameras.iter().find(|c| c.index == index).ok_or_else(|| {
            StudioError::request(format!("no camera {index} (there are {})", self.cameras.len()))
        })
    }
}

/// What the preview engine needs of the session, taken under its lock.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// The state's sequence number.
    pub seq: u64,
    /// The key's frame.
    pub frame: u32,
    /// The key's cameras.
    pub cameras: Vec<StudioCamera>,
    /// The key's labels, shared.
    pub labels: Arc<Vec<u8>>,
    /// The key's regions, shared.
    pub regions: Arc<Vec<u8>>,
    /// Collage width and height.
    pub res: [u32; 2],
    /// The seamless blend.
    pub seamless: bool,
    /// What the canvas shows.
    pub view: (ViewMode, Option<u32>),
    /// Show the preview and thumbnails denoised (when the denoiser is installed).
    pub denoise: bool,
}

/// The session's state.
#[derive(Debug)]
pub struct Session {
    /// The keys by frame; the current one always exists.
    pub keys: BTreeMap<u32, Key>,
    /// The frame edited.
    pub frame: u32,
    /// Collage width and height.
    pub res: [u32; 2],
    /// The seamless blend (the remapper's `--seamless` preset).
    pub seamless: bool,
    /// What the canvas shows.
    pub view: (ViewMode, Option<u32>),
    /// Show the preview and thumbnails denoised (the page's toggle; on by default).
    pub denoise: bool,
    /// Grows with every change that makes images stale; images carry it.
    pub seq: u64,
    /// Grows with every edit a save keeps (strokes, undo, cameras, keys, the blend) and not with
    /// what the canvas shows: unsaved changes are edits since the last save.
    pub edits: u64,
}

impl Session {
    /// A session at `frame` with one key.
    pub fn new(res: [u32; 2], frame: u32, key: Key) -> Self {
        Self {
            keys: BTreeMap::from([(frame, key)]),
            frame,
            res,
            seamless: false,
            view: (ViewMode::Final, None),
            denoise: true,
            seq: 1,
            edits: 0,
        }
    }

    /// The key edited.
    pub fn key(&self) -> &Key {
        &self.keys[&self.frame]
    }

    fn key_mut(&mut self) -> &mut Key {
        self.keys.get_mut(&self.frame).expect("the current key exists")
    }

    /// The `state` message.
    pub fn state(&self, id: Option<u64>) -> Outbound {
        let key = self.key();
        let cameras: Vec<_> = key
            .cameras
            .iter()
            .map(|c| {
                json!({"index": c.index, "name": c.name, "color": c.colour(), "eye": c.eye,
                       "target": c.target, "up": c.up, "fov_deg": c.fov_deg})
            })
            .collect();
        Outbound::json(json!({
            "type": "state", "id": id, "cameras": cameras, "res": self.res, "frame": self.frame,
            "frames": self.keys.keys().collect::<Vec<_>>(), "seamless": self.seamless,
            "can_undo": key.maps.can_undo(), "can_redo": key.maps.can_redo(), "seq": self.seq,
            "view": {"mode": self.view.0, "camera": self.view.1},
            "denoise": self.denoise,
            "denoiser": tracer::denoise::Denoiser::shared().map(|d| d.version().to_owned()).ok(),
        }))
    }

    /// The `labels` message: the whole map of `layer`.
    pub fn labels(&self, layer: Layer) -> Outbound {
        let data = BASE64.encode(self.key().maps.layer(layer));
        Outbound::json(json!({"type": "labels", "layer": layer, "data": data, "frame": self.frame}))
    }

    /// A snapshot for the engine.
    pub fn snapshot(&self) -> Snapshot {
        let key = self.key();
        Snapshot {
            seq: self.seq,
            frame: self.frame,
            cameras: key.cameras.clone(),
            labels: Arc::new(key.maps.labels.clone()),
            regions: Arc::new(key.maps.regions.clone()),
            res: self.res,
            seamless: self.seamless,
            view: self.view,
            denoise: self.denoise,
        }
    }

    /// Applies a paint patch (base64 `data`) as one undo step; refuses a bad one whole.
    /// Returns whether the map changed.
    pub fn paint(&mut self, layer: Layer, rect: [u32; 4], data: &str) -> Result<bool> {
        let bytes =
            BASE64.decode(data).map_err(|e| StudioError::request(format!("data is not base64: {e}")))?;
        let key = self.key();
        let cameras = key.cameras.len() as u8;
        match layer {
            Layer::Labels => key.maps.check(rect, &bytes, |b| b <= cameras)?,
            Layer::Regions => key.maps.check(rect, &bytes, |_| true)?,
        }
        let changed = self.key_mut().maps.paint(layer, rect, &bytes);
        if changed {
            self.seq += 1;
            self.edits += 1;
        }
        Ok(changed)
    }

    /// Undoes (or with `redo`, redoes) a step, a stroke or a camera edit; returns the layer
    /// it touched (none for a camera edit).
    pub fn undo(&mut self, redo: bool) -> Option<Option<Layer>> {
        let key = self.key_mut();
        let undone = if redo { key.maps.redo() } else { key.maps.undo() }?;
        let layer = match undone {
            Undone::Layer(layer) => Some(layer),
            Undone::Camera(camera) => {
                let i = camera.index as usize - 1;
                key.cameras[i] = camera;
                None
            }
        };
        self.seq += 1;
        self.edits += 1;
        Some(layer)
    }

    /// Moves a camera (checked first), as one undo step (with the other edits of its drag).
    pub fn edit_camera(&mut self, edit: &crate::protocol::CameraEdit) -> Result<()> {
        let before = self.key().camera(edit.index)?.clone();
        let moved = before.edited(edit)?;
        let key = self.key_mut();
        key.cameras[edit.index as usize - 1] = moved.clone();
        key.maps.camera_edited(before, moved, edit.gesture);
        self.seq += 1;
        self.edits += 1;
        Ok(())
    }

    /// Adds a copy of camera `index`; returns the new camera's index.
    pub fn duplicate_camera(&mut self, index: u32) -> Result<u32> {
        let key = self.key();
        if key.cameras.len() >= MAX_CAMERAS {
            return Err(StudioError::request(format!("a key holds at most {MAX_CAMERAS} cameras")));
        }
        let copy = key.camera(index)?.clone();
        let new = key.cameras.len() as u32 + 1;
        let copy = StudioCamera { index: new, name: format!("{} copy", copy.name), ..copy };
        self.key_mut().cameras.push(copy);
        self.seq += 1;
        self.edits += 1;
        Ok(new)
    }

    /// Switches to the key at `frame`, creating it with `cameras` and blank maps if new.
    pub fn switch_frame(
        &mut self,
        frame: u32,
        cameras: impl FnOnce() -> Result<Vec<StudioCamera>>,
    ) -> Result<()> {
        if !self.keys.contains_key(&frame) {
            let [w, h] = self.res;
            self.keys.insert(frame, Key { cameras: cameras()?, maps: Maps::new(w, h) });
            self.edits += 1;
        }
        self.frame = frame;
        self.seq += 1;
        Ok(())
    }

    /// Sets what the canvas shows; a camera is needed for `source` and `weights`.
    pub fn set_view(&mut self, mode: ViewMode, camera: Option<u32>) -> Result<()> {
        let camera = match (mode, camera) {
            (ViewMode::Source | ViewMode::Weights, None) => {
                return Err(StudioError::request(format!("view {mode:?} needs a camera")));
            }
            (_, Some(c)) => Some(self.key().camera(c)?.index),
            (_, None) => None,
        };
        self.view = (mode, camera);
        self.seq += 1;
        Ok(())
    }

    /// Shows the preview denoised or raw.
    pub fn set_denoise(&mut self, on: bool) {
        if self.denoise != on {
            self.denoise = on;
            self.seq += 1;
        }
    }

    /// Sets the remapper's blend.
    pub fn set_seamless(&mut self, seamless: bool) {
        if self.seamless != seamless {
            self.seamless = seamless;
            self.seq += 1;
            self.edits += 1;
        }
    }
}
