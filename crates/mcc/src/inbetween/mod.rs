//! The in-betweener (docs/design/workflow.md §7): keyframe ray files in, one ray file per animation frame
//! out.
//!
//! Keys are (frame, ray file) pairs. Every key is first brought to the output resolution (given,
//! or the earliest key's) with the lens reader's rule ([`RaySampler`], docs/design/workflow.md §6: a key
//! already at that size is kept bit for bit); keys need share no cameras, they are only rays. A
//! frame's ray at pixel p is then interpolated from the keys' rays at p:
//!
//! * **at a key** the key's ray, bit for bit; **before the first / after the last key** the
//!   nearest key's, bit for bit (the animation holds);
//! * [`InbetweenMode::Linear`]: origins lerp and directions slerp between the two surrounding
//!   keys ([`lerp_rays`], the crate's accurate slerp), s = (t − t_k)/(t_{k+1} − t_k);
//! * [`InbetweenMode::Smooth`] (the default): C1 everywhere, described below.
//!
//! # The smooth scheme
//!
//! **Origins** follow the Catmull–Rom (cardinal, tension 0) spline *in the frame domain*: a cubic
//! Hermite segment between each pair of keys, with the tangent (velocity, per frame) of interior
//! key k taken from its neighbours, m_k = (p_{k+1} − p_{k−1}) / (t_{k+1} − t_{k−1}), and the
//! Hermite tangents of a segment h = t_{k+1} − t_k frames long scaled by h. Each segment's
//! velocity at its ends is then exactly m_k and m_{k+1} per frame, whatever the key spacing
//! (keys at 0, 150, 400, 500 have no velocity jump), so the curve is C1 at interior keys. The end
//! keys get velocity 0: the hold before the first and after the last key then joins C1 too (the
//! motion eases in and out; two keys give a smoothstep-eased lerp).
//!
//! **Directions** use the same Hermite curve in a chart of the sphere attached to each segment:
//! with u ⟂ a the unit vector towards b in the plane of the key directions a and b, w = a × u,
//! θ the arc from a to b and n(φ, ψ) = cos ψ·(a cos φ + u sin φ) + w sin ψ, the direction is
//! n(φ(s), ψ(s)) where φ runs from 0 to θ and ψ from 0 to 0 along Hermite cubics whose end
//! derivatives are the key tangents written in the chart: φ'(a) = m_a·u, ψ'(a) = m_a·w,
//! φ'(b) = m_b·u_b, ψ'(b) = m_b·w, with u_b = u cos θ − a sin θ the circle's tangent at b.
//! The direction tangents are the Catmull–Rom differences of the sphere's logarithm,
//! m_k = (log_{d_k} d_{k+1} − log_{d_k} d_{k−1}) / (t_{k+1} − t_{k−1}), vectors in the tangent
//! plane of d_k (zero at the end keys). Why this is C1 and safe:
//!
//! * *C1*: on the equator ψ = 0 the chart's partial derivatives are ∂n/∂φ = the circle's unit
//!   tangent (u at a, u_b at b) and ∂n/∂ψ = w, an orthonormal basis of the tangent plane there.
//!   So the velocity at a segment's end is u(m·u) + w(m·w) = m (m lies in that plane): both
//!   segments meeting at key k leave and reach d_k with the velocity m_k per frame. Within a
//!   segment n(φ, ψ) is a smooth (C∞) map of smooth functions of time.
//! * *Unit, never NaN*: n is a unit vector for every real φ, ψ (a, u, w orthonormal); the chart
//!   has no singular point at all (only its inverse does, at ±w, which is never needed). Every
//!   division is guarded: u comes from the shorter of b − a and a + b (no cancellation for nearly
//!   parallel or nearly opposite keys), and when a and b span no plane (equal, or exactly
//!   opposite) u is the crate's deterministic perpendicular (`any_orthonormal_vector`, as
//!   [`crate::slerp::slerp`] chooses). The logarithm is bounded by π, so tangents are at most
//!   2π/(t_{k+1} − t_{k−1}) per frame and the chart coordinates stay within
//!   |ψ|, |φ − θ·h01| ≤ (4/27)·4π ≈ 1.9: nearly opposite neighbouring keys swing fast but
//!   finitely. A final normalisation removes rounding, so directions are unit to f32 precision.
//! * *Continuity of the value*: the chart reaches a at s = 0 exactly and b at s = 1 to rounding
//!   (n(θ, 0) = a cos θ + u sin θ, within 1e-6 of b); the key frame itself returns the key's ray.
//!
//! The only discontinuity is the inherent one: which great circle joins two *exactly* opposite
//! keys (any does), fixed deterministically per pixel.
//!
//! # Cost
//! Tangents are computed once, on the first smooth frame, for interior keys only (one extra ray
//! per pixel per interior key; keys are otherwise held once, at the output resolution). A frame
//! reads two keys and (smooth) their two tangents per pixel; rows run in parallel with rayon;
//! nothing is allocated per pixel, and [`Keys::frame_into`] reuses the output buffer. The smooth
//! kernel is branch-free with polynomial trigonometry (no libm call), so each row is one loop
//! that LLVM vectorises (SSE2, or AVX2 where the CPU has it, chosen at run time; no FMA, so both
//! give the same bits). Each pixel is a pure function of the key data and the frame: the bits do
//! not depend on the thread count. Linear frames call the crate's scalar [`crate::slerp::slerp`]
//! per pixel, so they are slower than smooth ones
//! (docs/performance.md, ledger: "vectorised smooth in-between").

