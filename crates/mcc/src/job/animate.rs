//! An animation rendered through per-frame ray files (docs/design/workflow.md §6 lens reader, §8
//! workflow; `animate`, the animation demo). Every frame is an independent unit of work: any
//! sub-range renders alone, and a frame is skipped only when it is finished by
//! `tracer::job::check_finished`'s rule (docs/farm.md: EXR and PNG there and whole, the same
//! settings and rays in the header); a stale or damaged frame is rendered again and the reason
//! told. So a crashed run resumes and a render farm's job array can split a shot by frame ranges
//! over a shared folder.
//!
//! Motion blur (a shutter interval): each eye ray gets a time in the shutter interval; the lens
//! reader interpolates the ray files of frames f and f+1 by it (camera-ray blur), and an
//! animated scene's moving geometry is posed at the motion steps over the shutter and
//! interpolated to the ray's time (geometry blur, docs/design/tracer.md §3.12, which needs no next
//! frame: the animation holds its last keys past its end).

use super::progress::JobProgress;
use super::rerender::{FrameRays, Framing, LENS_DIR_KEY, carrier_camera};
use crate::error::{MccError, Result};
use crate::lens_reader::{LensReader, RaySource};
use crate::names::{find_rerender_rays, rerender_name};
use crate::ray_file::{RayFile, RayFormat};
use glam::UVec2;
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};
use tracer::integrator::PathTracer;
use tracer::job::{
    CameraRender, Provenance, Quality, RenderInfo, SceneSetup, Stale, check_finished, write_render,
};
use tracer::lens::LensChain;
use tracer::render::Rendered;
use tracer::scene::DEFAULT_MOTION_STEPS;

/// The header key recording what the camera-ray blur did to a frame (with a shutter only).
pub const RAY_BLUR_KEY: &str = "mcctrace/ray_blur";

/// What the EXR header names as the camera of an animated frame.
const ANIMATED: &str = "multicamera collage (animated)";

/// The EXR of `frame` in `out` (its PNG preview is beside it).
pub fn frame_exr(out: &Path, frame: u32) -> PathBuf {
    out.join(format!("frame{frame:04}.exr"))
}

/// A shot to render: the scene, the folder of per-frame ray files, the frames and how.
#[derive(Clone, Debug)]
pub struct Animate {
    /// The scene file, recorded in every frame's header.
    pub scene: PathBuf,
    /// The folder of per-frame ray files `rerender-frameFFFF.{mcr|txt}`.
    pub lens_dir: PathBuf,
    /// The frames to render (both ends included).
    pub frames: RangeInclusive<u32>,
    /// The output folder: `frameFFFF.exr` and `.png` per frame.
    pub out: PathBuf,
    /// How the scene is loaded and posed (its frame rate times the frames).
    pub setup: SceneSetup,
    /// Sampling settings.
    pub quality: Quality,
    /// When the shutter opens and closes, in frames after each frame's start; `(0, 0)`: none.
    pub shutter: (f32, f32),
    /// The overscan border cut from the ray files' pixels, recorded in the header.
    pub crop: u32,
    /// The film and its crop ([`Animate::framing`]).
    pub framing: Framing,
}

/// What a run of an [`Animate`] tells as it goes.
pub enum AnimateEvent<'a> {
    /// A frame's files are there but not finished (stale, damaged, half there): rendered again.
    Stale {
        /// The frame.
        frame: u32,
        /// Why its files are not finished.
        why: &'a Stale,
    },
    /// Every frame is checked: these are finished and skipped (said before anything loads).
    Planned {
        /// The finished frames.
        skipped: &'a [u32],
        /// The frames to render.
        todo: &'a [u32],
    },
    /// The scene is loaded, with these warnings; the frames' renders begin.
    Loaded {
        /// What the loader warned about.
        warnings: &'a [String],
    },
    /// Posing a frame over its shutter found something its blur cannot show (told once a run).
    Warned {
        /// The warning.
        warning: &'a str,
    },
    /// A frame is rendered and written.
    Written {
        /// The frame.
        frame: u32,
        /// The render's name (`frame F`).
        name: &'a str,
        /// The render (cropped).
        rendered: &'a Rendered,
        /// Its EXR (the PNG is beside it).
        exr: &'a Path,
    },
}

