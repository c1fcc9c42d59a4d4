//! A [`Coat`] over any base lobe: glossy (over Lambert), glossytranslucent (over diffuse
//! reflection and transmission, a coat on each face), carpaint (three flake lobes over Lambert)
//! and glossycoating (over whatever its base material is).
//!
//! - Reflection on the side of wo: the coat's own lobes, plus the base weighted by what the
//!   coat lets in and out, (1 - F(cos_o)) (1 - F(cos_i)), and by the layer's absorption.
//! - Transmission (the base lets light through to the other face): the base weighted by
//!   (1 - F_o(cos_o)) (1 - F_i(cos_i)) with the coat of each face, and one crossing of each
//!   coat's absorption.
//!
//! Both weights are symmetric in the two directions, so the result is reciprocal, and what
//! the base receives is at most 1 - F(cos_o) of what arrives, so the sum stays within 1 for
//! any base. Over a diffuse base (`diffuse_base`) the base term is divided by the coat's
//! average transmission 1 - F_avg (the larger of the two faces' for transmission), so that the
//! base reflects Kd (1 - F(cos_o)) in all, as LuxRender's Glossy2 does at normal incidence.
//! LuxRender weights the base by 1 - F at the half vector instead, which brightens grazing
//! views beyond what the surface receives (albedo up to about 1.5).
//!
//! Unlike LuxRender, whose coat vanishes on back faces, glossy and glossycoating put the same
//! coat on both faces, so meshes with inconsistent winding do not show matte patches;
//! glossytranslucent's `backface_*` parameters give the back face its own.

use glam::{Vec2, Vec3};

use super::coat::{Coat, CoatSample};
use super::local::{flip_z, same_hemisphere};
use super::sample::LocalSample;
use super::Bxdf;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coating {
    /// The coat on the face the shading normal points out of, and on the other face.
    pub front: Coat,
    pub back: Coat,
    /// The base is diffuse: normalise its share (see the module notes).
    pub diffuse_base: bool,
}

/// Mirrors a lower-hemisphere direction to the upper one.
fn up(w: Vec3) -> Vec3 {
    if w.z < 0.0 {
        flip_z(w)
    } else {
        w
    }
}

/// a / b per channel, 0 where b vanishes.
fn safe_div(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::select(b.cmpgt(Vec3::splat(1e-6)), a / b, Vec3::ZERO)
}

impl Coating {
    /// The same coat on both faces.
    pub fn two_sided(coat: Coat, diffuse_base: bool) -> Self {
        Self {
            front: coat,
            back: coat,
            diffuse_base,
        }
    }

    fn coat(&self, w: Vec3) -> &Coat {
        if w.z >= 0.0 {
            &self.front
        } else {
            &self.back
        }
    }

    pub fn is_specular(&self, base: &Bxdf) -> bool {
        base.is_specular() && self.front.is_smooth() && self.back.is_smooth()
    }

    /// What multiplies the base's f for the pair (wo, wi).
    fn base_weight(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        if cos_o == 0.0 || cos_i == 0.0 {
            return Vec3::ZERO;
        }
        let (coat_o, coat_i) = (self.coat(wo), self.coat(wi));
        let passed = (Vec3::ONE - coat_o.fresnel(cos_o)) * (Vec3::ONE - coat_i.fresnel(cos_i));
        if same_hemisphere(wo, wi) {
            let w = passed * coat_o.absorption(cos_o, cos_i);
            if self.diffuse_base {
                safe_div(w, Vec3::ONE - coat_o.average_fresnel())
            } else {
                w
            }
        } else {
            let w = passed * coat_o.absorption_once(cos_o) * coat_i.absorption_once(cos_i);
            if self.diffuse_base {
                let t_avg = (Vec3::ONE - coat_o.average_fresnel())
                    .max(Vec3::ONE - coat_i.average_fresnel());
                safe_div(w, t_avg)
            } else {
                w
            }
        }
    }

    /// Probability of sampling the coat rather than the base, by each one's approximate
    /// albedo seen from `wo`.
    fn coat_probability(&self, base: &Bxdf, wo: Vec3) -> f32 {
        let cos_o = wo.z.abs();
        let coat = self.coat(wo);
        let f = coat.fresnel(cos_o);
        let to_coat = f.element_sum();
        let to_base =
            (base.albedo_hint(cos_o) * (Vec3::ONE - f) * coat.absorption(cos_o, 1.0)).element_sum();
        if to_coat + to_base > 0.0 {
            to_coat / (to_coat + to_base)
        } else {
            0.0
        }
    }

    pub fn f(&self, base: &Bxdf, wo: Vec3, wi: Vec3) -> Vec3 {
        let mut f = self.base_weight(wo, wi) * base.f(wo, wi);
        if same_hemisphere(wo, wi) {
            f += self.coat(wo).f(up(wo), up(wi));
        }
        f
    }

    pub fn pdf(&self, base: &Bxdf, wo: Vec3, wi: Vec3) -> f32 {
        let p_coat = self.coat_probability(base, wo);
        let coat = if same_hemisphere(wo, wi) {
            self.coat(wo).pdf(up(wo), up(wi))
        } else {
            0.0
        };
        p_coat * coat + (1.0 - p_coat) * base.pdf(wo, wi)
    }

    pub fn sample(&self, base: &Bxdf, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let p_coat = self.coat_probability(base, wo);
        if u_lobe < p_coat {
            let wi = match self.coat(wo).sample(up(wo), u_lobe / p_coat, u)? {
                // A microfacet reflection that goes below the surface is lost (the coat's
                // density counts it only above).
                CoatSample::Glossy(wi) if wi.z <= 0.0 => return None,
                CoatSample::Glossy(wi) => wi,
                CoatSample::Specular { wi, f, probability } => {
                    let wi = if wo.z < 0.0 { flip_z(wi) } else { wi };
                    return LocalSample::specular(wi, f, p_coat * probability);
                }
            };
            let wi = if wo.z < 0.0 { flip_z(wi) } else { wi };
            return LocalSample::non_specular(wi, self.f(base, wo, wi), self.pdf(base, wo, wi));
        }
        let u_base = ((u_lobe - p_coat) / (1.0 - p_coat)).clamp(0.0, 1.0 - f32::EPSILON);
        let s = base.sample(wo, u_base, u)?;
        if s.specular {
            let f = self.base_weight(wo, s.wi) * s.f;
            return LocalSample::specular(s.wi, f, (1.0 - p_coat) * s.pdf);
        }
        LocalSample::non_specular(s.wi, self.f(base, wo, s.wi), self.pdf(base, wo, s.wi))
    }
}
