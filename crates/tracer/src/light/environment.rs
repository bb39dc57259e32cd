//! An environment image as a light (pbrt-v4 §12.5.2 `ImageInfiniteLight`): radiance looked up
//! per direction, and directions sampled in proportion to luminance × sin θ through a marginal
//! (rows) and conditional (columns) distribution, so bright skies and suns are found by light
//! sampling instead of by luck.
//!
//! Radiance is piecewise constant per texel, the same pieces the sampling uses, so the density
//! is exact; every texel keeps a small floor weight so no direction with radiance has zero
//! density.

use super::Distribution;
use crate::scene::EnvironmentMap;
use glam::{Quat, Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// An importance-sampled equirectangular environment.
#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    width: u32,
    height: u32,
    /// Radiance per texel (strength applied), row-major from the top.
    radiance: Vec<Vec3>,
    rows: Distribution,
    columns: Vec<Distribution>,
    /// World → map rotation (the inverse of the map's rotation about +Y).
    map_from_world: Quat,
    /// Average luminance over the sphere (for choosing among lights).
    mean_luminance: f64,
}

/// A sampled direction towards the environment.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentSample {
    /// Unit direction, world space.
    pub wi: Vec3,
    /// Radiance arriving from it.
    pub radiance: Vec3,
    /// Solid-angle density.
    pub pdf: f32,
}

impl EnvironmentLight {
    /// Prepares `map` (None if it is empty or black everywhere).
    pub fn new(map: &EnvironmentMap) -> Option<Self> {
        let (w, h) = (map.texture.width, map.texture.height);
        if w == 0 || h == 0 {
            return None;
        }
        let radiance: Vec<Vec3> = map.texture.texels.iter().map(|t| t.truncate() * map.strength).collect();
        let lum: Vec<f64> = radiance.iter().map(|c| super::luminance(c.max(Vec3::ZERO)) as f64).collect();
        let total: f64 = lum.iter().sum();
        if !(total > 0.0) || !total.is_finite() {
            return None;
        }
        let floor = 1e-3 * total / lum.len() as f64;
        let mut row_weights = Vec::with_capacity(h as usize);
        let mut columns = Vec::with_capacity(h as usize);
        let mut mean = 0.0;
        for y in 0..h as usize {
            let sin_theta = ((y as f64 + 0.5) / h as f64 * std::f64::consts::PI).sin();
            let row = &lum[y * w as usize..(y + 1) * w as usize];
            let weights: Vec<f64> = row.iter().map(|l| (l + floor) * sin_theta).collect();
            row_weights.push(weights.iter().sum());
            mean += row.iter().sum::<f64>() * sin_theta;
            columns.push(Distribution::new(&weights)?);
        }
        // ∫ L dω / 4π with dω = (2π/w)(π/h) sin θ per texel.
        let mean_luminance =
            mean * (TAU as f64 / w as f64) * (PI as f64 / h as f64) / (4.0 * std::f64::consts::PI);
        Some(Self {
            width: w,
            height: h,
            radiance,
            rows: Distribution::new(&row_weights)?,
            columns,
            map_from_world: Quat::from_rotation_y(-map.rotation),
            mean_luminance,
        })
    }

    /// Emitted power for choosing among lights: the flux through a disk of `radius` (the scene's
    /// bounding sphere) from every direction.
    pub fn power(&self, radius: f32) -> f64 {
        4.0 * std::f64::consts::PI * std::f64::consts::PI * (radius as f64).powi(2) * self.mean_luminance
    }

    /// Texel column and row seen along world direction `w`.
    #[inline]
    fn texel(&self, w: Vec3) -> (usize, usize) {
        let d = self.map_from_world * w;
        let s = 0.5 + d.x.atan2(-d.z) / TAU;
        let t = d.y.clamp(-1.0, 1.0).acos() / PI;
        let x = ((s * self.width as f32) as usize).min(self.width as usize - 1);
        let y = ((t * self.height as f32) as usize).min(self.height as usize - 1);
        (x, y)
    }

    /// Radiance arriving from world direction `w` (unit).
    #[inline]
    pub fn radiance(&self, w: Vec3) -> Vec3 {
        let (x, y) = self.texel(w);
        self.radiance[y * self.width as usize + x]
    }

