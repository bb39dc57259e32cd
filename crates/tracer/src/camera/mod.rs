//! Cameras: map a film position and a lens sample to a world-space eye ray (docs/design/tracer.md §3.8).
//! Film positions are continuous pixel coordinates, x right, y down, origin at the top-left corner;
//! pixel (i, j) covers [i, i+1) × [j, j+1) and its centre is (i + ½, j + ½).
//!
//! Every model uses the glTF camera convention in camera space: +X right, +Y up, looking down −Z.
//! The rays leave the camera; lens shaders (`crate::lens`) may rewrite them afterwards.

mod equirect;
mod fisheye;
mod orthographic;
mod overscan;
mod perspective;
mod thin_lens;

pub use equirect::Equirectangular;
pub use fisheye::Fisheye;
pub use orthographic::Orthographic;
pub use overscan::Overscan;
pub use perspective::Perspective;
pub use thin_lens::ThinLens;

use crate::error::{Result, TracerError};
use crate::ray::Ray;
use glam::{Affine3A, Mat3, UVec2, Vec2, Vec3};

/// One camera sample: where on the film, where on the lens, and when.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSample {
    /// Film position in continuous pixel coordinates (x right, y down, origin top-left).
    pub p_film: Vec2,
    /// Lens position in [0, 1)², mapped to the aperture by cameras that have one.
    pub p_lens: Vec2,
    /// Scene time in frames.
    pub time: f32,
}

impl CameraSample {
    /// The sample at the centre of pixel (i, j), through the lens centre, at `time`.
    pub fn pixel_centre(i: u32, j: u32, time: f32) -> Self {
        Self { p_film: Vec2::new(i as f32 + 0.5, j as f32 + 0.5), p_lens: Vec2::splat(0.5), time }
    }
}

/// A camera model: turns a [`CameraSample`] into a world-space eye ray.
pub trait Camera: Send + Sync {
    /// The eye ray for `sample`, or `None` where the film position maps to no ray (e.g. outside a
    /// fisheye's image circle).
    fn generate_ray(&self, sample: &CameraSample) -> Option<Ray>;

    /// The film resolution this camera was built for, in pixels.
    fn resolution(&self) -> UVec2;

    /// Whether rays depend on `CameraSample::p_lens` (if not, no lens numbers are drawn).
    fn uses_lens(&self) -> bool {
        false
    }
}

/// The projection a camera uses, with its parameters. Angles are in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole perspective with a vertical field of view.
    Perspective {
        /// Full vertical field of view.
        fov_y: f32,
    },
    /// Orthographic: parallel rays through a window `2 · half_height` tall (glTF's `ymag`).
    Orthographic {
        /// Half the height of the view window, in world units.
        half_height: f32,
    },
    /// Perspective through a thin lens: depth of field.
    ThinLens {
        /// Full vertical field of view.
        fov_y: f32,
        /// Radius of the aperture, in world units.
        lens_radius: f32,
        /// Distance along the view direction to the plane in focus.
        focus_distance: f32,
    },
    /// Equidistant fisheye: the image circle (inscribed in the film) spans `fov` degrees.
    Fisheye {
        /// Full angle across the image circle's diameter.
        fov: f32,
    },
    /// Equirectangular panorama: 360° across, 180° down.
    Equirectangular,
}

/// A camera as a scene or the command line describes it: where it is and how it projects.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesc {
    /// The camera's name (glTF node or camera name, camera-list entry, or "ad-hoc").
    pub name: String,
    /// Camera-to-world transform (rigid): camera space looks down −Z with +Y up.
    pub world_from_camera: Affine3A,
    /// Projection model and parameters.
    pub projection: Projection,
}

impl CameraDesc {
    /// A camera at `from` looking at `at` with `up` roughly up.
    pub fn look_at(name: &str, from: Vec3, at: Vec3, up: Vec3, projection: Projection) -> Result<Self> {
        Ok(Self { name: name.to_owned(), world_from_camera: look_at(from, at, up)?, projection })
    }

