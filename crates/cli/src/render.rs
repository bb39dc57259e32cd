//! `mcctrace render`: render a scene from one or more cameras (docs/design.md §3, §8).

use crate::args::{Resolution, Vec3Arg};
use crate::output::{Png, RenderInfo, write_render};
use crate::progress::Bar;
use crate::with_threads;
use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use glam::UVec2;
use std::path::{Path, PathBuf};
use tracer::camera::{Camera, CameraDesc, Overscan, Projection};
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{RenderSettings, Rendered, render};
use tracer::scene::{CameraSelector, PunctualLight, Scene, SpotFalloff};

/// Camera models selectable from the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Model {
    /// Pinhole perspective (vertical field of view --fov).
    Perspective,
    /// Parallel projection (window height 2 × --ortho-half-height).
    Orthographic,
    /// Perspective with depth of field (--lens-radius, --focus-distance).
    ThinLens,
    /// Equidistant fisheye (image circle spans --fov, default 180°).
    Fisheye,
    /// Full 360° × 180° latitude–longitude panorama.
    Equirectangular,
}

/// Scene and camera choice shared by every command that renders.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    pub scene: PathBuf,
    /// Camera of the scene, by name or 0-based index; repeat for several views (numbered 1, 2,
    /// … in this order). Default: the scene's first camera.
    #[arg(long = "camera", value_name = "NAME|INDEX")]
    pub cameras: Vec<String>,
    /// Ad-hoc camera position (for scenes without cameras, e.g. OBJ), as x,y,z.
    #[arg(long, value_name = "X,Y,Z", requires = "look_at", conflicts_with = "cameras")]
    pub look_from: Option<Vec3Arg>,
    /// Ad-hoc camera target, as x,y,z.
    #[arg(long, value_name = "X,Y,Z", requires = "look_from")]
    pub look_at: Option<Vec3Arg>,
    /// Ad-hoc camera up direction.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,1,0")]
    pub up: Vec3Arg,
    /// Vertical field of view in degrees (ad-hoc cameras; the fisheye's full angle).
    #[arg(long, value_name = "DEGREES")]
    pub fov: Option<f32>,
    /// Camera model, overriding the scene camera's projection (its position is kept).
    #[arg(long, value_enum)]
    pub model: Option<Model>,
    /// Thin-lens aperture radius, in scene units.
    #[arg(long, default_value_t = 0.0)]
    pub lens_radius: f32,
    /// Thin-lens focus distance, in scene units.
    #[arg(long, default_value_t = 1.0)]
    pub focus_distance: f32,
    /// Orthographic half height, in scene units.
    #[arg(long, default_value_t = 1.0)]
    pub ortho_half_height: f32,
    /// A JSON camera list (for scenes without cameras, e.g. OBJ); its cameras are added to the
    /// scene's and can be picked with --camera.
    #[arg(long, value_name = "FILE")]
    pub cameras_file: Option<PathBuf>,
}

