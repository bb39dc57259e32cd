//! The preview worker (docs/studio.md, "Engine"): one thread that turns session snapshots into
//! pictures, reusing what a change cannot have touched — a camera's rays and view while its
//! pose stands, the remap while the maps and the cameras used stand, the tracer while the
//! frame stands.

use super::pictures::{self, composite, label_image, png, region_image, srgb};
use super::{Shared, Stale};
use crate::camera::StudioCamera;
use crate::error::{Result, StudioError};
use crate::protocol::{ImageHeader, ImageKind, Outbound, ViewMode};
use crate::session::Snapshot;
use glam::UVec2;
use mcc::job::Rerender;
use mcc::lens_writer::pixel_centre_rays;
use mcc::remap::{RemapConfig, RemapOutput, remap};
use mcc::{Collage, RayFile};
use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};
use std::sync::Arc;
use tracer::denoise::{Aux, DenoiseError, Denoiser, Settings};
use tracer::film::FilmImages;
use tracer::image::RgbImage;
use tracer::integrator::PathTracer;
use tracer::job::{CameraRender, Quality};
use tracer::lens::{FrameInfo, LensChain};

/// The remapper's settings for the session's blend (the batch commands' presets).
pub fn remap_config(seamless: bool) -> RemapConfig {
    if seamless { RemapConfig::SEAMLESS } else { RemapConfig::GLASSNER }
}

/// A camera's cached work, valid while its pose key stands.
struct CameraCache {
    key: [u32; 10],
    rays: RayFile,
    thumb: Option<RgbImage>,
    /// The thumbnail's samples per pixel.
    thumb_spp: u32,
    view: Option<RgbImage>,
    /// No thumbnail of this camera has been shown yet: its first is a recognisable one.
    first: bool,
    /// The thumbnail shown was denoised (the page's toggle when it was made).
    denoised: bool,
}

/// The first thumbnail of a camera (what a new page shows before anything is painted): half the
/// collage's size at this many samples, recognisable where the ¼-size, 1-spp thumbnail of a
/// camera move (made for speed while dragging) is a blur. On the café at 480×270 it costs about
/// 16 times a move's thumbnail, once per camera.
const FIRST_THUMB_DIVISOR: u32 = 2;
const FIRST_THUMB_SPP: u32 = 4;

/// The preview worker's caches.
pub struct Worker {
    shared: Arc<Shared>,
    frame: Option<u32>,
    tracer: Option<Arc<PathTracer>>,
    cameras: BTreeMap<u32, CameraCache>,
    remap: Option<(u64, Arc<RemapOutput>)>,
}

impl Worker {
    /// A worker with empty caches.
    pub fn new(shared: Arc<Shared>) -> Self {
        Self { shared, frame: None, tracer: None, cameras: BTreeMap::new(), remap: None }
    }

    /// Serves snapshots until the engine stops.
    pub fn run(mut self) {
        let mut done = 0;
        loop {
            let snap = match self.shared.wait_for_change(done) {
                Some(session) => session.snapshot(),
                None => return,
            };
            done = snap.seq;
            let shared = Arc::clone(&self.shared);
            if let Err(e) = shared.pool.install(|| self.refresh(&snap))
                && !e.is_cancelled()
            {
                self.shared.broadcast(Outbound::error(None, format!("preview: {e}")));
            }
        }
    }

    /// The preview's quality; with `denoise`, the film records the albedo and normal the
    /// denoiser needs.
    fn quality(spp: u32, denoise: bool) -> Quality {
        let denoise = denoise.then_some(Settings::PREVIEW.quality);
        Quality { denoise, ..Quality::DEFAULT.with_spp(spp) }
    }

    /// Whether this snapshot's pictures are shown denoised: the page's toggle, when the
    /// denoiser is installed (without it the studio shows raw samples, as the toggle says).
    fn denoising(snap: &Snapshot) -> bool {
        snap.denoise && Denoiser::shared().is_ok()
    }

