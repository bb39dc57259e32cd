//! The lens reader (docs/design/workflow.md §6): a lens shader that replaces every eye ray by the ray a
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
/// vertical blend by under 3e-8 rad: the fused result matches docs/design/workflow.md §6's nested form to
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

    /// The interpolated ray at film position `p` of the output (docs/design/workflow.md §6).
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

    /// Hands the reader of a directory the rays of `frame` (and, with motion blur, of the frame
    /// after it, `None` when that has no file) already read by the caller, so `begin_frame` of
    /// that frame reads no file (an animation hashes the same rays for its header).
    pub fn with_frame(mut self, frame: u32, current: Arc<RayFile>, next: Option<Arc<RayFile>>) -> Self {
        self.loaded = Some((frame, current));
        self.next = next.and_then(|rays| Some((frame.checked_add(1)?, rays)));
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
mod tests {
    //! Tests of the lens reader (docs/design/workflow.md §6).

    use super::*;
    use crate::names::rerender_name;
    use crate::ray_file::RayFormat;
    use crate::slerp::angle_between;
    use crate::test_util::{Rng, scratch_dir};
    use glam::Vec3;
    use tracer::camera::{CameraDesc, Projection};
    use tracer::lens::{FrameInfo, LensChain, RayGenerator};

    /// A smooth but non-linear field of rays, with some jitter so interpolation is not trivial.
    fn field(w: u32, h: u32, seed: u64) -> RayFile {
        let mut rng = Rng::new(seed);
        let rays = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32, (p / w) as f32);
                let o = Vec3::new(x * 0.1, y * 0.2, (x * y).sin()) + rng.direction() * 0.01;
                let d = Vec3::new((x * 0.3).sin(), (y * 0.25).cos(), -1.0 - 0.1 * x) + rng.direction() * 0.05;
                StoredRay::new(o, d.normalize())
            })
            .collect();
        RayFile::new(w, h, seed as u32, 0, rays).unwrap()
    }

    fn bits(r: &StoredRay) -> [u32; 6] {
        bytemuck::cast(*r)
    }

    fn close(a: &StoredRay, b: &StoredRay) -> bool {
        (a.origin - b.origin).length() < 1e-5 && angle_between(a.direction, b.direction) < 1e-5
    }

    #[test]
    fn exact_at_pixel_centres_of_a_same_size_output() {
        for (w, h) in [(1, 1), (1, 7), (9, 1), (31, 17)] {
            let f = Arc::new(field(w, h, 1));
            let s = RaySampler::new(f.clone(), UVec2::new(w, h)).unwrap();
            for j in 0..h {
                for i in 0..w {
                    let got = s.at(Vec2::new(i as f32 + 0.5, j as f32 + 0.5));
                    assert_eq!(bits(&got), bits(f.get(i, j)), "{w}x{h} ({i}, {j})");
                }
            }
        }
    }

    #[test]
    fn continuous_between_centres() {
        let f = Arc::new(field(12, 9, 2));
        let s = RaySampler::new(f.clone(), UVec2::new(30, 20)).unwrap();
        // Largest neighbour differences bound how fast the ray may move per unit of u.
        let step = 1e-3f32;
        for y in [0.0f32, 3.3, 9.99, 14.5, 20.0] {
            let mut prev = s.at(Vec2::new(0.0, y));
            let mut x = step;
            while x <= 30.0 {
                let r = s.at(Vec2::new(x, y));
                let moved = (r.origin - prev.origin).length();
                let turned = angle_between(r.direction, prev.direction);
                // One output pixel is 0.4 file pixels; neighbours differ by < 1 unit and < 1 rad.
                assert!(moved < 2e-3 && turned < 2e-3, "jump at ({x}, {y}): {moved} {turned}");
                assert!(r.defect().is_none());
                prev = r;
                x += step;
            }
        }
    }

    #[test]
    fn twice_and_half_size_outputs_sample_the_right_positions() {
        let (w, h) = (8, 6);
        let f = Arc::new(field(w, h, 3));
        let lerp = |a: StoredRay, b: StoredRay, t: f32| lerp_rays(&a, &b, t);
        let r = |i: u32, j: u32| *f.get(i, j);
        // 2×: output pixel centre x = i + ½ maps to u = (i + ½)/2 − ½.
        let s2 = RaySampler::new(f.clone(), UVec2::new(2 * w, 2 * h)).unwrap();
        assert_eq!(bits(&s2.at(Vec2::new(0.5, 0.5))), bits(&r(0, 0)), "u = −¼ clamps to 0");
        let got = s2.at(Vec2::new(3.5, 0.5)); // u = 1.25, v = −0.25 → 0
        assert!(close(&got, &lerp(r(1, 0), r(2, 0), 0.25)));
        let got = s2.at(Vec2::new(3.5, 4.5)); // u = 1.25, v = 1.75
        let want = lerp(lerp(r(1, 1), r(2, 1), 0.25), lerp(r(1, 2), r(2, 2), 0.25), 0.75);
        assert!(close(&got, &want));
        assert_eq!(bits(&s2.at(Vec2::new(15.5, 11.5))), bits(&r(7, 5)), "u = 7.25 clamps to 7");
        // ½×: output pixel centre x = i + ½ maps to u = 2i + ½: midway between file pixels 2i and 2i+1.
        let s_half = RaySampler::new(f.clone(), UVec2::new(w / 2, h / 2)).unwrap();
        for j in 0..h / 2 {
            for i in 0..w / 2 {
                let got = s_half.at(Vec2::new(i as f32 + 0.5, j as f32 + 0.5));
                let (a, b) = (2 * i, 2 * j);
                let want =
                    lerp(lerp(r(a, b), r(a + 1, b), 0.5), lerp(r(a, b + 1), r(a + 1, b + 1), 0.5), 0.5);
                assert!(close(&got, &want), "({i}, {j})");
            }
        }
    }

    fn camera(res: UVec2) -> Box<dyn tracer::camera::Camera> {
        CameraDesc::look_at("c", Vec3::ZERO, -Vec3::Z, Vec3::Y, Projection::Perspective { fov_y: 1.0 })
            .unwrap()
            .build(res)
            .unwrap()
    }

    #[test]
    fn shades_through_a_lens_chain_from_a_file_or_directory() {
        let dir = scratch_dir("lens-reader");
        let f = field(10, 8, 4);
        let fixed = dir.join("lens.txt");
        f.write(&fixed, RayFormat::Text).unwrap();
        for f_num in [3u32, 4] {
            let mut g = field(10, 8, f_num as u64 + 10);
            g.frame = f_num;
            g.write(&dir.join(rerender_name(f_num, RayFormat::Binary)), RayFormat::Binary).unwrap();
        }
        let cam = camera(UVec2::new(10, 8));
        let info = |frame| FrameInfo { frame, camera_id: 0, shutter: (frame as f32, frame as f32 + 0.5) };
        // Fixed file: every frame the same rays; the ray's time is kept.
        let mut chain = LensChain::new();
        chain.push(Box::new(LensReader::new(RaySource::File(fixed.clone()))));
        for frame in [0, 7] {
            chain.begin_frame(cam.as_ref(), info(frame)).unwrap();
            let s = CameraSample {
                p_film: Vec2::new(3.5, 2.5),
                p_lens: Vec2::splat(0.5),
                time: frame as f32 + 0.25,
            };
            let ray = chain.generator(cam.as_ref()).generate(&s).unwrap();
            assert_eq!(ray.origin, f.get(3, 2).origin);
            assert_eq!(ray.direction, f.get(3, 2).direction);
            assert_eq!(ray.time, frame as f32 + 0.25);
        }
        // Directory: the frame's own file; a missing frame is an error naming the file it wanted.
        let mut chain = LensChain::new();
        chain.push(Box::new(LensReader::new(RaySource::Directory(dir.clone()))));
        chain.begin_frame(cam.as_ref(), info(4)).unwrap();
        let s = CameraSample { p_film: Vec2::new(0.5, 0.5), p_lens: Vec2::splat(0.5), time: 4.0 };
        assert_eq!(
            chain.generator(cam.as_ref()).generate(&s).unwrap().origin,
            field(10, 8, 14).get(0, 0).origin
        );
        let err = chain.begin_frame(cam.as_ref(), info(5)).unwrap_err().to_string();
        assert!(err.contains("rerender-frame0005"), "{err}");
        // Motion blur: halfway through the shutter of frame 3, halfway between frames 3 and 4.
        let mut chain = LensChain::new();
        chain.push(Box::new(LensReader::new(RaySource::Directory(dir.clone())).with_motion_blur(true)));
        chain.begin_frame(cam.as_ref(), info(3)).unwrap();
        let s = CameraSample { p_film: Vec2::new(2.5, 1.5), p_lens: Vec2::splat(0.5), time: 3.5 };
        let ray = chain.generator(cam.as_ref()).generate(&s).unwrap();
        let want = lerp_rays(field(10, 8, 13).get(2, 1), field(10, 8, 14).get(2, 1), 0.5);
        assert!(close(&StoredRay::new(ray.origin, ray.direction), &want));
        // Frame 4 has no successor: it holds still.
        chain.begin_frame(cam.as_ref(), info(4)).unwrap();
        let s = CameraSample { time: 4.5, ..s };
        let ray = chain.generator(cam.as_ref()).generate(&s).unwrap();
        assert_eq!(ray.origin, field(10, 8, 14).get(2, 1).origin);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Rays handed over with `with_frame` are used as they are: the frame renders with its file
    /// gone, blending into the next frame's rays handed with it.
    #[test]
    fn rays_handed_over_are_not_read_again() {
        let dir = scratch_dir("lens-reader-handed");
        let (this, next) = (Arc::new(field(10, 8, 21)), Arc::new(field(10, 8, 22)));
        let cam = camera(UVec2::new(10, 8));
        let mut chain = LensChain::new();
        let reader = LensReader::new(RaySource::Directory(dir.clone())).with_motion_blur(true).with_frame(
            6,
            this.clone(),
            Some(next.clone()),
        );
        chain.push(Box::new(reader));
        chain.begin_frame(cam.as_ref(), FrameInfo { frame: 6, camera_id: 0, shutter: (6.0, 6.5) }).unwrap();
        let s = CameraSample { p_film: Vec2::new(2.5, 1.5), p_lens: Vec2::splat(0.5), time: 6.5 };
        let ray = chain.generator(cam.as_ref()).generate(&s).unwrap();
        let want = lerp_rays(this.get(2, 1), next.get(2, 1), 0.5);
        assert!(close(&StoredRay::new(ray.origin, ray.direction), &want));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn in_memory_rays_at_another_resolution() {
        let f = Arc::new(field(6, 4, 5));
        let mut reader = LensReader::new(RaySource::Rays(f.clone()));
        let cam = camera(UVec2::new(12, 8));
        let mut chain = LensChain::new();
        chain.push(Box::new(LensReader::new(RaySource::Rays(f.clone()))));
        chain.begin_frame(cam.as_ref(), FrameInfo { frame: 0, camera_id: 0, shutter: (0.0, 0.0) }).unwrap();
        let upstream = chain.generator(cam.as_ref());
        let ctx = FrameContext {
            frame: 0,
            camera_id: 0,
            resolution: UVec2::new(12, 8),
            shutter: (0.0, 0.0),
            upstream: &upstream,
        };
        reader.begin_frame(&ctx).unwrap();
        let sampler = reader.sampler().unwrap();
        for p in [Vec2::new(0.0, 0.0), Vec2::new(5.3, 7.9), Vec2::new(12.0, 8.0)] {
            let s = CameraSample { p_film: p, p_lens: Vec2::ZERO, time: 0.0 };
            let r = upstream.generate(&s).unwrap();
            assert_eq!(StoredRay::new(r.origin, r.direction), sampler.at(p));
        }
    }

    #[test]
    fn fused_blend_matches_the_nested_slerps() {
        // Close neighbours (a smooth camera): the fused path is taken; compare with
        // docs/design/workflow.md §6's form.
        let (w, h) = (40, 30);
        let rays = (0..w * h)
            .map(|p| {
                let (x, y) = ((p % w) as f32, (p / w) as f32);
                let d = Vec3::new(x * 0.004 - 0.08, y * 0.0035 - 0.05, -1.0).normalize();
                StoredRay::new(Vec3::new(x, y * 0.5, 1.0), d)
            })
            .collect();
        let f = Arc::new(RayFile::new(w, h, 0, 0, rays).unwrap());
        let s = RaySampler::new(f.clone(), UVec2::new(97, 61)).unwrap();
        let mut rng = Rng::new(12);
        for _ in 0..20000 {
            let p = Vec2::new(rng.unit() * 97.0, rng.unit() * 61.0);
            let got = s.at(p);
            let u = (p.x as f64 * 40.0 / 97.0 - 0.5).clamp(0.0, 39.0);
            let v = (p.y as f64 * 30.0 / 61.0 - 0.5).clamp(0.0, 29.0);
            let (i, j) = (u.floor() as u32, v.floor() as u32);
            let (i1, j1) = ((i + 1).min(39), (j + 1).min(29));
            let (ss, tt) = ((u - i as f64) as f32, (v - j as f64) as f32);
            let want = lerp_rays(
                &lerp_rays(f.get(i, j), f.get(i1, j), ss),
                &lerp_rays(f.get(i, j1), f.get(i1, j1), ss),
                tt,
            );
            assert!(angle_between(got.direction, want.direction) < 2e-7, "{p}");
            assert!((got.origin - want.origin).length() < 1e-5, "{p}");
            assert!((got.direction.length() - 1.0).abs() < 1e-6);
        }
    }
}
