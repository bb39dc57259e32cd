//! The scene rendered through a collage's rays (docs/design/workflow.md §6, §8): the lens reader
//! replaces every eye ray with one from a ray file, in memory or on disk, at any output
//! resolution, and the overscan border the views were rendered with can be cut off; one band of
//! the output (`--tile I/N`, docs/farm.md) renders alone, and finished outputs are told from
//! stale ones.

use crate::error::{MccError, Result};
use crate::lens_reader::{LensReader, RaySource};
use crate::ray_file::RayFile;
use glam::{UVec2, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tracer::camera::{Camera, CameraDesc, Projection};
use tracer::integrator::PathTracer;
use tracer::job::{
    Band, CameraRender, EnvironmentImage, Provenance, Quality, RenderInfo, SceneSetup, Stale, check_finished,
    write_exr, write_render,
};
use tracer::lens::LensChain;
use tracer::render::{Progress, Rendered};

/// What the EXR header names as the camera of a rerender.
const CAMERA: &str = "multicamera collage";
/// EXR header key of the collage a rerender's rays were remapped from (docs/design/tracer.md §3.6).
pub const COLLAGE_KEY: &str = "mcctrace/collage";
/// EXR header key of the ray file a rerender read (docs/design/tracer.md §3.6).
pub const LENS_FILE_KEY: &str = "mcctrace/lens_file";
/// EXR header key of the folder of per-frame ray files an animation read (docs/design/tracer.md §3.6).
pub const LENS_DIR_KEY: &str = "mcctrace/lens_dir";

/// The camera of a render through the lens reader: it only carries the film size, since the
/// reader replaces every ray.
pub fn carrier_camera(resolution: UVec2) -> tracer::Result<Box<dyn Camera>> {
    let projection = Projection::Perspective { fov_y: 1.0 };
    CameraDesc::look_at("lens reader", Vec3::ZERO, -Vec3::Z, Vec3::Y, projection)?.build(resolution)
}

/// The rays frame `frame` of an animation goes through, from the folder of per-frame ray files:
/// its own file's, and with motion blur the next frame's when there is one (the lens reader
/// blends the two). Read once, they give both the frame's header hash ([`FrameRays::digest`])
/// and its render ([`crate::LensReader::with_frame`]).
#[derive(Clone, Debug)]
pub struct FrameRays {
    /// The frame.
    pub frame: u32,
    /// Its own rays.
    pub current: Arc<RayFile>,
    /// With motion blur, the next frame's rays, if it has a file.
    pub next: Option<Arc<RayFile>>,
}

impl FrameRays {
    /// Reads the rays of `frame` from `dir`; rays `earlier` holds (the frame before, whose next
    /// is this frame) are taken from it instead of read again.
    pub fn read(dir: &Path, frame: u32, motion_blur: bool, earlier: Option<&FrameRays>) -> Result<Self> {
        let held = |f: u32| {
            earlier
                .into_iter()
                .flat_map(|e| {
                    [(e.frame, &e.current)].into_iter().chain(e.next.as_ref().map(|n| (e.frame + 1, n)))
                })
                .find(|(g, _)| *g == f)
                .map(|(_, r)| r.clone())
        };
        let current = match held(frame) {
            Some(rays) => rays,
            None => Arc::new(RayFile::read(&crate::names::find_rerender_rays(dir, frame)?)?),
        };
        let next = match frame.checked_add(1).filter(|_| motion_blur) {
            Some(f) => match held(f) {
                Some(rays) => Some(rays),
                None => crate::names::rerender_rays_if_any(dir, f)?
                    .map(|p| RayFile::read(&p).map(Arc::new))
                    .transpose()?,
            },
            None => None,
        };
        Ok(Self { frame, current, next })
    }

    /// The hash ([`RayFile::digest`]) the frame's header records: its own rays', and the next
    /// frame's joined by `+` when it blends them.
    pub fn digest(&self) -> String {
        let mut digest = self.current.digest();
        if let Some(next) = &self.next {
            digest = format!("{digest}+{}", next.digest());
        }
        digest
    }
}

/// The hash ([`FrameRays::digest`]) of the rays frame `frame` of an animation reads from the
/// folder `dir`.
pub fn lens_dir_digest(dir: &Path, frame: u32, motion_blur: bool) -> Result<String> {
    Ok(FrameRays::read(dir, frame, motion_blur, None)?.digest())
}

/// How the film of a render through a ray file is framed when an overscan border is cut off:
/// the film spans the whole ray file, and `border` film pixels go from each side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Framing {
    /// The film rendered, before the crop.
    pub film: UVec2,
    /// Columns cut from the left and right (x) and rows from the top and bottom (y).
    pub border: UVec2,
}