mod kernel;
#[cfg(test)]
mod tests;

use crate::error::{MccError, Result};
use crate::lens_reader::RaySampler;
use crate::names::rerender_name;
use crate::ray_file::{MAX_PIXELS, MAX_SIDE, RayFile, RayFormat, StoredRay};
use crate::slerp::lerp_rays;
use glam::{UVec2, Vec2};
use kernel::Hermite;
use rayon::prelude::*;
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// How frames between keys are interpolated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum InbetweenMode {
    /// C1 across interior keys and at the holds (see the module notes). The default.
    #[default]
    Smooth,
    /// Origins lerp, directions slerp between the two surrounding keys (C0 only).
    Linear,
}

/// One key: its frame and its rays at the output resolution.
#[derive(Debug)]
struct Key {
    frame: u32,
    rays: Vec<StoredRay>,
}

/// The keys of an in-betweening, resampled to one output resolution and sorted by frame.
#[derive(Debug)]
pub struct Keys {
    width: u32,
    height: u32,
    keys: Vec<Key>,
    /// Per key, the per-pixel velocities (origin, direction) per frame; `None` for the end keys,
    /// whose velocity is zero. Computed on the first smooth frame.
    tangents: OnceLock<Vec<Option<Vec<StoredRay>>>>,
    /// A row of zero velocities (the end keys' tangents).
    zeros: Vec<StoredRay>,
}

/// What a frame is made of: which keys, and with which weights.
enum Plan<'a> {
    Hold(&'a [StoredRay]),
    Linear {
        a: &'a [StoredRay],
        b: &'a [StoredRay],
        s: f32,
    },
    Smooth {
        a: &'a [StoredRay],
        b: &'a [StoredRay],
        ta: Option<&'a [StoredRay]>,
        tb: Option<&'a [StoredRay]>,
        zeros: &'a [StoredRay],
        h: Hermite,
    },
}

impl<'a> Plan<'a> {
    /// The ray of pixel index `i` (the keys' rays are all at the output resolution).
    #[inline]
    fn ray(&self, i: usize) -> StoredRay {
        let mut out = [StoredRay::default()];
        self.fill(i, &mut out);
        out[0]
    }

    /// Fills `out` (at most a row) with the rays of pixel indices `first ..`. Smooth rows are
    /// one vectorised loop (see [`kernel::smooth_row`]): the bits of a pixel do not depend on
    /// where the row starts.
    #[inline]
    fn fill(&self, first: usize, out: &mut [StoredRay]) {
        let range = first..first + out.len();
        match *self {
            Plan::Hold(rays) => out.copy_from_slice(&rays[range]),
            Plan::Linear { a, b, s } => {
                for ((o, a), b) in out.iter_mut().zip(&a[range.clone()]).zip(&b[range]) {
                    *o = lerp_rays(a, b, s);
                }
            }
            Plan::Smooth { a, b, ta, tb, zeros, h } => {
                // End keys have zero velocity: a row of zeros stands in for their tangents.
                let n = out.len();
                let tangents = |t: Option<&'a [StoredRay]>| t.map_or(&zeros[..n], |t| &t[range.clone()]);
                let (ma, mb) = (tangents(ta), tangents(tb));
                kernel::smooth_row(&a[range.clone()], &b[range.clone()], ma, mb, h, out);
            }
        }
    }
}