/// Where an [`Animate`] reports: its frames' stages and its events.
pub type AnimateProgress = dyn for<'e> JobProgress<AnimateEvent<'e>>;

/// What a run did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct AnimateReport {
    /// Frames rendered by this run.
    pub rendered: Vec<u32>,
    /// Frames skipped because they were finished.
    pub skipped: Vec<u32>,
    /// Frames rendered again, and why their files were not finished (missing files aside).
    pub stale: Vec<(u32, Stale)>,
    /// Frames the shutter asked to blur that had no next frame's rays to blend: rendered sharp.
    pub sharp: Vec<u32>,
}

impl Animate {
    /// The film and its crop for rays in `lens_dir` from frame `first` on: `res` (the size after
    /// the crop) or the first frame's ray file's size, less a border of `crop` ray pixels.
    /// `Ok(Err(size))` when the crop leaves nothing of rays of that size.
    pub fn framing(
        lens_dir: &Path,
        first: u32,
        crop: u32,
        res: Option<UVec2>,
    ) -> Result<std::result::Result<Framing, UVec2>> {
        let rays = match res {
            // Without a crop the film is `res` itself: no ray file need be read.
            Some(r) if crop == 0 => return Ok(Ok(Framing { film: r, border: UVec2::ZERO })),
            _ => {
                let rays = RayFile::read(&find_rerender_rays(lens_dir, first)?)?;
                UVec2::new(rays.width, rays.height)
            }
        };
        Ok(Framing::new(rays, crop, res).ok_or(rays))
    }

    /// Whether the shutter is open for a while (camera-ray blur).
    pub fn motion_blur(&self) -> bool {
        self.shutter.1 > self.shutter.0
    }

    /// What the header records of the camera-ray blur of `rays`' frame: nothing without a
    /// shutter; else the two frames blended, or that there was no next frame to blend.
    fn ray_blur(&self, rays: &FrameRays) -> Vec<(&'static str, String)> {
        if !self.motion_blur() {
            return Vec::new();
        }
        let f = rays.frame;
        let what = match &rays.next {
            Some(_) => format!("frames {f} and {}", f + 1),
            None => format!(
                "none: no ray file for frame {}, so frame {f}'s rays hold over the shutter",
                f as u64 + 1
            ),
        };
        vec![(RAY_BLUR_KEY, what)]
    }

