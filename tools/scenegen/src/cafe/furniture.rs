//! Furniture: the round café table, bentwood bistro chairs, bar stools, the counter with its
//! zinc top, the back bar's shelves and bottles, and an espresso machine. Each is modelled in
//! its own frame (origin on the floor, front towards +z) and placed by its node.

use super::Object;
use super::materials::Mat;
use super::mesh::{Profile, capsule, cuboid, lathe, torus};
use super::staging::TABLE_TOP_Y;
use glam::Vec3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Wood texture repeats per metre (the texture shows ~11 growth rings).
const WOOD_UV: f32 = 1.6;

/// The round table: a wooden top with a rounded edge on a cast-iron pedestal.
pub fn table() -> Object {
    let mut o = Object::new("table");
    let (r, t, y) = (0.40, 0.03, f64::from(TABLE_TOP_Y));
    let edge = t / 2.0;
    let top = Profile::start(0.0, y - t)
        .line(r - edge, y - t, 8)
        .arc(r - edge, y - edge, edge, -FRAC_PI_2, FRAC_PI_2, 10)
        .line(0.0, y, 8);
    let top = lathe(&top, Vec3::ZERO, 128, 1.0).planar_uv(Vec3::X * WOOD_UV, Vec3::Z * WOOD_UV);
    o.add(Mat::Wood, top);
    let stand = Profile::start(0.0, 0.0)
        .line(0.2, 0.0, 4)
        .arc(0.2, 0.012, 0.012, -FRAC_PI_2, FRAC_PI_2, 8)
        .line(0.05, 0.045, 8)
        .arc(0.05, 0.075, 0.03, -FRAC_PI_2, -PI, 8)
        .line(0.028, y - t - 0.05, 8)
        .arc(0.06, y - t - 0.05, 0.032, PI, FRAC_PI_2, 8)
        .line(0.14, y - t - 0.018, 4)
        .crease()
        .line(0.14, y - t, 2)
        .crease()
        .line(0.0, y - t - 0.0005, 2);
    o.add(Mat::BlackMetal, lathe(&stand, Vec3::ZERO, 64, 1.0));
    o
}

/// A bentwood bistro chair (front +z): round seat, splayed legs with a ring, hoop back.
pub fn chair() -> Object {
    let mut o = Object::new("bistro_chair");
    let seat = Profile::start(0.0, 0.43)
        .line(0.19, 0.43, 6)
        .arc(0.19, 0.445, 0.015, -FRAC_PI_2, FRAC_PI_2, 8)
        .line(0.0, 0.46, 6);
    o.add(Mat::Wood, lathe(&seat, Vec3::ZERO, 64, 1.0).planar_uv(Vec3::X * WOOD_UV, Vec3::Z * WOOD_UV));
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let top = Vec3::new(0.12 * sx, 0.432, 0.12 * sz);
        let foot = Vec3::new(0.175 * sx, 0.0, 0.175 * sz);
        o.add(Mat::WoodDark, capsule(top, foot, 0.016, 0.013, 16, 4, f64::from(WOOD_UV)));
    }
    o.add(
        Mat::WoodDark,
        torus(Vec3::new(0.0, 0.2, 0.0), Vec3::Y, Vec3::X, 0.148, 0.009, (0.0, TAU), 64, 8, 1.0),
    );
    // Back uprights rising from the seat's rear, joined by two hoops.
    let (back_z, back_y) = (-0.2, 0.80);
    for sx in [-1.0f32, 1.0] {
        let a = Vec3::new(0.15 * sx, 0.44, -0.14);
        o.add(Mat::WoodDark, capsule(a, Vec3::new(0.17 * sx, back_y, back_z), 0.016, 0.016, 16, 6, 1.0));
    }
    let hoop_center = Vec3::new(0.0, back_y, back_z);
    o.add(Mat::WoodDark, torus(hoop_center, Vec3::Z, Vec3::X, 0.17, 0.016, (0.0, PI), 48, 10, 1.0));
    o.add(
        Mat::WoodDark,
        torus(hoop_center + Vec3::new(0.0, -0.02, 0.0), Vec3::Z, Vec3::X, 0.10, 0.012, (0.0, PI), 32, 8, 1.0),
    );
    // The inner hoop's legs, down to the seat.
    for sx in [-1.0f32, 1.0] {
        let end = hoop_center + Vec3::new(0.10 * sx, -0.02, 0.0);
        o.add(Mat::WoodDark, capsule(Vec3::new(0.10 * sx, 0.45, -0.15), end, 0.012, 0.012, 16, 6, 1.0));
    }
    o
}

