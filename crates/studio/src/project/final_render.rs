//! "Render final" (docs/studio.md, "Render final"): saves the project, then runs exactly what
//! `mcctrace rerender SCENE --collage collage.png --rays views` runs — the batch remap job on
//! the saved files and the rerender job — with progress to every tab and a cancel.

use super::save::{VIEWS, save};
use crate::engine::Shared;
use crate::engine::pictures::{png, srgb};
use crate::engine::worker::remap_config;
use crate::error::{Result, StudioError};
use crate::protocol::{ImageHeader, ImageKind, Outbound};
use glam::UVec2;
use mcc::job::{COLLAGE_KEY, CollageFiles, RemapJob, Rerender};
use mcc::names::rerender_name;
use mcc::ray_file::RayFormat;
use serde_json::json;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use tracer::job::Quality;
use tracer::render::Progress;

/// Reports the final render's progress to every tab, about every percent.
struct FinalProgress<'a> {
    shared: &'a Shared,
    total: AtomicU64,
    done: AtomicU64,
    sent: AtomicU64,
}

impl Progress for FinalProgress<'_> {
    fn begin(&self, _label: &str, total: u64) {
        self.total.store(total, Ordering::SeqCst);
    }

    fn advance(&self, samples: u64) {
        let done = self.done.fetch_add(samples, Ordering::SeqCst) + samples;
        let total = self.total.load(Ordering::SeqCst).max(1);
        let step = (total / 100).max(1);
        let sent = self.sent.load(Ordering::SeqCst);
        if done >= sent + step
            && self.sent.compare_exchange(sent, done, Ordering::SeqCst, Ordering::SeqCst).is_ok()
        {
            self.shared.broadcast(Outbound::json(
                json!({"type": "progress", "job": "final", "done": done, "total": total}),
            ));
        }
    }

    fn cancelled(&self) -> bool {
        self.shared.final_cancel.load(Ordering::SeqCst)
    }
}

/// Starts the final render at `res` and `spp`, the shutter open over `shutter` (frames after
/// the key's frame; `(0, 0)`: none), on a thread of its own; refuses a second one.
pub fn start_final(
    shared: &Arc<Shared>,
    id: Option<u64>,
    res: [u32; 2],
    spp: u32,
    shutter: (f32, f32),
) -> Result<()> {
    super::check_res(res)?;
    if spp == 0 || spp > 65536 {
        return Err(StudioError::request(format!("spp {spp}: give 1 to 65536 samples per pixel")));
    }
    let (open, close) = shutter;
    // `rerender --shutter`'s rule: the lens reader's camera rays span one frame at most.
    if !((0.0..=1.0).contains(&open) && (0.0..=1.0).contains(&close) && open <= close) {
        return Err(StudioError::request(format!(
            "shutter [{open}, {close}]: need 0 ≤ open ≤ close ≤ 1 (fractions of a frame)"
        )));
    }
    if shared.final_running.swap(true, Ordering::SeqCst) {
        return Err(StudioError::request("a final render is already running"));
    }
    shared.final_cancel.store(false, Ordering::SeqCst);
    let shared = Arc::clone(shared);
    std::thread::spawn(move || {
        let reply = match shared.pool.install(|| render_final(&shared, res, spp, shutter)) {
            Ok((exr, image)) => {
                let header = ImageHeader {
                    kind: ImageKind::Final,
                    camera: None,
                    seq: shared.seq(),
                    spp,
                    w: res[0],
                    h: res[1],
                };
                if let Ok(bytes) = png(&srgb(&image)) {
                    shared.picture(ImageKind::Final, None, header.message(bytes));
                }
                Outbound::json(json!({"type": "final", "id": id, "exr": exr}))
            }
            Err(e) if e.is_cancelled() => {
                Outbound::json(json!({"type": "final", "id": id, "cancelled": true}))
            }
            Err(e) => Outbound::error(id, format!("render final: {e}")),
        };
        shared.final_running.store(false, Ordering::SeqCst);
        shared.broadcast(reply);
    });
    Ok(())
}

/// Saves, remaps the saved collage, rerenders and writes `final/rerender-frameFFFF.exr` (+ PNG,
/// + the rays), as `rerender --out final/rerender-frameFFFF.exr [--shutter OPEN..CLOSE]` does.
pub fn render_final(
    shared: &Shared,
    res: [u32; 2],
    spp: u32,
    shutter: (f32, f32),
) -> Result<(PathBuf, tracer::image::RgbImage)> {
    let dir = save(shared)?;
    let (frame, seamless) = {
        let s = shared.session();
        (s.frame, s.seamless)
    };
    let collage = dir.join("collage.png");
    let job = RemapJob {
        config: remap_config(seamless),
        ..RemapJob::new(CollageFiles::new(&collage, dir.join(VIEWS), frame))
    };
    let remapped = job.run()?;
    let quality = Quality::DEFAULT.with_spp(spp);
    let rerender = Rerender {
        resolution: Some(UVec2::new(res[0], res[1])),
        quality,
        rays_from: Some((COLLAGE_KEY, collage)),
        // The scene's setup (frame rate, overrides) goes in the header as `rerender` records it.
        environment_map: shared.source.setup.environment_image.clone(),
        setup: Some(shared.source.setup.clone()),
        shutter,
        ..Rerender::new(remapped.output.rays.clone(), frame)
    };
    let tracer = shared.source.tracer_in_shutter(frame, shutter, &quality)?;
    let progress =
        FinalProgress { shared, total: AtomicU64::new(0), done: AtomicU64::new(0), sent: AtomicU64::new(0) };
    let rendered = rerender.run(&tracer, &progress)?;
    let out = dir.join("final").join(format!("rerender-frame{frame:04}.exr"));
    std::fs::create_dir_all(dir.join("final")).map_err(|e| StudioError::io(dir.join("final"), e))?;
    rerender.write(&out, &rendered, &shared.source.path)?;
    remapped
        .write_rays(&dir.join("final").join(rerender_name(frame, RayFormat::Binary)), RayFormat::Binary)?;
    Ok((out, rendered.images.image))
}
