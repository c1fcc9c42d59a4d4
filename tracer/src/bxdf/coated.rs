//! LuxRender's Glossy2: a diffuse base under a glossy coat.
//!
//! - Coat: GGX microfacet reflection with Schlick's Fresnel, R0 = Ks (a specular reflection
//!   when the roughness is zero).
//! - Base: Lambert Kd, shaped by the light the coat reflects on the way in and on the way out,
//!   (1 - F(cos_i)) (1 - F(cos_o)) / (1 - F_avg), so that it reflects Kd (1 - F(cos_o)) in all,
//!   and attenuated by absorption in the coat, exp(-Ka d (1/cos_i + 1/cos_o)) (LuxRender's
//!   CoatingAbsorption). LuxRender weights the base by 1 - F at the half vector instead, which
//!   brightens grazing views beyond what the surface receives (albedo up to about 1.5); this
//!   form matches it at normal incidence, stays reciprocal and keeps the sum within 1.
//! - multibounce: the energy the coat's masking and shadowing remove is returned as a diffuse
//!   lobe coloured by the coat's average Fresnel (Kulla and Conty 2017), where LuxRender adds
//!   an ad-hoc (1 - G) term.
//!
//! Unlike LuxRender, whose coat vanishes on back faces, the coat is two-sided, so meshes with
//! inconsistent winding do not show matte patches.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::fresnel;
use super::ggx_albedo;
use super::local::{cosine_hemisphere_pdf, reflect, same_hemisphere, sample_cosine_hemisphere};
use super::microfacet::TrowbridgeReitz;
use super::sample::LocalSample;

/// Cosine-weighted hemispherical average of Schlick's Fresnel: 2 * integral F(mu) mu dmu.
fn schlick_average(r0: Vec3) -> Vec3 {
    r0 + (Vec3::ONE - r0) / 21.0
}

#[derive(Clone, Copy, Debug)]
pub struct Coated {
    pub kd: Vec3,
    /// The coat's normal-incidence reflectance.
    pub ks: Vec3,
    /// Absorption coefficient of the coat and its thickness.
    pub ka: Vec3,
    pub depth: f32,
    /// None: a smooth, specular coat.
    pub distrib: Option<TrowbridgeReitz>,
    /// Isotropic roughness for the multibounce term; None when multibounce is off.
    pub multibounce_alpha: Option<f32>,
}

impl Coated {
    fn absorption(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        if self.depth > 0.0 && self.ka != Vec3::ZERO {
            let path = self.depth * (cos_i + cos_o) / (cos_i * cos_o);
            (-self.ka * path).exp()
        } else {
            Vec3::ONE
        }
    }

    /// Probability of sampling the coat, by each lobe's approximate albedo seen from `wo`.
    fn coat_probability(&self, cos_o: f32) -> f32 {
        let f = fresnel::schlick(cos_o, self.ks);
        let coat = f.element_sum();
        let base = (self.kd * (Vec3::ONE - f) * self.absorption(cos_o, 1.0)).element_sum();
        if coat + base > 0.0 {
            coat / (coat + base)
        } else {
            0.0
        }
    }

    fn base_f(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        let in_out = (Vec3::ONE - fresnel::schlick(cos_o, self.ks))
            * (Vec3::ONE - fresnel::schlick(cos_i, self.ks));
        // Dividing by the hemispherical average of 1 - F makes the base reflect Kd (1 - F(cos_o))
        // in all: the coat takes its share once, as in LuxRender, not once on each crossing.
        let transmitted_avg = Vec3::ONE - schlick_average(self.ks);
        let normalised = Vec3::select(
            transmitted_avg.cmpgt(Vec3::splat(1e-6)),
            in_out / transmitted_avg,
            Vec3::ZERO,
        );
        self.kd * normalised * self.absorption(cos_o, cos_i) * FRAC_1_PI
    }

    fn multibounce_f(&self, alpha: f32, cos_o: f32, cos_i: f32) -> Vec3 {
        let e_avg = ggx_albedo::average_albedo(alpha);
        if e_avg >= 1.0 {
            return Vec3::ZERO;
        }
        let lost =
            (1.0 - ggx_albedo::albedo(alpha, cos_o)) * (1.0 - ggx_albedo::albedo(alpha, cos_i));
        // Average Schlick reflectance over the hemisphere, and the colour after many bounces.
        let f_avg = schlick_average(self.ks);
        let f_ms = f_avg * f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg));
        f_ms * (lost * FRAC_1_PI / (1.0 - e_avg))
    }

    /// `wo` is in the upper hemisphere (the BSDF mirrors back-face queries).
    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        let mut f = self.base_f(cos_o, cos_i);
        if let Some(distrib) = self.distrib {
            let wm = (wo + wi).normalize();
            let s = fresnel::schlick(wo.dot(wm), self.ks);
            f += s * (distrib.d(wm) * distrib.g(wo, wi) / (4.0 * cos_o * cos_i));
        }
        if let Some(alpha) = self.multibounce_alpha {
            f += self.multibounce_f(alpha, cos_o, cos_i);
        }
        f
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let p_coat = self.coat_probability(wo.z.abs());
        let coat = match self.distrib {
            Some(distrib) => {
                let wm = (wo + wi).normalize();
                distrib.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs())
            }
            None => 0.0,
        };
        p_coat * coat + (1.0 - p_coat) * cosine_hemisphere_pdf(wi.z.abs())
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let p_coat = self.coat_probability(wo.z);
        let wi = if u_lobe < p_coat {
            let Some(distrib) = self.distrib else {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                let f = fresnel::schlick(wo.z, self.ks) / wi.z;
                return LocalSample::specular(wi, f, p_coat);
            };
            reflect(wo, distrib.sample_wm(wo, u))
        } else {
            sample_cosine_hemisphere(u)
        };
        LocalSample::non_specular(wi, self.f(wo, wi), self.pdf(wo, wi))
    }
}
