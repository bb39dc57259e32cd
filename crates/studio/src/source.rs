//! The scene a studio session renders (docs/studio.md, "Engine"): loaded once, posed per key
//! frame, with the cameras the session was started with.

use crate::camera::StudioCamera;
use crate::error::{Result, StudioError};
use std::path::PathBuf;
use std::sync::Arc;
use tracer::integrator::PathTracer;
use tracer::job::{Quality, SceneSetup};
use tracer::scene::{CameraSelector, DEFAULT_MOTION_STEPS, Scene};

/// The scene file, loaded, and which of its cameras the studio starts with.
pub struct SceneSource {
    /// The scene file.
    pub path: PathBuf,
    /// How it was loaded (frame rate, overrides).
    pub setup: SceneSetup,
    scene: Scene,
    /// The names of the cameras to start each key with (all the scene's when empty).
    pub names: Vec<String>,
}

impl SceneSource {
    /// Loads `path`; `names` picks cameras by name or number from 1, as `render --camera` does
    /// (every camera when empty). An unknown one is an error listing the scene's cameras.
    pub fn load(path: PathBuf, names: Vec<String>) -> Result<Self> {
        let setup = SceneSetup::default();
        let scene = setup.load(&path)?;
        for name in &names {
            scene.camera(&CameraSelector::parse(name))?;
        }
        if scene.cameras.is_empty() {
            return Err(StudioError::Project {
                path,
                message: "the scene has no camera: the studio needs at least one to paint".into(),
            });
        }
        Ok(Self { path, setup, scene, names })
    }

    /// The scene posed at `frame` (the scene itself when it is not animated).
    pub fn posed(&self, frame: u32) -> Result<Scene> {
        Ok(self.setup.at_frame(self.scene.clone(), frame)?)
    }

    /// The scene at `frame` prepared for tracing with `quality`'s depths.
    pub fn tracer(&self, frame: u32, quality: &Quality) -> Result<Arc<PathTracer>> {
        Ok(Arc::new(quality.tracer(&self.posed(frame)?)?))
    }

    /// The scene at `frame` with its moving geometry in motion over `shutter` (frames after
    /// the frame's start, at the default motion steps), prepared for tracing with `quality`'s
    /// depths: what `rerender --shutter` traces.
    pub fn tracer_in_shutter(
        &self,
        frame: u32,
        shutter: (f32, f32),
        quality: &Quality,
    ) -> Result<Arc<PathTracer>> {
        let scene =
            self.setup.at_frame_in_shutter(self.scene.clone(), frame, shutter, DEFAULT_MOTION_STEPS)?;
        Ok(Arc::new(quality.tracer(&scene)?))
    }

    /// The starting cameras of a key at `frame`, numbered from 1.
    pub fn cameras(&self, frame: u32) -> Result<Vec<StudioCamera>> {
        let scene = self.posed(frame)?;
        let descs: Vec<_> = if self.names.is_empty() {
            scene.cameras.iter().collect()
        } else {
            let pick = |n: &String| scene.camera(&CameraSelector::parse(n));
            self.names.iter().map(pick).collect::<tracer::Result<_>>()?
        };
        Ok(descs.iter().enumerate().map(|(i, d)| StudioCamera::from_desc(i as u32 + 1, d)).collect())
    }
}
