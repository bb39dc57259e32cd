//! Procedural textures: every one seamlessly tileable (periodic noise, integer stripe counts),
//! a pure function of its pixel coordinates, encoded as 8-bit RGB PNG. Base colours are designed
//! in linear RGB and stored sRGB-encoded (glTF's convention for base colour); normal and
//! metallic-roughness maps are stored linear.

use anyhow::Result;
use glam::{Vec2, Vec3};
use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};

/// An 8-bit RGB image.
pub struct Texture {
    pub name: &'static str,
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl Texture {
    /// Fills a `size` × `size` image with `f(x, y)` at pixel centres, (x, y) in [0, 1)², already
    /// encoded to bytes.
    fn new(name: &'static str, size: u32, f: impl Fn(f32, f32) -> [u8; 3]) -> Texture {
        let mut rgb = Vec::with_capacity((size * size * 3) as usize);
        for j in 0..size {
            for i in 0..size {
                let (x, y) = ((i as f32 + 0.5) / size as f32, (j as f32 + 0.5) / size as f32);
                rgb.extend(f(x, y));
            }
        }
        Texture { name, width: size, height: size, rgb }
    }

    /// The PNG file (maximum compression; the encoder is deterministic).
    pub fn png(&self) -> Result<Vec<u8>> {
        encode_png(self.width, self.height, &self.rgb)
    }
}

/// Encodes 8-bit RGB pixels as PNG.
pub fn encode_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Best, FilterType::Adaptive).write_image(
        rgb,
        width,
        height,
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(out)
}

/// Linear [0, 1] → 8-bit sRGB.
pub fn srgb8(c: Vec3) -> [u8; 3] {
    c.to_array().map(|v| {
        let v = v.clamp(0.0, 1.0);
        let s = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0).round() as u8
    })
}

/// Linear [0, 1] → 8-bit linear.
pub fn linear8(c: Vec3) -> [u8; 3] {
    c.to_array().map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// A hash of a lattice point to [0, 1).
pub fn hash(x: i32, y: i32, seed: u32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ seed.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2c1b_3c6d);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297a_2d39);
    h ^= h >> 15;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Value noise in [0, 1] with lattice period (px, py): x in [0, 1) spans px lattice cells.
pub fn noise(x: f32, y: f32, px: i32, py: i32, seed: u32) -> f32 {
    let (sx, sy) = (x * px as f32, y * py as f32);
    let (fx, fy) = (sx.floor(), sy.floor());
    let (tx, ty) = (sx - fx, sy - fy);
    let smooth = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (ux, uy) = (smooth(tx), smooth(ty));
    let (ix, iy) = (fx as i32, fy as i32);
    let h = |dx: i32, dy: i32| hash((ix + dx).rem_euclid(px), (iy + dy).rem_euclid(py), seed);
    let a = h(0, 0) + (h(1, 0) - h(0, 0)) * ux;
    let b = h(0, 1) + (h(1, 1) - h(0, 1)) * ux;
    a + (b - a) * uy
}

/// Fractal sum of `octaves` periodic noises (each doubling the lattice), normalised to [0, 1].
pub fn fbm(x: f32, y: f32, px: i32, py: i32, octaves: u32, seed: u32) -> f32 {
    let (mut sum, mut amp, mut norm) = (0.0, 1.0, 0.0);
    for o in 0..octaves {
        sum += amp * noise(x, y, px << o, py << o, seed.wrapping_add(o * 101));
        norm += amp;
        amp *= 0.5;
    }
    sum / norm
}

fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Wood grain running along u (base colour): warped growth rings and fine fibres.
pub fn wood() -> Texture {
    let light = Vec3::new(0.50, 0.25, 0.105);
    let dark = Vec3::new(0.20, 0.075, 0.028);
    Texture::new("wood", 512, |x, y| {
        // Flat-sawn grain: rings bent into broad arches, with a finer wobble.
        let rings = y * 12.0 + 1.8 * fbm(x, y, 2, 3, 3, 11) + 0.25 * fbm(x, y, 6, 12, 3, 12);
        let t = rings.fract();
        let late = smoothstep(0.72, 0.88, t) * (1.0 - smoothstep(0.93, 1.0, t));
        let fibre = noise(x, y, 8, 256, 13) * 0.6 + noise(x, y, 16, 384, 14) * 0.4;
        let tone = (0.1 + 0.75 * late + 0.4 * (fibre - 0.5)).clamp(0.0, 1.0);
        let c = light.lerp(dark, tone) * (0.9 + 0.2 * fbm(x, y, 2, 4, 3, 15));
        srgb8(c)
    })
}

