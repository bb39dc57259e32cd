//! Lens shaders (docs/design/tracer.md §3.8): after the camera builds an eye ray, each
//! shader of the chain is called in order and may rewrite the ray or drop the sample. A shader
//! gets a per-frame set-up call before any ray is traced and a tear-down call after the last.
//!
//! Set-up receives a [`RayGenerator`] for *everything upstream of the shader*: the camera and the
//! shaders before it in the chain. That is what lets a shader such as the MCC lens writer record
//! the exact pixel-centre ray that reaches it without any per-ray locking or bookkeeping.

use crate::camera::{Camera, CameraSample};
use crate::error::{LensError, Result, TracerError};
use crate::ray::Ray;
use glam::UVec2;

/// Produces the eye ray for a camera sample: a camera, or a camera followed by lens shaders.
pub trait RayGenerator: Sync {
    /// The ray for `sample`, or `None` if the sample is dropped.
    fn generate(&self, sample: &CameraSample) -> Option<Ray>;
}

/// What a lens shader learns about the frame it is about to shade.
pub struct FrameContext<'a> {
    /// The frame number being rendered.
    pub frame: u32,
    /// The view's camera number (1-based, in command-line order; docs/design/mcc.md §4.3).
    pub camera_id: u32,
    /// Film resolution in pixels.
    pub resolution: UVec2,
    /// Shutter interval in scene time (frames): eye rays carry times in `[shutter.0, shutter.1)`.
    pub shutter: (f32, f32),
    /// The camera and every lens shader before this one.
    pub upstream: &'a dyn RayGenerator,
}

/// A lens shader: rewrites (or drops) eye rays between the camera and the integrator.
///
/// `shade` is called once per camera sample from many threads at once, so it takes `&self` and
/// must not lock; anything it needs per frame is prepared in [`LensShader::begin_frame`].
pub trait LensShader: Send + Sync {
    /// A short name for messages.
    fn name(&self) -> &str;

    /// Per-frame set-up, before any ray of the frame is traced.
    fn begin_frame(&mut self, _ctx: &FrameContext<'_>) -> Result<(), LensError> {
        Ok(())
    }

    /// Rewrites the eye ray of `sample` (which reached this shader as `ray`), or drops it.
    fn shade(&self, sample: &CameraSample, ray: Ray) -> Option<Ray>;

    /// Per-frame tear-down, after the last ray of the frame (e.g. write a file).
    fn end_frame(&mut self, _ctx: &FrameContext<'_>) -> Result<(), LensError> {
        Ok(())
    }
}

/// A camera followed by a (possibly empty) prefix of a lens chain.
struct Upstream<'a> {
    camera: &'a dyn Camera,
    shaders: &'a [Box<dyn LensShader>],
}

impl RayGenerator for Upstream<'_> {
    #[inline]
    fn generate(&self, sample: &CameraSample) -> Option<Ray> {
        let mut ray = self.camera.generate_ray(sample)?;
        for shader in self.shaders {
            ray = shader.shade(sample, ray)?;
        }
        Some(ray)
    }
}

/// An ordered chain of lens shaders.
#[derive(Default)]
pub struct LensChain {
    shaders: Vec<Box<dyn LensShader>>,
}

impl LensChain {
    /// An empty chain: the camera's rays pass unchanged.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends a shader at the end of the chain.
    pub fn push(&mut self, shader: Box<dyn LensShader>) {
        self.shaders.push(shader);
    }

    /// True when the chain holds no shader.
    pub fn is_empty(&self) -> bool {
        self.shaders.is_empty()
    }

    /// The shaders, in order.
    pub fn shaders(&self) -> &[Box<dyn LensShader>] {
        &self.shaders
    }

    /// Calls every shader's per-frame set-up, in order; each sees the camera and the shaders
    /// before it as its upstream.
    pub fn begin_frame(&mut self, camera: &dyn Camera, frame: FrameInfo) -> Result<()> {
        for i in 0..self.shaders.len() {
            let (before, rest) = self.shaders.split_at_mut(i);
            let upstream = Upstream { camera, shaders: before };
            let ctx = frame.context(camera, &upstream);
            let shader = &mut rest[0];
            shader
                .begin_frame(&ctx)
                .map_err(|error| TracerError::Lens { shader: shader.name().to_owned(), error })?;
        }
        Ok(())
    }

