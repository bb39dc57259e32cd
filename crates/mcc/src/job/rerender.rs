//! The scene rendered through a collage's rays (docs/design.md §6, §8): the lens reader
//! replaces every eye ray with one from a ray file, in memory or on disk, at any output
//! resolution, and the overscan border the views were rendered with can be cut off.

use crate::error::{MccError, Result};
use crate::lens_reader::{LensReader, RaySource};
use crate::ray_file::RayFile;
use glam::{UVec2, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tracer::camera::{Camera, CameraDesc, Projection};
use tracer::integrator::PathTracer;
use tracer::job::{CameraRender, Quality, RenderInfo, write_render};
use tracer::lens::LensChain;
use tracer::render::{Progress, Rendered};

/// What the EXR header names as the camera of a rerender.
const CAMERA: &str = "multicamera collage";

/// The camera of a render through the lens reader: it only carries the film size, since the
/// reader replaces every ray.
pub fn carrier_camera(resolution: UVec2) -> tracer::Result<Box<dyn Camera>> {
    let projection = Projection::Perspective { fov_y: 1.0 };
    CameraDesc::look_at("lens reader", Vec3::ZERO, -Vec3::Z, Vec3::Y, projection)?.build(resolution)
}

/// A rerender: the scene through `rays`, one frame.
#[derive(Clone, Debug)]
pub struct Rerender {
    /// The remapped rays (one per collage pixel).
    pub rays: Arc<RayFile>,
    /// The output resolution; `None`: the rays'.
    pub resolution: Option<UVec2>,
    /// A border to cut from every side, in collage pixels (undoes `--overscan`).
    pub crop: u32,
    /// The frame (passed to the lens reader; names the output).
    pub frame: u32,
    /// Samples, seed, depths and film layers.
    pub quality: Quality,
}

impl Rerender {
    /// A rerender of frame `frame` through `rays` at their resolution, default quality, no crop.
    pub fn new(rays: impl Into<Arc<RayFile>>, frame: u32) -> Self {
        Self { rays: rays.into(), resolution: None, crop: 0, frame, quality: Quality::DEFAULT }
    }

    /// A rerender through the lens file `path` (a remapped or in-betweened ray file).
    pub fn from_lens_file(path: &Path, frame: u32) -> Result<Self> {
        Ok(Self::new(RayFile::read(path)?, frame))
    }

    /// The film size before cropping.
    pub fn film_size(&self) -> UVec2 {
        self.resolution.unwrap_or(UVec2::new(self.rays.width, self.rays.height))
    }

    /// The border cut from the film, in output pixels (the crop scaled from the collage's
    /// width to the film's); `None` when it leaves nothing of the film.
    pub fn output_crop(&self) -> Option<u32> {
        let res = self.film_size();
        let n = (self.crop as f64 * res.x as f64 / self.rays.width as f64).round() as u32;
        (n == 0 || (2 * n as u64) < res.x.min(res.y) as u64).then_some(n)
    }

    /// Renders `tracer`'s scene (posed at this frame, prepared with `quality.tracer`) through
    /// the rays and crops the film. The crop is checked before anything is traced.
    pub fn run(&self, tracer: &PathTracer, progress: &dyn Progress) -> Result<Rendered> {
        let film = self.film_size();
        let crop = self.output_crop().ok_or_else(|| {
            MccError::Settings(format!("crop {} leaves nothing of a {}x{} image", self.crop, film.x, film.y))
        })?;
        let camera = carrier_camera(film)?;
        let mut lenses = LensChain::new();
        lenses.push(Box::new(LensReader::new(RaySource::Rays(Arc::clone(&self.rays)))));
        let job = CameraRender {
            tracer,
            camera: camera.as_ref(),
            name: "rerender",
            camera_id: 0,
            frame: self.frame,
            shutter: (0.0, 0.0),
            quality: self.quality,
        };
        let mut rendered = job.run(&mut lenses, progress)?;
        if crop > 0 {
            rendered.images = rendered.images.without_border(crop).expect("output_crop checked the border");
        }
        Ok(rendered)
    }

    /// Writes a finished rerender of `scene` to `exr` and its preview PNG beside it; returns
    /// the PNG's path.
    pub fn write(&self, exr: &Path, rendered: &Rendered, scene: &Path) -> Result<PathBuf> {
        let info = RenderInfo { scene, camera: CAMERA, frame: self.frame, quality: &self.quality };
        Ok(write_render(exr, rendered, &info)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray_file::StoredRay;
    use crate::test_util::sky_scene;
    use tracer::TracerError;
    use tracer::render::NoProgress;

    /// Rays looking down −Z from the origin, one per pixel of a `w` × `h` collage.
    fn rays(w: u32, h: u32) -> RayFile {
        let rays = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32 / w as f32 - 0.5, (p / w) as f32 / h as f32 - 0.5);
                StoredRay::new(Vec3::ZERO, Vec3::new(x, -y, -2.0).normalize())
            })
            .collect();
        RayFile::new(w, h, 0, 0, rays).unwrap()
    }

    /// Always cancelled.
    struct Stop;

    impl Progress for Stop {
        fn advance(&self, _samples: u64) {}
        fn cancelled(&self) -> bool {
            true
        }
    }

    /// The crop is given in collage pixels and scaled to the film; one that leaves nothing is
    /// refused before anything is traced; a cancelled rerender says so.
    #[test]
    fn crops_in_collage_pixels_and_refuses_what_leaves_nothing() {
        let sky = Vec3::new(0.5, 0.25, 0.125);
        let quality = Quality::DEFAULT.with_spp(1);
        let tracer = quality.tracer(&sky_scene(sky)).unwrap();
        let job = Rerender {
            resolution: Some(UVec2::new(20, 16)),
            crop: 2,
            quality,
            ..Rerender::new(rays(10, 8), 0)
        };
        assert_eq!(job.output_crop(), Some(4));
        let rendered = job.run(&tracer, &NoProgress).unwrap();
        let image = &rendered.images.image;
        assert_eq!((image.width, image.height), (12, 8));
        assert!(image.pixels.iter().all(|p| *p == sky));
        assert_eq!(rendered.images.samples.width, 12);

        let whole = Rerender { crop: 4, resolution: None, ..job.clone() };
        assert_eq!(whole.output_crop(), None);
        let err = whole.run(&tracer, &NoProgress).unwrap_err().to_string();
        assert!(err.contains("crop 4 leaves nothing of a 10x8 image"), "{err}");
        let err = job.run(&tracer, &Stop).unwrap_err();
        assert!(matches!(err, MccError::Tracer(TracerError::Cancelled)), "{err}");
    }
}