    /// The picture shown for a render: denoised in preview mode when `denoise`, else raw. Newer
    /// state stops the filter within one of its tiles (`stale`), so a denoise in progress never
    /// holds up the next stroke.
    fn shown(images: FilmImages, denoise: bool, stale: &Stale<'_>) -> Result<RgbImage> {
        if !denoise {
            return Ok(images.image);
        }
        let aux = Aux { albedo: &images.albedo, normal: &images.normal };
        let denoised = Denoiser::shared()
            .and_then(|d| d.denoise_cancellable(&images.image, Some(aux), Settings::PREVIEW, stale))
            .map_err(|e| match e {
                DenoiseError::Cancelled => tracer::TracerError::Cancelled,
                e => e.into(),
            })?;
        Ok(denoised)
    }

    fn send(
        &self,
        snap: &Snapshot,
        kind: ImageKind,
        camera: Option<u32>,
        spp: u32,
        image: &image::RgbImage,
    ) -> Result<()> {
        let header = ImageHeader { kind, camera, seq: snap.seq, spp, w: image.width(), h: image.height() };
        self.shared.picture(kind, camera, header.message(png(image)?));
        Ok(())
    }

    fn coarse(&self, snap: &Snapshot) -> UVec2 {
        let d = self.shared.settings.coarse_divisor.max(1);
        UVec2::new((snap.res[0] / d).max(1), (snap.res[1] / d).max(1))
    }

    /// Everything for one snapshot, most urgent first; stops at the first sign of newer state.
    fn refresh(&mut self, snap: &Snapshot) -> Result<()> {
        let shared = Arc::clone(&self.shared);
        let stale = Stale::new(&shared, snap.seq);
        if self.frame != Some(snap.frame) {
            self.tracer = Some(self.shared.source.tracer(snap.frame, &Quality::DEFAULT)?);
            self.cameras.clear();
            self.remap = None;
            self.frame = Some(snap.frame);
        }
        let tracer = Arc::clone(self.tracer.as_ref().expect("set above"));
        self.update_rays(snap)?;
        let denoise = Self::denoising(snap);
        // Moved cameras' thumbnails first: the page shows a camera move there. The cache keeps
        // the raw samples (painted pixels fall back on them); the page sees them denoised.
        let coarse = self.coarse(snap);
        for cam in &snap.cameras {
            if self.cameras[&cam.index].thumb.is_none() {
                self.show_thumb(&tracer, snap, cam, denoise, &stale)?;
            }
        }
        let res = UVec2::new(snap.res[0], snap.res[1]);
        let painted = snap.labels.iter().any(|&l| l != 0);
        let debug = matches!(snap.view.0, ViewMode::Weights | ViewMode::Dominant);
        let remapped = if painted { Some(self.remap(snap, debug)?) } else { None };
        let rays = remapped.as_ref().map(|out| Arc::new(out.rays.clone()));
        if let Some(rays) = &rays {
            let image = Self::shown(
                self.rerender(&tracer, snap, rays, coarse, Self::quality(1, denoise), &stale)?,
                denoise,
                &stale,
            )?;
            let views = &self.cameras;
            let full = composite(res.x, res.y, &image, &snap.labels, |k| {
                views.get(&(k as u32)).and_then(|c| c.view.as_ref().or(c.thumb.as_ref()))
            });
            self.send(snap, ImageKind::Preview, None, 1, &srgb(&full))?;
        }
        self.view_picture(snap, remapped.as_deref())?;
        // Thumbnails shown the other way than the toggle now says: after the stroke's first
        // picture, which they held up by four renders when they came first (seconds on a
        // loaded machine, at the render threads' low priority).
        for cam in &snap.cameras {
            if self.cameras[&cam.index].denoised != denoise {
                self.show_thumb(&tracer, snap, cam, denoise, &stale)?;
            }
        }
        // Idle: the views at full resolution, then the preview with more and more samples.
        let view_spp = self.shared.settings.view_spp;
        for cam in &snap.cameras {
            if self.cameras[&cam.index].view.is_none() {
                let image =
                    self.render_view(&tracer, snap, cam, res, Self::quality(view_spp, false), &stale)?.image;
                self.cameras.get_mut(&cam.index).expect("updated").view = Some(image);
                if snap.view == (ViewMode::Source, Some(cam.index)) {
                    self.view_picture(snap, remapped.as_deref())?;
                }
            }
        }
        if let Some(rays) = &rays {
            let mut spp = 1;
            loop {
                let images = self.rerender(&tracer, snap, rays, res, Self::quality(spp, denoise), &stale)?;
                let raw = denoise.then(|| images.image.clone());
                let mut image = Self::shown(images, denoise, &stale)?;
                if spp < view_spp {
                    // Painted pixels keep their camera's view samples until the rerender has
                    // as many there (it traces those very rays); from then on it is exactly
                    // `mcctrace rerender --spp N`.
                    let views = &self.cameras;
                    image = composite(res.x, res.y, &image, &snap.labels, |k| {
                        views.get(&(k as u32)).and_then(|c| c.view.as_ref())
                    });
                } else if let Some(raw) = &raw {
                    // Denoised, the painted pixels still show the camera's own samples.
                    image = composite(res.x, res.y, &image, &snap.labels, |_| Some(raw));
                }
                self.send(snap, ImageKind::Preview, None, spp, &srgb(&image))?;
                if spp >= self.shared.settings.preview_spp {
                    break;
                }
                spp = (spp * 4).min(self.shared.settings.preview_spp);
            }
        }
        Ok(())
    }