/// A bar stool: wooden seat on three black legs with a foot ring.
pub fn stool() -> Object {
    let mut o = Object::new("bar_stool");
    let seat = Profile::start(0.0, 0.74)
        .line(0.16, 0.74, 4)
        .arc(0.16, 0.76, 0.02, -FRAC_PI_2, FRAC_PI_2, 8)
        .line(0.0, 0.78, 4);
    o.add(Mat::Wood, lathe(&seat, Vec3::ZERO, 64, 1.0).planar_uv(Vec3::X * WOOD_UV, Vec3::Z * WOOD_UV));
    for k in 0..3 {
        let a = TAU / 3.0 * f64::from(k) + 0.3;
        let dir = Vec3::new(a.cos() as f32, 0.0, a.sin() as f32);
        o.add(Mat::BlackMetal, capsule(dir * 0.1 + Vec3::Y * 0.745, dir * 0.21, 0.013, 0.013, 16, 4, 1.0));
    }
    o.add(
        Mat::BlackMetal,
        torus(Vec3::new(0.0, 0.28, 0.0), Vec3::Y, Vec3::X, 0.17, 0.009, (0.0, TAU), 64, 8, 1.0),
    );
    o
}

/// The counter's extent (world): front face at `COUNTER_FRONT_Z`, against the back wall.
pub const COUNTER_X: (f32, f32) = (-2.1, 2.1);
pub const COUNTER_FRONT_Z: f32 = 2.3;
pub const COUNTER_HEIGHT: f32 = 1.04;

/// The counter (world coordinates): panelled wooden front, black kick plate, zinc top with a
/// rounded nose and an espresso machine.
pub fn counter() -> Object {
    let mut o = Object::new("counter");
    let (x0, x1) = COUNTER_X;
    let (z0, z1) = (COUNTER_FRONT_Z, 2.9);
    let h = COUNTER_HEIGHT;
    o.add(Mat::BlackMetal, cuboid(Vec3::new(x0 + 0.03, 0.0, z0 + 0.05), Vec3::new(x1 - 0.03, 0.12, z1), 1.0));
    o.add(Mat::Wood, cuboid(Vec3::new(x0, 0.12, z0 + 0.02), Vec3::new(x1, h - 0.04, z1), WOOD_UV));
    // Raised panels on the front.
    let panels = 6;
    let w = (x1 - x0 - 0.1) / panels as f32;
    for k in 0..panels {
        let a = x0 + 0.05 + w * k as f32;
        o.add(
            Mat::WoodDark,
            cuboid(Vec3::new(a + 0.04, 0.24, z0), Vec3::new(a + w - 0.04, h - 0.16, z0 + 0.02), WOOD_UV),
        );
    }
    // Zinc slab with a rounded front nose.
    let zinc_uv = 2.0;
    o.add(Mat::Zinc, cuboid(Vec3::new(x0 - 0.05, h - 0.04, z0), Vec3::new(x1 + 0.05, h, z1 + 0.05), zinc_uv));
    o.add(
        Mat::Zinc,
        capsule(
            Vec3::new(x0 - 0.05, h - 0.02, z0),
            Vec3::new(x1 + 0.05, h - 0.02, z0),
            0.022,
            0.022,
            32,
            4,
            1.0,
        )
        .planar_uv(Vec3::X * zinc_uv, Vec3::Z * zinc_uv),
    );
    // Espresso machine.
    let m0 = MACHINE;
    o.add(Mat::Steel, cuboid(m0, m0 + Vec3::new(0.62, 0.42, 0.4), 1.0));
    o.add(Mat::BlackMetal, cuboid(m0 + Vec3::new(0.0, 0.42, 0.0), m0 + Vec3::new(0.62, 0.44, 0.4), 1.0));
    for k in 0..2 {
        let gx = m0.x + 0.18 + 0.26 * k as f32;
        let group = Vec3::new(gx, h + 0.27, m0.z);
        o.add(Mat::Steel, capsule(group, group - Vec3::new(0.0, 0.06, 0.05), 0.03, 0.035, 32, 4, 1.0));
        o.add(
            Mat::BlackMetal,
            capsule(
                group - Vec3::new(0.0, 0.06, 0.05),
                group - Vec3::new(0.0, 0.06, 0.2),
                0.012,
                0.012,
                16,
                4,
                1.0,
            ),
        );
        o.add(
            Mat::Steel,
            cuboid(Vec3::new(gx - 0.07, h, m0.z - 0.14), Vec3::new(gx + 0.07, h + 0.02, m0.z), 1.0),
        );
    }
    o.add(
        Mat::Steel,
        capsule(m0 + Vec3::new(0.5, 0.3, 0.0), m0 + Vec3::new(0.56, 0.12, -0.06), 0.008, 0.008, 16, 8, 1.0),
    );
    o
}

