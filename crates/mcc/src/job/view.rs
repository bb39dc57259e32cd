//! A view rendered to files (docs/design.md §4.3, §4.4, §4.7, §8): a camera's render written as EXR
//! and PNG, with the lens writer recording its pixel-centre rays beside them and the tagger
//! stamping the view's number into the PNG when asked (what `render --lens-writer --tag` makes),
//! or one band of it (`render --tile I/N`, docs/farm.md), and told finished when it is.

use crate::error::{MccError, Result};
use crate::lens_writer::LensWriter;
use crate::names::view_rays_name;
use crate::ray_file::{RayFile, RayFormat};
use crate::tag::TagCode;
use std::path::{Path, PathBuf};
use tracer::image::RgbImage;
use tracer::image_io::{linear_to_srgb8, write_png_rgb8};
use tracer::job::{
    Band, CameraRender, Companion, Provenance, RenderInfo, SceneSetup, Stale, check_finished_with, write_exr,
    write_render,
};
use tracer::lens::LensChain;
use tracer::render::{Progress, Rendered};

/// A view to render: the camera's render, where it goes and what comes with it.
#[derive(Clone, Copy)]
pub struct ViewRender<'a> {
    /// The camera's render (its `camera_id` is the view's number).
    pub render: CameraRender<'a>,
    /// The scene file, recorded in the EXR header.
    pub scene: &'a Path,
    /// The EXR to write; the PNG goes beside it.
    pub exr: &'a Path,
    /// Record the pixel-centre rays as `frameFFFFcameraCC.{mcr|txt}` in the EXR's folder.
    pub rays: Option<RayFormat>,
    /// Stamp the view's number into the PNG's low bits with this code.
    pub tag: Option<TagCode>,
    /// The camera model and environment image, for the EXR header.
    pub provenance: Provenance<'a>,
    /// How the scene was set up, for the EXR header.
    pub setup: Option<&'a SceneSetup>,
    /// Only this band of the view, written to [`Band::path`] of `exr` without a PNG (no rays,
    /// no tag: those need the whole view).
    pub band: Option<Band>,
}

/// The files a [`ViewRender`] wrote.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ViewFiles {
    /// The EXR.
    pub exr: PathBuf,
    /// The PNG beside it (tagged or a plain preview); none for a band.
    pub png: Option<PathBuf>,
    /// The ray file, if recorded.
    pub rays: Option<PathBuf>,
}

