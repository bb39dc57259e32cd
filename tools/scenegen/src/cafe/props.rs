//! Table props: cups of coffee on saucers (glossy ceramic), a spoon and a lidded sugar bowl
//! (polished steel), a drinking glass (transmissive), and a vase of flowers.

use super::Object;
use super::materials::Mat;
use super::mesh::{Mesh, Profile, capsule, ellipsoid, lathe, sphere, torus, tube};
use super::staging::TABLE_TOP_Y;
use glam::{Affine3A, DVec2, Mat3A, Quat, Vec3};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Outer radius of the cup at height y above its foot.
fn cup_outer(y: f64) -> f64 {
    0.025 + 0.016 * (y / 0.065).clamp(0.0, 1.0).sqrt()
}
const CUP_HEIGHT: f64 = 0.065;
const CUP_WALL: f64 = 0.0032;
const SAUCER_TOP: f32 = 0.009;
/// Segments around the cups.
const SEGMENTS: u32 = 64;

/// A cup standing at the origin, handle along +x: on a saucer with coffee, or empty alone.
pub fn cup(saucer: bool) -> Object {
    let mut o = Object::new(if saucer { "cup_on_saucer" } else { "cup" });
    let mat = Mat::Ceramic;
    let lift = if saucer { SAUCER_TOP } else { 0.0 };
    if saucer {
        let s = Profile::start(0.0, 0.0)
            .line(0.042, 0.0, 3)
            .crease()
            .line(0.045, 0.003, 1)
            .crease()
            .points((1..=10).map(|k| {
                let t = f64::from(k) / 10.0;
                (0.045 + 0.028 * t, 0.003 + 0.009 * t * t)
            }))
            .arc(0.073, 0.0135, 0.0015, -FRAC_PI_2, FRAC_PI_2, 8)
            .points((1..=10).map(|k| {
                let t = 1.0 - f64::from(k) / 10.0;
                (0.045 + 0.028 * t, f64::from(SAUCER_TOP) + 0.006 * t * t)
            }))
            .line(0.0, f64::from(SAUCER_TOP), 4);
        o.add(mat, lathe(&s, Vec3::ZERO, SEGMENTS, 1.0));
    }
    let foot = f64::from(lift);
    let h = CUP_HEIGHT;
    let outer = (1..=16).map(|k| {
        let y = 0.004 + (h - 0.004) * f64::from(k) / 16.0;
        (cup_outer(y), foot + y)
    });
    let inner = (0..=14).map(|k| {
        let y = h - (h - 0.012) * f64::from(k) / 14.0;
        (cup_outer(y) - CUP_WALL, foot + y)
    });
    let rim = cup_outer(h) - CUP_WALL / 2.0;
    let cup = Profile::start(0.0, foot)
        .line(0.021, foot, 3)
        .crease()
        .line(0.024, foot + 0.004, 1)
        .crease()
        .points(outer)
        .arc(rim, foot + h, CUP_WALL / 2.0, 0.0, PI, 8)
        .points(inner)
        .line(0.0, foot + 0.009, 4);
    o.add(mat, lathe(&cup, Vec3::ZERO, SEGMENTS, 1.0));
    if saucer {
        let level = 0.048;
        let coffee =
            Profile::start(cup_outer(level) - CUP_WALL + 0.0005, foot + level).line(0.0, foot + level, 4);
        o.add(Mat::Coffee, lathe(&coffee, Vec3::ZERO, SEGMENTS, 1.0));
    }
    let handle_center = Vec3::new((cup_outer(0.035) + 0.002) as f32, lift + 0.036, 0.0);
    let handle = torus(handle_center, Vec3::Z, Vec3::X, 0.016, 0.0045, (-1.9, 1.9), 48, 16, 1.0);
    o.add(mat, handle);
    o
}

/// Where the couple's cups stand (group coordinates) and their handles' angles.
pub const TABLE_CUPS: [(Vec3, f32); 2] =
    [(Vec3::new(-0.17, TABLE_TOP_Y, 0.0), 0.9), (Vec3::new(0.265, TABLE_TOP_Y, 0.0), 1.5)];

/// A teaspoon lying on the table at `at`, its handle turned by `yaw` from +z.
fn spoon(at: Vec3, yaw: f32) -> Mesh {
    let place = Affine3A::from_rotation_translation(Quat::from_rotation_y(yaw), at);
    let mut m = ellipsoid(
        Vec3::new(0.0, 0.003, 0.0),
        Vec3::new(0.011, 0.003, 0.017),
        Mat3A::IDENTITY,
        32,
        16,
        DVec2::ONE,
    );
    m.append(tube(Vec3::new(0.0, 0.004, 0.015), Vec3::new(0.0, 0.007, 0.11), 0.0022, 0.003, 16, 8, 1.0));
    m.append(sphere(Vec3::new(0.0, 0.007, 0.11), 0.003, 16, 8));
    m.transformed(place)
}

