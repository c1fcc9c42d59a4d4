//! LuxRender 1.x's FresnelBlend (Ashikhmin and Shirley's BRDF, pbrt's substrate): the lobe of
//! the `glossy_lossy` material and of the names it kept for older exports, `substrate` and
//! `plastic`. A diffuse term that fades as the glossy one's Fresnel grows, so that together
//! they lose little energy at any angle, with an optional absorbing layer on the diffuse part:
//!
//! - diffuse: 28 / (23 pi) Rd (1 - Rs) (1 - (1 - cos_i / 2)^5) (1 - (1 - cos_o / 2)^5), times
//!   exp(-Ka d (1 / cos_i + 1 / cos_o)) where the depth d is positive;
//! - glossy: D(wh) F(wi . wh) / (4 |wi . wh| max(cos_i, cos_o)), F Schlick's from Rs.
//!
//! D is GGX at alpha = roughness: LuxRender's Schlick distribution of r = u v is GGX at
//! alpha^2 = r for an isotropic roughness (the rule [`super::microfacet`] follows everywhere).
//! Directions are drawn half by the cosine, half from the visible microfacet normals, as
//! LuxRender draws them half by the cosine and half from D.

use std::f32::consts::{FRAC_1_PI, PI};

use glam::{Vec2, Vec3};

use super::fresnel;
use super::local::{reflect, same_hemisphere, sample_cosine_hemisphere};
use super::lobe::Lobe;
use super::microfacet::TrowbridgeReitz;
use super::sample::LocalSample;

#[derive(Clone, Copy, Debug)]
pub struct FresnelBlend {
    /// Diffuse reflectance, in [0, 1].
    pub rd: Vec3,
    /// Normal-incidence specular reflectance, in [0, 1].
    pub rs: Vec3,
    /// Absorption coefficient of the layer over the diffuse part, and its depth.
    pub absorption: Vec3,
    pub depth: f32,
    pub distrib: TrowbridgeReitz,
}

impl FresnelBlend {
    fn diffuse(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        let fade = |c: f32| 1.0 - libm::powf(1.0 - 0.5 * c, 5.0);
        let layer = if self.depth > 0.0 {
            let path = self.depth * (cos_i + cos_o) / (cos_i * cos_o);
            Vec3::new(
                libm::expf(-self.absorption.x * path),
                libm::expf(-self.absorption.y * path),
                libm::expf(-self.absorption.z * path),
            )
        } else {
            Vec3::ONE
        };
        self.rd * (Vec3::ONE - self.rs) * layer * (28.0 / (23.0 * PI) * fade(cos_i) * fade(cos_o))
    }
}

impl Lobe for FresnelBlend {
    const GATHERS_BROADLY: bool = true;

    fn albedo_hint(&self, cos_o: f32) -> Vec3 {
        self.rd * (Vec3::ONE - self.rs) + fresnel::schlick(cos_o, self.rs)
    }

    /// `wo` is in the upper hemisphere (the BSDF mirrors back-face queries).
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        let wh = wo + wi;
        if cos_o == 0.0 || cos_i == 0.0 || wh.length_squared() == 0.0 {
            return Vec3::ZERO;
        }
        let wh = wh.normalize();
        let cos_h = wi.dot(wh).abs();
        let glossy = fresnel::schlick(cos_h, self.rs)
            * (self.distrib.d(wh) / (4.0 * cos_h * cos_i.max(cos_o)));
        self.diffuse(cos_o, cos_i) + glossy
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let wh = wo + wi;
        if wh.length_squared() == 0.0 {
            return 0.0;
        }
        let wh = wh.normalize();
        let glossy = self.distrib.d_visible(wo, wh) / (4.0 * wo.dot(wh).abs());
        0.5 * (wi.z.abs() * FRAC_1_PI + glossy)
    }

    /// `u_lobe` below one half draws by the cosine, else from the visible normals.
    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wi = if u_lobe < 0.5 {
            sample_cosine_hemisphere(u)
        } else {
            reflect(wo, self.distrib.sample_wm(wo, u))
        };
        if !same_hemisphere(wo, wi) {
            return None;
        }
        LocalSample::non_specular(wi, self.f(wo, wi), self.pdf(wo, wi))
    }
}