impl ViewRender<'_> {
    /// The EXR header this view's file records.
    pub fn info(&self) -> RenderInfo<'_> {
        let res = self.render.camera.resolution();
        RenderInfo {
            shutter: self.render.shutter,
            provenance: self.provenance,
            setup: self.setup,
            band: self.band.map(|b| (b, res)),
            ..RenderInfo::new(self.scene, self.render.name, self.render.frame, &self.render.quality)
        }
    }

    /// The file this job writes its image to: the EXR, or its band's file.
    pub fn target(&self) -> PathBuf {
        self.band.map_or_else(|| self.exr.to_path_buf(), |b| b.path(self.exr))
    }

    /// The rows of the view this job renders, `None` for all; `Some` empty for a band past the
    /// last row (nothing to render).
    pub fn rows(&self) -> Option<std::ops::Range<u32>> {
        self.band.map(|b| b.rows(self.render.camera.resolution().y))
    }

    /// The ray file the lens writer records for this view, if it records one.
    pub fn rays_path(&self) -> Option<PathBuf> {
        let dir = self.exr.parent().map(Path::to_path_buf).unwrap_or_default();
        self.rays.map(|format| dir.join(view_rays_name(self.render.frame, self.render.camera_id, format)))
    }

    /// `Ok` when the view's files on disk are a finished render of this job (docs/farm.md), so it
    /// can be skipped; else why not. By `tracer::job::check_finished`'s rule, and with the
    /// lens writer's ray file (there, read back whole, one ray per pixel of the view) and the
    /// tag (every pixel of the PNG carries the view's number in this code) when the job makes
    /// them.
    pub fn check(&self) -> std::result::Result<(), Stale> {
        let res = self.render.camera.resolution();
        let size = self.rows().map_or(res, |r| glam::UVec2::new(res.x, r.len() as u32));
        let png = self.exr.with_extension("png");
        let target = self.target();
        let id = self.render.camera_id;
        let tagged = |path: &Path| -> std::result::Result<(), String> {
            let code = self.tag.expect("checked only when tagging");
            let image = crate::png::read_image(path).map_err(|e| e.to_string())?.to_rgb8();
            match image.pixels().position(|p| code.decode(p.0) != id) {
                None => Ok(()),
                Some(at) => Err(format!(
                    "pixel ({}, {}) is not tagged as view {id}",
                    at as u32 % image.width(),
                    at as u32 / image.width()
                )),
            }
        };
        let whole_rays = |path: &Path| -> std::result::Result<(), String> {
            let rays = RayFile::read(path).map_err(|e| e.to_string())?;
            let got = glam::UVec2::new(rays.width, rays.height);
            if got != res {
                return Err(format!("{}x{} rays, the view {}x{}", got.x, got.y, res.x, res.y));
            }
            Ok(())
        };
        let rays = self.rays_path();
        let mut companions = Vec::new();
        if self.tag.is_some() && self.band.is_none() {
            companions.push(Companion { path: &png, check: &tagged });
        }
        if let Some(path) = &rays {
            companions.push(Companion { path, check: &whole_rays });
        }
        let png = self.band.is_none().then_some(png.as_path());
        check_finished_with(&target, png, &self.info().settings(), size, &companions)
    }

    /// Renders the view and writes its files; returns the render and what was written.
    pub fn run(&self, progress: &dyn Progress) -> Result<(Rendered, ViewFiles)> {
        let id = self.render.camera_id;
        if let Some(code) = self.tag {
            code.check_id(id)?;
        }
        if let Some(band) = self.band.filter(|_| self.rays.is_some() || self.tag.is_some()) {
            return Err(MccError::Settings(format!(
                "band {band}: the lens writer's rays and the camera tag need the whole view; render it \
                 without --tile"
            )));
        }
        let dir = self.exr.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut lenses = LensChain::new();
        if let Some(format) = self.rays {
            lenses.push(Box::new(LensWriter::new(&dir, format)));
        }
        let rows = self.rows();
        if let Some(rows) = rows.as_ref().filter(|r| r.is_empty()) {
            let res = self.render.camera.resolution();
            return Err(MccError::Settings(format!(
                "band {} of a {}-row image is empty (rows {}..{}): nothing to render",
                self.band.expect("rows come from a band"),
                res.y,
                rows.start,
                rows.end
            )));
        }
        let rendered = self.render.run_rows(&mut lenses, progress, rows.map(|r| (r.start, r.end)))?;
        let info = self.info();
        let target = self.target();
        let png = match (self.band, self.tag) {
            (Some(_), _) => {
                write_exr(&target, &rendered, &info)?;
                None
            }
            (None, None) => Some(write_render(self.exr, &rendered, &info)?),
            (None, Some(code)) => {
                let denoised = write_exr(self.exr, &rendered, &info)?;
                let png = self.exr.with_extension("png");
                write_tagged_png(&png, denoised.as_ref().unwrap_or(&rendered.images.image), code, id)?;
                Some(png)
            }
        };
        Ok((rendered, ViewFiles { exr: target, png, rays: self.rays_path() }))
    }
}