    /// The header of `frame`, its rays' hash being `digest` and its blur `extra`.
    fn info<'b>(&'b self, frame: u32, digest: &'b str, extra: &'b [(&'b str, String)]) -> RenderInfo<'b> {
        let provenance = Provenance {
            projection: None,
            environment_map: self.setup.environment_image.as_ref(),
            rays_from: Some((LENS_DIR_KEY, &self.lens_dir)),
            rays_digest: Some(digest),
        };
        RenderInfo {
            shutter: self.shutter,
            provenance,
            setup: Some(&self.setup),
            crop: self.crop,
            extra,
            ..RenderInfo::new(&self.scene, ANIMATED, frame, &self.quality)
        }
    }

    /// The rays `frame` goes through (those of `earlier` reused, not read again).
    fn rays(&self, frame: u32, earlier: Option<&FrameRays>) -> Result<FrameRays> {
        FrameRays::read(&self.lens_dir, frame, self.motion_blur(), earlier)
            .map_err(|e| e.during(format!("frame {frame}: reading its rays")))
    }

    /// Whether `frame` is finished in the output folder (`Ok`), or why not. Its rays are read
    /// (for their hash) only when its EXR is there to compare with.
    pub fn status(&self, frame: u32) -> Result<std::result::Result<(), Stale>> {
        let exr = frame_exr(&self.out, frame);
        if !exr.is_file() {
            return Ok(Err(Stale::Missing(exr)));
        }
        let rays = self.rays(frame, None)?;
        let (digest, blur) = (rays.digest(), self.ray_blur(&rays));
        let settings = self.info(frame, &digest, &blur).settings();
        Ok(check_finished(&exr, Some(&exr.with_extension("png")), &settings, self.framing.output()))
    }

    /// Renders the frames that are not finished into the output folder (created if missing).
    pub fn run(&self, progress: &AnimateProgress) -> Result<AnimateReport> {
        std::fs::create_dir_all(&self.out)
            .map_err(|e| MccError::step(format!("creating {}", self.out.display()), e))?;
        let mut report = AnimateReport::default();
        let mut todo = Vec::new();
        for frame in self.frames.clone() {
            match self.status(frame)? {
                Ok(()) => report.skipped.push(frame),
                Err(Stale::Missing(_)) if !frame_exr(&self.out, frame).exists() => todo.push(frame),
                Err(why) => {
                    progress.event(AnimateEvent::Stale { frame, why: &why });
                    report.stale.push((frame, why));
                    todo.push(frame);
                }
            }
        }
        progress.event(AnimateEvent::Planned { skipped: &report.skipped, todo: &todo });
        if !todo.is_empty() {
            report.sharp = self.render(&todo, progress)?;
            report.rendered = todo;
        }
        Ok(report)
    }

    /// Renders and writes `frames`; returns those the shutter asked to blur that have no next
    /// frame's rays to blend with.
    fn render(&self, frames: &[u32], progress: &AnimateProgress) -> Result<Vec<u32>> {
        let base = self.setup.load(&self.scene)?;
        progress.event(AnimateEvent::Loaded { warnings: &base.warnings });
        let quality = self.quality;
        // A static scene gets one BVH for the whole run; an animated one is posed per frame and
        // the previous frame's BVH refitted to it (`PathTracer::reposed`: the same bits as a
        // fresh build, so a resumed shot matches a continuous run).
        let still = if base.animation.is_none() { Some(quality.tracer(&base)?) } else { None };
        let mut previous: Option<PathTracer> = None;
        let camera = carrier_camera(self.framing.film)?;
        let mut earlier: Option<FrameRays> = None;
        let mut sharp = Vec::new();
        let mut told: Vec<String> = Vec::new();
        for &frame in frames {
            // Read once: hashed for the header and handed to the lens reader, which reads nothing.
            let rays = self.rays(frame, earlier.as_ref())?;
            let (digest, blur) = (rays.digest(), self.ray_blur(&rays));
            if self.motion_blur() && rays.next.is_none() {
                sharp.push(frame);
            }
            let reader = LensReader::new(RaySource::Directory(self.lens_dir.clone()))
                .with_motion_blur(self.motion_blur())
                .with_frame(frame, rays.current.clone(), rays.next.clone());
            let mut lenses = LensChain::new();
            lenses.push(Box::new(reader));
            let tracer = match &still {
                Some(t) => t,
                None => {
                    let setup = &self.setup;
                    let scene = setup
                        .pose_in_shutter(&base, frame, self.shutter, DEFAULT_MOTION_STEPS)
                        .map_err(|e| {
                            MccError::from(e).during(format!(
                                "posing the scene at frame {frame} ({} s)",
                                setup.frame_seconds(frame)
                            ))
                        })?;
                    for w in scene.warnings.iter().skip(base.warnings.len()) {
                        if !told.contains(w) {
                            progress.event(AnimateEvent::Warned { warning: w });
                            told.push(w.clone());
                        }
                    }
                    let tracer = match previous.take() {
                        Some(tracer) => tracer.reposed(&scene)?,
                        None => quality.tracer(&scene)?,
                    };
                    &*previous.insert(tracer)
                }
            };
            let name = format!("frame {frame}");
            let job = CameraRender {
                tracer,
                camera: camera.as_ref(),
                name: &name,
                camera_id: 0,
                frame,
                shutter: self.shutter,
                quality,
            };
            let rendered = job.run(&mut lenses, progress.stages()).map_err(|e| {
                MccError::from(e).during(format!("frame {frame} (rays from {})", self.lens_dir.display()))
            })?;
            let rendered = self.framing.crop(rendered);
            let exr = frame_exr(&self.out, frame);
            write_render(&exr, &rendered, &self.info(frame, &digest, &blur))?;
            earlier = Some(rays);
            progress.event(AnimateEvent::Written { frame, name: &name, rendered: &rendered, exr: &exr });
        }
        Ok(sharp)
    }

    /// The one warning of a run whose shutter found no next frame's rays for `sharp` frames
    /// (typically the shot's last): their camera rays hold over the shutter (moving geometry
    /// still blurs), and their headers say so. `flag`
    /// names the shutter as the caller's user gave it (`--shutter 0..0.5`).
    pub fn sharp_warning(&self, sharp: &[u32], flag: &str) -> Option<String> {
        let &first = sharp.first()?;
        let frames = match sharp {
            [one] => format!("frame {one} has"),
            _ => {
                let listed: Vec<String> = sharp.iter().take(4).map(u32::to_string).collect();
                let more =
                    if sharp.len() > 4 { format!(" and {} more", sharp.len() - 4) } else { String::new() };
                format!("frames {}{more} have", listed.join(", "))
            }
        };
        let next = first.saturating_add(1);
        Some(format!(
            "{flag}: {frames} no next frame's ray file in {} (for frame {first}: {}), so the camera-ray \
             blur has nothing to blend: the camera's rays hold over the shutter, the header saying \
             {RAY_BLUR_KEY} = none (moving geometry still blurs). To blur the camera too, write the \
             next frame's rays (`keys` or `inbetween --frames …..={next}`)",
            self.lens_dir.display(),
            rerender_name(next, RayFormat::Binary),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::job::Silent;
    use crate::test_util::{scratch_dir, view};

    /// The job runs without any caller's types: it renders the frames, skips them when run
    /// again, and renders again (saying why) those whose settings changed.
    #[test]
    fn renders_resumes_and_rerenders_stale_frames() {
        let dir = scratch_dir("animate-job");
        let scene = dir.join("far.obj");
        std::fs::write(&scene, "v 0 0 100\nv 1 0 100\nv 0 1 100\nf 1 2 3\n").unwrap();
        let lens_dir = dir.join("lens");
        std::fs::create_dir_all(&lens_dir).unwrap();
        for frame in 0..2 {
            view(frame + 1, 6, 4)
                .write(&lens_dir.join(rerender_name(frame, RayFormat::Binary)), RayFormat::Binary)
                .unwrap();
        }
        let framing = Animate::framing(&lens_dir, 0, 0, None).unwrap().unwrap();
        assert_eq!(framing, Framing { film: UVec2::new(6, 4), border: UVec2::ZERO });
        assert_eq!(Animate::framing(&lens_dir, 0, 2, None).unwrap(), Err(UVec2::new(6, 4)));
        let job = Animate {
            scene,
            lens_dir,
            frames: 0..=1,
            out: dir.join("frames"),
            setup: SceneSetup::default(),
            quality: Quality::DEFAULT.with_spp(1),
            shutter: (0.0, 0.0),
            crop: 0,
            framing,
        };
        let first = job.run(&Silent).unwrap();
        assert_eq!((first.rendered, first.skipped), (vec![0, 1], vec![]));
        assert!(frame_exr(&job.out, 1).is_file() && frame_exr(&job.out, 1).with_extension("png").is_file());
        assert_eq!(job.status(0).unwrap(), Ok(()));
        let again = job.run(&Silent).unwrap();
        assert_eq!((again.rendered, again.skipped), (vec![], vec![0, 1]));
        let more = Animate { quality: Quality::DEFAULT.with_spp(2), frames: 1..=1, ..job.clone() };
        let stale = more.run(&Silent).unwrap();
        assert_eq!(stale.rendered, vec![1]);
        assert_eq!(
            stale.stale.iter().map(|(f, why)| (*f, why.to_string())).collect::<Vec<_>>(),
            [(1, "spp 1 ≠ 2".to_owned())]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
