//! The room (world coordinates): tiled floor, plaster walls over a painted dado, ceiling with an
//! emissive panel, the window in the +x wall with a daylight "sky" quad behind it, the pendant
//! lamp over the table, and a painting.

use super::Object;
use super::materials::Mat;
use super::mesh::{Mesh, Profile, cuboid, lathe, quad, tube};
use super::staging::{PENDANT_SHADE_Y, ROOM_HEIGHT, ROOM_X, ROOM_Z, SPOT_POSITION};
use super::textures::FLOOR_TEXTURE_METRES;
use glam::{DVec2, Vec2, Vec3, Vec4};

/// The window opening in the +x wall: z range and y range; the wall's thickness.
pub const WINDOW_Z: (f32, f32) = (-1.7, 1.1);
pub const WINDOW_Y: (f32, f32) = (0.85, 2.55);
const WALL_THICKNESS: f32 = 0.18;
/// Height of the painted dado (the lower wall) and its rail.
const DADO: f32 = 0.85;
/// The ceiling panel: centre (x, z) and size (x, z).
pub const PANEL_CENTER: Vec2 = Vec2::new(0.15, -0.85);
pub const PANEL_SIZE: Vec2 = Vec2::new(2.4, 0.6);

/// A wall quad from `origin` along `eu`, `ev`, split at height `DADO` into paint and plaster
/// (`ev` must be vertical, starting at the floor).
fn wall(o: &mut Object, origin: Vec3, eu: Vec3, height: f32, flip: bool) {
    let lower = quad(origin, eu, Vec3::Y * DADO, Vec2::ZERO, 1.0);
    let upper = quad(origin + Vec3::Y * DADO, eu, Vec3::Y * (height - DADO), Vec2::ZERO, 1.0);
    let f = |m: Mesh| if flip { m.flipped() } else { m };
    o.add(Mat::WallPaint, f(lower));
    o.add(Mat::Plaster, f(upper));
}

pub fn room() -> Object {
    let mut o = Object::new("room");
    let (x0, x1) = ROOM_X;
    let (z0, z1) = ROOM_Z;
    let h = ROOM_HEIGHT;
    let (dx, dz) = (x1 - x0, z1 - z0);
    let per = 1.0 / FLOOR_TEXTURE_METRES;
    // The floor faces +y with u along +x and v along +z, so its tangent is +x with w = +1
    // (the bitangent N × T = −z points to decreasing v, up the texture image).
    let floor = quad(Vec3::new(x0, 0.0, z0), Vec3::X * dx, Vec3::Z * dz, Vec2::ZERO, per).flipped();
    o.add(Mat::FloorTiles, floor.with_tangent(Vec4::new(1.0, 0.0, 0.0, 1.0)));
    o.add(Mat::Ceiling, quad(Vec3::new(x0, h, z0), Vec3::X * dx, Vec3::Z * dz, Vec2::ZERO, 1.0));
    wall(&mut o, Vec3::new(x0, 0.0, z1), Vec3::X * dx, h, true); // back (behind the counter), faces −z
    wall(&mut o, Vec3::new(x0, 0.0, z0), Vec3::X * dx, h, false); // front, faces +z
    wall(&mut o, Vec3::new(x0, 0.0, z0), Vec3::Z * dz, h, true); // left, faces +x
    // The right wall (faces −x) around the window opening.
    let (w0, w1) = WINDOW_Z;
    let (wy0, wy1) = WINDOW_Y;
    let right = |z: f32, y: f32| Vec3::new(x1, y, z);
    o.add(Mat::WallPaint, quad(right(z0, 0.0), Vec3::Z * dz, Vec3::Y * DADO, Vec2::ZERO, 1.0));
    o.add(Mat::Plaster, quad(right(z0, wy1), Vec3::Z * dz, Vec3::Y * (h - wy1), Vec2::ZERO, 1.0));
    o.add(Mat::Plaster, quad(right(z0, DADO), Vec3::Z * (w0 - z0), Vec3::Y * (wy1 - DADO), Vec2::ZERO, 1.0));
    o.add(Mat::Plaster, quad(right(w1, DADO), Vec3::Z * (z1 - w1), Vec3::Y * (wy1 - DADO), Vec2::ZERO, 1.0));
    // The opening's reveals.
    let t = Vec3::X * WALL_THICKNESS;
    o.add(Mat::Plaster, quad(right(w0, wy0), t, Vec3::Z * (w1 - w0), Vec2::ZERO, 1.0).flipped());
    o.add(Mat::Plaster, quad(right(w0, wy1), t, Vec3::Z * (w1 - w0), Vec2::ZERO, 1.0));
    o.add(Mat::Plaster, quad(right(w0, wy0), t, Vec3::Y * (wy1 - wy0), Vec2::ZERO, 1.0));
    o.add(Mat::Plaster, quad(right(w1, wy0), t, Vec3::Y * (wy1 - wy0), Vec2::ZERO, 1.0).flipped());
    // Dado rails, interrupted by the window sill.
    let rail = |a: Vec3, b: Vec3| {
        cuboid(a.min(b) + Vec3::new(0.0, DADO - 0.02, 0.0), a.max(b) + Vec3::new(0.0, DADO + 0.02, 0.0), 1.0)
    };
    o.add(Mat::WoodDark, rail(Vec3::new(x0, 0.0, z1 - 0.025), Vec3::new(x1, 0.0, z1)));
    o.add(Mat::WoodDark, rail(Vec3::new(x0, 0.0, z0), Vec3::new(x1, 0.0, z0 + 0.025)));
    o.add(Mat::WoodDark, rail(Vec3::new(x0, 0.0, z0), Vec3::new(x0 + 0.025, 0.0, z1)));
    o.add(Mat::WoodDark, rail(Vec3::new(x1 - 0.025, 0.0, z0), Vec3::new(x1, 0.0, w0 - 0.1)));
    o.add(Mat::WoodDark, rail(Vec3::new(x1 - 0.025, 0.0, w1 + 0.1), Vec3::new(x1, 0.0, z1)));
    o
}

