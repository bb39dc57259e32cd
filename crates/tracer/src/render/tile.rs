//! One tile of one pass over the film (docs/design/tracer.md §3.3): every pixel's samples of the pass,
//! each a camera sample (film, lens and time from the sampler), its ray through the lens chain
//! and the path tracer, added to the pixel's accumulator. The loop [`super::cpu`] compiles once
//! per x86-64 level; a leaf of the render module.

use crate::camera::CameraSample;
use crate::film::PixelAccumulator;
use crate::integrator::{FirstHit, PathTracer};
use crate::lens::RayGenerator;
use crate::sampler::{Sampler, sets};
use glam::{UVec2, Vec2};

/// Tile edge in pixels: big enough to amortise scheduling, small enough to balance 2+ cores.
pub(super) const TILE: u32 = 16;

/// The samples one pass over the film takes: each pixel's indices `start` .. its end, added
/// to its accumulator from `previous` if there is one (`ends` and `previous` are row-major over
/// the pass's rows).
pub(super) struct Pass<'a> {
    pub(super) start: u32,
    pub(super) ends: Ends<'a>,
    pub(super) previous: Option<&'a [PixelAccumulator]>,
}

/// Where each pixel's samples end.
pub(super) enum Ends<'a> {
    /// The same for every pixel.
    All(u32),
    /// Per pixel, row-major.
    PerPixel(&'a [u32]),
}

/// Everything one tile's tracing needs (shared by all tiles of a frame).
pub(super) struct TileJob<'a> {
    pub(super) tracer: &'a PathTracer,
    pub(super) generator: &'a dyn RayGenerator,
    pub(super) res: UVec2,
    /// The film rows traced (`start..end`); tiles are counted from `start`.
    pub(super) rows: (u32, u32),
    pub(super) tiles_x: u32,
    /// The seed of the sample sequence.
    pub(super) seed: u32,
    pub(super) pass: &'a Pass<'a>,
    pub(super) frame_time: f32,
    pub(super) shutter_length: f32,
    /// Pinhole cameras and instantaneous shutters draw no lens or time numbers.
    pub(super) needs_lens_time: bool,
}

impl TileJob<'_> {
    /// Traces the pass's samples of tile `tile`: its pixels' accumulators in row-major order
    /// within the tile, the rays traced and the samples taken.
    #[inline(always)]
    pub(super) fn trace_tile<const AOV: bool, const ALPHA: bool, const LAMBERT: bool>(
        &self,
        tile: u32,
    ) -> (Vec<PixelAccumulator>, u64, u64) {
        let (res, tracer) = (self.res, self.tracer);
        let x0 = (tile % self.tiles_x) * TILE;
        let y0 = self.rows.0 + (tile / self.tiles_x) * TILE;
        let x1 = (x0 + TILE).min(res.x);
        let y1 = (y0 + TILE).min(self.rows.1);
        let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
        let (mut rays, mut samples) = (0u64, 0u64);
        let pass = self.pass;
        for y in y0..y1 {
            for x in x0..x1 {
                let pixel = UVec2::new(x, y);
                let i = ((y - self.rows.0) * res.x + x) as usize;
                let mut acc = pass.previous.map_or_else(PixelAccumulator::default, |p| p[i]);
                let end = match pass.ends {
                    Ends::All(end) => end,
                    Ends::PerPixel(ends) => ends[i],
                };
                samples += end.saturating_sub(pass.start) as u64;
                for index in pass.start..end {
                    let sampler = Sampler::new(pixel, index, self.seed);
                    let [jx, jy, l0, l1] = sampler.get(sets::CAMERA);
                    let [lens_u, lens_v, u_time, _] =
                        if self.needs_lens_time { sampler.get(sets::LENS_TIME) } else { [0.5; 4] };
                    let sample = CameraSample {
                        p_film: Vec2::new(x as f32 + jx, y as f32 + jy),
                        p_lens: Vec2::new(lens_u, lens_v),
                        time: self.frame_time + self.shutter_length * u_time,
                    };
                    let Some(ray) = self.generator.generate(&sample) else {
                        acc.drop_sample();
                        continue;
                    };
                    let mut first = FirstHit::default();
                    let path =
                        tracer.radiance::<AOV, ALPHA, LAMBERT>(ray, &sampler, Vec2::new(l0, l1), &mut first);
                    rays += path.rays as u64;
                    acc.add(path.radiance);
                    if AOV {
                        acc.add_first_hit(&first);
                    }
                }
                out.push(acc);
            }
        }
        (out, rays, samples)
    }
}