impl Framing {
    /// The framing of rays `rays` (width × height, in collage pixels) with a border of `crop`
    /// collage pixels cut, the rest shown at `output` pixels (`None`: one pixel per ray).
    /// `None` when the crop leaves nothing of the rays.
    pub fn new(rays: UVec2, crop: u32, output: Option<UVec2>) -> Option<Self> {
        if 2 * crop as u64 >= rays.x.min(rays.y) as u64 {
            return None;
        }
        let inner = rays - 2 * crop;
        let output = output.unwrap_or(inner);
        // The border scales with the picture, per axis, so `output` is exactly what is left.
        let scale = |out: u32, inner: u32| (crop as f64 * out as f64 / inner as f64).round() as u32;
        let border = UVec2::new(scale(output.x, inner.x), scale(output.y, inner.y));
        Some(Self { film: output + 2 * border, border })
    }

    /// The output size, after the crop.
    pub fn output(&self) -> UVec2 {
        self.film - 2 * self.border
    }

    /// `rendered` (at the film size) without the border.
    pub fn crop(&self, rendered: Rendered) -> Rendered {
        self.crop_margins(rendered, self.border)
    }

    /// `rendered`, film rows of a band of the output, without the border's columns (its rows
    /// were never rendered).
    pub fn crop_band(&self, rendered: Rendered) -> Rendered {
        self.crop_margins(rendered, UVec2::new(self.border.x, 0))
    }

    fn crop_margins(&self, mut rendered: Rendered, margins: UVec2) -> Rendered {
        if margins != UVec2::ZERO {
            rendered.images =
                rendered.images.without_margins(margins.x, margins.y).expect("the border leaves the output");
        }
        rendered
    }
}

/// A warning when an output of `output` pixels shows `shown` collage pixels at another aspect
/// ratio (more than 1 % off): the picture is stretched.
pub fn stretch_warning(shown: UVec2, output: UVec2) -> Option<String> {
    let aspect = |s: UVec2| s.x as f64 / s.y as f64;
    let (from, to) = (aspect(shown), aspect(output));
    ((to / from - 1.0).abs() > 0.01).then(|| {
        format!(
            "the output {}x{} (aspect {to:.2}) shows {}x{} collage pixels (aspect {from:.2}): the picture is \
             stretched",
            output.x, output.y, shown.x, shown.y
        )
    })
}

