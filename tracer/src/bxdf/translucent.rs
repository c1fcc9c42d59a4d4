//! The lobe of mattetranslucent: diffuse reflection plus diffuse transmission, two-sided.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::diffuse::OrenNayar;
use super::local::{cosine_hemisphere_pdf, flip_z, same_hemisphere, sample_cosine_hemisphere};
use super::lobe::Lobe;
use super::sample::LocalSample;

/// mattetranslucent: diffuse reflection `r` on the side of `wo`, diffuse transmission `t` to
/// the other side, each with the same Oren-Nayar roughness.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseTranslucent {
    pub r: Vec3,
    pub t: Vec3,
    pub roughness: OrenNayar,
}

impl DiffuseTranslucent {
    /// Probability of sampling the reflection lobe, by albedo.
    fn reflect_probability(&self) -> f32 {
        let (r, t) = (self.r.element_sum(), self.t.element_sum());
        if r + t > 0.0 {
            r / (r + t)
        } else {
            0.5
        }
    }
}

impl Lobe for DiffuseTranslucent {
    fn albedo_hint(&self, _cos_o: f32) -> Vec3 {
        self.r + self.t
    }

    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wi.z == 0.0 {
            return Vec3::ZERO;
        }
        if same_hemisphere(wo, wi) {
            self.r * (FRAC_1_PI * self.roughness.factor(wo, wi))
        } else {
            self.t * (FRAC_1_PI * self.roughness.factor(wo, flip_z(wi)))
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let p_r = self.reflect_probability();
        let lobe = if same_hemisphere(wo, wi) {
            p_r
        } else {
            1.0 - p_r
        };
        lobe * cosine_hemisphere_pdf(wi.z.abs())
    }

    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        let up = sample_cosine_hemisphere(u);
        let wi = if u_lobe < self.reflect_probability() {
            up
        } else {
            flip_z(up)
        };
        LocalSample::non_specular(wi, self.f(wo, wi), self.pdf(wo, wi))
    }
}
