//! Loading an equirectangular environment image ([`EnvironmentMap`]).
//!
//! The image is read as linear radiance: OpenEXR (the usual format for sky and studio maps,
//! through [`crate::image_io::read_exr_rgb`]), or PNG/JPEG/TIFF, whose 8- and 16-bit values are
//! decoded from sRGB (float TIFFs are linear already). Its layout is the one documented on
//! [`EnvironmentMap`], the equirectangular camera's: column 0 is longitude −180°, the centre
//! column looks down −Z, the right half is +X; row 0 is straight up (+Y). A panorama rendered
//! with mcctrace's equirectangular camera (looking down −Z, +Y up) is therefore a ready-made
//! environment map.
//!
//! Errors name the file: unreadable, malformed, empty, non-finite texels. Negative texels (a
//! filter's ringing) are clamped to zero. A map that is not 2:1 still works (each texel spans
//! 360°/width × 180°/height); [`EnvironmentMap::warnings`] says so.

use super::EnvironmentMap;
use super::images::{self, ColorSpace};
use crate::error::{Result, TracerError};
use crate::texture::{Texels, Texture};
use glam::Vec4;
use std::path::Path;

impl EnvironmentMap {
    /// Loads an equirectangular image from `path`, turned by `rotation_radians` about +Y and
    /// multiplied by `strength`.
    pub fn load(path: &Path, rotation_radians: f32, strength: f32) -> Result<Self> {
        let bad = |message: String| TracerError::image(path, message);
        if !rotation_radians.is_finite() {
            return Err(bad(format!("environment rotation {rotation_radians} must be finite")));
        }
        if !(strength.is_finite() && strength >= 0.0) {
            return Err(bad(format!("environment strength {strength} must be finite and ≥ 0")));
        }
        let is_exr = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let name = path.display().to_string();
        let mut texture = if is_exr {
            let rgb = crate::image_io::read_exr_rgb(path)?;
            let texels = rgb.pixels.iter().map(|p| p.extend(1.0)).collect();
            Texture::new(name, rgb.width, rgb.height, texels)
        } else {
            let bytes = std::fs::read(path).map_err(|e| TracerError::io(path, e))?;
            let image = images::decode(&bytes).map_err(bad)?;
            images::to_texture(name, &image, ColorSpace::Srgb).into_linear()
        };
        if texture.width == 0 || texture.height == 0 || texture.texels.is_empty() {
            return Err(bad("the environment image is empty".to_owned()));
        }
        if let Some(i) = texture.texels.iter().position(|t| !t.truncate().is_finite()) {
            let (x, y) = (i % texture.width as usize, i / texture.width as usize);
            return Err(bad(format!("pixel ({x}, {y}) of the environment image is not finite")));
        }
        let texels = texture.texels.iter().map(|t| t.max(Vec4::ZERO).truncate().extend(1.0)).collect();
        texture.texels = Texels::Float(texels);
        Ok(Self { texture, rotation: rotation_radians, strength })
    }

    /// A uniform sky of `radiance` (finite, non-negative) in every direction: a 2 × 1 image, so
    /// that it is importance-sampled as a light like any environment image.
    pub fn uniform(radiance: glam::Vec3) -> Self {
        let texel = radiance.extend(1.0);
        let texture = Texture::new(format!("uniform sky {radiance}"), 2, 1, vec![texel; 2]);
        Self { texture, rotation: 0.0, strength: 1.0 }
    }

    /// What is unusual about the map, for the user: a shape other than 2:1, or no light at all.
    pub fn warnings(&self) -> Vec<String> {
        let t = &self.texture;
        let mut warnings = Vec::new();
        if t.width != 2 * t.height {
            warnings.push(format!(
                "{}: the environment image is {} × {}, not 2:1; it is stretched over the sphere",
                t.name, t.width, t.height
            ));
        }
        if self.strength == 0.0 || t.texels.iter().all(|v| v.truncate().max_element() <= 0.0) {
            warnings.push(format!("{}: the environment image is black: it lights nothing", t.name));
        }
        warnings
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::RgbImage;
    use crate::scene::gltf::tests::TempDir;
    use glam::Vec3;

    #[test]
    fn scene_environment_map_loads_exr_and_png() {
        let dir = TempDir::new("envmap");
        let mut rgb = RgbImage::new(8, 4);
        rgb.set(5, 1, Vec3::new(2.0, -1.0, 0.5));
        let exr = dir.0.join("sky.exr");
        crate::image_io::write_exr(&exr, &rgb, &[], &[]).unwrap();
        let map = EnvironmentMap::load(&exr, 0.5, 2.0).unwrap();
        assert_eq!((map.texture.width, map.texture.height, map.rotation, map.strength), (8, 4, 0.5, 2.0));
        // Row-major from the top; negative values clamped.
        assert_eq!(map.texture.texels.get(8 + 5), Vec4::new(2.0, 0.0, 0.5, 1.0));
        assert!(map.warnings().is_empty(), "{:?}", map.warnings());

        let png = dir.0.join("sky.png");
        crate::image_io::write_png_rgb8(&png, 3, 1, &[128, 128, 128, 255, 0, 0, 0, 0, 0]).unwrap();
        let map = EnvironmentMap::load(&png, 0.0, 1.0).unwrap();
        assert!((map.texture.texels.get(0).x - 0.215_860_5).abs() < 1e-6);
        let warnings = map.warnings().join("\n");
        assert!(warnings.contains("sky.png") && warnings.contains("3 × 1, not 2:1"), "{warnings}");
    }

    #[test]
    fn scene_environment_map_errors_name_the_file() {
        let dir = TempDir::new("envmap-errors");
        let message = EnvironmentMap::load(&dir.0.join("none.exr"), 0.0, 1.0).unwrap_err().to_string();
        assert!(message.contains("none.exr"), "{message}");
        let junk = dir.write("junk.exr", b"not an exr");
        let message = EnvironmentMap::load(&junk, 0.0, 1.0).unwrap_err().to_string();
        assert!(message.contains("junk.exr"), "{message}");
        let text = dir.write("notes.png", b"hello");
        let message = EnvironmentMap::load(&text, 0.0, 1.0).unwrap_err().to_string();
        assert!(message.contains("notes.png") && message.contains("not a PNG"), "{message}");
        let mut rgb = RgbImage::new(2, 1);
        rgb.set(1, 0, Vec3::new(f32::NAN, 0.0, 0.0));
        let nan = dir.0.join("nan.exr");
        crate::image_io::write_exr(&nan, &rgb, &[], &[]).unwrap();
        let message = EnvironmentMap::load(&nan, 0.0, 1.0).unwrap_err().to_string();
        assert!(message.contains("nan.exr") && message.contains("pixel (1, 0)"), "{message}");
        let ok = dir.0.join("ok.exr");
        crate::image_io::write_exr(&ok, &RgbImage::new(2, 1), &[], &[]).unwrap();
        let message = EnvironmentMap::load(&ok, 0.0, -1.0).unwrap_err().to_string();
        assert!(message.contains("strength"), "{message}");
        assert!(EnvironmentMap::load(&ok, 0.0, 1.0).unwrap().warnings().join(" ").contains("black"));
    }
}
