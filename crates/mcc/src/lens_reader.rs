//! The lens reader (docs/design.md §6): a lens shader that replaces every eye ray by the ray a
//! ray file gives for the sample's film position, interpolated at any output resolution.
//!
//! For an output of W × H and a file of w × h, film position (x, y) maps to u = x·w/W − ½,
//! v = y·h/H − ½, clamped to [0, w−1] × [0, h−1]; with i = ⌊u⌋, j = ⌊v⌋ (their +1 neighbours
//! clamped), s = u − i, t = v − j, rows j and j+1 are interpolated with s, then the two results
//! with t. Interpolating rays lerps origins and slerps directions ([`crate::slerp::lerp_rays`],
//! exact at s, t ∈ {0, 1}): pixel centres of a same-size output give the file's rays bit for bit,
//! and the rays vary continuously in between.
//!
//! The file is loaded in `begin_frame` (a fixed file once, a per-frame `rerender-frameFFFF` file
//! from a directory each frame); `shade` only reads shared, immutable data: no lock. It costs
//! four ray loads and three ray interpolations, trigonometry-free for neighbouring rays closer
//! than 0.01 rad (see [`crate::slerp`]), and a single normalisation when all four are that close. With motion blur the files of frames f and f+1 are both
//! loaded and their rays interpolated by the ray's time (f+1 missing: frame f holds).

use crate::error::{MccError, Result};
use crate::names::{find_rerender_rays, rerender_rays_if_any};
use crate::ray_file::{RayFile, StoredRay};
use crate::slerp::lerp_rays;
use glam::{UVec2, Vec2};
use std::path::PathBuf;
use std::sync::Arc;
use tracer::camera::CameraSample;
use tracer::error::LensError;
use tracer::lens::{FrameContext, LensShader};
use tracer::ray::Ray;

/// Squared chord below which the four directions of a cell are blended with one normalisation.
/// All pairwise angles are then under 0.01 rad, where a normalised lerp is within 0.016·θ³
/// ≤ 1.6e-8 rad of a slerp, and the row results' lengths differ by under θ²/8, which moves the
/// vertical blend by under 3e-8 rad: the fused result matches docs/design.md §6's nested form to
/// below f32 resolution (6e-8).
const FUSED_CHORD_SQUARED: f32 = 2.5e-5;

/// Where a lens reader gets its rays.
#[derive(Clone, Debug)]
pub enum RaySource {
    /// One file for every frame (loaded once).
    File(PathBuf),
    /// `rerender-frameFFFF.{mcr|txt}` in a directory, one per frame.
    Directory(PathBuf),
    /// Rays already in memory (e.g. straight from the remapper).
    Rays(Arc<RayFile>),
}

/// A ray file and the scale factors that map an output film onto it.
#[derive(Clone, Debug)]
pub struct RaySampler {
    rays: Arc<RayFile>,
    /// w / W and h / H.
    scale: (f64, f64),
}

impl RaySampler {
    /// A sampler of `rays` for an output film of `resolution` pixels; refuses a ray file whose
    /// fields disagree (an empty one, or one with the wrong number of rays).
    pub fn new(rays: Arc<RayFile>, resolution: UVec2) -> Result<Self> {
        let (w, h) = (rays.width as usize, rays.height as usize);
        if w == 0 || h == 0 || rays.rays.len() != w * h || resolution.x == 0 || resolution.y == 0 {
            return Err(MccError::input(
                "lens reader",
                format!(
                    "cannot map a {}x{} film onto a {w}x{h} ray file holding {} rays",
                    resolution.x,
                    resolution.y,
                    rays.rays.len()
                ),
            ));
        }
        let scale = (w as f64 / resolution.x as f64, h as f64 / resolution.y as f64);
        Ok(Self { rays, scale })
    }

    /// The ray file.
    pub fn rays(&self) -> &RayFile {
        &self.rays
    }

    /// The interpolated ray at film position `p` of the output (docs/design.md §6).
    #[inline]
    pub fn at(&self, p: Vec2) -> StoredRay {
        let f = &*self.rays;
        let (w, h) = (f.width as usize, f.height as usize);
        // `max`/`min` rather than `clamp`: a NaN position lands on the first pixel instead of
        // propagating.
        let u = (p.x as f64 * self.scale.0 - 0.5).max(0.0).min((w - 1) as f64);
        let v = (p.y as f64 * self.scale.1 - 0.5).max(0.0).min((h - 1) as f64);
        let (i, j) = ((u as usize).min(w - 1), (v as usize).min(h - 1));
        let (i1, j1) = ((i + 1).min(w - 1), (j + 1).min(h - 1));
        let (s, t) = ((u - i as f64) as f32, (v - j as f64) as f32);
        let (a, b) = (&f.rays[j * w + i], &f.rays[j * w + i1]);
        if t == 0.0 {
            return lerp_rays(a, b, s);
        }
        let (c, d) = (&f.rays[j1 * w + i], &f.rays[j1 * w + i1]);
        let close = |p: &StoredRay| (p.direction - a.direction).length_squared() < FUSED_CHORD_SQUARED;
        if s != 0.0 && close(b) && close(c) && close(d) {
            // Neighbouring directions this close: one normalisation of the bilinear blend equals
            // the three nested ones (see FUSED_CHORD_SQUARED) at a third of the cost.
            let lerp = |p: &StoredRay, q: &StoredRay| StoredRay {
                origin: p.origin + (q.origin - p.origin) * s,
                direction: p.direction + (q.direction - p.direction) * s,
            };
            let (top, bottom) = (lerp(a, b), lerp(c, d));
            let direction =
                (top.direction + (bottom.direction - top.direction) * t).normalize_or(a.direction);
            return StoredRay { origin: top.origin + (bottom.origin - top.origin) * t, direction };
        }
        lerp_rays(&lerp_rays(a, b, s), &lerp_rays(c, d, s), t)
    }
}