/// The espresso machine's corner on the counter (world).
const MACHINE: Vec3 = Vec3::new(0.55, COUNTER_HEIGHT, 2.45);

/// A prop's place: base position and turn about +y (radians).
pub type Spot = (Vec3, f32);

/// Where cups stand (world), as (base, handle angle about +y): on the bar with saucers, and
/// on the machine's warming tray without.
pub fn counter_cups() -> (Vec<Spot>, Vec<Spot>) {
    let bar =
        (0..3).map(|k| (Vec3::new(-1.2 + 0.22 * k as f32, COUNTER_HEIGHT, 2.5), 0.4 * k as f32)).collect();
    let tray =
        (0..4).map(|k| (MACHINE + Vec3::new(0.1 + 0.14 * k as f32, 0.44, 0.2), 0.3 * k as f32)).collect();
    (bar, tray)
}

const SHELVES: [f32; 2] = [1.45, 1.85];

/// Bottles on the back bar's shelves (world): base position, and whether it is a clear carafe
/// (else a green wine bottle).
pub fn bottles(wall_z: f32) -> Vec<(Vec3, bool)> {
    let mut out = vec![];
    for (k, y) in SHELVES.into_iter().enumerate() {
        for b in 0..11 {
            let x = -1.75 + 0.33 * b as f32 + 0.07 * k as f32;
            out.push((Vec3::new(x, y, wall_z - 0.13), (b + k) % 3 == 0));
        }
    }
    out
}

/// The back bar's shelves and brackets (world coordinates).
pub fn back_bar(wall_z: f32) -> Object {
    let mut o = Object::new("back_bar");
    for y in SHELVES {
        o.add(
            Mat::WoodDark,
            cuboid(Vec3::new(-1.9, y - 0.03, wall_z - 0.26), Vec3::new(1.9, y, wall_z), WOOD_UV),
        );
    }
    // Brackets under the shelves.
    for x in [-1.6f32, 0.0, 1.6] {
        for y in [1.42f32, 1.82] {
            o.add(
                Mat::BlackMetal,
                cuboid(Vec3::new(x - 0.01, y - 0.12, wall_z - 0.2), Vec3::new(x + 0.01, y, wall_z), 1.0),
            );
        }
    }
    o
}

/// A wine bottle (green glass, drawn opaque) or a clear carafe (transmissive): a closed solid
/// standing at the origin.
pub fn bottle(carafe: bool) -> Object {
    let (name, mat, h, r, neck) = if carafe {
        ("carafe", Mat::Glass, 0.24, 0.045, 0.018)
    } else {
        ("wine_bottle", Mat::Bottle, 0.30, 0.036, 0.013)
    };
    let mut o = Object::new(name);
    let shoulder = h * 0.62;
    let p = Profile::start(0.0, 0.0)
        .line(r - 0.004, 0.0, 2)
        .arc(r - 0.004, 0.004, 0.004, -FRAC_PI_2, 0.0, 4)
        .line(r, shoulder, 6)
        .arc(neck, shoulder, r - neck, 0.0, FRAC_PI_2 * 0.85, 12)
        .line(neck, h - 0.01, 6)
        .arc(neck - 0.002, h - 0.002, 0.002, 0.0, FRAC_PI_2, 3)
        .line(0.0, h, 2);
    o.add(mat, lathe(&p, Vec3::ZERO, 48, 1.0));
    o
}
