//! The `scatter` material's lobe: the surface scatters like a particle, into the whole sphere,
//! with Schlick's approximation of the Henyey-Greenstein phase function (LuxRender's
//! SchlickScatter). It is what LuxRender puts on a surface that stands for a volume.
//!
//! f = R phase(wo, wi) / |cos_i|, so that f |cos_i| / pdf = R when wi is drawn from the phase
//! function: the albedo is R from every direction, as a scattering event's is. The asymmetry
//! g is per channel (k = g (1.55 - 0.55 g^2) as LuxRender); sampling uses the channels'
//! mean.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::sample::LocalSample;

/// Below this |cos_i| the lobe is zero: f divides by it.
const MIN_COS: f32 = 1e-4;

#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    r: Vec3,
    /// Schlick's k per channel, and their mean for sampling.
    k: Vec3,
    k_mean: f32,
}

/// Schlick's phase function with parameter k for c = the cosine between the light's travel
/// before and after the event (1 is straight on).
fn schlick_phase(k: f32, c: f32) -> f32 {
    let d = 1.0 - k * c;
    (1.0 - k * k) / (4.0 * PI * d * d)
}

impl Scatter {
    /// `r` the albedo, `g` the asymmetry per channel in [-1, 1] (positive scatters forward).
    pub fn new(r: Vec3, g: Vec3) -> Self {
        // Keeps |k| < 1, where the phase function is finite.
        let g = g.clamp(Vec3::splat(-0.99), Vec3::splat(0.99));
        let k = g * (Vec3::splat(1.55) - 0.55 * g * g);
        Self {
            r,
            k,
            k_mean: k.element_sum() / 3.0,
        }
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let cos_i = wi.z.abs();
        if cos_i < MIN_COS {
            return Vec3::ZERO;
        }
        // The path arrives along -wo and continues along wi.
        let c = (-wo).dot(wi);
        let phase = Vec3::new(
            schlick_phase(self.k.x, c),
            schlick_phase(self.k.y, c),
            schlick_phase(self.k.z, c),
        );
        self.r * phase / cos_i
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        schlick_phase(self.k_mean, (-wo).dot(wi))
    }

    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<LocalSample> {
        let k = self.k_mean;
        // Inverse of the phase function's cumulative distribution in c.
        let c = if k.abs() < 1e-4 {
            2.0 * u.x - 1.0
        } else {
            (2.0 * u.x + k - 1.0) / (2.0 * k * u.x - k + 1.0)
        }
        .clamp(-1.0, 1.0);
        let s = (1.0 - c * c).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let axis = -wo;
        let t1 = axis.any_orthonormal_vector();
        let t2 = axis.cross(t1);
        let wi = (axis * c + (t1 * phi.cos() + t2 * phi.sin()) * s).normalize();
        LocalSample::non_specular(wi, self.f(wo, wi), self.pdf(wo, wi))
    }

    pub fn albedo_hint(&self) -> Vec3 {
        self.r
    }
}