impl Keys {
    /// Keys from (frame, rays) pairs in memory, in any order, resampled to `resolution` (default:
    /// the resolution of the key with the earliest frame). Refuses an empty list, two keys for
    /// one frame, and keys whose rays are malformed (wrong count, non-finite, non-unit).
    pub fn new(keys: Vec<(u32, RayFile)>, resolution: Option<UVec2>) -> Result<Self> {
        if keys.is_empty() {
            return Err(no_keys());
        }
        let mut keys: Vec<(usize, u32, RayFile)> =
            keys.into_iter().enumerate().map(|(n, (frame, rays))| (n, frame, rays)).collect();
        keys.sort_by_key(|&(n, frame, _)| (frame, n));
        for pair in keys.windows(2) {
            if pair[0].1 == pair[1].1 {
                return Err(MccError::input(
                    "in-betweener keys",
                    format!(
                        "frame {} has two keys (keys {} and {} as given, counting from 1); each frame takes one key",
                        pair[0].1,
                        pair[0].0 + 1,
                        pair[1].0 + 1
                    ),
                ));
            }
        }
        for (_, frame, rays) in &keys {
            check_in_memory(*frame, rays)?;
        }
        let resolution = resolution.unwrap_or(UVec2::new(keys[0].2.width, keys[0].2.height));
        check_resolution(resolution)?;
        let keys = keys
            .into_iter()
            .map(|(_, frame, rays)| {
                let what = || format!("key at frame {frame}");
                Ok(Key { frame, rays: resample(rays, resolution).map_err(|e| rename(e, what()))? })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self::from_parts(resolution, keys))
    }

    /// Keys from (frame, ray file) pairs on disk, in any order, resampled to `resolution`
    /// (default: that of the key with the earliest frame). Two keys for one frame are refused
    /// before anything is read (the error names both files); a file that cannot be read is
    /// refused with its name. Each key is resampled as soon as it is read, so only one copy of
    /// each is held.
    pub fn load(keys: &[(u32, PathBuf)], resolution: Option<UVec2>) -> Result<Self> {
        Self::load_cropped(keys, 0, resolution)
    }

    /// [`Self::load`], each key first cut by a border of `crop` of its own pixels (the overscan
    /// its views were rendered with); `resolution` is then the size after the crop.
    pub fn load_cropped(keys: &[(u32, PathBuf)], crop: u32, resolution: Option<UVec2>) -> Result<Self> {
        if keys.is_empty() {
            return Err(no_keys());
        }
        let mut order: Vec<&(u32, PathBuf)> = keys.iter().collect();
        order.sort_by_key(|(frame, _)| *frame);
        for pair in order.windows(2) {
            if pair[0].0 == pair[1].0 {
                return Err(MccError::ray_file(
                    &pair[1].1,
                    format!(
                        "frame {} already has a key, {}; each frame takes one key",
                        pair[1].0,
                        pair[0].1.display()
                    ),
                ));
            }
        }
        let mut resolution = resolution;
        if let Some(r) = resolution {
            check_resolution(r)?;
        }
        let mut loaded = Vec::with_capacity(order.len());
        for (frame, path) in order {
            let rays = crop_key(RayFile::read(path)?, crop).map_err(|m| MccError::ray_file(path, m))?;
            let res = *resolution.get_or_insert(UVec2::new(rays.width, rays.height));
            let what = || format!("key at frame {frame} ({})", path.display());
            loaded.push(Key { frame: *frame, rays: resample(rays, res).map_err(|e| rename(e, what()))? });
        }
        Ok(Self::from_parts(resolution.expect("at least one key"), loaded))
    }

    fn from_parts(resolution: UVec2, keys: Vec<Key>) -> Self {
        let zeros = vec![StoredRay::default(); resolution.x as usize];
        Self { width: resolution.x, height: resolution.y, keys, tangents: OnceLock::new(), zeros }
    }

    /// The output resolution every frame has.
    pub fn resolution(&self) -> UVec2 {
        UVec2::new(self.width, self.height)
    }

    /// The key frames, ascending.
    pub fn frames(&self) -> Vec<u32> {
        self.keys.iter().map(|k| k.frame).collect()
    }

    /// The rays of key `index` (in frame order) at the output resolution.
    pub fn key_rays(&self, index: usize) -> &[StoredRay] {
        &self.keys[index].rays
    }

    /// The rays of `frame`: a computed ray file (flag set, camera id 0, `frame` set).
    pub fn frame(&self, frame: u32, mode: InbetweenMode) -> RayFile {
        let mut out = RayFile { width: 0, height: 0, frame, camera_id: 0, computed: true, rays: Vec::new() };
        self.frame_into(frame, mode, &mut out);
        out
    }

    /// [`Keys::frame`] into an existing ray file, reusing its ray buffer when it has the right
    /// size (a fresh buffer costs its page faults again:
    /// docs/performance.md, ledger: "in-between buffer reuse").
    pub fn frame_into(&self, frame: u32, mode: InbetweenMode, out: &mut RayFile) {
        let n = self.width as usize * self.height as usize;
        if out.rays.len() != n {
            out.rays = bytemuck::zeroed_vec(n);
        }
        (out.width, out.height, out.frame, out.camera_id, out.computed) =
            (self.width, self.height, frame, 0, true);
        let plan = self.plan(frame as f64, mode);
        let w = self.width as usize;
        out.rays.par_chunks_mut(w).enumerate().for_each(|(j, row)| plan.fill(j * w, row));
    }

    /// The ray of pixel index `pixel` (row-major) at any `time` in frames, including between
    /// frames (what [`Keys::frame`] computes at integer times, bit for bit).
    pub fn ray(&self, pixel: usize, time: f64, mode: InbetweenMode) -> StoredRay {
        self.plan(time, mode).ray(pixel)
    }

    /// Which keys and weights make the frame at `time`.
    fn plan(&self, time: f64, mode: InbetweenMode) -> Plan<'_> {
        let keys = &self.keys;
        let last = keys.len() - 1;
        // A NaN time holds the first key.
        if time.is_nan() || time <= keys[0].frame as f64 {
            return Plan::Hold(&keys[0].rays);
        }
        if time >= keys[last].frame as f64 {
            return Plan::Hold(&keys[last].rays);
        }
        // keys[k].frame ≤ time < keys[k + 1].frame, with k < last.
        let k = keys.partition_point(|key| key.frame as f64 <= time) - 1;
        let (a, b) = (&keys[k], &keys[k + 1]);
        if time == a.frame as f64 {
            return Plan::Hold(&a.rays);
        }
        let h = (b.frame - a.frame) as f64;
        let s = (time - a.frame as f64) / h;
        match mode {
            InbetweenMode::Linear => Plan::Linear { a: &a.rays, b: &b.rays, s: s as f32 },
            InbetweenMode::Smooth => {
                let tangents = self.tangents();
                Plan::Smooth {
                    a: &a.rays,
                    b: &b.rays,
                    ta: tangents[k].as_deref(),
                    tb: tangents[k + 1].as_deref(),
                    zeros: &self.zeros,
                    h: Hermite::new(s, h),
                }
            }
        }
    }

