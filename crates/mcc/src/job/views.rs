//! A scene's views rendered one after the other (docs/design.md §3, §4.3, §8; `render`, the
//! demos' source views): each a [`ViewRender`] with the lens writer's rays and the tagger's stamp
//! when asked, or one band of each (docs/farm.md); a band, and on resume a whole view, skipped
//! when already finished; the views also gathered into one OpenRaster file when asked.

use super::progress::JobProgress;
use super::view::{ViewFiles, ViewRender};
use crate::error::Result;
use crate::layers::openraster;
use crate::ray_file::RayFormat;
use crate::tag::TagCode;
use glam::UVec2;
use std::ops::Range;
use std::path::{Path, PathBuf};
use tracer::camera::{Camera, CameraDesc, Overscan};
use tracer::integrator::PathTracer;
use tracer::job::{Band, CameraRender, Provenance, Quality, SceneSetup, Stale};
use tracer::render::Rendered;

/// A camera to render, with its view number.
#[derive(Clone, Debug)]
pub struct View {
    /// The view number (1-based; names its files).
    pub id: u32,
    /// The camera.
    pub desc: CameraDesc,
}

impl View {
    /// The camera at `res`, with an overscan border of `overscan` pixels.
    pub fn camera(&self, res: UVec2, overscan: u32) -> tracer::Result<Box<dyn Camera>> {
        let camera = self.desc.build(res)?;
        Ok(if overscan > 0 { Box::new(Overscan::new(camera, overscan)) } else { camera })
    }
}

/// Views of one posed scene to render, and what comes with each.
#[derive(Clone, Copy)]
pub struct RenderViews<'a> {
    /// The scene, loaded and posed.
    pub tracer: &'a PathTracer,
    /// The scene file, recorded in the EXR headers.
    pub scene: &'a Path,
    /// The views, in order.
    pub views: &'a [View],
    /// Each view's EXR (the PNG goes beside it).
    pub exrs: &'a [PathBuf],
    /// The picture's size (before any overscan).
    pub resolution: UVec2,
    /// An extra border rendered around each view, in pixels.
    pub overscan: u32,
    /// The frame (names the ray files; recorded in the header).
    pub frame: u32,
    /// When the shutter opens and closes, in frames after the frame's start (the scene given
    /// in motion over it: `SceneSetup::at_frame_in_shutter`); `(0, 0)`: none.
    pub shutter: (f32, f32),
    /// Sampling settings.
    pub quality: Quality,
    /// Record the pixel-centre rays in this encoding.
    pub rays: Option<RayFormat>,
    /// Stamp the view's number into the PNG with this code.
    pub tag: Option<TagCode>,
    /// How the scene was set up, for the headers (its environment image too).
    pub setup: Option<&'a SceneSetup>,
    /// Only this band of each view.
    pub band: Option<Band>,
    /// Skip a view whose files are finished (a band is always skipped when finished).
    pub resume: bool,
    /// Also write the views as one OpenRaster file, a layer per camera.
    pub layers: Option<&'a Path>,
}

/// What a [`RenderViews`] tells as it goes.
pub enum ViewsEvent<'a> {
    /// The band asked for lies past the view's last row: nothing to render.
    EmptyBand {
        /// The view.
        view: &'a View,
        /// The band.
        band: Band,
        /// Its rows (empty).
        rows: Range<u32>,
    },
    /// The view's (or band's) files are finished: skipped.
    Finished {
        /// The view.
        view: &'a View,
        /// What was checked: `band I/N` or `view`.
        what: &'a str,
        /// The file checked.
        target: &'a Path,
    },
    /// The view's (or band's) files are there but not finished: rendered again.
    Stale {
        /// The view.
        view: &'a View,
        /// What was checked: `band I/N` or `view`.
        what: &'a str,
        /// Why they are not finished.
        why: &'a Stale,
    },
    /// A view is rendered and its files written.
    Written {
        /// The view.
        view: &'a View,
        /// Its render.
        rendered: &'a Rendered,
        /// What was written.
        files: &'a ViewFiles,
    },
}

/// Where a [`RenderViews`] reports: each view's stages and its events.
pub type ViewsProgress = dyn for<'e> JobProgress<ViewsEvent<'e>>;

impl RenderViews<'_> {
    /// Renders every view not finished (or its band) and writes its files, then the layered
    /// file; returns the files of the views rendered, in order.
    pub fn run(&self, progress: &ViewsProgress) -> Result<Vec<ViewFiles>> {
        let mut layers = Vec::new();
        let mut written = Vec::new();
        for (view, exr) in self.views.iter().zip(self.exrs) {
            let camera = view.camera(self.resolution, self.overscan)?;
            let job = ViewRender {
                render: CameraRender {
                    tracer: self.tracer,
                    camera: camera.as_ref(),
                    name: &view.desc.name,
                    camera_id: view.id,
                    frame: self.frame,
                    shutter: self.shutter,
                    quality: self.quality,
                },
                scene: self.scene,
                exr,
                rays: self.rays,
                tag: self.tag,
                provenance: Provenance {
                    projection: Some(view.desc.projection),
                    environment_map: self.setup.and_then(|s| s.environment_image.as_ref()),
                    rays_from: None,
                    rays_digest: None,
                },
                setup: self.setup,
                band: self.band,
            };
            let what = match self.band {
                Some(band) => {
                    let rows = job.rows().expect("a band has rows");
                    if rows.is_empty() {
                        progress.event(ViewsEvent::EmptyBand { view, band, rows });
                        continue;
                    }
                    Some(format!("band {band}"))
                }
                None => self.resume.then(|| "view".to_owned()),
            };
            if let Some(what) = &what {
                let target = job.target();
                match job.check() {
                    Ok(()) => {
                        progress.event(ViewsEvent::Finished { view, what, target: &target });
                        continue;
                    }
                    // Not rendered yet: nothing to tell.
                    Err(Stale::Missing(path)) if path == target => {}
                    Err(why) => progress.event(ViewsEvent::Stale { view, what, why: &why }),
                }
            }
            let (rendered, files) = job.run(progress.stages())?;
            progress.event(ViewsEvent::Written { view, rendered: &rendered, files: &files });
            if self.layers.is_some() {
                layers.push((view.id, &view.desc.name, openraster::srgb8(&rendered.images.image)));
            }
            written.push(files);
        }
        if let Some(path) = self.layers {
            let views: Vec<_> = layers
                .iter()
                .map(|(id, name, image)| openraster::ViewLayer { id: *id, name, image })
                .collect();
            openraster::write(path, &views)?;
        }
        Ok(written)
    }
}
