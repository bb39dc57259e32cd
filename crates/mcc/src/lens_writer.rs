//! The lens writer (docs/design/mcc.md §4.7, `render --lens-writer`): a lens shader that records the
//! pixel-centre eye ray of every pixel of a source view into `frameFFFFcameraCC.{mcr|txt}`.
//!
//! The column's writer appended one line per traced ray inside a lock — slow, and it needed pixel
//! coordinates on every line because the order was arbitrary. Here the shader asks its upstream
//! (the camera and every lens shader before it in the chain) for each pixel-centre ray once, in
//! [`LensShader::begin_frame`], with rows in parallel and no lock at all; `shade` passes rays
//! through untouched, and [`LensShader::end_frame`] writes the file atomically. The rays are
//! exactly what reaches this shader for the sample (i + ½, j + ½), lens centre, time = the
//! shutter's opening, whatever sampling the render itself uses.

use crate::error::MccError;
use crate::names::view_rays_name;
use crate::ray_file::{RayFile, RayFormat, StoredRay};
use glam::UVec2;
use rayon::prelude::*;
use std::path::PathBuf;
use tracer::camera::CameraSample;
use tracer::error::LensError;
use tracer::lens::{FrameContext, FrameInfo, LensShader, RayGenerator};
use tracer::ray::Ray;

/// Records every pixel-centre eye ray of a view and writes its ray file.
#[derive(Debug)]
pub struct LensWriter {
    dir: PathBuf,
    format: RayFormat,
    /// The frame being recorded (rays filled in `begin_frame`, written in `end_frame`).
    current: Option<RayFile>,
}

impl LensWriter {
    /// A writer that puts its files into `dir` (created if missing) in `format`.
    pub fn new(dir: impl Into<PathBuf>, format: RayFormat) -> Self {
        Self { dir: dir.into(), format, current: None }
    }

    /// Records the frame's rays from `ctx.upstream`.
    fn record(&mut self, ctx: &FrameContext<'_>) -> Result<(), MccError> {
        std::fs::create_dir_all(&self.dir).map_err(|e| MccError::io(&self.dir, e))?;
        // Reuse last frame's allocation: the size rarely changes between frames.
        let reuse = self.current.take().map(|f| f.rays).unwrap_or_default();
        let frame = FrameInfo { frame: ctx.frame, camera_id: ctx.camera_id, shutter: ctx.shutter };
        self.current = Some(pixel_centre_rays(ctx.upstream, ctx.resolution, frame, reuse)?);
        Ok(())
    }
}

/// The pixel-centre eye ray of every pixel of a `resolution` film from `upstream` (lens centre,
/// time = the shutter's opening), as the view's ray file for `frame`: what the lens writer
/// records, and what the studio takes from a camera model without tracing (docs/design/mcc.md
/// §4.7). `reuse` is an allocation to fill. Rows run in parallel; a dropped or bad ray is an
/// error naming the first such pixel, whatever the thread count.
pub fn pixel_centre_rays(
    upstream: &dyn RayGenerator,
    resolution: UVec2,
    frame: FrameInfo,
    mut rays: Vec<StoredRay>,
) -> Result<RayFile, MccError> {
    let (w, h) = (resolution.x, resolution.y);
    rays.clear();
    rays.resize(w as usize * h as usize, StoredRay::default());
    let time = frame.shutter.0;
    // Every row reports its first bad pixel; the smallest (row, column) wins, so the error is
    // the same whatever the thread count.
    let problem = rays
        .par_chunks_mut(w.max(1) as usize)
        .enumerate()
        .filter_map(|(j, row)| {
            for (i, out) in row.iter_mut().enumerate() {
                let (i, j) = (i as u32, j as u32);
                let Some(ray) = upstream.generate(&CameraSample::pixel_centre(i, j, time)) else {
                    return Some((j, i, None));
                };
                *out = StoredRay::new(ray.origin, ray.direction);
                if let Some(defect) = out.defect() {
                    return Some((j, i, Some(defect)));
                }
            }
            None
        })
        .min_by_key(|&(j, i, _)| (j, i));
    let (frame, camera) = (frame.frame, frame.camera_id);
    if let Some((j, i, defect)) = problem {
        return Err(match defect {
            None => MccError::DroppedRay { frame, camera, i, j },
            Some(message) => MccError::BadRay { frame, camera, i, j, message },
        });
    }
    RayFile::new(w, h, frame, camera, rays)
}

impl LensShader for LensWriter {
    fn name(&self) -> &str {
        "lens writer"
    }

    fn begin_frame(&mut self, ctx: &FrameContext<'_>) -> Result<(), LensError> {
        self.record(ctx).map_err(|e| Box::new(e) as LensError)
    }

    #[inline]
    fn shade(&self, _sample: &CameraSample, ray: Ray) -> Option<Ray> {
        Some(ray)
    }

