//! A studio camera (docs/studio.md, "Engine"): a scene camera (or a copy of one) with the eye,
//! target, up and field of view the page edits, turned back into the tracer's camera model.

use crate::error::{Result, StudioError};
use crate::protocol::CameraEdit;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use tracer::camera::{CameraDesc, Projection};

/// A camera of one key: its tag number, name and pose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudioCamera {
    /// The 1-based tag number (the label painted for it).
    pub index: u32,
    /// Its name (the scene's, or "NAME copy").
    pub name: String,
    /// Eye position.
    pub eye: [f32; 3],
    /// The point looked at.
    pub target: [f32; 3],
    /// Roughly up.
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
}

impl StudioCamera {
    /// The studio's form of a scene camera: eye and axes from its transform, the target one
    /// unit ahead, the field of view of a perspective or thin-lens camera (other projections
    /// are shown through a perspective camera of 60°).
    pub fn from_desc(index: u32, desc: &CameraDesc) -> Self {
        let m = desc.world_from_camera;
        let eye = Vec3::from(m.translation);
        let forward = -Vec3::from(m.matrix3.z_axis).normalize_or_zero();
        let up = Vec3::from(m.matrix3.y_axis).normalize_or_zero();
        let fov_y = match desc.projection {
            Projection::Perspective { fov_y } | Projection::ThinLens { fov_y, .. } => fov_y,
            _ => 60f32.to_radians(),
        };
        Self {
            index,
            name: desc.name.clone(),
            eye: eye.to_array(),
            target: (eye + forward).to_array(),
            up: up.to_array(),
            fov_deg: fov_y.to_degrees(),
        }
    }

    /// The camera model (pinhole perspective) for the tracer; an error names the camera.
    pub fn desc(&self) -> Result<CameraDesc> {
        let projection = Projection::Perspective { fov_y: self.fov_deg.to_radians() };
        CameraDesc::look_at(&self.name, self.eye.into(), self.target.into(), self.up.into(), projection)
            .map_err(|e| StudioError::request(format!("camera {} ('{}'): {e}", self.index, self.name)))
    }

    /// This camera moved as `edit` says, checked: finite numbers, a field of view in (0°, 180°),
    /// a target away from the eye and an up not along the view.
    pub fn edited(&self, edit: &CameraEdit) -> Result<Self> {
        let moved =
            Self { eye: edit.eye, target: edit.target, up: edit.up, fov_deg: edit.fov_deg, ..self.clone() };
        let finite = [moved.eye, moved.target, moved.up].iter().flatten().all(|v| v.is_finite());
        if !(finite && moved.fov_deg > 0.0 && moved.fov_deg < 180.0) {
            return Err(StudioError::request(format!(
                "camera {}: eye, target and up must be finite and fov_deg in (0, 180)",
                self.index
            )));
        }
        moved.desc()?;
        Ok(moved)
    }

    /// Bits that change whenever the pose does (a cache key).
    pub fn key(&self) -> [u32; 10] {
        let v = [self.eye, self.target, self.up].concat();
        let mut out = [0u32; 10];
        for (o, x) in out.iter_mut().zip(v.iter().chain([&self.fov_deg])) {
            *o = x.to_bits();
        }
        out
    }

    /// The camera's colour on the page: the remapper's debug colour for it, `#rrggbb`.
    pub fn colour(&self) -> String {
        let [r, g, b] = colour(self.index);
        format!("#{r:02x}{g:02x}{b:02x}")
    }
}

/// The colour of camera `index` (1-based): the one the remapper's dominant-camera picture uses.
pub fn colour(index: u32) -> [u8; 3] {
    mcc::remap::debug::camera_colour(index.saturating_sub(1) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_camera_round_trips_through_the_studio_form() {
        let from = Vec3::new(1.0, 2.0, 3.0);
        let desc = CameraDesc::look_at(
            "left",
            from,
            Vec3::new(0.0, 1.0, -2.0),
            Vec3::Y,
            Projection::Perspective { fov_y: 0.8 },
        )
        .unwrap();
        let cam = StudioCamera::from_desc(2, &desc);
        let back = cam.desc().unwrap();
        assert!(back.world_from_camera.abs_diff_eq(desc.world_from_camera, 1e-5));
        assert!((cam.fov_deg - 0.8f32.to_degrees()).abs() < 1e-4);
        let edit = CameraEdit {
            index: 2,
            eye: [0.0; 3],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_deg: 50.0,
            gesture: None,
        };
        assert!(cam.edited(&edit).is_err(), "a target at the eye is refused");
        let edit = CameraEdit { target: [0.0, 0.0, -1.0], fov_deg: 190.0, ..edit };
        assert!(cam.edited(&edit).is_err());
        let moved = cam.edited(&CameraEdit { fov_deg: 40.0, ..edit }).unwrap();
        assert_ne!(moved.key(), cam.key());
        assert_eq!(cam.colour().len(), 7);
    }
}