/// A rerender: the scene through `rays`, one frame.
#[derive(Clone, Debug)]
pub struct Rerender {
    /// The remapped rays (one per collage pixel).
    pub rays: Arc<RayFile>,
    /// The output resolution, after the crop; `None`: the rays' less the crop.
    pub resolution: Option<UVec2>,
    /// A border to cut from every side, in collage pixels (undoes `--overscan`).
    pub crop: u32,
    /// The frame (passed to the lens reader; names the output).
    pub frame: u32,
    /// When the shutter opens and closes, in frames after the frame's start: each ray gets a
    /// time in it, and the scene's moving geometry (posed in motion over it by the caller:
    /// `SceneSetup::at_frame_in_shutter`) is seen at that time; `(0, 0)`: none.
    pub shutter: (f32, f32),
    /// Samples, seed, depths and film layers.
    pub quality: Quality,
    /// Where the rays came from, as the EXR header records it: ([`COLLAGE_KEY`] or
    /// [`LENS_FILE_KEY`], the file); `None` for rays made in memory.
    pub rays_from: Option<(&'static str, PathBuf)>,
    /// The environment image lighting the scene, recorded in the EXR header.
    pub environment_map: Option<EnvironmentImage>,
    /// How the scene was set up, recorded in the EXR header.
    pub setup: Option<SceneSetup>,
    /// Only this band of the output, written to [`Band::path`] of the output without a PNG.
    pub band: Option<Band>,
}

impl Rerender {
    /// A rerender of frame `frame` through `rays` at their resolution, default quality, no crop.
    pub fn new(rays: impl Into<Arc<RayFile>>, frame: u32) -> Self {
        Self {
            rays: rays.into(),
            resolution: None,
            crop: 0,
            frame,
            shutter: (0.0, 0.0),
            quality: Quality::DEFAULT,
            rays_from: None,
            environment_map: None,
            setup: None,
            band: None,
        }
    }

    /// A rerender through the lens file `path` (a remapped or in-betweened ray file).
    pub fn from_lens_file(path: &Path, frame: u32) -> Result<Self> {
        Ok(Self {
            rays_from: Some((LENS_FILE_KEY, path.to_path_buf())),
            ..Self::new(RayFile::read(path)?, frame)
        })
    }

    /// The size of the rays (the collage's, overscan border included).
    pub fn rays_size(&self) -> UVec2 {
        UVec2::new(self.rays.width, self.rays.height)
    }

    /// The film and the border cut from it; `None` when the crop leaves nothing of the rays.
    pub fn framing(&self) -> Option<Framing> {
        Framing::new(self.rays_size(), self.crop, self.resolution)
    }

    /// A warning when the output resolution stretches the collage (another aspect ratio).
    pub fn stretch_warning(&self) -> Option<String> {
        let shown = self.rays_size().saturating_sub(UVec2::splat(2 * self.crop));
        stretch_warning(shown, self.resolution?)
    }

    /// The output rows this job renders (all without a band; empty for a band past the last
    /// row); `None` when the crop leaves nothing.
    pub fn rows(&self) -> Option<std::ops::Range<u32>> {
        let output = self.framing()?.output();
        Some(self.band.map_or(0..output.y, |b| b.rows(output.y)))
    }

    /// Renders `tracer`'s scene (posed at this frame, prepared with `quality.tracer`) through
    /// the rays and crops the film (a band: its rows). The crop, and a band past the last row,
    /// are refused before anything is traced.
    pub fn run(&self, tracer: &PathTracer, progress: &dyn Progress) -> Result<Rendered> {
        let size = self.rays_size();
        let framing = self.framing().ok_or_else(|| {
            MccError::Settings(format!("crop {} leaves nothing of a {}x{} image", self.crop, size.x, size.y))
        })?;
        let rows = self.rows().expect("the framing exists");
        if rows.is_empty() {
            return Err(MccError::Settings(format!(
                "band {} of a {}-row image is empty (rows {}..{}): nothing to render",
                self.band.expect("only a band is empty"),
                framing.output().y,
                rows.start,
                rows.end
            )));
        }
        let camera = carrier_camera(framing.film)?;
        let mut lenses = LensChain::new();
        lenses.push(Box::new(LensReader::new(RaySource::Rays(Arc::clone(&self.rays)))));
        let job = CameraRender {
            tracer,
            camera: camera.as_ref(),
            name: "rerender",
            camera_id: 0,
            frame: self.frame,
            shutter: self.shutter,
            quality: self.quality,
        };
        Ok(match self.band {
            None => framing.crop(job.run(&mut lenses, progress)?),
            Some(_) => {
                let film_rows = (rows.start + framing.border.y, rows.end + framing.border.y);
                framing.crop_band(job.run_rows(&mut lenses, progress, Some(film_rows))?)
            }
        })
    }