    /// Builds the camera for a film of `resolution` pixels.
    pub fn build(&self, resolution: UVec2) -> Result<Box<dyn Camera>> {
        if resolution.x == 0 || resolution.y == 0 {
            return Err(TracerError::Settings(format!(
                "resolution {}x{} is empty",
                resolution.x, resolution.y
            )));
        }
        let check_fov = |fov: f32, max: f32| {
            if fov.is_finite() && fov > 0.0 && fov < max {
                Ok(())
            } else {
                Err(TracerError::Settings(format!(
                    "camera '{}': field of view {:.3}° must be in (0°, {:.0}°)",
                    self.name,
                    fov.to_degrees(),
                    max.to_degrees()
                )))
            }
        };
        let frame = CameraFrame::new(&self.world_from_camera, resolution);
        Ok(match self.projection {
            Projection::Perspective { fov_y } => {
                check_fov(fov_y, std::f32::consts::PI)?;
                Box::new(Perspective::new(frame, fov_y))
            }
            Projection::Orthographic { half_height } => {
                if !(half_height.is_finite() && half_height > 0.0) {
                    return Err(TracerError::Settings(format!(
                        "camera '{}': orthographic half height {half_height} must be positive",
                        self.name
                    )));
                }
                Box::new(Orthographic::new(frame, half_height))
            }
            Projection::ThinLens { fov_y, lens_radius, focus_distance } => {
                check_fov(fov_y, std::f32::consts::PI)?;
                if !(lens_radius.is_finite()
                    && lens_radius >= 0.0
                    && focus_distance.is_finite()
                    && focus_distance > 0.0)
                {
                    return Err(TracerError::Settings(format!(
                        "camera '{}': lens radius {lens_radius} must be ≥ 0 and focus distance {focus_distance} > 0",
                        self.name
                    )));
                }
                Box::new(ThinLens::new(frame, fov_y, lens_radius, focus_distance))
            }
            Projection::Fisheye { fov } => {
                check_fov(fov, 2.0 * std::f32::consts::PI + 1e-3)?;
                Box::new(Fisheye::new(frame, fov))
            }
            Projection::Equirectangular => Box::new(Equirectangular::new(frame)),
        })
    }
}

/// Camera-to-world transform from a look-at description.
pub fn look_at(from: Vec3, at: Vec3, up: Vec3) -> Result<Affine3A> {
    let forward = at - from;
    let bad = |what: &str| Err(TracerError::Settings(format!("camera look-at: {what}")));
    if !(from.is_finite() && at.is_finite() && up.is_finite()) {
        return bad("coordinates must be finite");
    }
    if forward.length_squared() == 0.0 {
        return bad("look-from and look-at are the same point");
    }
    let f = forward.normalize();
    let r = f.cross(up);
    if r.length_squared() < 1e-12 * up.length_squared().max(1e-30) || up.length_squared() == 0.0 {
        return bad("the up vector is parallel to the view direction");
    }
    let r = r.normalize();
    let u = r.cross(f);
    Ok(Affine3A::from_mat3_translation(Mat3::from_cols(r, u, -f), from))
}

/// What every camera model needs: the film size and the camera's rigid frame in world space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraFrame {
    pub resolution: UVec2,
    /// World-space position of the camera.
    pub origin: Vec3,
    /// World-space unit axes of camera space (+X right, +Y up, +Z backwards).
    pub right: Vec3,
    pub up: Vec3,
    pub back: Vec3,
}

impl CameraFrame {
    fn new(world_from_camera: &Affine3A, resolution: UVec2) -> Self {
        // Strip any scale the scene graph put on the camera node: cameras are rigid.
        let m = world_from_camera.matrix3;
        Self {
            resolution,
            origin: world_from_camera.translation.into(),
            right: Vec3::from(m.x_axis).normalize_or(Vec3::X),
            up: Vec3::from(m.y_axis).normalize_or(Vec3::Y),
            back: Vec3::from(m.z_axis).normalize_or(Vec3::Z),
        }
    }

    /// Width over height of the film.
    pub fn aspect(&self) -> f32 {
        self.resolution.x as f32 / self.resolution.y as f32
    }