/// The window: painted frame with a mullion and a transom, an inner sill, the pavement outside
/// and the emissive sky quad facing into the room.
pub fn window() -> Object {
    let mut o = Object::new("window");
    let x1 = ROOM_X.1;
    let (w0, w1) = WINDOW_Z;
    let (wy0, wy1) = WINDOW_Y;
    let (fa, fb) = (x1 + 0.06, x1 + 0.12);
    let bar = 0.06;
    let zm = 0.5 * (w0 + w1);
    let frame = [
        (Vec3::new(fa, wy0, w0), Vec3::new(fb, wy0 + bar, w1)),
        (Vec3::new(fa, wy1 - bar, w0), Vec3::new(fb, wy1, w1)),
        (Vec3::new(fa, wy0, w0), Vec3::new(fb, wy1, w0 + bar)),
        (Vec3::new(fa, wy0, w1 - bar), Vec3::new(fb, wy1, w1)),
        (Vec3::new(fa, wy0, zm - bar / 2.0), Vec3::new(fb, wy1, zm + bar / 2.0)),
        (Vec3::new(fa, 2.08, w0), Vec3::new(fb, 2.08 + bar * 0.8, w1)),
    ];
    for (lo, hi) in frame {
        o.add(Mat::WindowFrame, cuboid(lo, hi, 1.0));
    }
    o.add(
        Mat::WindowFrame,
        cuboid(Vec3::new(x1 - 0.1, wy0 - 0.03, w0 - 0.08), Vec3::new(fa, wy0 + 0.012, w1 + 0.08), 1.0),
    );
    let out = x1 + WALL_THICKNESS;
    let sky_x = x1 + 0.8;
    o.add(
        Mat::Pavement,
        quad(
            Vec3::new(out, 0.0, w0 - 2.0),
            Vec3::X * (sky_x - out),
            Vec3::Z * (w1 - w0 + 4.0),
            Vec2::ZERO,
            1.0,
        )
        .flipped(),
    );
    // The sky faces −x (into the room): emissive, one-sided.
    let (sz0, sz1, sy0, sy1) = (w0 - 2.0, w1 + 2.0, 0.0, wy1 + 1.5);
    o.add(
        Mat::Sky,
        quad(Vec3::new(sky_x, sy0, sz0), Vec3::Z * (sz1 - sz0), Vec3::Y * (sy1 - sy0), Vec2::ZERO, 1.0),
    );
    o
}