    /// The interior keys' per-pixel velocities, computed once.
    fn tangents(&self) -> &[Option<Vec<StoredRay>>] {
        self.tangents.get_or_init(|| {
            let n = self.keys.len();
            (0..n)
                .map(|k| {
                    if k == 0 || k == n - 1 {
                        return None;
                    }
                    let (prev, key, next) = (&self.keys[k - 1], &self.keys[k], &self.keys[k + 1]);
                    let span = (next.frame - prev.frame) as f64;
                    let mut out: Vec<StoredRay> = bytemuck::zeroed_vec(key.rays.len());
                    const CHUNK: usize = 1 << 14;
                    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, chunk)| {
                        for (i, m) in (c * CHUNK..).zip(chunk) {
                            *m = kernel::tangent(&prev.rays[i], &key.rays[i], &next.rays[i], span);
                        }
                    });
                    Some(out)
                })
                .collect()
        })
    }
}

/// Writes the frames `frames` as `out_dir/rerender-frameFFFF.{mcr|txt}` (created if missing),
/// each atomically, calling `progress(frame)` after each file is in place. Returns the paths in
/// frame order. Computing frame n + 1 overlaps writing frame n.
pub fn write_frames(
    keys: &Keys,
    frames: RangeInclusive<u32>,
    mode: InbetweenMode,
    out_dir: &Path,
    format: RayFormat,
    progress: &dyn Fn(u32),
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out_dir).map_err(|e| MccError::io(out_dir, e))?;
    let mut written = Vec::with_capacity(frames.size_hint().0);
    // Two buffers: the writer thread holds one while this thread computes into the other.
    let (to_writer, writer_in) = std::sync::mpsc::sync_channel::<(PathBuf, RayFile)>(1);
    let (writer_out, from_writer) = std::sync::mpsc::channel::<(PathBuf, RayFile, Result<()>)>();
    std::thread::scope(|scope| -> Result<()> {
        scope.spawn(move || {
            for (path, file) in writer_in {
                let result = file.write(&path, format);
                if writer_out.send((path, file, result)).is_err() {
                    break;
                }
            }
        });
        let mut spare = vec![empty_file(), empty_file()];
        let mut in_flight = 0usize;
        let mut finish = |in_flight: &mut usize, spare: &mut Vec<RayFile>| -> Result<()> {
            let (path, file, result) = from_writer.recv().expect("the writer thread answers every frame");
            *in_flight -= 1;
            result?;
            progress(file.frame);
            spare.push(file);
            written.push(path);
            Ok(())
        };
        for frame in frames {
            if spare.is_empty() {
                finish(&mut in_flight, &mut spare)?;
            }
            let mut file = spare.pop().expect("a free buffer");
            keys.frame_into(frame, mode, &mut file);
            let path = out_dir.join(rerender_name(frame, format));
            to_writer.send((path, file)).expect("the writer thread lives while frames are sent");
            in_flight += 1;
        }
        drop(to_writer);
        while in_flight > 0 {
            finish(&mut in_flight, &mut spare)?;
        }
        Ok(())
    })?;
    Ok(written)
}

