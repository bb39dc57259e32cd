//! The stack's sheen layer: the lobe the material's reading of `KHR_materials_sheen` chooses
//! ([`SheenModel`]), Cycles' microfibre sheen ([`Sheen`]) for Blender's files or the
//! specification's Charlie sheen ([`Charlie`]) for the others. Both take the same inputs and
//! leave the layers below 1 − their albedo.

use super::charlie::Charlie;
use super::sheen::Sheen;
use crate::material::SheenModel;
use glam::{Vec2, Vec3};

/// One of the two sheen lobes, with wo fixed.
#[derive(Clone, Copy, Debug)]
pub enum SheenLayer {
    /// Cycles' microfibre LTC lobe.
    Cycles(Sheen),
    /// The glTF specification's Charlie lobe.
    Charlie(Charlie),
}

impl SheenLayer {
    /// The `model` sheen of colour `color`, roughness `roughness` on unit normal `n` (either
    /// side), geometric normal `ng` facing wo, seen from `wo` (each lobe's `new`).
    #[inline]
    pub fn new(model: SheenModel, color: Vec3, roughness: f32, n: Vec3, ng: Vec3, wo: Vec3) -> Self {
        match model {
            SheenModel::Cycles => Self::Cycles(Sheen::new(color, roughness, n, ng, wo)),
            SheenModel::Charlie => Self::Charlie(Charlie::new(color, roughness, n, ng, wo)),
        }
    }

    /// The share of light the sheen takes from the layers below for this wo.
    #[inline]
    pub fn albedo(&self) -> f32 {
        match self {
            Self::Cycles(s) => s.albedo(),
            Self::Charlie(s) => s.albedo(),
        }
    }

    /// This lobe with its value scaled by `k` > 0.
    #[inline]
    pub fn scaled(self, k: f32) -> Self {
        match self {
            Self::Cycles(s) => Self::Cycles(s.scaled(k)),
            Self::Charlie(s) => Self::Charlie(s.scaled(k)),
        }
    }

    /// f · cos(sheen normal, wi) / `cos_s` and the density of `wi` (world, unit).
    #[inline]
    pub fn eval(&self, wi: Vec3, cos_s: f32) -> (Vec3, f32) {
        match self {
            Self::Cycles(s) => s.eval(wi, cos_s),
            Self::Charlie(s) => s.eval(wi, cos_s),
        }
    }

    /// A direction sampled from the lobe (world, unit).
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<Vec3> {
        match self {
            Self::Cycles(s) => s.sample(u),
            Self::Charlie(s) => s.sample(u),
        }
    }
}
