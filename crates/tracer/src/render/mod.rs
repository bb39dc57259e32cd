//! The render loop: samples every pixel of the film through the camera and the lens chain and
//! the path tracer, in parallel tiles on the current rayon pool.
//!
//! Determinism: each pixel is computed by exactly one task, its samples in index order, with
//! random numbers that depend only on (pixel, sample, dimension, seed) — so the image is the
//! same bit for bit whatever the thread count and whichever thread takes which tile. Adaptive
//! sampling (`crate::adaptive`) adds a second pass whose per-pixel counts are a pure function
//! of the first pass's film; each pixel goes on from its pilot samples' indices.

use crate::adaptive;
use crate::camera::Camera;
use crate::error::{Result, TracerError};
use crate::film::{Film, FilmImages, PixelAccumulator};
use crate::integrator::PathTracer;
use crate::lens::{FrameInfo, LensChain, RayGenerator};
use crate::sampler::MAX_SAMPLES_PER_PIXEL;
use glam::UVec2;
use rayon::prelude::*;
use std::time::Instant;

mod cpu;
mod tile;

use tile::{Ends, Pass, TILE, TileJob};

/// The most pixels a film may have (refused before allocating).
pub const MAX_PIXELS: u64 = 1 << 28;

/// What to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Samples per pixel (1 ..= 65536 / the tracer's first-vertex split).
    pub spp: u32,
    /// Seed of the sample sequence.
    pub seed: u32,
    /// Frame number (passed to lens shaders; the shutter opens at this time).
    pub frame: u32,
    /// The view's camera number, 1-based (passed to lens shaders).
    pub camera_id: u32,
    /// Shutter open and close as offsets from the frame, in frames; equal values mean no
    /// motion blur (and no time dimension is sampled).
    pub shutter: (f32, f32),
    /// Whether to record first-hit albedo, normal and depth.
    pub aovs: bool,
    /// Whether to spread the samples adaptively (`crate::adaptive`): `spp` is then the average
    /// per pixel, a quarter of it taken everywhere and the rest where the relative noise is
    /// highest.
    pub adaptive: bool,
    /// Only the film rows `start..end` (a band of the image, docs/farm.md): the film returned
    /// holds those rows, each pixel exactly as a whole render computes it; `None`: every row.
    pub rows: Option<(u32, u32)>,
}

impl RenderSettings {
    /// A still render at `spp` samples per pixel, seed 0, frame 0, camera 1.
    pub const fn still(spp: u32) -> Self {
        Self {
            spp,
            seed: 0,
            frame: 0,
            camera_id: 1,
            shutter: (0.0, 0.0),
            aovs: false,
            adaptive: false,
            rows: None,
        }
    }
}

/// Progress reports from long work, and the caller's way to stop it. The render loop calls
/// `advance` from worker threads and asks `cancelled` before each tile; the jobs around it
/// (`crate::job`) bracket each stage with `begin` and `finish`.
pub trait Progress: Sync {
    /// `samples` more pixel samples are finished (a render takes about width × height × spp).
    fn advance(&self, samples: u64);

    /// A stage of about `total` units called `label` begins (a camera's render: its samples).
    fn begin(&self, _label: &str, _total: u64) {}

    /// The stage begun last is over.
    fn finish(&self) {}

    /// Whether the caller wants the work stopped: a render then skips its remaining tiles and
    /// returns [`TracerError::Cancelled`], writing nothing. Once true it must stay true.
    fn cancelled(&self) -> bool {
        false
    }
}

/// A progress sink that ignores everything.
pub struct NoProgress;

impl Progress for NoProgress {
    fn advance(&self, _samples: u64) {}
}

/// Counts from one render.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Wall-clock seconds spent tracing (lens set-up and tear-down excluded).
    pub seconds: f64,
    /// Camera samples taken (with adaptive sampling, at most width × height × spp).
    pub samples: u64,
    /// Rays traced (camera, continuation and shadow rays).
    pub rays: u64,
    /// Samples that came out NaN or infinite (recorded as black).
    pub nonfinite_samples: u64,
    /// Samples the camera or a lens shader dropped (recorded as black).
    pub dropped_samples: u64,
}

