//! A finished render written out (docs/design/tracer.md §3.6): linear EXR with the settings in its header
//! and optional AOV layers, and an sRGB PNG preview beside it, both atomically.

use super::{Band, EnvironmentImage, Quality, SceneSetup};
use crate::camera::Projection;
use crate::denoise::{Aux, Denoiser, Settings};
use crate::error::Result;
use crate::image::RgbImage;
use crate::image_io::{Aov, write_exr as write_exr_file, write_png_srgb};
use crate::render::Rendered;
use std::path::{Path, PathBuf};

/// How a picture was taken beyond its quality settings, for the EXR header: the camera model,
/// the environment image, and where a workflow's eye rays came from.
#[derive(Clone, Copy, Debug, Default)]
pub struct Provenance<'a> {
    /// The camera model and its lens settings; `None` when no projection made the rays.
    pub projection: Option<Projection>,
    /// The environment image lighting the scene, if any.
    pub environment_map: Option<&'a EnvironmentImage>,
    /// Where the eye rays came from, as a header key (`mcctrace/…`, named by the workflow: the
    /// collage or lens file of a rerender) and its file.
    pub rays_from: Option<(&'a str, &'a Path)>,
    /// A content hash of those rays (`mcctrace/rays_sha256`), so a changed lens file is told
    /// from the same one when a run resumes (docs/farm.md).
    pub rays_digest: Option<&'a str>,
}

/// Header keys of the render's counts, which differ between runs of the same settings (the
/// seconds) or add up over bands: not settings, so resuming does not compare them.
pub const COUNT_KEYS: [&str; 3] = ["mcctrace/seconds", "mcctrace/rays", "mcctrace/samples"];

/// Header key: what a denoised picture was denoised with (OIDN's version, filter, auxiliaries).
/// A record of the machine's library, not a setting: resuming does not compare it.
pub const DENOISER_KEY: &str = "mcctrace/denoiser";

/// Header key: the OIDN quality a picture is denoised at (`fast`, `balanced`, `high`), present
/// only when it is denoised; a setting.
pub const DENOISE_KEY: &str = "mcctrace/denoise";

/// Header key: how the auxiliaries guide the filter (`as-rendered`, `clean` or `prefiltered`,
/// [`Settings::for_final`]); a setting, derived from the others, so bands merge the same way.
pub const DENOISE_AUX_KEY: &str = "mcctrace/denoise_aux";

/// The layer holding the denoised beauty beside the raw one (`denoised.R`, `.G`, `.B`).
pub const DENOISED_LAYER: &str = "denoised";

/// Whether a header key records a setting (compared when resuming or merging), rather than a
/// count or the denoiser's description.
pub fn is_setting_key(key: &str) -> bool {
    key.starts_with("mcctrace/") && !COUNT_KEYS.contains(&key) && key != DENOISER_KEY
}

/// What the EXR header records besides the pixels.
#[derive(Clone, Copy, Debug)]
pub struct RenderInfo<'a> {
    /// The scene file.
    pub scene: &'a Path,
    /// The camera's name (or what stood for it, e.g. "multicamera collage").
    pub camera: &'a str,
    /// The frame.
    pub frame: u32,
    /// The settings rendered with (with `aovs`, the layers are written too).
    pub quality: &'a Quality,
    /// Shutter open and close, in frames after the frame's start.
    pub shutter: (f32, f32),
    /// Camera model, environment image, ray source.
    pub provenance: Provenance<'a>,
    /// How the scene was set up (frame rate, environment and falloff overrides), if known.
    pub setup: Option<&'a SceneSetup>,
    /// The border cut from the film (`--crop`), in input pixels; 0: none.
    pub crop: u32,
    /// The band this file holds, and the whole image's size; `None`: the whole image.
    pub band: Option<(Band, glam::UVec2)>,
    /// What a workflow adds to the header as `mcctrace/…` keys (e.g. what its camera-ray blur
    /// did to the frame), recorded and compared on resume like the settings.
    pub extra: &'a [(&'a str, String)],
}

impl<'a> RenderInfo<'a> {
    /// The header of frame `frame` of `scene` through `camera` at `quality`: shutter closed,
    /// nothing more known.
    pub fn new(scene: &'a Path, camera: &'a str, frame: u32, quality: &'a Quality) -> Self {
        Self {
            scene,
            camera,
            frame,
            quality,
            shutter: (0.0, 0.0),
            provenance: Provenance::default(),
            setup: None,
            crop: 0,
            band: None,
            extra: &[],
        }
    }

    /// How this picture is denoised, if it is: the quality asked for, the auxiliaries used as
    /// [`Settings::for_final`] says for depth of field, motion blur (the shutter open) and the
    /// samples (with `adaptive`, a pixel gets at least a quarter of them).
    pub fn denoise_settings(&self) -> Option<Settings> {
        let q = self.quality;
        let lens = matches!(self.provenance.projection, Some(Projection::ThinLens { lens_radius, .. }) if lens_radius > 0.0);
        let motion = self.shutter.1 > self.shutter.0;
        let spp = if q.adaptive { q.spp / 4 } else { q.spp };
        q.denoise.map(|quality| Settings::for_final(quality, spp, lens, motion))
    }

