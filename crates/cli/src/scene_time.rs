//! Scene time (docs/design.md §3.1 scenes, §8 workflow): an animated glTF scene is posed at frame /
//! fps seconds for every command that renders; a static scene is used as loaded (no rebuild).

use anyhow::{Context, bail};
use tracer::scene::Scene;

/// Frames per second when --fps is not given (film's rate).
pub const DEFAULT_FPS: f32 = 24.0;

/// The scene time of `frame` at `fps` frames per second, in seconds (computed in f64 so that
/// frame / fps rounds once).
pub fn frame_seconds(frame: u32, fps: f32) -> f32 {
    (frame as f64 / fps as f64) as f32
}

/// Refuses a frame rate that is not a positive finite number.
pub fn check_fps(fps: f32) -> anyhow::Result<()> {
    if !(fps.is_finite() && fps > 0.0) {
        bail!("--fps {fps}: the frame rate must be a positive number of frames per second");
    }
    Ok(())
}

/// Whether the scene moves (has keyframe animation): only then is it re-posed per frame.
pub fn is_animated(scene: &Scene) -> bool {
    scene.animation.is_some()
}

/// `scene` posed at `frame` / `fps` seconds; a static scene is returned as it is.
pub fn at_frame(scene: Scene, frame: u32, fps: f32) -> anyhow::Result<Scene> {
    check_fps(fps)?;
    if !is_animated(&scene) {
        return Ok(scene);
    }
    let seconds = frame_seconds(frame, fps);
    scene
        .at_time(seconds)
        .with_context(|| format!("posing the scene at frame {frame} ({seconds} s at {fps} fps)"))
}
