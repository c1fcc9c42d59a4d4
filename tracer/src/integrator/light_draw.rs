//! A vertex's light sample: its random numbers, the share of the vertex's light samples its
//! kind gets, and the BSDF samples its weight counts against.

use glam::Vec2;

use super::glossy_split::GLOSSY_SPLIT;
use crate::sampler::VertexSamples;

/// A light sample's random numbers, the share of a vertex's light samples its kind (lights,
/// or lamp images) gets, and the BSDF samples its MIS weight counts against it.
#[derive(Clone, Copy)]
pub(super) struct LightDraw {
    pub(super) share: f32,
    pub(super) u_select: f32,
    pub(super) u: Vec2,
    /// The BSDF samples the vertex weighs its light sample against.
    pub(super) bsdf_counts: BsdfCounts,
}

impl LightDraw {
    pub(super) fn new(share: f32, u_select: f32, u: Vec2) -> Self {
        Self {
            share,
            u_select,
            u,
            bsdf_counts: BsdfCounts::ONE,
        }
    }

    /// A vertex's light sample, all of it for the lights.
    pub(super) fn lights_only(u: &VertexSamples) -> Self {
        Self::new(1.0, u.light_select, u.light)
    }
}

/// The BSDF samples a vertex's light sample is weighed against: 1, the continuations' count at
/// a branching vertex; at a split vertex [`GLOSSY_SPLIT`](super::glossy_split::GLOSSY_SPLIT) for lamps and 1 for environment maps
/// (the split's samples take only the lamps' light; the path's own sample goes on to find the
/// environment's).
#[derive(Clone, Copy, Debug)]
pub(super) struct BsdfCounts {
    pub(super) lamps: f32,
    pub(super) environment: f32,
}

impl BsdfCounts {
    pub(super) const ONE: Self = Self::all(1.0);
    pub(super) const SPLIT: Self = Self {
        lamps: GLOSSY_SPLIT as f32,
        environment: 1.0,
    };

    pub(super) const fn all(count: f32) -> Self {
        Self {
            lamps: count,
            environment: count,
        }
    }

    /// The count for a light sample from a lamp, or from the environment (`at_infinity`: an
    /// environment map, a sky or its sun disc).
    pub(super) fn for_light(&self, at_infinity: bool) -> f32 {
        if at_infinity {
            self.environment
        } else {
            self.lamps
        }
    }
}