    /// The `mcctrace/…` header attributes besides the render's counts (docs/design/tracer.md §3.6):
    /// stable keys; those of the provenance only when known.
    pub fn settings(&self) -> Vec<(&'a str, String)> {
        let q = self.quality;
        let mut out = vec![
            ("mcctrace/scene", self.scene.display().to_string()),
            ("mcctrace/camera", self.camera.to_owned()),
            ("mcctrace/spp", q.spp.to_string()),
            ("mcctrace/seed", q.seed.to_string()),
            ("mcctrace/max_depth", q.max_depth.to_string()),
            ("mcctrace/rr_depth", q.rr_depth.to_string()),
            ("mcctrace/split", q.split.to_string()),
            ("mcctrace/adaptive", q.adaptive.to_string()),
            ("mcctrace/aovs", q.aovs.to_string()),
            ("mcctrace/frame", self.frame.to_string()),
            ("mcctrace/shutter", format!("{}..{}", self.shutter.0, self.shutter.1)),
        ];
        if let Some(settings) = self.denoise_settings() {
            // Only when asked, so outputs written before denoising existed still resume.
            out.push((DENOISE_KEY, settings.quality.name().to_owned()));
            out.push((DENOISE_AUX_KEY, settings.guide.name().to_owned()));
        }
        let p = &self.provenance;
        if let Some(projection) = &p.projection {
            out.push(("mcctrace/projection", describe_projection(projection)));
        }
        if let Some(env) = p.environment_map {
            out.push(("mcctrace/environment_map", env.path.display().to_string()));
            out.push(("mcctrace/environment_rotation", format!("{}", env.rotation.to_degrees())));
            out.push(("mcctrace/environment_strength", env.strength.to_string()));
        }
        if let Some((key, path)) = p.rays_from {
            out.push((key, path.display().to_string()));
        }
        if let Some(digest) = p.rays_digest {
            out.push(("mcctrace/rays_sha256", digest.to_owned()));
        }
        if let Some(setup) = self.setup {
            out.push(("mcctrace/fps", setup.fps.to_string()));
            if let Some(c) = setup.environment {
                out.push(("mcctrace/environment", format!("{},{},{}", c.x, c.y, c.z)));
            }
            if let Some(reading) = setup.reading {
                out.push(("mcctrace/gltf_reading", format!("{reading:?}")));
            }
            if let Some(falloff) = setup.spot_falloff {
                out.push(("mcctrace/spot_falloff", format!("{falloff:?}")));
            }
            if let Some(c) = setup.sky {
                out.push(("mcctrace/sky", format!("{},{},{}", c.x, c.y, c.z)));
            }
            if setup.exposure != 0.0 {
                out.push(("mcctrace/exposure", setup.exposure.to_string()));
            }
        }
        if self.crop > 0 {
            out.push(("mcctrace/crop", self.crop.to_string()));
        }
        if let Some((band, size)) = self.band {
            out.extend(band.header(size.x, size.y));
        }
        out.extend(self.extra.iter().map(|(k, v)| (*k, v.clone())));
        out
    }
}

/// A projection in words with its parameters (angles in degrees, lengths in world units), as the
/// header's `mcctrace/projection` records it.
pub fn describe_projection(p: &Projection) -> String {
    match *p {
        Projection::Perspective { fov_y } => format!("perspective fov_y={}", fov_y.to_degrees()),
        Projection::Orthographic { half_height } => format!("orthographic half_height={half_height}"),
        Projection::ThinLens { fov_y, lens_radius, focus_distance } => format!(
            "thin_lens fov_y={} lens_radius={lens_radius} focus_distance={focus_distance}",
            fov_y.to_degrees()
        ),
        Projection::Fisheye { fov } => format!("fisheye fov={}", fov.to_degrees()),
        Projection::Equirectangular => "equirectangular".to_owned(),
    }
}

/// The denoised beauty of a whole picture and what made it (`DENOISER_KEY`'s value).
pub fn denoise_final(
    image: &RgbImage,
    albedo: &RgbImage,
    normal: &RgbImage,
    settings: Settings,
) -> Result<(RgbImage, String)> {
    let denoiser = Denoiser::shared()?;
    let denoised = denoiser.denoise(image, Some(Aux { albedo, normal }), settings)?;
    Ok((denoised, denoiser.describe(settings, true)))
}