    fn end_frame(&mut self, ctx: &FrameContext<'_>) -> Result<(), LensError> {
        let Some(file) = &self.current else {
            return Err("end_frame without begin_frame: no rays recorded".into());
        };
        let path = self.dir.join(view_rays_name(ctx.frame, ctx.camera_id, self.format));
        file.write(&path, self.format).map_err(|e| Box::new(e) as LensError)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::scratch_dir;
    use glam::Vec3;
    use tracer::camera::{Camera, CameraDesc, Projection};
    use tracer::lens::LensChain;

    fn camera(projection: Projection, res: UVec2) -> Box<dyn Camera> {
        CameraDesc::look_at("c", Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.5, -1.0), Vec3::Y, projection)
            .unwrap()
            .build(res)
            .unwrap()
    }

    const INFO: FrameInfo = FrameInfo { frame: 5, camera_id: 3, shutter: (5.0, 5.5) };

    fn bits(r: &StoredRay) -> [u32; 6] {
        bytemuck::cast(*r)
    }

    #[test]
    fn records_the_cameras_pixel_centre_rays_bit_for_bit() {
        let dir = scratch_dir("lens-writer");
        let res = UVec2::new(37, 21);
        for (projection, format) in [
            (Projection::Perspective { fov_y: 0.9 }, RayFormat::Binary),
            (Projection::ThinLens { fov_y: 0.9, lens_radius: 0.2, focus_distance: 4.0 }, RayFormat::Text),
            (Projection::Equirectangular, RayFormat::Binary),
        ] {
            let cam = camera(projection, res);
            let mut chain = LensChain::new();
            chain.push(Box::new(LensWriter::new(&dir, format)));
            chain.begin_frame(cam.as_ref(), INFO).unwrap();
            chain.end_frame(cam.as_ref(), INFO).unwrap();
            let path = dir.join(format!("frame0005camera03.{}", format.extension()));
            let file = RayFile::read(&path).unwrap();
            assert_eq!((file.width, file.height), (37, 21));
            if format == RayFormat::Binary {
                assert_eq!((file.frame, file.camera_id, file.computed), (5, 3, false));
            }
            for j in 0..21 {
                for i in 0..37 {
                    let r = cam.generate_ray(&CameraSample::pixel_centre(i, j, 5.0)).unwrap();
                    assert_eq!(
                        bits(file.get(i, j)),
                        bits(&StoredRay::new(r.origin, r.direction)),
                        "{projection:?} ({i}, {j})"
                    );
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Turns every ray by a fixed rotation and shifts its origin: visible in what follows.
    struct Twist;
    impl LensShader for Twist {
        fn name(&self) -> &str {
            "twist"
        }
        fn shade(&self, _s: &CameraSample, ray: Ray) -> Option<Ray> {
            let q = glam::Quat::from_rotation_y(0.3);
            Some(Ray { origin: ray.origin + Vec3::X, direction: q * ray.direction, time: ray.time })
        }
    }

    #[test]
    fn records_what_earlier_shaders_made_and_passes_rays_through() {
        let dir = scratch_dir("lens-writer-chain");
        let res = UVec2::new(8, 6);
        let cam = camera(Projection::Perspective { fov_y: 1.0 }, res);
        let mut chain = LensChain::new();
        chain.push(Box::new(Twist));
        chain.push(Box::new(LensWriter::new(&dir, RayFormat::Binary)));
        chain.begin_frame(cam.as_ref(), INFO).unwrap();
        chain.end_frame(cam.as_ref(), INFO).unwrap();
        // The full pipeline's rays are the twisted ones, and the writer does not change them.
        let pipeline = chain.generator(cam.as_ref());
        let file = RayFile::read(&dir.join("frame0005camera03.mcr")).unwrap();
        for j in 0..6 {
            for i in 0..8 {
                let want = pipeline.generate(&CameraSample::pixel_centre(i, j, 5.0)).unwrap();
                assert_eq!(bits(file.get(i, j)), bits(&StoredRay::new(want.origin, want.direction)));
                let bare = cam.generate_ray(&CameraSample::pixel_centre(i, j, 5.0)).unwrap();
                assert_ne!(file.get(i, j).origin, bare.origin);
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn dropped_pixels_are_errors_naming_camera_and_pixel() {
        let dir = scratch_dir("lens-writer-fisheye");
        let cam = camera(Projection::Fisheye { fov: 3.0 }, UVec2::new(16, 16));
        let mut chain = LensChain::new();
        chain.push(Box::new(LensWriter::new(&dir, RayFormat::Binary)));
        let err = chain.begin_frame(cam.as_ref(), INFO).unwrap_err().to_string();
        assert!(
            err.contains("lens writer") && err.contains("camera 3") && err.contains("pixel (0, 0)"),
            "{err}"
        );
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
