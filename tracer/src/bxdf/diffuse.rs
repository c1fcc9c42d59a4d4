//! The diffuse lobe of matte: Lambert or Oren-Nayar reflection, two-sided; the Oren-Nayar
//! terms it shares with [`super::translucent`].

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::local::same_hemisphere;
use super::lobe::Lobe;
use super::sample::{cosine_pdf, LocalSample};

/// The Oren-Nayar roughness terms (pbrt's qualitative model); A = 1, B = 0 is Lambert.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrenNayar {
    a: f32,
    b: f32,
}

impl OrenNayar {
    /// `sigma_degrees`: standard deviation of the facet slope angle, clamped to [0, 90].
    pub fn new(sigma_degrees: f32) -> Self {
        let sigma = sigma_degrees.clamp(0.0, 90.0).to_radians();
        let s2 = sigma * sigma;
        Self {
            a: 1.0 - s2 / (2.0 * (s2 + 0.33)),
            b: 0.45 * s2 / (s2 + 0.09),
        }
    }

    /// The factor multiplying R/pi for two directions in the same (upper) hemisphere.
    pub fn factor(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.b == 0.0 {
            return self.a;
        }
        let sin_i = (1.0 - wi.z * wi.z).max(0.0).sqrt();
        let sin_o = (1.0 - wo.z * wo.z).max(0.0).sqrt();
        // cos(phi_i - phi_o) from the projections onto the tangent plane.
        let max_cos = if sin_i > 1e-4 && sin_o > 1e-4 {
            ((wi.x * wo.x + wi.y * wo.y) / (sin_i * sin_o)).max(0.0)
        } else {
            0.0
        };
        let (cos_i, cos_o) = (wi.z.abs(), wo.z.abs());
        let (sin_alpha, tan_beta) = if cos_i > cos_o {
            (sin_o, sin_i / cos_i)
        } else {
            (sin_i, sin_o / cos_o)
        };
        self.a + self.b * max_cos * sin_alpha * tan_beta
    }
}

/// matte: diffuse reflection.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseReflection {
    pub r: Vec3,
    pub roughness: OrenNayar,
}

impl DiffuseReflection {
    /// The lobe's value for every pair of directions it reflects, where that is one value
    /// (Lambert: no Oren-Nayar slope term).
    pub fn lambert_value(&self) -> Option<Vec3> {
        (self.roughness.b == 0.0).then(|| self.r * (FRAC_1_PI * self.roughness.a))
    }
}

impl Lobe for DiffuseReflection {
    const GATHERS_BROADLY: bool = true;

    fn albedo_hint(&self, _cos_o: f32) -> Vec3 {
        self.r
    }

    /// `wo` is in the upper hemisphere (the BSDF mirrors back-face queries).
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        self.r * (FRAC_1_PI * self.roughness.factor(wo, wi))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        cosine_pdf(wo, wi)
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        LocalSample::cosine(wo, u, |wi| self.f(wo, wi))
    }
}