    /// The EXR header of this rerender of `scene`, its rays' hash being `digest`
    /// ([`RayFile::digest`]).
    fn info<'a>(&'a self, scene: &'a Path, digest: &'a str) -> RenderInfo<'a> {
        let provenance = Provenance {
            projection: None,
            environment_map: self.environment_map.as_ref(),
            rays_from: self.rays_from.as_ref().map(|(key, path)| (*key, path.as_path())),
            rays_digest: Some(digest),
        };
        let output = self.framing().map_or(UVec2::ZERO, |f| f.output());
        RenderInfo {
            provenance,
            setup: self.setup.as_ref(),
            crop: self.crop,
            band: self.band.map(|b| (b, output)),
            shutter: self.shutter,
            ..RenderInfo::new(scene, CAMERA, self.frame, &self.quality)
        }
    }

    /// The file this job writes its image to for the output `exr`: `exr`, or its band's file.
    pub fn target(&self, exr: &Path) -> PathBuf {
        self.band.map_or_else(|| exr.to_path_buf(), |b| b.path(exr))
    }

    /// `Ok` when the output `exr` of `scene` on disk (its band's file for a band; the PNG too
    /// for the whole image) is a finished render of this job (docs/farm.md), so it can be
    /// skipped; else why not.
    pub fn check(&self, exr: &Path, scene: &Path) -> std::result::Result<(), Stale> {
        let digest = self.rays.digest();
        let (Some(framing), Some(rows)) = (self.framing(), self.rows()) else {
            return Err(Stale::Missing(self.target(exr)));
        };
        let size = UVec2::new(framing.output().x, rows.len() as u32);
        let png = exr.with_extension("png");
        let png = self.band.is_none().then_some(png.as_path());
        check_finished(&self.target(exr), png, &self.info(scene, &digest).settings(), size)
    }

    /// Writes a finished rerender of `scene` for the output `exr`: the EXR and its preview PNG
    /// beside it, whose path it returns, or for a band the band's file alone, whose path it
    /// returns.
    pub fn write(&self, exr: &Path, rendered: &Rendered, scene: &Path) -> Result<PathBuf> {
        let digest = self.rays.digest();
        let info = self.info(scene, &digest);
        match self.band {
            None => Ok(write_render(exr, rendered, &info)?),
            Some(band) => {
                let path = band.path(exr);
                write_exr(&path, rendered, &info)?;
                Ok(path)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray_file::StoredRay;
    use crate::test_util::sky_scene;
    use tracer::TracerError;
    use tracer::render::NoProgress;

    /// A frame's rays are read once: the next frame's, held by the frame before, are taken from
    /// it (its file may be gone); the hash joins both with motion blur, as the header records it.
    #[test]
    fn frame_rays_are_read_once_and_hashed_together() {
        let dir = crate::test_util::scratch_dir("frame-rays");
        let (a, b) =
            (rays(4, 3), RayFile { rays: rays(4, 3).rays.into_iter().rev().collect(), ..rays(4, 3) });
        let format = crate::ray_file::RayFormat::Binary;
        a.write(&dir.join(crate::names::rerender_name(3, format)), format).unwrap();
        b.write(&dir.join(crate::names::rerender_name(4, format)), format).unwrap();
        let third = FrameRays::read(&dir, 3, true, None).unwrap();
        assert_eq!(third.digest(), format!("{}+{}", a.digest(), b.digest()));
        assert_eq!(lens_dir_digest(&dir, 3, true).unwrap(), third.digest());
        assert_eq!(lens_dir_digest(&dir, 3, false).unwrap(), a.digest());
        std::fs::remove_file(dir.join(crate::names::rerender_name(4, format))).unwrap();
        let fourth = FrameRays::read(&dir, 4, true, Some(&third)).unwrap();
        assert!(Arc::ptr_eq(&fourth.current, third.next.as_ref().unwrap()), "frame 4 is not read again");
        assert!(fourth.next.is_none() && fourth.digest() == b.digest());
        assert!(FrameRays::read(&dir, 4, true, None).is_err(), "without them, the file is read");
        std::fs::remove_dir_all(&dir).unwrap();
    }

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

    /// The crop is given in collage pixels and scaled to the film; the resolution is the
    /// output's, after the crop; a crop that leaves nothing is refused before anything is
    /// traced; a cancelled rerender says so.
    #[test]
    fn crops_in_collage_pixels_and_refuses_what_leaves_nothing() {
        let sky = Vec3::new(0.5, 0.25, 0.125);
        let quality = Quality::DEFAULT.with_spp(1);
        let tracer = quality.tracer(&sky_scene(sky)).unwrap();
        let job = Rerender {
            resolution: Some(UVec2::new(12, 8)),
            crop: 2,
            quality,
            ..Rerender::new(rays(10, 8), 0)
        };
        // 6 x 4 collage pixels are left, shown at 12 x 8: the 2-pixel border becomes 4.
        assert_eq!(job.framing(), Some(Framing { film: UVec2::new(20, 16), border: UVec2::new(4, 4) }));
        assert_eq!(job.stretch_warning(), None);
        let rendered = job.run(&tracer, &NoProgress).unwrap();
        let image = &rendered.images.image;
        assert_eq!((image.width, image.height), (12, 8));
        assert!(image.pixels.iter().all(|p| *p == sky));
        assert_eq!(rendered.images.samples.width, 12);
        let native = Rerender { resolution: None, ..job.clone() }.run(&tracer, &NoProgress).unwrap();
        assert_eq!((native.images.image.width, native.images.image.height), (6, 4));

        let whole = Rerender { crop: 4, resolution: None, ..job.clone() };
        assert_eq!(whole.framing(), None);
        let err = whole.run(&tracer, &NoProgress).unwrap_err().to_string();
        assert!(err.contains("crop 4 leaves nothing of a 10x8 image"), "{err}");
        let err = Rerender { resolution: Some(UVec2::new(20, 20)), ..whole }.run(&tracer, &NoProgress);
        assert!(err.unwrap_err().to_string().contains("crop 4 leaves nothing of a 10x8 image"));
        let err = job.run(&tracer, &Stop).unwrap_err();
        assert!(matches!(err, MccError::Tracer(TracerError::Cancelled)), "{err}");
    }

    /// What a first-time user hit: 176 x 106 overscanned views, `--crop 8 --res 320x180` must
    /// write 320 x 180; an output of another aspect, or of one axis scaled differently, keeps
    /// its size exactly and is said to stretch.
    #[test]
    fn the_resolution_is_the_output_after_the_crop() {
        let f = Framing::new(UVec2::new(176, 106), 8, Some(UVec2::new(320, 180))).unwrap();
        assert_eq!(
            (f.film, f.border, f.output()),
            (UVec2::new(352, 212), UVec2::new(16, 16), UVec2::new(320, 180))
        );
        let f = Framing::new(UVec2::new(176, 106), 8, None).unwrap();
        assert_eq!(
            (f.film, f.border, f.output()),
            (UVec2::new(176, 106), UVec2::new(8, 8), UVec2::new(160, 90))
        );
        let f = Framing::new(UVec2::new(176, 106), 8, Some(UVec2::new(100, 100))).unwrap();
        assert_eq!(f.output(), UVec2::new(100, 100));
        assert_eq!(Framing::new(UVec2::new(176, 106), 53, None), None);
        let w = stretch_warning(UVec2::new(160, 90), UVec2::new(100, 100)).unwrap();
        assert!(
            w.contains("100x100 (aspect 1.00)") && w.contains("160x90") && w.contains("(aspect 1.78)"),
            "{w}"
        );
        assert_eq!(stretch_warning(UVec2::new(160, 90), UVec2::new(320, 180)), None);
        assert_eq!(stretch_warning(UVec2::new(160, 90), UVec2::new(321, 180)), None);
    }
}
