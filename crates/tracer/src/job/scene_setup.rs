//! Scene set-up for rendering (docs/design/tracer.md §3.1): a scene file loaded with the environment,
//! sky, exposure and spot-light falloff the user chose in place of the file's, and an animated
//! scene posed at frame / fps seconds (a static one is used as loaded, with no rebuild). A scene
//! that nothing lights gets a warning saying how to light it.

use crate::error::{Result, TracerError};
use crate::scene::{EnvironmentMap, GltfReading, PunctualLight, Scene, SpotFalloff};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// An equirectangular environment image to light the scene with.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentImage {
    /// The image file (EXR; PNG/JPEG/TIFF read as sRGB).
    pub path: PathBuf,
    /// Rotation about +Y, in radians.
    pub rotation: f32,
    /// Radiance multiplier.
    pub strength: f32,
}

/// How to turn a scene file into the scene to render. The default changes nothing and runs at
/// [`SceneSetup::DEFAULT_FPS`].
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSetup {
    /// Frames per second: frame F is posed at F / fps seconds.
    pub fps: f32,
    /// A constant environment radiance replacing the scene's.
    pub environment: Option<Vec3>,
    /// An environment image replacing the constant environment where rays leave the scene.
    pub environment_image: Option<EnvironmentImage>,
    /// A reading of glTF files replacing the loader's choice by `asset.generator` (docs/cycles.md,
    /// "Two readings of one file"); the spot falloff follows it unless `spot_falloff` is given.
    pub reading: Option<GltfReading>,
    /// A spot-light falloff replacing the reading's.
    pub spot_falloff: Option<SpotFalloff>,
    /// A uniform sky of this radiance, importance-sampled as an environment light, replacing
    /// the scene's environment (for models that carry no light).
    pub sky: Option<Vec3>,
    /// Exposure in stops: every light, emitter and environment is scaled by 2^EV, so the
    /// picture is the unexposed one × 2^EV (light transport is linear). 0 changes nothing.
    pub exposure: f32,
}

impl Default for SceneSetup {
    fn default() -> Self {
        Self {
            fps: Self::DEFAULT_FPS,
            environment: None,
            environment_image: None,
            reading: None,
            spot_falloff: None,
            sky: None,
            exposure: 0.0,
        }
    }
}

impl SceneSetup {
    /// Frames per second unless told otherwise (film's rate).
    pub const DEFAULT_FPS: f32 = 24.0;

    /// The largest exposure, in stops either way (2^64 is still a finite f32 factor).
    pub const MAX_EXPOSURE: f32 = 64.0;

    /// The radiance of Blender's default world: a uniform grey of 0.050876 (sRGB 0.25).
    pub const BLENDER_GREY_SKY: f32 = 0.050_876;

    /// Loads the scene at `path` (at t = 0) with the overrides applied; the loader's warnings,
    /// and the environment image's, are in `Scene::warnings`.
    pub fn load(&self, path: &Path) -> Result<Scene> {
        let mut scene = Scene::load(path)?;
        self.apply(&mut scene)?;
        Ok(scene)
    }

    /// Applies the overrides to a scene in memory (loading the environment image).
    /// `Scene::at_time` carries the environment over, so an animated scene loads its image
    /// once, not per frame; its lights it rebuilds, so [`SceneSetup::pose`] applies the
    /// falloff again.
    pub fn apply(&self, scene: &mut Scene) -> Result<()> {
        let scale = self.exposure_scale()?;
        if let Some(color) = self.environment {
            scene.environment.color = color;
        }
        if let Some(image) = &self.environment_image {
            let map = EnvironmentMap::load(&image.path, image.rotation, image.strength)?;
            scene.warnings.extend(map.warnings());
            scene.environment_map = Some(map);
        }
        if let Some(radiance) = self.sky {
            if !(radiance.is_finite() && radiance.min_element() >= 0.0) {
                return Err(TracerError::Settings(format!(
                    "sky radiance {radiance}: must be finite and non-negative"
                )));
            }
            scene.environment.color = Vec3::ZERO;
            scene.environment_map = Some(EnvironmentMap::uniform(radiance));
        }
        if scale != 1.0 {
            for m in &mut scene.materials {
                m.emission *= scale;
            }
            scene.environment.color *= scale;
            if let Some(map) = &mut scene.environment_map {
                map.strength *= scale;
            }
        }
        self.apply_lights(scene);
        if !scene.has_light() {
            scene.warnings.push(format!(
                "{}: nothing in the scene gives light (no emissive surface, punctual light or environment), \
                 so it renders black; light it with a sky (--sky grey), an environment image (--env-map FILE) \
                 or a light in the file",
                scene.path.display()
            ));
        }
        Ok(())
    }

