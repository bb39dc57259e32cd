//! Scene set-up for rendering (docs/design.md §3.1): a scene file loaded with the environment and
//! spot-light falloff the user chose in place of the file's, and an animated scene posed at
//! frame / fps seconds (a static one is used as loaded, with no rebuild).

use crate::error::{Result, TracerError};
use crate::scene::{EnvironmentMap, PunctualLight, Scene, SpotFalloff};
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
    /// A spot-light falloff replacing the loader's choice.
    pub spot_falloff: Option<SpotFalloff>,
}

impl Default for SceneSetup {
    fn default() -> Self {
        Self { fps: Self::DEFAULT_FPS, environment: None, environment_image: None, spot_falloff: None }
    }
}

impl SceneSetup {
    /// Frames per second unless told otherwise (film's rate).
    pub const DEFAULT_FPS: f32 = 24.0;

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
        if let Some(color) = self.environment {
            scene.environment.color = color;
        }
        if let Some(image) = &self.environment_image {
            let map = EnvironmentMap::load(&image.path, image.rotation, image.strength)?;
            scene.warnings.extend(map.warnings());
            scene.environment_map = Some(map);
        }
        self.apply_lights(scene);
        Ok(())
    }

    /// Applies the spot-light falloff.
    fn apply_lights(&self, scene: &mut Scene) {
        let Some(falloff) = self.spot_falloff else { return };
        for light in &mut scene.lights {
            if let PunctualLight::Spot { falloff: f, .. } = light {
                *f = falloff;
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
