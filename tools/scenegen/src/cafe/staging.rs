//! Where things stand: the seating group's frame, the figures' seats, the cameras and the
//! punctual light. Positions in "group" coordinates are relative to the table's centre on the
//! floor (the couple faces along ±x); the group node places them in the room.

use crate::gltf_writer::look_at_rotation;
use glam::{Affine3A, Quat, Vec2, Vec3};
use std::f32::consts::FRAC_PI_2;

/// Height of the table top's upper surface.
pub const TABLE_TOP_Y: f32 = 0.75;
/// Where a seated figure's head sits (figure frame): the face looks along +z. The figures are
/// modelled around it, and the cameras aim at the faces it places.
pub const HEAD_CENTER: Vec3 = Vec3::new(0.0, 1.33, 0.09);
/// Distance from the table's centre to each chair's centre.
pub const SEAT_DISTANCE: f32 = 0.85;

/// The room: floor at y = 0, ceiling at `ROOM_HEIGHT`, walls at these x and z.
pub const ROOM_X: (f32, f32) = (-4.0, 4.0);
pub const ROOM_Z: (f32, f32) = (-4.0, 3.2);
pub const ROOM_HEIGHT: f32 = 3.0;

/// The seating group's node transform (table, chairs, couple and table props).
pub const GROUP_TRANSLATION: Vec3 = Vec3::new(0.15, 0.0, -0.35);
pub const GROUP_YAW: f32 = 0.1;

pub fn group_rotation() -> Quat {
    Quat::from_rotation_y(GROUP_YAW)
}

pub fn group_to_world() -> Affine3A {
    Affine3A::from_rotation_translation(group_rotation(), GROUP_TRANSLATION)
}

/// A seated figure's (and its chair's) transform within the group: figure A on the −x side
/// facing +x, figure B on the +x side facing −x.
pub fn seat(figure_b: bool) -> (Vec3, Quat) {
    if figure_b {
        (Vec3::new(SEAT_DISTANCE, 0.0, 0.0), Quat::from_rotation_y(-FRAC_PI_2))
    } else {
        (Vec3::new(-SEAT_DISTANCE, 0.0, 0.0), Quat::from_rotation_y(FRAC_PI_2))
    }
}

/// A perspective camera: name, eye and target in world coordinates, vertical field of view.
pub struct CameraDef {
    pub name: &'static str,
    pub eye: Vec3,
    pub target: Vec3,
    pub yfov_deg: f32,
}

pub const ASPECT: f32 = 16.0 / 9.0;

/// The point between a figure's eyes (group coordinates).
pub fn face(figure_b: bool) -> Vec3 {
    let (at, turn) = seat(figure_b);
    at + turn * (HEAD_CENTER + Vec3::new(0.0, -0.005, 0.086))
}

/// The target that makes a camera at `eye` with vertical field `yfov_deg` (no roll) show
/// `subject` at `pixel`, given as fractions of the image's width and height from its top-left.
pub fn aim(eye: Vec3, subject: Vec3, pixel: Vec2, yfov_deg: f32) -> Vec3 {
    let tan = (yfov_deg.to_radians() / 2.0).tan();
    let want = Vec2::new((2.0 * pixel.x - 1.0) * tan * ASPECT, (1.0 - 2.0 * pixel.y) * tan);
    let mut target = subject;
    // Fixed-point iteration: move the target until the subject's film position is `want`.
    for _ in 0..200 {
        let q = look_at_rotation(eye, target, Vec3::Y);
        let local = q.inverse() * (subject - eye);
        let film = Vec2::new(local.x, local.y) / -local.z;
        let err = film - want;
        let dist = (target - eye).length();
        target += (q * Vec3::new(err.x, err.y, 0.0)) * dist;
    }
    target
}

/// The three cameras: `left` over figure A's shoulder at figure B's face (B's face in the
/// image's left third), `right` the reverse shot over B's shoulder at A's face (in the right
/// third). Both stand on the same side of the couple's line of action (the 180° rule), so
/// B looks right and A looks left, as across the table. `wide` shows the room.
pub fn cameras() -> Vec<CameraDef> {
    let g = group_to_world();
    let ots = |name, eye: Vec3, figure_b, pixel: Vec2| {
        let eye = g.transform_point3(eye);
        let subject = g.transform_point3(face(figure_b));
        CameraDef { name, eye, target: aim(eye, subject, pixel, OTS_FOV), yfov_deg: OTS_FOV }
    };
    vec![
        ots("left", Vec3::new(-1.35, 1.45, -0.70), true, Vec2::new(0.23, 0.40)),
        ots("right", Vec3::new(1.35, 1.45, -0.70), false, Vec2::new(0.77, 0.40)),
        CameraDef {
            name: "wide",
            eye: Vec3::new(-2.3, 1.8, -2.8),
            target: Vec3::new(0.7, 1.05, 0.6),
            yfov_deg: 55.0,
        },
    ]
}

/// The over-the-shoulder cameras' vertical field of view, degrees.
const OTS_FOV: f32 = 40.0;

/// The pendant lamp over the table (group coordinates): the spot light sits inside its shade.
pub const PENDANT_SHADE_Y: f32 = 2.15;
pub const SPOT_POSITION: Vec3 = Vec3::new(0.0, 2.28, 0.0);
/// The spot's power as Blender shows it (watts); the file stores candela = W / 4π × 683
/// (Blender's exporter), i.e. a radiant intensity of W / 4π W/sr.
pub const SPOT_WATTS: f64 = 150.0;
pub const SPOT_COLOR: [f64; 3] = [1.0, 0.78, 0.52];
pub const SPOT_INNER: f64 = 0.45;
pub const SPOT_OUTER: f64 = 0.75;

pub fn spot_candela() -> f64 {
    SPOT_WATTS / (4.0 * std::f64::consts::PI) * 683.0
}