/// Sampling and quality settings shared by every command that renders.
#[derive(Args, Debug, Clone)]
pub struct QualityArgs {
    /// Samples per pixel (1 … 65536; with --split N, 1 … 65536 / N).
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Output resolution (default 640x360; for `rerender` and `animate`, the ray file's).
    #[arg(long, value_name = "WxH")]
    pub res: Option<Resolution>,
    /// Seed of the sample sequence: the same seed gives the same image bit for bit.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Render threads (default: all cores). The image does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Maximum scattering vertices per path (the Cornell reference uses 4).
    #[arg(long, default_value_t = IntegratorConfig::DEFAULT.max_depth)]
    pub max_depth: u32,
    /// Russian roulette starts after this many scattering vertices.
    #[arg(long, default_value_t = IntegratorConfig::DEFAULT.rr_depth)]
    pub rr_depth: u32,
    /// Paths continued from each camera ray's first hit (first-vertex splitting): each of the
    /// --spp samples traces N indirect paths. Pays where indirect light makes the noise (the
    /// Cornell box: 2 reaches the same error ≈ 1.1-1.16x sooner); costs where the noise is in
    /// what the camera sees (textures, depth of field, small lights: the café ≈ 1.2x slower).
    #[arg(long, default_value_t = IntegratorConfig::DEFAULT.split, value_name = "N",
          value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub split: u32,
    /// Environment radiance (constant colour) as r,g,b, replacing the scene's.
    #[arg(long, value_name = "R,G,B")]
    pub env: Option<Vec3Arg>,
    /// An equirectangular environment image (EXR; PNG/JPEG read as sRGB), importance-sampled.
    #[arg(long, value_name = "FILE")]
    pub env_map: Option<PathBuf>,
    /// Rotation of the environment image about +Y, in degrees.
    #[arg(long, default_value_t = 0.0, value_name = "DEGREES")]
    pub env_rotation: f32,
    /// Radiance multiplier of the environment image.
    #[arg(long, default_value_t = 1.0)]
    pub env_strength: f32,
    /// Spot-light falloff, overriding the loader's choice (Blender's for Blender-made files).
    #[arg(long, value_enum)]
    pub spot_falloff: Option<FalloffArg>,
    /// Also write albedo, normal, depth, per-sample variance and sample-count layers into the
    /// EXR.
    #[arg(long)]
    pub aovs: bool,
    /// Adaptive sampling: --spp becomes the average per pixel; a quarter of it goes to every
    /// pixel, the rest where the noise relative to the pixel's brightness is highest.
    #[arg(long)]
    pub adaptive: bool,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Spot-light falloff shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FalloffArg {
    /// Blender Cycles' smoothstep falloff.
    Blender,
    /// The glTF specification's recommended falloff.
    Gltf,
}

/// Ray-file encodings, for every command that writes ray files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RayFormatArg {
    /// Binary .mcr (smaller and faster; the default).
    Binary,
    /// The column's text format, .txt.
    Text,
}

impl From<RayFormatArg> for mcc::RayFormat {
    fn from(f: RayFormatArg) -> Self {
        match f {
            RayFormatArg::Binary => mcc::RayFormat::Binary,
            RayFormatArg::Text => mcc::RayFormat::Text,
        }
    }
}

impl QualityArgs {
    /// The resolution asked for, or the default 640x360.
    pub fn resolution(&self) -> UVec2 {
        self.res.map_or(UVec2::new(640, 360), |r| r.0)
    }
}

/// Arguments of `mcctrace render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub quality: QualityArgs,
    /// Frame number (used in output names and by lens shaders; an animated scene is posed at
    /// FRAME / --fps seconds).
    #[arg(long, default_value_t = 0)]
    pub frame: u32,
    /// Frames per second: the scene time of frame F is F / FPS seconds.
    #[arg(long, default_value_t = crate::scene_time::DEFAULT_FPS)]
    pub fps: f32,
    /// Output: an .exr file (one camera), or a directory that receives
    /// frameFFFFcameraCC.exr and .png per camera.
    #[arg(long)]
    pub out: PathBuf,
    /// MCC lens writer: also record every pixel's centre ray as frameFFFFcameraCC.mcr (or .txt).
    #[arg(long)]
    pub lens_writer: bool,
    /// MCC camera tagger: the PNG beside each EXR carries the camera number in its low bits.
    #[arg(long)]
    pub tag: bool,
    /// Bits per channel of the camera tag (camera ids 1 … 2^(3·bits) − 1).
    #[arg(long, default_value_t = 2, value_name = "B")]
    pub tag_bits: u8,
    /// Encoding of ray files.
    #[arg(long, value_enum, default_value = "binary")]
    pub ray_format: RayFormatArg,
    /// Render an extra border of N pixels around each view (undo with `rerender --crop N`).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub overscan: u32,
    /// Number of the first view; the others follow in command-line order (for views rendered
    /// in separate runs).
    #[arg(long, default_value_t = 1, value_name = "ID")]
    pub first_id: u32,
}

/// A camera to render, with its view number.
pub struct View {
    pub id: u32,
    pub desc: CameraDesc,
}

/// Loads the scene, reporting its warnings on stderr unless quiet.
pub fn load_scene(path: &Path, quiet: bool) -> anyhow::Result<Scene> {
    let scene = Scene::load(path)?;
    if !quiet {
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
    }
    Ok(scene)
}