/// The floor texture spans 2 × 2 tiles; this is the grout's half-width and the bevel, as
/// fractions of a tile.
const GROUT: f32 = 0.012;
const BEVEL: f32 = 0.014;
/// Tile thickness above the grout, metres, and the texture's size on the floor.
const TILE_RELIEF: f32 = 0.0015;
pub const FLOOR_TEXTURE_METRES: f32 = 0.6;

/// (tile index, distance from the tile's nearest edge as a fraction of a tile).
fn tile_at(x: f32, y: f32) -> ((i32, i32), f32) {
    let (sx, sy) = (x * 2.0, y * 2.0);
    let (fx, fy) = (sx.fract(), sy.fract());
    let edge = fx.min(1.0 - fx).min(fy).min(1.0 - fy);
    ((sx.floor() as i32, sy.floor() as i32), edge)
}

/// Tile height in metres (grout at 0), tileable.
fn tile_height(x: f32, y: f32) -> f32 {
    let (_, edge) = tile_at(x.rem_euclid(1.0), y.rem_euclid(1.0));
    let bump = fbm(x.rem_euclid(1.0), y.rem_euclid(1.0), 8, 8, 3, 21) - 0.5;
    TILE_RELIEF * (smoothstep(GROUT, GROUT + BEVEL, edge) + 0.08 * bump)
}

/// Chequered black and cream marble tiles with grey grout (base colour).
pub fn floor_tiles() -> Texture {
    let cream = Vec3::new(0.72, 0.68, 0.60);
    let black = Vec3::new(0.030, 0.030, 0.034);
    let grout = Vec3::new(0.30, 0.29, 0.27);
    Texture::new("floor_tiles", 512, |x, y| {
        let ((ti, tj), edge) = tile_at(x, y);
        if edge < GROUT {
            return srgb8(grout * (0.9 + 0.2 * noise(x, y, 64, 64, 22)));
        }
        let vary = 0.94 + 0.12 * hash(ti, tj, 23);
        let vein = (1.0
            - ((x * 3.0 + y * 2.0 + 2.5 * fbm(x, y, 4, 4, 5, 24)) * std::f32::consts::PI * 2.0).sin().abs())
        .powf(12.0);
        let c = if (ti + tj) % 2 == 0 {
            cream * vary * (1.0 - 0.25 * vein)
        } else {
            black * vary + Vec3::splat(0.05 * vein)
        };
        srgb8(c)
    })
}

/// The tiles' tangent-space normal map (glTF convention: +x along u, +y towards decreasing v,
/// i.e. up the image), from [`tile_height`].
pub fn floor_tiles_normal() -> Texture {
    let size = 512;
    let pixel = FLOOR_TEXTURE_METRES / size as f32;
    let d = 1.0 / size as f32;
    Texture::new("floor_tiles_normal", size, |x, y| {
        let dh_dx = (tile_height(x + d, y) - tile_height(x - d, y)) / (2.0 * pixel);
        let dh_dy = (tile_height(x, y + d) - tile_height(x, y - d)) / (2.0 * pixel);
        // The height rises along +u (x) and +v (y, down the image); tangent-space y is up the
        // image, so its slope has the opposite sign.
        let n = Vec3::new(-dh_dx, dh_dy, 1.0).normalize();
        linear8(n * 0.5 + 0.5)
    })
}

/// Stocking-stitch knit (base colour, near white: the material's factor colours it).
pub fn knit() -> Texture {
    let (cols, rows) = (20.0, 24.0);
    Texture::new("knit", 256, |x, y| {
        let (cx, cy) = ((x * cols).fract(), (y * rows).fract());
        // Each stitch is a V of two slanted legs, columns separated by a groove.
        let leg = |px: f32, slant: f32| {
            let (dx, dy) = (cx - px, cy - 0.5);
            let (a, b) = (dx - slant * dy, dy);
            1.0 - (a / 0.16).powi(2) - (b / 0.6).powi(2)
        };
        let v = leg(0.29, 0.3).max(leg(0.71, -0.3)).max(0.0).sqrt();
        let fuzz = noise(x, y, 128, 128, 31);
        let c = Vec3::splat(0.78) * (0.35 + 0.65 * v) * (0.92 + 0.16 * fuzz);
        srgb8(c)
    })
}