/// A finished render.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The images.
    pub images: FilmImages,
    /// The counts.
    pub stats: RenderStats,
}

/// Renders one frame of `camera` through `lenses` with `tracer`.
pub fn render(
    tracer: &PathTracer,
    camera: &dyn Camera,
    lenses: &mut LensChain,
    settings: &RenderSettings,
    progress: &dyn Progress,
) -> Result<Rendered> {
    let res = camera.resolution();
    // Each camera sample's split branches take sample indices of their own (`Sampler::branch`).
    let split = tracer.config().split;
    let most_spp = MAX_SAMPLES_PER_PIXEL / split;
    if settings.spp == 0 || settings.spp > most_spp {
        let per_branch =
            if split > 1 { format!(" with {split} paths split from each first hit") } else { String::new() };
        return Err(TracerError::Settings(format!(
            "{} samples per pixel: must be 1 ..= {most_spp}{per_branch}",
            settings.spp
        )));
    }
    if res.x == 0 || res.y == 0 || res.x as u64 * res.y as u64 > MAX_PIXELS {
        return Err(TracerError::Settings(format!(
            "resolution {}x{}: must be non-empty and at most {MAX_PIXELS} pixels",
            res.x, res.y
        )));
    }
    let (first, end) = settings.rows.unwrap_or((0, res.y));
    if first >= end || end > res.y {
        return Err(TracerError::Settings(format!(
            "rows {first}..{end} of a {}x{} film: must be a non-empty range inside it",
            res.x, res.y
        )));
    }
    let (open, close) = settings.shutter;
    if !(open.is_finite() && close.is_finite() && open <= close) {
        return Err(TracerError::Settings(format!(
            "shutter {open}..{close} must be finite with open ≤ close"
        )));
    }
    let frame = FrameInfo {
        frame: settings.frame,
        camera_id: settings.camera_id,
        shutter: (settings.frame as f32 + open, settings.frame as f32 + close),
    };
    lenses.begin_frame(camera, frame)?;
    let start = Instant::now();
    let (pixels, rays) = {
        let generator = lenses.generator(camera);
        let lens = camera.uses_lens();
        let trace = |pass: &Pass, rows: (u32, u32), p: &dyn Progress| {
            // Specialised loops: no AOV bookkeeping without AOVs, no alpha tests without
            // alpha-tested materials, and the Lambert-only path where every surface is an
            // untextured, flat-shaded Lambertian lit by triangles (never with alpha tests).
            let (g, s) = (&generator, settings);
            let job = FilmPass { tracer, generator: g, uses_lens: lens, res, rows, settings: s, pass };
            match (settings.aovs, tracer.has_alpha(), tracer.lambert_only()) {
                (true, true, _) => job.trace::<true, true, false>(p),
                (true, false, true) => job.trace::<true, false, true>(p),
                (true, false, false) => job.trace::<true, false, false>(p),
                (false, true, _) => job.trace::<false, true, false>(p),
                (false, false, true) => job.trace::<false, false, true>(p),
                (false, false, false) => job.trace::<false, false, false>(p),
            }
        };
        match adaptive::pilot_spp(settings.spp).filter(|_| settings.adaptive) {
            None => trace(
                &Pass { start: 0, ends: Ends::All(settings.spp), previous: None },
                (first, end),
                progress,
            ),
            Some(pilot) => {
                // The counts are a function of the whole pilot film (its noise total, the carry
                // from pixel to pixel), so a band takes the pilot everywhere; only its own rows'
                // pilot counts as its work (rays, progress), so the bands' counts add up to the
                // whole render's.
                let pass = Pass { start: 0, ends: Ends::All(pilot), previous: None };
                let outside = Unreported(progress);
                let (mut film, pilot_rays) = trace(&pass, (first, end), progress);
                if first > 0 {
                    let (above, _) = trace(&pass, (0, first), &outside);
                    film.splice(0..0, above);
                }
                if end < res.y {
                    film.extend(trace(&pass, (end, res.y), &outside).0);
                }
                if progress.cancelled() {
                    return Err(TracerError::Cancelled);
                }
                let counts = adaptive::sample_counts(&film, res.x, res.y, settings.spp, most_spp);
                let band = (first * res.x) as usize..(end * res.x) as usize;
                let pass = Pass {
                    start: pilot,
                    ends: Ends::PerPixel(&counts[band.clone()]),
                    previous: Some(&film[band]),
                };
                let (film, rays) = trace(&pass, (first, end), progress);
                (film, pilot_rays + rays)
            }
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    // A cancelled render skipped tiles: its film is incomplete, and the lens shaders' tear-down
    // (the lens writer's file) must not run on it.
    if progress.cancelled() {
        return Err(TracerError::Cancelled);
    }
    lenses.end_frame(camera, frame)?;

    let film = Film::new(res.x, end - first, pixels);
    let stats = RenderStats {
        seconds,
        samples: film.samples(),
        rays,
        nonfinite_samples: film.nonfinite_samples(),
        dropped_samples: film.dropped_samples(),
    };
    Ok(Rendered { images: film.images(), stats })
}

/// A progress sink that passes cancellation on but reports no work: the pilot pass a band
/// takes outside its rows.
struct Unreported<'a>(&'a dyn Progress);

impl Progress for Unreported<'_> {
    fn advance(&self, _samples: u64) {}
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

/// One pass over the film rows `rows` (`start..end`).
struct FilmPass<'a> {
    tracer: &'a PathTracer,
    generator: &'a dyn RayGenerator,
    uses_lens: bool,
    res: UVec2,
    rows: (u32, u32),
    settings: &'a RenderSettings,
    pass: &'a Pass<'a>,
}