/// The cameras the arguments select, numbered in command-line order (after adding those of
/// --cameras-file to the scene's).
pub fn select_views(scene: &mut Scene, a: &SceneArgs) -> anyhow::Result<Vec<View>> {
    if let Some(file) = &a.cameras_file {
        scene.cameras.extend(tracer::scene::camera_list::load(file)?);
    }
    let scene = &*scene;
    let fov = a.fov.map(f32::to_radians);
    let mut descs = if let (Some(from), Some(at)) = (a.look_from, a.look_at) {
        let projection = Projection::Perspective { fov_y: fov.unwrap_or(45f32.to_radians()) };
        vec![CameraDesc::look_at("ad-hoc", from.0, at.0, a.up.0, projection)?]
    } else if a.cameras.is_empty() {
        vec![scene.camera(&CameraSelector::Index(0))?.clone()]
    } else {
        a.cameras
            .iter()
            .map(|c| scene.camera(&CameraSelector::parse(c)).cloned())
            .collect::<Result<_, _>>()?
    };
    if let Some(model) = a.model {
        for d in &mut descs {
            let scene_fov = match d.projection {
                Projection::Perspective { fov_y } | Projection::ThinLens { fov_y, .. } => Some(fov_y),
                _ => None,
            };
            let fov_y = fov.or(scene_fov).unwrap_or(45f32.to_radians());
            d.projection = match model {
                Model::Perspective => Projection::Perspective { fov_y },
                Model::Orthographic => Projection::Orthographic { half_height: a.ortho_half_height },
                Model::ThinLens => Projection::ThinLens {
                    fov_y,
                    lens_radius: a.lens_radius,
                    focus_distance: a.focus_distance,
                },
                Model::Fisheye => Projection::Fisheye { fov: fov.unwrap_or(std::f32::consts::PI) },
                Model::Equirectangular => Projection::Equirectangular,
            };
        }
    } else if fov.is_some() && a.look_from.is_none() {
        bail!("--fov applies to ad-hoc cameras and --model; scene cameras keep their own field of view");
    }
    Ok(descs.into_iter().zip(1..).map(|(desc, id)| View { id, desc }).collect())
}

/// The integrator configuration the arguments ask for.
pub fn integrator_config(q: &QualityArgs) -> IntegratorConfig {
    IntegratorConfig::DEFAULT.with_max_depth(q.max_depth).with_rr_depth(q.rr_depth).with_split(q.split)
}

/// Prepares the scene for tracing (BVH, lights) with the quality settings applied.
pub fn prepare(scene: &mut Scene, q: &QualityArgs) -> anyhow::Result<PathTracer> {
    apply_environment(scene, q)?;
    apply_light_overrides(scene, q);
    Ok(PathTracer::new(scene, integrator_config(q))?)
}

/// Applies --env and --env-map (loading the image). `Scene::at_time` carries both over, so an
/// animated scene loads its environment image once, not per frame.
pub fn apply_environment(scene: &mut Scene, q: &QualityArgs) -> anyhow::Result<()> {
    if let Some(env) = q.env {
        scene.environment.color = env.0;
    }
    if let Some(file) = &q.env_map {
        let map = tracer::scene::EnvironmentMap::load(file, q.env_rotation.to_radians(), q.env_strength)?;
        if !q.quiet {
            for w in map.warnings() {
                eprintln!("warning: {w}");
            }
        }
        scene.environment_map = Some(map);
    }
    Ok(())
}

/// Applies --spot-falloff to the scene's lights (which `Scene::at_time` rebuilds each frame).
pub fn apply_light_overrides(scene: &mut Scene, q: &QualityArgs) {
    if let Some(f) = q.spot_falloff {
        let falloff = match f {
            FalloffArg::Blender => SpotFalloff::Blender,
            FalloffArg::Gltf => SpotFalloff::Gltf,
        };
        for light in &mut scene.lights {
            if let PunctualLight::Spot { falloff: f, .. } = light {
                *f = falloff;
            }
        }
    }
}

/// Builds `view`'s camera at `res`, with an overscan border of `overscan` pixels.
pub fn build_camera(view: &View, res: UVec2, overscan: u32) -> anyhow::Result<Box<dyn Camera>> {
    let camera = view.desc.build(res)?;
    Ok(if overscan > 0 { Box::new(Overscan::new(camera, overscan)) } else { camera })
}

/// Renders through `camera` with a progress bar; warns about non-finite samples.
pub fn render_camera(
    tracer: &PathTracer,
    camera: &dyn Camera,
    name: &str,
    camera_id: u32,
    lenses: &mut LensChain,
    q: &QualityArgs,
    frame: u32,
) -> anyhow::Result<Rendered> {
    render_camera_with_shutter(tracer, camera, name, camera_id, lenses, q, frame, (0.0, 0.0))
}