/// Writes `image` (linear) as an 8-bit sRGB PNG tagged with `camera`.
fn write_tagged_png(path: &Path, image: &RgbImage, code: TagCode, camera: u32) -> Result<()> {
    let bytes: Vec<u8> = image.pixels.iter().flat_map(|p| p.to_array().map(linear_to_srgb8)).collect();
    let mut rgb = image::RgbImage::from_raw(image.width, image.height, bytes)
        .ok_or_else(|| MccError::image(path, "the image's size does not match its pixels"))?;
    code.tag_rgb(&mut rgb, camera)?;
    write_png_rgb8(path, image.width, image.height, rgb.as_raw())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray_file::RayFile;
    use crate::test_util::{forward_camera, scratch_dir, sky_scene};
    use glam::{UVec2, Vec3};
    use tracer::camera::CameraSample;
    use tracer::job::Quality;
    use tracer::render::NoProgress;

    /// A tagged view with rays writes its EXR, a PNG whose every pixel carries the view's
    /// number, and the camera's own pixel-centre rays; an untagged one a plain preview.
    #[test]
    fn writes_the_view_its_tag_and_its_rays() {
        let dir = scratch_dir("view-render");
        let sky = Vec3::new(0.2, 0.4, 0.6);
        let quality = Quality::DEFAULT.with_spp(2);
        let tracer = quality.tracer(&sky_scene(sky)).unwrap();
        let camera = forward_camera(UVec2::new(8, 6));
        let render = CameraRender {
            tracer: &tracer,
            camera: camera.as_ref(),
            name: "forward",
            camera_id: 5,
            frame: 3,
            shutter: (0.0, 0.0),
            quality,
        };
        let exr = dir.join("views/frame0003camera05.exr");
        std::fs::create_dir_all(exr.parent().unwrap()).unwrap();
        let code = TagCode::default();
        let job = ViewRender {
            render,
            scene: Path::new("sky"),
            exr: &exr,
            rays: Some(RayFormat::Text),
            tag: Some(code),
            provenance: Provenance::default(),
            setup: None,
            band: None,
        };
        let (rendered, files) = job.run(&NoProgress).unwrap();
        assert!(rendered.images.image.pixels.iter().all(|p| *p == sky));
        assert_eq!(files.png, Some(dir.join("views/frame0003camera05.png")));
        assert_eq!(files.rays.as_deref(), Some(dir.join("views/frame0003camera05.txt").as_path()));
        assert!(files.exr.is_file());
        let png = crate::png::read_image(files.png.as_ref().unwrap()).unwrap().to_rgb8();
        assert!(png.pixels().all(|p| code.decode(p.0) == 5));
        let rays = RayFile::read(files.rays.as_ref().unwrap()).unwrap();
        let centre = camera.generate_ray(&CameraSample::pixel_centre(7, 2, 3.0)).unwrap();
        let stored = rays.get(7, 2);
        assert!((stored.direction - centre.direction).length() < 1e-6 && stored.origin == centre.origin);

        let plain = ViewRender { rays: None, tag: None, exr: &dir.join("plain.exr"), ..job };
        let (_, files) = plain.run(&NoProgress).unwrap();
        assert_eq!(files.rays, None);
        let png = crate::png::read_image(files.png.as_ref().unwrap()).unwrap().to_rgb8();
        let srgb = sky.to_array().map(tracer::image_io::linear_to_srgb8);
        assert!(png.pixels().all(|p| p.0 == srgb));
        // Finished: the EXR, the tagged PNG and the rays; each missing, damaged or changed piece
        // says so.
        assert_eq!(job.check(), Ok(()));
        let rays_file = job.rays_path().unwrap();
        let more = Quality { spp: 3, ..quality };
        let stale = ViewRender { render: CameraRender { quality: more, ..render }, ..job };
        assert_eq!(stale.check().unwrap_err().to_string(), "spp 2 ≠ 3");
        std::fs::remove_file(&rays_file).unwrap();
        assert_eq!(job.check(), Err(Stale::Missing(rays_file.clone())));
        std::fs::write(&rays_file, "garbage").unwrap();
        assert!(matches!(job.check(), Err(Stale::Damaged { path, .. }) if path == rays_file));
        let other_id = ViewRender { rays: None, render: CameraRender { camera_id: 6, ..render }, ..job };
        let err = other_id.check().unwrap_err().to_string();
        assert!(err.contains("not tagged as view 6"), "{err}");
        let bad = ViewRender { render: CameraRender { camera_id: 64, ..render }, ..job };
        assert!(bad.run(&NoProgress).unwrap_err().to_string().contains("camera id 64"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
