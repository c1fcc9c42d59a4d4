//! The `scatter` material's lobe: the surface scatters like a particle, into the whole sphere,
//! with Schlick's approximation of the Henyey-Greenstein phase function (LuxRender's
//! SchlickScatter). It is what LuxRender puts on a surface that stands for a volume.
//!
//! f = R phase(wo, wi) / |cos_i|, so that f |cos_i| / pdf = R when wi is drawn from the phase
//! function: the albedo is R from every direction, as a scattering event's is. The asymmetry
//! g is per channel; the phase function and its sampling are the volumes'
//! ([`crate::medium::phase`]).

use glam::{Vec2, Vec3};

use super::lobe::Lobe;
use super::sample::LocalSample;
use crate::medium::phase::Phase;

/// Below this |cos_i| the lobe is zero: f divides by it.
const MIN_COS: f32 = 1e-4;

#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    r: Vec3,
    phase: Phase,
}

impl Scatter {
    /// `r` the albedo, `g` the asymmetry per channel in [-1, 1] (positive scatters forward).
    pub fn new(r: Vec3, g: Vec3) -> Self {
        Self {
            r,
            phase: Phase::new(g),
        }
    }
}

impl Lobe for Scatter {
    fn albedo_hint(&self, _cos_o: f32) -> Vec3 {
        self.r
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let cos_i = wi.z.abs();
        if cos_i < MIN_COS {
            return Vec3::ZERO;
        }
        // The path arrives along -wo and continues along wi.
        self.r * self.phase.eval(wo, wi) / cos_i
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.phase.pdf(wo, wi)
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        let wi = self.phase.sample(wo, u);
        LocalSample::non_specular(wi, self.f(wo, wi), self.pdf(wo, wi))
    }
}