/// A lidded sugar bowl at `base`.
fn sugar_bowl(base: Vec3) -> Mesh {
    let body = Profile::start(0.0, 0.0)
        .line(0.026, 0.0, 3)
        .crease()
        .points((0..=16).map(|k| {
            let t = f64::from(k) / 16.0;
            (0.026 + 0.02 * (PI * 0.85 * t).sin(), 0.058 * t)
        }))
        .crease()
        .line(0.03, 0.058, 2)
        .crease()
        .arc(0.0, 0.05, 0.042, 0.19, FRAC_PI_2, 16);
    let mut m = lathe(&body, base, 64, 1.0);
    m.append(sphere(base + Vec3::new(0.0, 0.098, 0.0), 0.0095, 32, 16));
    m
}

/// A tumbler: a closed solid with outer and inner walls and a thick bottom.
fn glass(base: Vec3) -> Mesh {
    let (r0, r1, h, wall) = (0.031, 0.036, 0.11, super::materials::GLASS_WALL);
    let p = Profile::start(0.0, 0.0)
        .line(r0 - 0.002, 0.0, 2)
        .arc(r0 - 0.002, 0.002, 0.002, -FRAC_PI_2, 0.0, 4)
        .line(r1, h, 12)
        .arc(r1 - wall / 2.0, h, wall / 2.0, 0.0, PI, 8)
        .line(r0 - wall, 0.012, 12)
        .arc(r0 - wall - 0.004, 0.012, 0.004, 0.0, -FRAC_PI_2, 4)
        .line(0.0, 0.008, 2);
    lathe(&p, base, 64, 1.0)
}

/// A bulbous vase at `base` with three flowers.
fn vase(o: &mut Object, base: Vec3) {
    let h = 0.15;
    let outer = (0..=24).map(|k| {
        let t = f64::from(k) / 24.0;
        (0.022 + 0.032 * (PI * (0.15 + 0.8 * t)).sin().powf(1.5) * (1.0 - t * 0.5), h * t)
    });
    let p = Profile::start(0.0, 0.0)
        .line(0.03, 0.0, 3)
        .crease()
        .points(outer.skip(1))
        .line(0.027, h + 0.006, 2)
        .arc(0.025, h + 0.006, 0.002, 0.0, PI, 6)
        .line(0.02, h - 0.03, 4)
        .line(0.0, h - 0.03, 3);
    o.add(Mat::CeramicTeal, lathe(&p, base, 64, 1.0));
    let stems = [(0.0f32, 0.33f32, 0.07f32), (2.2, 0.29, 0.1), (4.1, 0.31, 0.085)];
    for (k, (angle, height, lean)) in stems.into_iter().enumerate() {
        let dir = Vec3::new(angle.cos(), 0.0, angle.sin());
        let a = base + Vec3::Y * (h as f32 - 0.04);
        let mid = base + Vec3::Y * (height * 0.6) + dir * lean * 0.35;
        let tip = base + Vec3::Y * height + dir * lean;
        o.add(Mat::Leaf, capsule(a, mid, 0.003, 0.003, 8, 4, 1.0));
        o.add(Mat::Leaf, capsule(mid, tip, 0.003, 0.0028, 8, 4, 1.0));
        let leaf_rot = Mat3A::from_rotation_y(-angle + 0.8) * Mat3A::from_rotation_x(0.9);
        o.add(
            Mat::Leaf,
            ellipsoid(
                mid + Vec3::Y * 0.01 + dir.cross(Vec3::Y) * 0.015,
                Vec3::new(0.009, 0.0025, 0.03),
                leaf_rot,
                16,
                8,
                DVec2::ONE,
            ),
        );
        // The blossom faces up and outwards.
        let up = (Vec3::Y + dir * 0.6).normalize();
        let tilt = Mat3A::from_quat(Quat::from_rotation_arc(Vec3::Y, up));
        o.add(Mat::PetalYellow, sphere(tip, 0.009, 16, 8));
        let petals = 7;
        for p in 0..petals {
            let a = TAU as f32 * p as f32 / petals as f32 + k as f32;
            let radial = Vec3::new(a.cos(), 0.0, a.sin());
            let rot = tilt * Mat3A::from_rotation_y(-a) * Mat3A::from_rotation_z(0.35);
            let petal = ellipsoid(
                tip + tilt * (radial * 0.019 + Vec3::Y * 0.003),
                Vec3::new(0.016, 0.003, 0.009),
                rot,
                16,
                8,
                DVec2::ONE,
            );
            o.add(Mat::PetalRed, petal);
        }
    }
}

/// Everything else on the table (group coordinates): a spoon by figure A's cup, the sugar
/// bowl, the glass and the vase.
pub fn table_props() -> Object {
    let mut o = Object::new("table_props");
    let top = TABLE_TOP_Y;
    o.add(Mat::Steel, spoon(Vec3::new(-0.10, top, 0.085), 0.3));
    o.add(Mat::Steel, sugar_bowl(Vec3::new(-0.04, top, -0.22)));
    o.add(Mat::Glass, glass(Vec3::new(0.12, top, -0.15)));
    vase(&mut o, Vec3::new(0.0, top, 0.21));
    o
}