/// The emissive ceiling panel (facing down, one-sided) in a thin black frame.
pub fn ceiling_panel() -> Object {
    let mut o = Object::new("ceiling_panel");
    let y = ROOM_HEIGHT - 0.015;
    let lo = PANEL_CENTER - PANEL_SIZE / 2.0;
    let panel =
        quad(Vec3::new(lo.x, y, lo.y), Vec3::X * PANEL_SIZE.x, Vec3::Z * PANEL_SIZE.y, Vec2::ZERO, 1.0);
    debug_assert!(panel.normals[0].y < 0.0);
    o.add(Mat::LampPanel, panel);
    let (hi, w) = (PANEL_CENTER + PANEL_SIZE / 2.0, 0.03);
    let bars = [
        (Vec2::new(lo.x - w, lo.y - w), Vec2::new(hi.x + w, lo.y)),
        (Vec2::new(lo.x - w, hi.y), Vec2::new(hi.x + w, hi.y + w)),
        (Vec2::new(lo.x - w, lo.y), Vec2::new(lo.x, hi.y)),
        (Vec2::new(hi.x, lo.y), Vec2::new(hi.x + w, hi.y)),
    ];
    for (a, b) in bars {
        o.add(Mat::BlackMetal, cuboid(Vec3::new(a.x, y - 0.01, a.y), Vec3::new(b.x, ROOM_HEIGHT, b.y), 1.0));
    }
    o
}

/// The pendant lamp over the table (group coordinates): an enamel shade, open below, on a cord
/// from the ceiling. The spot light sits inside the shade, clear of it.
pub fn pendant() -> Object {
    let mut o = Object::new("pendant");
    let (y0, top) = (f64::from(PENDANT_SHADE_Y), f64::from(SPOT_POSITION.y) + 0.08);
    let shell = 0.004;
    // The outer surface (t = 0 at the top, 1 at the rim) and its outward normal; the inner
    // surface is the outer one moved a shell's thickness inwards along it.
    let outer = move |t: f64| DVec2::new(0.03 + 0.19 * t.powf(1.6), top - (top - y0) * t);
    let normal = move |t: f64| DVec2::new(top - y0, 0.304 * t.powf(0.6)).normalize();
    let inner = move |t: f64| outer(t) - normal(t) * shell;
    let rim = outer(1.0) - normal(1.0) * (shell / 2.0);
    let rim_angle = normal(1.0).y.atan2(normal(1.0).x);
    let steps = |from: u32, to: u32| -> Vec<f64> {
        if from <= to {
            (from..=to).map(|k| f64::from(k) / 20.0).collect()
        } else {
            (to..=from).rev().map(|k| f64::from(k) / 20.0).collect()
        }
    };
    // Walked with the shell on the left: the cavity's roof, down the inside, round the rim,
    // up the outside, the neck and its top.
    let p = Profile::start(0.0, top)
        .points(steps(0, 20).into_iter().map(|t| inner(t).into()))
        .arc(rim.x, rim.y, shell / 2.0, rim_angle - std::f64::consts::PI, rim_angle, 6)
        .points(steps(19, 0).into_iter().map(|t| outer(t).into()))
        .crease()
        .line(0.03, top + 0.03, 2)
        .crease()
        .line(0.0, top + 0.03, 2);
    o.add(Mat::Enamel, lathe(&p, Vec3::ZERO, 64, 1.0));
    o.add(
        Mat::BlackMetal,
        tube(Vec3::Y * (top as f32 + 0.02), Vec3::Y * ROOM_HEIGHT, 0.005, 0.005, 12, 4, 1.0),
    );
    o
}

/// A framed cubist painting on the left wall (x = ROOM_X.0), facing +x.
pub fn painting() -> Object {
    let mut o = Object::new("painting");
    let x = ROOM_X.0 + 0.02;
    let (zc, yc, w, h) = (1.3f32, 1.75f32, 1.0f32, 0.8f32);
    // Seen from +x, image right is −z: u runs along −z, v down.
    let mut canvas =
        quad(Vec3::new(x, yc + h / 2.0, zc + w / 2.0), Vec3::NEG_Z * w, Vec3::NEG_Y * h, Vec2::ZERO, 1.0)
            .flipped();
    for uv in &mut canvas.uvs {
        *uv /= Vec2::new(w, h);
    }
    debug_assert!(canvas.normals[0].x > 0.0);
    o.add(Mat::Painting, canvas);
    let (b, d) = (0.06, 0.035);
    let (z0, z1, y0, y1) = (zc - w / 2.0, zc + w / 2.0, yc - h / 2.0, yc + h / 2.0);
    let x0 = ROOM_X.0;
    for (lo, hi) in [
        (Vec3::new(x0, y0 - b, z0 - b), Vec3::new(x0 + d, y0, z1 + b)),
        (Vec3::new(x0, y1, z0 - b), Vec3::new(x0 + d, y1 + b, z1 + b)),
        (Vec3::new(x0, y0, z0 - b), Vec3::new(x0 + d, y1, z0)),
        (Vec3::new(x0, y0, z1), Vec3::new(x0 + d, y1, z1 + b)),
    ] {
        o.add(Mat::Gilt, cuboid(lo, hi, 1.0));
    }
    o
}