    /// 2^exposure, or an error when that is not a usable factor.
    fn exposure_scale(&self) -> Result<f32> {
        let ev = self.exposure;
        if !(ev.is_finite() && ev.abs() <= Self::MAX_EXPOSURE) {
            return Err(TracerError::Settings(format!(
                "exposure {ev}: must be a number of stops between -{max} and {max}",
                max = Self::MAX_EXPOSURE
            )));
        }
        Ok(ev.exp2())
    }

    /// Applies the spot-light falloff and the exposure to the punctual lights (which posing
    /// rebuilds).
    fn apply_lights(&self, scene: &mut Scene) {
        let scale = if self.exposure == 0.0 { 1.0 } else { self.exposure.exp2() };
        if let Some(reading) = self.reading {
            scene.set_reading(reading);
        }
        let falloff = self.spot_falloff.or(self.reading.map(GltfReading::spot_falloff));
        for light in &mut scene.lights {
            match light {
                PunctualLight::Spot { falloff: f, intensity, .. } => {
                    if let Some(falloff) = falloff {
                        *f = falloff;
                    }
                    *intensity *= scale;
                }
                PunctualLight::Point { intensity, .. } => *intensity *= scale,
                PunctualLight::Directional { irradiance, .. } => *irradiance *= scale,
            }
        }
    }

    /// The scene time of `frame`, in seconds (computed in f64 so that frame / fps rounds once).
    pub fn frame_seconds(&self, frame: u32) -> f32 {
        (frame as f64 / self.fps as f64) as f32
    }

    /// Refuses a frame rate that is not a positive finite number.
    fn check_fps(&self) -> Result<()> {
        let fps = self.fps;
        if !(fps.is_finite() && fps > 0.0) {
            return Err(TracerError::Settings(format!(
                "frame rate {fps}: must be a positive number of frames per second"
            )));
        }
        Ok(())
    }

    /// `scene` (from [`SceneSetup::load`]) at `frame`: an animated scene posed there with the
    /// overrides kept, a static one returned as it is.
    pub fn at_frame(&self, scene: Scene, frame: u32) -> Result<Scene> {
        self.check_fps()?;
        if scene.animation.is_none() {
            return Ok(scene);
        }
        self.pose(&scene, frame)
    }

    /// `scene` (from [`SceneSetup::load`]) posed at `frame`, keeping it for other frames (a
    /// static scene is copied: use [`SceneSetup::at_frame`] when it is needed once).
    pub fn pose(&self, scene: &Scene, frame: u32) -> Result<Scene> {
        self.check_fps()?;
        let mut posed = scene.at_time(self.frame_seconds(frame))?;
        self.apply_lights(&mut posed);
        Ok(posed)
    }

    /// [`SceneSetup::at_frame`] with the geometry in motion over the shutter, open from
    /// `shutter.0` to `shutter.1` frames after the frame's start, at `steps` motion steps
    /// ([`Scene::in_motion`]; rays see the steps at times frame + open … frame + close, as the
    /// render loop draws them). A closed shutter, or a static scene, is [`SceneSetup::at_frame`].
    pub fn at_frame_in_shutter(
        &self,
        scene: Scene,
        frame: u32,
        shutter: (f32, f32),
        steps: usize,
    ) -> Result<Scene> {
        let posed = self.at_frame(scene, frame)?;
        self.in_shutter(posed, frame, shutter, steps)
    }

    /// [`SceneSetup::pose`] with the geometry in motion over the shutter (see
    /// [`SceneSetup::at_frame_in_shutter`]).
    pub fn pose_in_shutter(
        &self,
        scene: &Scene,
        frame: u32,
        shutter: (f32, f32),
        steps: usize,
    ) -> Result<Scene> {
        let posed = self.pose(scene, frame)?;
        self.in_shutter(posed, frame, shutter, steps)
    }