    /// Film position to normalised screen coordinates in [−1, 1]² (x right, y up).
    #[inline]
    pub fn screen(&self, p_film: Vec2) -> Vec2 {
        Vec2::new(
            2.0 * p_film.x / self.resolution.x as f32 - 1.0,
            1.0 - 2.0 * p_film.y / self.resolution.y as f32,
        )
    }

    /// A camera-space vector in world space.
    #[inline]
    pub fn to_world(self, v: Vec3) -> Vec3 {
        v.x * self.right + v.y * self.up + v.z * self.back
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell() -> CameraDesc {
        CameraDesc::look_at(
            "cornell",
            Vec3::new(2.78, 2.73, -8.0),
            Vec3::new(2.78, 2.73, 0.0),
            Vec3::Y,
            Projection::Perspective { fov_y: 39.307_648_f32.to_radians() },
        )
        .unwrap()
    }

    /// The Cornell reference's own formula for a pixel-centre direction (its README).
    #[test]
    fn perspective_matches_reference_formula() {
        let cam = cornell().build(UVec2::new(256, 256)).unwrap();
        let (from, at, up) = (Vec3::new(2.78, 2.73, -8.0), Vec3::new(2.78, 2.73, 0.0), Vec3::Y);
        let f = (at - from).normalize();
        let r = f.cross(up).normalize();
        let u = r.cross(f);
        let tan = (39.307_648_f32.to_radians() / 2.0).tan();
        for (i, j) in [(0, 0), (255, 0), (17, 200), (128, 128)] {
            let (s, t) = ((i as f32 + 0.5) / 256.0, (j as f32 + 0.5) / 256.0);
            let want = (f + (2.0 * s - 1.0) * tan * r + (1.0 - 2.0 * t) * tan * u).normalize();
            let ray = cam.generate_ray(&CameraSample::pixel_centre(i, j, 0.0)).unwrap();
            assert!((ray.direction - want).length() < 1e-6, "{i},{j}: {} vs {want}", ray.direction);
            assert_eq!(ray.origin, from);
        }
        // Image right is world −x for this camera (the reference README says so).
        let right = cam.generate_ray(&CameraSample::pixel_centre(255, 128, 0.0)).unwrap();
        assert!(right.direction.x < 0.0);
    }

    #[test]
    fn bad_cameras_are_errors() {
        assert!(look_at(Vec3::ZERO, Vec3::ZERO, Vec3::Y).is_err());
        assert!(look_at(Vec3::ZERO, Vec3::Y, Vec3::Y).is_err());
        let mut c = cornell();
        c.projection = Projection::Perspective { fov_y: 0.0 };
        assert!(c.build(UVec2::new(4, 4)).is_err());
        c.projection = Projection::Perspective { fov_y: 1.0 };
        assert!(c.build(UVec2::new(0, 4)).is_err());
    }

    #[test]
    fn every_model_gives_unit_rays() {
        let projections = [
            Projection::Perspective { fov_y: 1.0 },
            Projection::Orthographic { half_height: 2.0 },
            Projection::ThinLens { fov_y: 1.0, lens_radius: 0.1, focus_distance: 5.0 },
            Projection::Fisheye { fov: std::f32::consts::PI },
            Projection::Equirectangular,
        ];
        for projection in projections {
            let mut c = cornell();
            c.projection = projection;
            let cam = c.build(UVec2::new(64, 48)).unwrap();
            for j in 0..48 {
                for i in 0..64 {
                    let s = CameraSample {
                        p_film: Vec2::new(i as f32 + 0.3, j as f32 + 0.7),
                        p_lens: Vec2::new(0.2, 0.9),
                        time: 3.0,
                    };
                    if let Some(ray) = cam.generate_ray(&s) {
                        assert!(ray.is_valid(), "{projection:?} {ray:?}");
                        assert_eq!(ray.time, 3.0);
                    } else {
                        assert!(matches!(projection, Projection::Fisheye { .. }));
                    }
                }
            }
        }
    }
}