    /// Solid-angle density of [`EnvironmentLight::sample`] producing `w`.
    #[inline]
    pub fn pdf(&self, w: Vec3) -> f32 {
        let (x, y) = self.texel(w);
        let sin_theta = ((y as f32 + 0.5) / self.height as f32 * PI).sin();
        self.texel_pdf(x, y) / (2.0 * PI * PI * sin_theta)
    }

    #[inline]
    fn texel_pdf(&self, x: usize, y: usize) -> f32 {
        self.rows.pmf(y) * self.columns[y].pmf(x) * (self.width * self.height) as f32
    }

    /// A direction chosen in proportion to radiance × sin θ.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<EnvironmentSample> {
        let (y, _, v) = self.rows.sample(u.y);
        let (x, _, uu) = self.columns[y].sample(u.x);
        let s = (x as f32 + uu) / self.width as f32;
        let t = (y as f32 + v) / self.height as f32;
        let (phi, theta) = ((s - 0.5) * TAU, t * PI);
        let (sin_p, cos_p) = phi.sin_cos();
        let (sin_t, cos_t) = theta.sin_cos();
        let d = Vec3::new(sin_p * sin_t, cos_t, -cos_p * sin_t);
        let wi = (self.map_from_world.inverse() * d).normalize();
        // Report the density and radiance of the texel the direction lands in after the
        // rotation round trip (at a texel edge it can be the neighbour), so sample(), pdf()
        // and radiance() always agree.
        let pdf = self.pdf(wi);
        (pdf > 0.0 && pdf.is_finite()).then(|| EnvironmentSample { wi, radiance: self.radiance(wi), pdf })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Texture;
    use glam::Vec4;

    fn map(w: u32, h: u32, f: impl Fn(u32, u32) -> f32, rotation: f32) -> EnvironmentMap {
        let texels =
            (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| Vec4::splat(f(x, y))).collect();
        EnvironmentMap { texture: Texture::new("env", w, h, texels), rotation, strength: 2.0 }
    }

    /// ∫ L dω estimated by importance sampling equals the texel sum, and pdf() agrees with
    /// the density sample() reports.
    #[test]
    fn sampling_is_consistent() {
        let m = map(
            64,
            32,
            |x, y| if (20..24).contains(&x) && (5..8).contains(&y) { 50.0 } else { 0.1 + x as f32 * 0.01 },
            0.7,
        );
        let env = EnvironmentLight::new(&m).unwrap();
        // Reference: Σ L · dω per texel.
        let mut want = 0.0f64;
        for y in 0..32 {
            let sin = ((y as f64 + 0.5) / 32.0 * std::f64::consts::PI).sin();
            for x in 0..64 {
                let l = env.radiance[y * 64 + x].x as f64;
                want += l * sin * (TAU as f64 / 64.0) * (PI as f64 / 32.0);
            }
        }
        let n = 1 << 16;
        let mut est = 0.0f64;
        for i in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, ((i as u64 * 7919) % n as u64) as f32 / n as f32);
            let s = env.sample(u).unwrap();
            assert!((env.pdf(s.wi) - s.pdf).abs() <= 1e-3 * s.pdf, "{} vs {}", env.pdf(s.wi), s.pdf);
            assert_eq!(env.radiance(s.wi), s.radiance);
            est += s.radiance.x as f64 / s.pdf as f64;
        }
        est /= n as f64;
        assert!((est - want).abs() < 0.01 * want, "{est} vs {want}");
    }

    /// The rotation turns the map about +Y: the bright texel's direction rotates with it.
    #[test]
    fn rotation_turns_the_map() {
        let bright = |x: u32, y: u32| if x == 48 && y == 8 { 100.0 } else { 0.0 };
        let a = EnvironmentLight::new(&map(64, 16, bright, 0.0)).unwrap();
        let b = EnvironmentLight::new(&map(64, 16, bright, 1.0)).unwrap();
        let wa = a.sample(Vec2::splat(0.5)).unwrap().wi;
        let wb = b.sample(Vec2::splat(0.5)).unwrap().wi;
        assert!((Quat::from_rotation_y(1.0) * wa - wb).length() < 1e-4);
    }
}