    /// `posed` (at `frame`) with its motion over the shutter.
    fn in_shutter(&self, posed: Scene, frame: u32, shutter: (f32, f32), steps: usize) -> Result<Scene> {
        let (open, close) = shutter;
        if !(open.is_finite() && close.is_finite() && open <= close) {
            return Err(TracerError::Settings(format!(
                "shutter {open}..{close}: must be finite with open ≤ close"
            )));
        }
        if posed.animation.is_none() || open == close {
            return Ok(posed);
        }
        // Scene seconds in f64, so that frame + offset over fps rounds once.
        let seconds = |offset: f32| ((frame as f64 + offset as f64) / self.fps as f64) as f32;
        let frames = (frame as f32 + open, frame as f32 + close);
        posed.in_motion((seconds(open), seconds(close)), frames, steps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot(falloff: SpotFalloff) -> PunctualLight {
        PunctualLight::Spot {
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            intensity: Vec3::ONE,
            inner_cone: 0.2,
            outer_cone: 0.4,
            falloff,
        }
    }

    #[test]
    fn overrides_replace_the_environment_and_the_falloff() {
        let mut scene = Scene::default();
        scene.lights.push(spot(SpotFalloff::Blender));
        let setup = SceneSetup {
            environment: Some(Vec3::new(0.1, 0.2, 0.3)),
            spot_falloff: Some(SpotFalloff::Gltf),
            ..SceneSetup::default()
        };
        setup.apply(&mut scene).unwrap();
        assert_eq!(scene.environment.color, Vec3::new(0.1, 0.2, 0.3));
        assert_eq!(scene.lights[0], spot(SpotFalloff::Gltf));
        let unchanged = SceneSetup::default();
        unchanged.apply(&mut scene).unwrap();
        assert_eq!(scene.lights[0], spot(SpotFalloff::Gltf));
    }

    /// A reading chosen by hand replaces the loader's, and the spot falloff follows it unless a
    /// falloff is given too (`--spot-falloff` keeps working beside `--gltf-reading`).
    #[test]
    fn a_reading_sets_the_falloff_unless_one_is_given() {
        let mut scene = Scene::default();
        scene.lights.push(spot(SpotFalloff::Blender));
        let spec = SceneSetup { reading: Some(GltfReading::Spec), ..SceneSetup::default() };
        spec.apply(&mut scene).unwrap();
        assert_eq!((scene.reading, &scene.lights[0]), (GltfReading::Spec, &spot(SpotFalloff::Gltf)));
        let both = SceneSetup {
            reading: Some(GltfReading::Spec),
            spot_falloff: Some(SpotFalloff::Blender),
            ..SceneSetup::default()
        };
        both.apply(&mut scene).unwrap();
        assert_eq!((scene.reading, &scene.lights[0]), (GltfReading::Spec, &spot(SpotFalloff::Blender)));
        assert_eq!(GltfReading::of_generator("Khronos glTF Blender I/O v5.0.21"), GltfReading::Blender);
        assert_eq!(GltfReading::of_generator("COLLADA2GLTF"), GltfReading::Spec);
    }

    /// `--gltf-reading` re-reads a material's KHR_materials_volume, not only the spot falloff:
    /// thickness 0 is a thin wall by the specification alone, and the absorption follows the
    /// reading's formula (−ln c / d by the specification, (1 − c) / d in Blender's).
    #[test]
    fn a_reading_rereads_the_volumes() {
        let volume =
            crate::material::Volume { thickness: 0.0, colour: Vec3::new(0.9, 0.5, 0.25), distance: 2.0 };
        let glass = crate::material::Material {
            transmission: 1.0,
            volume: Some(volume),
            ..crate::material::Material::default()
        };
        let mut scene = Scene { materials: vec![glass], ..Scene::default() };
        for reading in [GltfReading::Spec, GltfReading::Blender, GltfReading::Spec] {
            SceneSetup { reading: Some(reading), ..SceneSetup::default() }.apply(&mut scene).unwrap();
            let m = &scene.materials[0];
            let (thin, sigma) = match reading {
                GltfReading::Spec => (true, -volume.colour.map(f32::ln) / 2.0),
                GltfReading::Blender => (false, (Vec3::ONE - volume.colour) / 2.0),
            };
            assert_eq!((m.thin_walled, m.attenuation), (thin, sigma), "{reading:?}");
        }
    }

    /// A model with nothing that gives light renders black: loading it says so, naming the file
    /// and the ways to light it; a sky lights it (as an importance-sampled environment).
    #[test]
    fn an_unlit_scene_is_named_and_a_sky_lights_it() {
        let mut scene = Scene { path: "model.gltf".into(), ..Scene::default() };
        SceneSetup::default().apply(&mut scene).unwrap();
        let said = scene.warnings.join("\n");
        assert!(said.contains("model.gltf: nothing in the scene gives light"), "{said}");
        assert!(said.contains("--sky") && said.contains("--env-map"), "{said}");
        let mut lit = Scene { path: "model.gltf".into(), ..Scene::default() };
        SceneSetup { sky: Some(Vec3::splat(0.5)), ..SceneSetup::default() }.apply(&mut lit).unwrap();
        assert!(lit.warnings.is_empty(), "{:?}", lit.warnings);
        let map = lit.environment_map.as_ref().unwrap();
        assert_eq!((map.texture.width, map.texture.height, map.strength), (2, 1, 1.0));
        assert!(map.texture.texels.iter().all(|t| t == glam::Vec4::new(0.5, 0.5, 0.5, 1.0)));
        let bad = SceneSetup { sky: Some(Vec3::new(0.1, -1.0, 0.1)), ..SceneSetup::default() };
        assert!(bad.apply(&mut Scene::default()).unwrap_err().to_string().contains("sky radiance"));
    }

    /// Exposure scales every source of light by 2^EV, punctual lights again after posing;
    /// out-of-range stops are refused.
    #[test]
    fn exposure_scales_every_light() {
        let mut scene = Scene::default();
        scene.lights.push(spot(SpotFalloff::Blender));
        scene.lights.push(PunctualLight::Directional { direction: -Vec3::Y, irradiance: Vec3::splat(3.0) });
        scene.materials.push(crate::material::Material {
            emission: Vec3::new(1.0, 2.0, 4.0),
            ..crate::material::Material::default()
        });
        scene.environment.color = Vec3::splat(0.25);
        let setup = SceneSetup { exposure: 2.0, ..SceneSetup::default() };
        setup.apply(&mut scene).unwrap();
        assert_eq!(scene.materials[0].emission, Vec3::new(4.0, 8.0, 16.0));
        assert_eq!(scene.environment.color, Vec3::ONE);
        assert!(
            matches!(scene.lights[0], PunctualLight::Spot { intensity, .. } if intensity == Vec3::splat(4.0))
        );
        assert!(
            matches!(scene.lights[1], PunctualLight::Directional { irradiance, .. } if irradiance == Vec3::splat(12.0))
        );
        let sky = SceneSetup { sky: Some(Vec3::ONE), exposure: -1.0, ..SceneSetup::default() };
        let mut dim = Scene::default();
        sky.apply(&mut dim).unwrap();
        assert_eq!(dim.environment_map.unwrap().strength, 0.5);
        for exposure in [f32::NAN, 65.0, -100.0] {
            let err =
                SceneSetup { exposure, ..SceneSetup::default() }.apply(&mut Scene::default()).unwrap_err();
            assert!(err.to_string().contains("exposure"), "{err}");
        }
    }

    #[test]
    fn frames_map_to_seconds_and_bad_rates_are_refused() {
        let setup = SceneSetup { fps: 30.0, ..SceneSetup::default() };
        assert_eq!(setup.frame_seconds(45), 1.5);
        let scene = Scene::default();
        assert!(setup.at_frame(scene.clone(), 3).is_ok());
        for fps in [0.0, -24.0, f32::NAN, f32::INFINITY] {
            let err = SceneSetup { fps, ..SceneSetup::default() }.at_frame(scene.clone(), 0).unwrap_err();
            assert!(err.to_string().contains("frame rate"), "{err}");
        }
    }
}