    /// Renders and sends camera `cam`'s thumbnail, denoised or not: the first one recognisable
    /// (half the collage's size, a few samples), later ones coarse at 1 spp. A raw one already
    /// cached is sent as it is.
    fn show_thumb(
        &mut self,
        tracer: &PathTracer,
        snap: &Snapshot,
        cam: &StudioCamera,
        denoise: bool,
        stale: &Stale<'_>,
    ) -> Result<()> {
        let cache = &self.cameras[&cam.index];
        if let (false, Some(raw)) = (denoise, &cache.thumb) {
            self.send(snap, ImageKind::Thumb, Some(cam.index), cache.thumb_spp, &srgb(raw))?;
            self.cameras.get_mut(&cam.index).expect("cached").denoised = false;
            return Ok(());
        }
        let d = self.shared.settings.coarse_divisor.clamp(1, FIRST_THUMB_DIVISOR);
        let first_size = UVec2::new((snap.res[0] / d).max(1), (snap.res[1] / d).max(1));
        let (size, spp) = if cache.first { (first_size, FIRST_THUMB_SPP) } else { (self.coarse(snap), 1) };
        let images = self.render_view(tracer, snap, cam, size, Self::quality(spp, denoise), stale)?;
        let raw = images.image.clone();
        let shown = Self::shown(images, denoise, stale)?;
        self.send(snap, ImageKind::Thumb, Some(cam.index), spp, &srgb(&shown))?;
        let cache = self.cameras.get_mut(&cam.index).expect("cached");
        (cache.thumb, cache.thumb_spp, cache.first, cache.denoised) = (Some(raw), spp, false, denoise);
        Ok(())
    }

    /// Recomputes the rays of cameras whose pose changed (from the camera model, no tracing)
    /// and forgets their pictures; drops cameras the key no longer has.
    fn update_rays(&mut self, snap: &Snapshot) -> Result<()> {
        let res = UVec2::new(snap.res[0], snap.res[1]);
        self.cameras.retain(|k, _| snap.cameras.iter().any(|c| c.index == *k));
        for cam in &snap.cameras {
            if self.cameras.get(&cam.index).is_some_and(|c| c.key == cam.key()) {
                continue;
            }
            let camera = cam.desc()?.build(res)?;
            let chain = LensChain::new();
            let info = FrameInfo { frame: snap.frame, camera_id: cam.index, shutter: (0.0, 0.0) };
            let rays = pixel_centre_rays(&chain.generator(camera.as_ref()), res, info, Vec::new())?;
            let first = self.cameras.get(&cam.index).is_none_or(|c| c.first);
            let cache = CameraCache {
                key: cam.key(),
                rays,
                thumb: None,
                thumb_spp: 0,
                view: None,
                first,
                denoised: false,
            };
            self.cameras.insert(cam.index, cache);
        }
        Ok(())
    }

