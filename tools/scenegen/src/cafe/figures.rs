//! The couple: two stylised seated figures built from smooth primitives (ellipsoids, tapered
//! capsules, a lofted torso). Each is modelled in its own frame: origin on the floor under the
//! middle of the chair seat, +y up, facing +z (towards the table), forearms resting on the table.

use super::Object;
use super::materials::Mat;
use super::mesh::{Section, capsule, ellipsoid, ellipsoid_shell, loft, sphere, tube};
use super::staging::{HEAD_CENTER, TABLE_TOP_Y};
use glam::{DVec2, Mat3A, Vec3};

/// What tells the two figures apart.
pub struct Style {
    pub name: &'static str,
    pub skin: Mat,
    pub hair: Mat,
    pub top: Mat,
    pub bottom: Mat,
    pub legs: Mat,
    /// Half the shoulder width, metres.
    pub shoulders: f64,
    /// Half the hip width.
    pub hips: f64,
    pub long_hair: bool,
    /// Hands around the cup (true) or resting flat, apart (false).
    pub hands_on_cup: bool,
}

pub const FIGURE_A: Style = Style {
    name: "figure_a",
    skin: Mat::SkinA,
    hair: Mat::HairA,
    top: Mat::SweaterA,
    bottom: Mat::TrousersA,
    legs: Mat::TrousersA,
    shoulders: 0.185,
    hips: 0.16,
    long_hair: false,
    hands_on_cup: false,
};

pub const FIGURE_B: Style = Style {
    name: "figure_b",
    skin: Mat::SkinB,
    hair: Mat::HairB,
    top: Mat::DressB,
    bottom: Mat::DressB,
    legs: Mat::TightsB,
    shoulders: 0.160,
    hips: 0.17,
    long_hair: true,
    hands_on_cup: true,
};

/// Cloth texture repeats per metre (the knit's stitches are ~6 mm, the tartan's sett ~12 cm).
const CLOTH_UV: f64 = 6.0;

/// The skull's semi-axes.
const SKULL: Vec3 = Vec3::new(0.082, 0.105, 0.098);

/// The torso leans forward: the spine's z offset at height y.
fn lean(y: f64) -> f64 {
    0.015 + (y - 0.5) * 0.11
}

/// One seated figure.
pub fn figure(s: &Style) -> Object {
    let mut o = Object::new(s.name);
    torso(&mut o, s);
    head(&mut o, s);
    arms(&mut o, s);
    legs(&mut o, s);
    o
}

fn torso(o: &mut Object, s: &Style) {
    let (sh, hp) = (s.shoulders, s.hips);
    let waist = 0.5 * (sh + hp) - 0.02;
    let sec = |y: f64, rx: f64, rz: f64| Section { y, cx: 0.0, cz: lean(y), rx, rz };
    let sections = [
        sec(0.47, 0.0, 0.0),
        sec(0.49, hp * 0.65, 0.085),
        sec(0.56, hp, 0.125),
        sec(0.68, waist, 0.105),
        sec(0.82, waist + 0.01, 0.11),
        sec(0.95, sh, 0.115),
        sec(1.05, sh - 0.005, 0.105),
        sec(1.11, sh * 0.66, 0.08),
        sec(1.145, 0.06, 0.05),
        sec(1.155, 0.0, 0.0),
    ];
    o.add(s.top, loft(&sections, 80, 56, CLOTH_UV));
    // The seat of the figure: hips and buttocks, in the bottom garment.
    o.add(
        s.bottom,
        ellipsoid(
            Vec3::new(0.0, 0.555, 0.0),
            Vec3::new(hp as f32, 0.085, 0.13),
            Mat3A::IDENTITY,
            56,
            28,
            DVec2::new(0.9, 0.5) * CLOTH_UV,
        ),
    );
}