/// Writes `rendered` to the EXR `path`: the beauty image, its AOV layers if the quality asked
/// for them, and `mcctrace/…` header attributes (settings and counts). With `denoise`, a whole
/// picture also gets its denoised beauty as layer [`DENOISED_LAYER`], which is returned, and
/// the denoiser in the header; a band instead keeps the albedo and normal layers the merge
/// denoises the whole image with (a band alone would show seams).
pub fn write_exr(path: &Path, rendered: &Rendered, info: &RenderInfo<'_>) -> Result<Option<RgbImage>> {
    let (images, q) = (&rendered.images, info.quality);
    let mut metadata = info.settings();
    let s = &rendered.stats;
    metadata.extend(COUNT_KEYS.into_iter().zip([
        format!("{:.6}", s.seconds),
        s.rays.to_string(),
        s.samples.to_string(),
    ]));
    let mut layers: Vec<Aov<'_>> = if q.aovs {
        vec![
            Aov::Rgb { name: "albedo", image: &images.albedo },
            Aov::Rgb { name: "normal", image: &images.normal },
            Aov::Gray { name: "depth", image: &images.depth },
            Aov::Rgb { name: "variance", image: &images.variance },
            Aov::Gray { name: "samples", image: &images.samples },
        ]
    } else if q.denoise.is_some() && info.band.is_some() {
        vec![
            Aov::Rgb { name: "albedo", image: &images.albedo },
            Aov::Rgb { name: "normal", image: &images.normal },
        ]
    } else {
        Vec::new()
    };
    let denoised = if let Some(settings) = info.denoise_settings().filter(|_| info.band.is_none()) {
        let (denoised, denoiser) = denoise_final(&images.image, &images.albedo, &images.normal, settings)?;
        metadata.push((DENOISER_KEY, denoiser));
        Some(denoised)
    } else {
        None
    };
    if let Some(image) = &denoised {
        layers.push(Aov::Rgb { name: DENOISED_LAYER, image });
    }
    write_exr_file(path, &images.image, &layers, &metadata)?;
    Ok(denoised)
}

/// Writes `rendered` to `exr` ([`write_exr`]) and its sRGB preview beside it, the denoised
/// picture when one was made; returns the PNG's path.
pub fn write_render(exr: &Path, rendered: &Rendered, info: &RenderInfo<'_>) -> Result<PathBuf> {
    let denoised = write_exr(exr, rendered, info)?;
    let png = exr.with_extension("png");
    write_png_srgb(&png, denoised.as_ref().unwrap_or(&rendered.images.image))?;
    Ok(png)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    /// The header keys: the quality's always, the provenance's when known, in a stable order.
    #[test]
    fn the_header_records_settings_and_provenance() {
        let quality = Quality { adaptive: true, rr_depth: 3, ..Quality::DEFAULT };
        let scene = Path::new("cafe.gltf");
        let plain = RenderInfo::new(scene, "left", 2, &quality).settings();
        let get = |s: &[(&str, String)], k: &str| s.iter().find(|(key, _)| *key == k).map(|(_, v)| v.clone());
        assert_eq!(get(&plain, "mcctrace/adaptive").as_deref(), Some("true"));
        assert_eq!(get(&plain, "mcctrace/rr_depth").as_deref(), Some("3"));
        assert_eq!(get(&plain, "mcctrace/shutter").as_deref(), Some("0..0"));
        assert_eq!(get(&plain, "mcctrace/projection"), None);
        let env =
            EnvironmentImage { path: PathBuf::from("sky.exr"), rotation: 90f32.to_radians(), strength: 2.0 };
        let lens = PathBuf::from("lens/rerender-frame0002.mcr");
        let info = RenderInfo {
            shutter: (0.0, 0.5),
            provenance: Provenance {
                projection: Some(Projection::ThinLens { fov_y: 0.5, lens_radius: 0.05, focus_distance: 2.5 }),
                environment_map: Some(&env),
                rays_from: Some(("mcctrace/lens_file", &lens)),
                rays_digest: Some("abc"),
            },
            ..RenderInfo::new(scene, "left", 2, &quality)
        };
        let full = info.settings();
        assert_eq!(get(&full, "mcctrace/shutter").as_deref(), Some("0..0.5"));
        let projection = get(&full, "mcctrace/projection").unwrap();
        assert!(
            projection.starts_with("thin_lens fov_y=28.6")
                && projection.ends_with("lens_radius=0.05 focus_distance=2.5")
        );
        assert_eq!(get(&full, "mcctrace/environment_map").as_deref(), Some("sky.exr"));
        assert_eq!(get(&full, "mcctrace/environment_strength").as_deref(), Some("2"));
        assert_eq!(get(&full, "mcctrace/lens_file").as_deref(), Some("lens/rerender-frame0002.mcr"));
        let keys = |s: &[(&str, String)]| s.iter().map(|(k, _)| k.to_string()).collect::<Vec<_>>();
        assert_eq!(keys(&full[..plain.len()]), keys(&plain));
        assert_eq!(describe_projection(&Projection::Equirectangular), "equirectangular");
    }
}