fn empty_file() -> RayFile {
    RayFile { width: 0, height: 0, frame: 0, camera_id: 0, computed: true, rays: Vec::new() }
}

/// `rays` without a border of `crop` pixels (an overscan cut off), or why not.
pub fn crop_key(rays: RayFile, crop: u32) -> std::result::Result<RayFile, String> {
    if crop == 0 {
        return Ok(rays);
    }
    rays.without_border(crop)
        .ok_or_else(|| format!("crop {crop} leaves nothing of a {}x{} key", rays.width, rays.height))
}

fn no_keys() -> MccError {
    MccError::input("in-betweener keys", "no keys: at least one (frame, ray file) key is needed")
}

/// Checks an in-memory key as the reader checks a file: size, ray count, finite unit rays.
fn check_in_memory(frame: u32, rays: &RayFile) -> Result<()> {
    let what = || format!("key at frame {frame}");
    if rays.width == 0 || rays.height == 0 || rays.rays.len() as u64 != rays.width as u64 * rays.height as u64
    {
        return Err(MccError::input(
            what(),
            format!("{} rays for a {}x{} ray file", rays.rays.len(), rays.width, rays.height),
        ));
    }
    if let Some((index, message)) = rays.first_defect() {
        let w = rays.width as usize;
        return Err(MccError::input(
            what(),
            format!("ray {index} (pixel ({}, {})): {message}", index % w, index / w),
        ));
    }
    Ok(())
}

fn check_resolution(r: UVec2) -> Result<()> {
    if r.x == 0 || r.y == 0 || r.x > MAX_SIDE || r.y > MAX_SIDE || r.x as u64 * r.y as u64 > MAX_PIXELS {
        return Err(MccError::Settings(format!(
            "in-betweener output resolution {}x{}: each side must be 1 … {MAX_SIDE}, at most {MAX_PIXELS} pixels",
            r.x, r.y
        )));
    }
    Ok(())
}

/// Gives an in-memory data error a better name (the key it concerns).
fn rename(e: MccError, what: String) -> MccError {
    match e {
        MccError::Input { message, .. } => MccError::Input { what, message },
        other => other,
    }
}

/// The rays of `file` at `resolution` by the lens reader's rule (docs/design/workflow.md §6), sampled at the
/// output pixel centres; a file already at that size is returned as it is (the rule is exact
/// there).
fn resample(file: RayFile, resolution: UVec2) -> Result<Vec<StoredRay>> {
    if (file.width, file.height) == (resolution.x, resolution.y) {
        return Ok(file.rays);
    }
    let sampler = RaySampler::new(Arc::new(file), resolution)?;
    let w = resolution.x as usize;
    let mut out: Vec<StoredRay> = bytemuck::zeroed_vec(w * resolution.y as usize);
    out.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
        for (i, r) in row.iter_mut().enumerate() {
            *r = sampler.at(Vec2::new(i as f32 + 0.5, j as f32 + 0.5));
        }
    });
    Ok(out)
}