/// [`render_camera`] with the shutter open from `shutter.0` to `shutter.1` frames after the
/// frame's start (each eye ray gets a time in it: motion blur through the lens shaders).
#[allow(clippy::too_many_arguments)]
pub fn render_camera_with_shutter(
    tracer: &PathTracer,
    camera: &dyn Camera,
    name: &str,
    camera_id: u32,
    lenses: &mut LensChain,
    q: &QualityArgs,
    frame: u32,
    shutter: (f32, f32),
) -> anyhow::Result<Rendered> {
    let settings = RenderSettings {
        spp: q.spp,
        seed: q.seed,
        frame,
        camera_id,
        shutter,
        aovs: q.aovs,
        adaptive: q.adaptive,
    };
    if q.adaptive && tracer::adaptive::pilot_spp(q.spp).is_none() && !q.quiet {
        eprintln!(
            "note: --adaptive needs --spp {} or more to split; {} samples go to every pixel",
            tracer::adaptive::PILOT_SHARE,
            q.spp
        );
    }
    let res = camera.resolution();
    let bar = Bar::new(res.x as u64 * res.y as u64 * q.spp as u64, name, q.quiet);
    let rendered = with_threads(q.threads, || render(tracer, camera, lenses, &settings, &bar))?;
    bar.finish();
    let rendered = rendered.with_context(|| format!("rendering camera '{name}'"))?;
    if rendered.stats.nonfinite_samples > 0 {
        eprintln!(
            "warning: camera '{name}': {} samples were NaN or infinite and were recorded as black",
            rendered.stats.nonfinite_samples
        );
    }
    Ok(rendered)
}

/// One line about a finished render.
pub fn summary(name: &str, q: &QualityArgs, r: &Rendered, out: &Path) -> String {
    let s = &r.stats;
    format!(
        "{name}: {}x{} at {} spp in {:.2} s ({:.2} M samples/s, {:.1} M rays/s) -> {}",
        r.images.image.width,
        r.images.image.height,
        q.spp,
        s.seconds,
        s.samples as f64 / s.seconds / 1e6,
        s.rays as f64 / s.seconds / 1e6,
        out.display()
    )
}

/// Where each view's EXR goes: `out` itself for one view and an .exr path, else docs/design.md §4.3
/// names in the directory `out`.
pub fn output_paths(out: &Path, views: &[View], frame: u32) -> anyhow::Result<Vec<PathBuf>> {
    let is_file = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if is_file {
        if views.len() != 1 {
            bail!(
                "--out {} names one file but {} cameras were given: give a directory",
                out.display(),
                views.len()
            );
        }
        if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        return Ok(vec![out.to_path_buf()]);
    }
    if out.extension().is_some() && !out.is_dir() {
        bail!("--out {}: expected an .exr file or a directory", out.display());
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    Ok(views.iter().map(|v| out.join(format!("frame{frame:04}camera{:02}.exr", v.id))).collect())
}

pub fn run(a: RenderArgs) -> anyhow::Result<()> {
    let q = &a.quality;
    let code = mcc::TagCode::new(a.tag_bits)?;
    let scene = load_scene(&a.scene.scene, q.quiet)?;
    // Pose an animated scene (cameras included) before picking cameras from it.
    let mut scene = crate::scene_time::at_frame(scene, a.frame, a.fps)?;
    let mut views = select_views(&mut scene, &a.scene)?;
    if a.first_id == 0 {
        bail!("--first-id must be at least 1 (0 means no camera)");
    }
    for v in &mut views {
        v.id += a.first_id - 1;
    }
    if a.tag {
        for v in &views {
            code.check_id(v.id)?;
        }
    }
    let outputs = output_paths(&a.out, &views, a.frame)?;
    let tracer = prepare(&mut scene, q)?;
    for (view, exr) in views.iter().zip(&outputs) {
        let camera = build_camera(view, q.resolution(), a.overscan)?;
        let mut lenses = LensChain::new();
        if a.lens_writer {
            let dir = exr.parent().map(Path::to_path_buf).unwrap_or_default();
            lenses.push(Box::new(mcc::LensWriter::new(dir, a.ray_format.into())));
        }
        let rendered =
            render_camera(&tracer, camera.as_ref(), &view.desc.name, view.id, &mut lenses, q, a.frame)?;
        let info = RenderInfo {
            scene: &a.scene.scene,
            camera: &view.desc.name,
            spp: q.spp,
            seed: q.seed,
            max_depth: q.max_depth,
            split: q.split,
            frame: a.frame,
        };
        let png = if a.tag { Png::Tagged { code, camera: view.id } } else { Png::Preview };
        write_render(exr, &rendered, &info, q.aovs, png)?;
        if !q.quiet {
            eprintln!("{}", summary(&view.desc.name, q, &rendered, exr));
        }
    }
    Ok(())
}
