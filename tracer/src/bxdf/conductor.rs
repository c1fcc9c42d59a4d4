//! Metals (metal, metal2, mirror): a specular or microfacet conductor.

use glam::{Vec2, Vec3};

use super::fresnel;
use super::local::{reflect, same_hemisphere};
use super::microfacet::TrowbridgeReitz;
use super::lobe::Lobe;
use super::sample::LocalSample;
use super::thin_film::ThinFilm;

/// The widest microfacet alpha [`Lobe::glossy_spread`] counts as glossy. A wider lobe sees a
/// lamp as light sampling does, and more BSDF samples add little (bench/RESULTS.md, "Figures
/// moved out of the code").
pub const GLOSSY_ALPHA: f32 = 0.1;

/// Where a conductor's reflectance comes from.
#[derive(Clone, Copy, Debug)]
pub enum ConductorFresnel {
    /// Exact Fresnel of the complex index eta + i k per channel.
    Complex { eta: Vec3, k: Vec3 },
    /// Schlick's approximation from the normal-incidence colour.
    Schlick { r0: Vec3 },
    /// A constant tint with no angular dependence (the `mirror` material's Kr).
    Constant(Vec3),
}

impl ConductorFresnel {
    fn eval(&self, cos_i: f32) -> Vec3 {
        match *self {
            ConductorFresnel::Complex { eta, k } => fresnel::conductor(cos_i.abs(), eta, k),
            ConductorFresnel::Schlick { r0 } => fresnel::schlick(cos_i, r0),
            ConductorFresnel::Constant(r) => r,
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub struct Conductor {
    pub fresnel: ConductorFresnel,
    /// None: a perfect mirror.
    pub distrib: Option<TrowbridgeReitz>,
    /// Interference on the perfect mirror's reflection (LuxRender has none on rough metals).
    pub film: Option<ThinFilm>,
}

impl Conductor {
    /// The reflectance at `cos`.
    pub fn fresnel_at(&self, cos: f32) -> Vec3 {
        self.fresnel.eval(cos)
    }
}

impl Lobe for Conductor {
    fn glossy_spread(&self) -> Option<f32> {
        match self.distrib {
            Some(d) if d.max_alpha() < GLOSSY_ALPHA => Some(d.reflection_spread()),
            _ => None,
        }
    }

    fn albedo_hint(&self, cos_o: f32) -> Vec3 {
        self.fresnel_at(cos_o)
    }

    fn is_specular(&self) -> bool {
        self.distrib.is_none()
    }

    /// `wo` is in the upper hemisphere (the BSDF mirrors back-face queries).
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(distrib) = self.distrib else {
            return Vec3::ZERO;
        };
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        let wm = wo + wi;
        if cos_o == 0.0 || cos_i == 0.0 || wm.length_squared() == 0.0 {
            return Vec3::ZERO;
        }
        let wm = wm.normalize();
        self.fresnel.eval(wo.dot(wm)) * (distrib.d(wm) * distrib.g(wo, wi) / (4.0 * cos_i * cos_o))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(distrib) = self.distrib else {
            return 0.0;
        };
        if !same_hemisphere(wo, wi) {
            return 0.0;
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return 0.0;
        }
        let wm = wm.normalize();
        distrib.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs())
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        if wo.z == 0.0 {
            return None;
        }
        let Some(distrib) = self.distrib else {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let mut reflected = self.fresnel.eval(wi.z);
            if let Some(film) = self.film {
                reflected *= film.weight(wi.z.abs());
            }
            return LocalSample::specular(wi, reflected / wi.z.abs(), 1.0);
        };
        let wm = distrib.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        if !same_hemisphere(wo, wi) {
            return None;
        }
        LocalSample::non_specular(wi, self.f(wo, wi), self.pdf(wo, wi))
    }
}