    /// Calls every shader's per-frame tear-down, in order.
    pub fn end_frame(&mut self, camera: &dyn Camera, frame: FrameInfo) -> Result<()> {
        for i in 0..self.shaders.len() {
            let (before, rest) = self.shaders.split_at_mut(i);
            let upstream = Upstream { camera, shaders: before };
            let ctx = frame.context(camera, &upstream);
            let shader = &mut rest[0];
            shader
                .end_frame(&ctx)
                .map_err(|error| TracerError::Lens { shader: shader.name().to_owned(), error })?;
        }
        Ok(())
    }

    /// A generator for the whole pipeline: the camera, then every shader.
    pub fn generator<'a>(&'a self, camera: &'a dyn Camera) -> impl RayGenerator + 'a {
        Upstream { camera, shaders: &self.shaders }
    }
}

/// The per-frame facts a chain passes on to its shaders (see [`FrameContext`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameInfo {
    /// Frame number.
    pub frame: u32,
    /// The view's camera number (1-based).
    pub camera_id: u32,
    /// Shutter interval in frames.
    pub shutter: (f32, f32),
}

impl FrameInfo {
    fn context<'a>(&self, camera: &dyn Camera, upstream: &'a dyn RayGenerator) -> FrameContext<'a> {
        FrameContext {
            frame: self.frame,
            camera_id: self.camera_id,
            resolution: camera.resolution(),
            shutter: self.shutter,
            upstream,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::{CameraDesc, Projection};
    use glam::{Vec2, Vec3};
    use std::sync::{Arc, Mutex};

    fn camera() -> Box<dyn Camera> {
        CameraDesc::look_at("c", Vec3::ZERO, -Vec3::Z, Vec3::Y, Projection::Perspective { fov_y: 1.0 })
            .unwrap()
            .build(UVec2::new(8, 4))
            .unwrap()
    }

    /// Appends a tag to the ray's time so the order of application is visible.
    struct Tagger {
        tag: f32,
        seen_at_begin: Arc<Mutex<Vec<f32>>>,
    }

    impl LensShader for Tagger {
        fn name(&self) -> &str {
            "tagger"
        }
        fn begin_frame(&mut self, ctx: &FrameContext<'_>) -> Result<(), LensError> {
            let r = ctx.upstream.generate(&CameraSample::pixel_centre(0, 0, 0.0)).unwrap();
            self.seen_at_begin.lock().unwrap().push(r.time);
            Ok(())
        }
        fn shade(&self, _s: &CameraSample, mut ray: Ray) -> Option<Ray> {
            ray.time = ray.time * 10.0 + self.tag;
            Some(ray)
        }
    }

    #[test]
    fn chain_runs_in_order_and_upstream_is_the_prefix() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let mut chain = LensChain::new();
        chain.push(Box::new(Tagger { tag: 1.0, seen_at_begin: seen.clone() }));
        chain.push(Box::new(Tagger { tag: 2.0, seen_at_begin: seen.clone() }));
        let cam = camera();
        chain.begin_frame(cam.as_ref(), FrameInfo { frame: 0, camera_id: 1, shutter: (0.0, 0.0) }).unwrap();
        // First shader saw the bare camera ray (time 0); the second saw the first's output (1).
        assert_eq!(*seen.lock().unwrap(), vec![0.0, 1.0]);
        let s = CameraSample { p_film: Vec2::new(1.0, 1.0), p_lens: Vec2::ZERO, time: 0.0 };
        assert_eq!(chain.generator(cam.as_ref()).generate(&s).unwrap().time, 12.0);
    }

    struct Failing;
    impl LensShader for Failing {
        fn name(&self) -> &str {
            "failing"
        }
        fn begin_frame(&mut self, _ctx: &FrameContext<'_>) -> Result<(), LensError> {
            Err("no such file".into())
        }
        fn shade(&self, _s: &CameraSample, _ray: Ray) -> Option<Ray> {
            None
        }
    }

    #[test]
    fn set_up_errors_name_the_shader() {
        let mut chain = LensChain::new();
        chain.push(Box::new(Failing));
        let cam = camera();
        let err = chain
            .begin_frame(cam.as_ref(), FrameInfo { frame: 0, camera_id: 1, shutter: (0.0, 0.0) })
            .unwrap_err();
        assert_eq!(err.to_string(), "lens shader 'failing': no such file");
    }
}