fn head(o: &mut Object, s: &Style) {
    let h = HEAD_CENTER;
    let id = Mat3A::IDENTITY;
    // Neck, skull, jaw, nose, ears.
    o.add(
        s.skin,
        tube(Vec3::new(0.0, 1.10, lean(1.10) as f32), Vec3::new(0.0, 1.245, 0.085), 0.05, 0.046, 40, 6, 1.0),
    );
    o.add(s.skin, ellipsoid(h, SKULL, id, 80, 40, DVec2::ONE));
    o.add(
        s.skin,
        ellipsoid(h + Vec3::new(0.0, -0.06, 0.025), Vec3::new(0.066, 0.07, 0.082), id, 48, 24, DVec2::ONE),
    );
    let nose_tilt = Mat3A::from_rotation_x(-0.35);
    o.add(
        s.skin,
        ellipsoid(
            h + Vec3::new(0.0, -0.03, 0.102),
            Vec3::new(0.014, 0.03, 0.02),
            nose_tilt,
            24,
            12,
            DVec2::ONE,
        ),
    );
    for side in [-1.0f32, 1.0] {
        o.add(
            s.skin,
            ellipsoid(
                h + Vec3::new(0.081 * side, -0.02, -0.005),
                Vec3::new(0.012, 0.03, 0.02),
                id,
                20,
                10,
                DVec2::ONE,
            ),
        );
        // Eyes: glossy dark spheres set into the skull's front.
        o.add(Mat::Eye, sphere(h + Vec3::new(0.03 * side, -0.005, 0.086), 0.0125, 24, 12));
        // Brows: flat ellipsoids in the hair colour.
        let brow = Mat3A::from_rotation_z(-0.12 * side) * Mat3A::from_rotation_x(-0.2);
        o.add(
            s.hair,
            ellipsoid(
                h + Vec3::new(0.031 * side, 0.018, 0.09),
                Vec3::new(0.02, 0.004, 0.008),
                brow,
                16,
                8,
                DVec2::ONE,
            ),
        );
    }
    o.add(
        Mat::Lips,
        ellipsoid(h + Vec3::new(0.0, -0.085, 0.097), Vec3::new(0.021, 0.0065, 0.008), id, 20, 10, DVec2::ONE),
    );
    // Hair: a cap over the skull, tilted back so the forehead shows.
    let tilt = Mat3A::from_rotation_x(-0.5);
    let cap_reach = if s.long_hair { 1.9 } else { 1.72 };
    o.add(s.hair, ellipsoid_shell(h, SKULL, 1.05, tilt, cap_reach, 80, 28));
    if s.long_hair {
        // A bun at the back of the head and hair falling to the nape.
        o.add(s.hair, sphere(h + Vec3::new(0.0, 0.05, -0.105), 0.052, 40, 20));
        o.add(
            s.hair,
            ellipsoid(
                h + Vec3::new(0.0, -0.07, -0.045),
                Vec3::new(0.085, 0.11, 0.065),
                Mat3A::from_rotation_x(0.25),
                56,
                28,
                DVec2::ONE,
            ),
        );
    }
}

fn arms(o: &mut Object, s: &Style) {
    let sh = s.shoulders as f32;
    let top = TABLE_TOP_Y;
    for side in [-1.0f32, 1.0] {
        let shoulder = Vec3::new((sh + 0.015) * side, 1.045, lean(1.045) as f32);
        let elbow = Vec3::new((sh + 0.035) * side, 0.83, 0.25);
        let (wrist, hand_c, hand_r, hand_rot) = if s.hands_on_cup {
            // Hands upright, cupping the cup in front of the figure.
            let wrist = Vec3::new(0.085 * side, top + 0.054, 0.53);
            let hand = Vec3::new(0.066 * side, top + 0.056, 0.585);
            (wrist, hand, Vec3::new(0.022, 0.042, 0.055), Mat3A::from_rotation_y(-0.25 * side))
        } else {
            // Hands resting flat on the table, turned slightly inwards.
            let wrist = Vec3::new(0.12 * side, top + 0.036, 0.5);
            let hand = Vec3::new(0.1 * side, top + 0.023, 0.56);
            (wrist, hand, Vec3::new(0.045, 0.02, 0.062), Mat3A::from_rotation_y(0.3 * side))
        };
        o.add(s.top, sphere(shoulder, 0.058, 40, 20));
        o.add(s.top, capsule(shoulder, elbow, 0.055, 0.045, 40, 8, CLOTH_UV));
        o.add(s.top, capsule(elbow, wrist, 0.045, 0.036, 40, 8, CLOTH_UV));
        o.add(s.skin, ellipsoid(hand_c, hand_r, hand_rot, 32, 16, DVec2::ONE));
        // The thumb.
        let thumb = hand_c + hand_rot * Vec3::new(-0.03 * side, 0.004, -0.01);
        o.add(
            s.skin,
            capsule(thumb, thumb + hand_rot * Vec3::new(-0.01 * side, 0.0, 0.035), 0.011, 0.009, 16, 3, 1.0),
        );
    }
}

fn legs(o: &mut Object, s: &Style) {
    for side in [-1.0f32, 1.0] {
        let hip = Vec3::new(0.085 * side, 0.53, 0.03);
        let knee = Vec3::new(0.1 * side, 0.53, 0.45);
        let ankle = Vec3::new(0.1 * side, 0.085, 0.47);
        o.add(s.bottom, capsule(hip, knee, 0.078, 0.058, 48, 10, CLOTH_UV));
        o.add(s.legs, capsule(knee, ankle, 0.055, 0.038, 40, 10, CLOTH_UV));
        o.add(
            Mat::Shoes,
            ellipsoid(
                Vec3::new(0.1 * side, 0.045, 0.535),
                Vec3::new(0.045, 0.045, 0.11),
                Mat3A::IDENTITY,
                32,
                16,
                DVec2::ONE,
            ),
        );
    }
}