/// A tartan in a 2/2 twill (base colour): burgundy ground, green and navy bands, a gold line.
pub fn plaid() -> Texture {
    let burgundy = Vec3::new(0.30, 0.025, 0.035);
    let green = Vec3::new(0.02, 0.075, 0.035);
    let navy = Vec3::new(0.02, 0.025, 0.09);
    let gold = Vec3::new(0.62, 0.45, 0.12);
    // The sett: (colour, threads), mirrored; 128 threads repeat twice across 256 px.
    let sett = [(burgundy, 24), (navy, 10), (burgundy, 4), (green, 18), (gold, 2), (green, 6)];
    let half: Vec<Vec3> = sett.iter().flat_map(|&(c, n)| std::iter::repeat_n(c, n)).collect();
    let thread: Vec<Vec3> = half.iter().chain(half.iter().rev()).copied().collect();
    let n = thread.len() as f32;
    Texture::new("plaid", 256, move |x, y| {
        let (i, j) = ((x * 2.0 * n) as usize % thread.len(), (y * 2.0 * n) as usize % thread.len());
        let (px, py) = ((x * 256.0) as i32, (y * 256.0) as i32);
        let warp_up = (px + py).rem_euclid(4) < 2;
        let c = if warp_up { thread[i] } else { thread[j] };
        let fibre = 0.9 + 0.2 * noise(x, y, 64, 256, 41);
        srgb8(c * fibre)
    })
}

/// Zinc bar-top metallic-roughness map (linear; G = roughness, B = metalness, R unused = 1):
/// brushed streaks along u and duller oxidised blotches.
pub fn zinc_metallic_roughness() -> Texture {
    Texture::new("zinc_metallic_roughness", 256, |x, y| {
        let streak = noise(x, y, 2, 96, 51) * 0.6 + noise(x, y, 4, 192, 52) * 0.4;
        let blotch = smoothstep(0.55, 0.75, fbm(x, y, 3, 3, 4, 53));
        let roughness = 0.18 + 0.16 * streak + 0.3 * blotch;
        let metallic = 1.0 - 0.3 * blotch;
        linear8(Vec3::new(1.0, roughness, metallic))
    })
}

/// A small cubist painting for the wall (base colour, not tiled): faceted Voronoi planes in an
/// ochre / terracotta / slate palette with dark contours.
pub fn painting() -> Texture {
    let palette = [
        Vec3::new(0.55, 0.33, 0.08),
        Vec3::new(0.45, 0.12, 0.05),
        Vec3::new(0.12, 0.18, 0.28),
        Vec3::new(0.28, 0.30, 0.12),
        Vec3::new(0.75, 0.68, 0.50),
        Vec3::new(0.06, 0.06, 0.07),
        Vec3::new(0.60, 0.45, 0.30),
    ];
    let seeds: Vec<(Vec2, Vec3, Vec2)> = (0..18)
        .map(|k| {
            let p = Vec2::new(hash(k, 1, 61), hash(k, 2, 61));
            let c = palette[(hash(k, 3, 61) * palette.len() as f32) as usize % palette.len()];
            let a = hash(k, 4, 61) * std::f32::consts::TAU;
            (p, c, Vec2::new(a.cos(), a.sin()))
        })
        .collect();
    Texture::new("painting", 256, move |x, y| {
        let p = Vec2::new(x, y);
        let mut best = (f32::MAX, 0usize);
        let mut second = f32::MAX;
        for (k, (s, _, _)) in seeds.iter().enumerate() {
            // An anisotropic metric makes the facets shard-like.
            let d = (p - *s) * Vec2::new(1.0, 0.6);
            let d = d.x.abs().max(d.y.abs()) * 0.6 + d.length() * 0.4;
            if d < best.0 {
                second = best.0;
                best = (d, k);
            } else if d < second {
                second = d;
            }
        }
        let (s, c, g) = seeds[best.1];
        if second - best.0 < 0.006 {
            return srgb8(Vec3::splat(0.03));
        }
        let shade = (0.8 + 1.6 * g.dot(p - s)).clamp(0.45, 1.25);
        let grain = 0.93 + 0.14 * noise(x, y, 64, 64, 62);
        srgb8(c * shade * grain)
    })
}

/// Every texture of the café, in a fixed order.
pub fn all() -> Vec<Texture> {
    vec![wood(), floor_tiles(), floor_tiles_normal(), knit(), plaid(), zinc_metallic_roughness(), painting()]
}