    fn render_view(
        &self,
        tracer: &PathTracer,
        snap: &Snapshot,
        cam: &StudioCamera,
        res: UVec2,
        quality: Quality,
        stale: &Stale<'_>,
    ) -> Result<FilmImages> {
        stale.check()?;
        let camera = cam.desc()?.build(res)?;
        let job = CameraRender {
            tracer,
            camera: camera.as_ref(),
            name: &cam.name,
            camera_id: cam.index,
            frame: snap.frame,
            shutter: (0.0, 0.0),
            quality,
        };
        Ok(job.run(&mut LensChain::new(), stale)?.images)
    }

    fn rerender(
        &self,
        tracer: &PathTracer,
        snap: &Snapshot,
        rays: &Arc<RayFile>,
        res: UVec2,
        quality: Quality,
        stale: &Stale<'_>,
    ) -> Result<FilmImages> {
        stale.check()?;
        let job = Rerender { resolution: Some(res), quality, ..Rerender::new(Arc::clone(rays), snap.frame) };
        Ok(job.run(tracer, stale)?.images)
    }

    /// The remap of the snapshot's maps, through `mcc`'s own remapper; reused while the maps,
    /// the painted cameras' poses and the settings stand.
    fn remap(&mut self, snap: &Snapshot, debug: bool) -> Result<Arc<RemapOutput>> {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (&snap.labels, &snap.regions, snap.seamless, debug, snap.frame).hash(&mut h);
        let ids: Vec<u32> = snap.labels.iter().map(|&l| l as u32).collect();
        let [w, hgt] = snap.res;
        let collage = Collage::new(w, hgt, ids)?;
        let used = collage.cameras();
        for id in &used {
            self.cameras
                .get(id)
                .ok_or_else(|| {
                    StudioError::request(format!("the labels use camera {id}, which the key lacks"))
                })?
                .key
                .hash(&mut h);
        }
        let key = h.finish();
        if let Some((k, out)) = &self.remap
            && *k == key
        {
            return Ok(Arc::clone(out));
        }
        let files: BTreeMap<u32, &RayFile> = used.iter().map(|id| (*id, &self.cameras[id].rays)).collect();
        let regions = pictures::regions(w, hgt, &snap.regions);
        let config = RemapConfig { debug, ..remap_config(snap.seamless) };
        let out = Arc::new(remap(&collage, &regions, &files, snap.frame, &config)?);
        self.remap = Some((key, Arc::clone(&out)));
        Ok(out)
    }

    /// The picture of the canvas's current view mode (none for `final`, which is the preview).
    fn view_picture(&self, snap: &Snapshot, remapped: Option<&RemapOutput>) -> Result<()> {
        let [w, h] = snap.res;
        let (mode, camera) = snap.view;
        let debug = remapped.and_then(|r| r.debug.as_ref());
        let image = match mode {
            ViewMode::Final => return Ok(()),
            ViewMode::Labels => label_image(w, h, &snap.labels),
            ViewMode::Regions => region_image(w, h, &snap.regions),
            ViewMode::Source => {
                let c = camera.and_then(|k| self.cameras.get(&k));
                match c.and_then(|c| c.view.as_ref().or(c.thumb.as_ref())) {
                    Some(v) => srgb(v),
                    None => return Ok(()),
                }
            }
            ViewMode::Dominant => match debug {
                Some(d) => d.dominant_image(),
                None => return Ok(()),
            },
            ViewMode::Weights => {
                let k = debug.zip(camera).and_then(|(d, c)| d.cameras.iter().position(|&id| id == c));
                match (debug, k) {
                    (Some(d), Some(k)) => image::DynamicImage::ImageLuma8(d.weight_image(k)).to_rgb8(),
                    _ => image::RgbImage::new(w, h),
                }
            }
        };
        self.send(snap, ImageKind::View, camera, 0, &image)
    }
}

#[cfg(test)]
#[path = "worker_tests.rs"]
mod tests;