/// The lens reader shader.
#[derive(Debug)]
pub struct LensReader {
    source: RaySource,
    motion_blur: bool,
    /// The rays of the frame last loaded, and which frame that was (directory sources).
    loaded: Option<(u32, Arc<RayFile>)>,
    /// With motion blur: the rays of the following frame, if it has a file.
    next: Option<(u32, Arc<RayFile>)>,
    current: Option<RaySampler>,
    following: Option<RaySampler>,
    frame_time: f32,
}

impl LensReader {
    /// A reader of `source`.
    pub fn new(source: RaySource) -> Self {
        Self {
            source,
            motion_blur: false,
            loaded: None,
            next: None,
            current: None,
            following: None,
            frame_time: 0.0,
        }
    }

    /// Interpolate frames f and f+1 by each ray's time (directory sources only: a fixed file is
    /// the same at every frame).
    pub fn with_motion_blur(mut self, on: bool) -> Self {
        self.motion_blur = on;
        self
    }

    /// The sampler for the current frame (after `begin_frame`).
    pub fn sampler(&self) -> Option<&RaySampler> {
        self.current.as_ref()
    }

    /// The rays of `frame` from a directory (`None` if it has no file), reusing what is loaded.
    fn frame_rays(&self, dir: &std::path::Path, frame: u32) -> Result<Option<Arc<RayFile>>> {
        for (f, rays) in self.loaded.iter().chain(&self.next) {
            if *f == frame {
                return Ok(Some(rays.clone()));
            }
        }
        match rerender_rays_if_any(dir, frame)? {
            Some(path) => Ok(Some(Arc::new(RayFile::read(&path)?))),
            None => Ok(None),
        }
    }

    /// Loads what frame `frame` needs; returns (this frame's rays, the next frame's if blurring).
    fn load(&mut self, frame: u32) -> Result<(Arc<RayFile>, Option<Arc<RayFile>>)> {
        match &self.source {
            RaySource::Rays(rays) => Ok((rays.clone(), None)),
            RaySource::File(path) => {
                let rays = match &self.loaded {
                    Some((_, rays)) => rays.clone(),
                    None => Arc::new(RayFile::read(path)?),
                };
                self.loaded = Some((0, rays.clone()));
                Ok((rays, None))
            }
            RaySource::Directory(dir) => {
                let dir = dir.clone();
                let current = match self.frame_rays(&dir, frame)? {
                    Some(rays) => rays,
                    // The error names the file that was looked for.
                    None => {
                        return Err(find_rerender_rays(&dir, frame)
                            .map_or_else(|e| e, |p| MccError::io(p, std::io::ErrorKind::NotFound.into())));
                    }
                };
                // The last frame has no successor: it holds still.
                let next = match frame.checked_add(1).filter(|_| self.motion_blur) {
                    Some(f) => self.frame_rays(&dir, f)?.map(|rays| (f, rays)),
                    None => None,
                };
                self.loaded = Some((frame, current.clone()));
                self.next = next;
                Ok((current, self.next.as_ref().map(|(_, r)| r.clone())))
            }
        }
    }
}

impl LensShader for LensReader {
    fn name(&self) -> &str {
        "lens reader"
    }

    fn begin_frame(&mut self, ctx: &FrameContext<'_>) -> Result<(), LensError> {
        let sampler = |rays| RaySampler::new(rays, ctx.resolution).map_err(|e| Box::new(e) as LensError);
        let (rays, next) = self.load(ctx.frame).map_err(|e| Box::new(e) as LensError)?;
        self.current = Some(sampler(rays)?);
        self.following = next.map(sampler).transpose()?;
        self.frame_time = ctx.frame as f32;
        Ok(())
    }

    #[inline]
    fn shade(&self, sample: &CameraSample, ray: Ray) -> Option<Ray> {
        let current = self.current.as_ref()?;
        let mut r = current.at(sample.p_film);
        if let Some(following) = &self.following {
            let tau = (ray.time - self.frame_time).clamp(0.0, 1.0);
            if tau > 0.0 {
                r = lerp_rays(&r, &following.at(sample.p_film), tau);
            }
        }
        // Stored directions are unit to 1e-4 (checked on load), as the tracer's rays are.
        Some(Ray { origin: r.origin, direction: r.direction, time: ray.time })
    }
}

#[cfg(test)]
#[path = "lens_reader_tests.rs"]
mod tests;