impl FilmPass<'_> {
    /// Traces the pass over its rows; returns their accumulators in row-major order and the
    /// ray count.
    fn trace<const AOV: bool, const ALPHA: bool, const LAMBERT: bool>(
        &self,
        progress: &dyn Progress,
    ) -> (Vec<PixelAccumulator>, u64) {
        let (res, settings) = (self.res, self.settings);
        let (first, end) = self.rows;
        let tiles_x = res.x.div_ceil(TILE);
        let tiles_y = (end - first).div_ceil(TILE);
        let frame_time = settings.frame as f32 + settings.shutter.0;
        let shutter_length = settings.shutter.1 - settings.shutter.0;
        // Pinhole cameras and instantaneous shutters draw no lens or time numbers.
        let needs_lens_time = self.uses_lens || shutter_length > 0.0;
        let job = TileJob {
            tracer: self.tracer,
            generator: self.generator,
            res,
            rows: self.rows,
            tiles_x,
            seed: settings.seed,
            pass: self.pass,
            frame_time,
            shutter_length,
            needs_lens_time,
        };
        let level = cpu::level();
        let tiles: Vec<(Vec<PixelAccumulator>, u64)> = (0..tiles_x * tiles_y)
            .into_par_iter()
            .map(|tile| {
                if progress.cancelled() {
                    return (Vec::new(), 0);
                }
                let (accs, rays, samples) = cpu::trace_tile::<AOV, ALPHA, LAMBERT>(level, &job, tile);
                progress.advance(samples);
                (accs, rays)
            })
            .collect();

        // Scatter tiles into row-major order.
        let mut pixels = vec![PixelAccumulator::default(); res.x as usize * (end - first) as usize];
        let mut rays = 0;
        for (tile, (accs, tile_rays)) in tiles.into_iter().enumerate() {
            rays += tile_rays;
            let tile = tile as u32;
            let x0 = (tile % tiles_x) * TILE;
            let y0 = (tile / tiles_x) * TILE;
            let w = (x0 + TILE).min(res.x) - x0;
            for (k, acc) in accs.into_iter().enumerate() {
                let (dx, dy) = (k as u32 % w, k as u32 / w);
                pixels[((y0 + dy) * res.x + x0 + dx) as usize] = acc;
            }
        }
        (pixels, rays)
    }
}

#[cfg(test)]
mod tests;
