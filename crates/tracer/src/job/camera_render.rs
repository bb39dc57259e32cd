//! One camera's render (docs/design/tracer.md §3.8): a prepared scene seen through a camera and its lens
//! chain at a frame, with progress and cancellation.

use super::Quality;
use crate::camera::Camera;
use crate::error::{Result, TracerError};
use crate::integrator::PathTracer;
use crate::lens::LensChain;
use crate::render::{Progress, RenderSettings, Rendered, render};

/// What to render: `camera` over `tracer`'s scene (prepared with `quality.tracer`), as view
/// `camera_id` of `frame`.
#[derive(Clone, Copy)]
pub struct CameraRender<'a> {
    /// The scene, prepared for tracing.
    pub tracer: &'a PathTracer,
    /// The camera (its resolution is the film's).
    pub camera: &'a dyn Camera,
    /// The camera's name, for progress and errors.
    pub name: &'a str,
    /// The view's number, passed to lens shaders (1-based; 0 for a collage's rerender).
    pub camera_id: u32,
    /// The frame, passed to lens shaders.
    pub frame: u32,
    /// Shutter open and close in frames after the frame's start; equal: no motion blur.
    pub shutter: (f32, f32),
    /// Samples, seed and film layers.
    pub quality: Quality,
}

impl CameraRender<'_> {
    /// Renders through `lenses`, reporting the samples to `progress` as one stage named after
    /// the camera. Errors name the camera; a cancelled render is [`TracerError::Cancelled`].
    pub fn run(&self, lenses: &mut LensChain, progress: &dyn Progress) -> Result<Rendered> {
        self.run_rows(lenses, progress, None)
    }

    /// Like [`CameraRender::run`], for the film rows `rows` only (`start..end`; `None`: all):
    /// a band of the image, each pixel as the whole render computes it (docs/farm.md).
    pub fn run_rows(
        &self,
        lenses: &mut LensChain,
        progress: &dyn Progress,
        rows: Option<(u32, u32)>,
    ) -> Result<Rendered> {
        let settings =
            RenderSettings { rows, ..self.quality.settings(self.frame, self.camera_id, self.shutter) };
        let res = self.camera.resolution();
        let height = rows.map_or(res.y, |(a, b)| b.saturating_sub(a));
        progress.begin(self.name, res.x as u64 * height as u64 * self.quality.spp as u64);
        let rendered = render(self.tracer, self.camera, lenses, &settings, progress);
        progress.finish();
        rendered.map_err(|e| match e {
            TracerError::Cancelled => e,
            e => TracerError::Render { camera: self.name.to_owned(), error: Box::new(e) },
        })
    }
}
