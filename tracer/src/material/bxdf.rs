//! The scattering functions in the local shading frame (z = shading normal), one variant per
//! kind of material, dispatched by match (no heap, no virtual calls).

use glam::{Vec2, Vec3};

use super::conductor::Conductor;
use super::dielectric::Dielectric;
use super::diffuse::{DiffuseReflection, DiffuseTranslucent};
use super::glossy::Glossy;
use super::local::flip_z;

/// A sampled direction in the local frame.
#[derive(Clone, Copy, Debug)]
pub struct LocalSample {
    pub wi: Vec3,
    pub f: Vec3,
    pub pdf: f32,
    pub specular: bool,
}

impl LocalSample {
    /// None when the density is zero or not finite (the direction cannot be used).
    pub fn non_specular(wi: Vec3, f: Vec3, pdf: f32) -> Option<Self> {
        (pdf > 0.0 && pdf.is_finite() && f.is_finite()).then_some(Self {
            wi,
            f,
            pdf,
            specular: false,
        })
    }

    /// `probability` is the discrete probability with which the lobe was chosen.
    pub fn specular(wi: Vec3, f: Vec3, probability: f32) -> Option<Self> {
        (probability > 0.0 && f.is_finite()).then_some(Self {
            wi,
            f,
            pdf: probability,
            specular: true,
        })
    }
}

#[derive(Clone, Copy, Debug)]
pub enum Bxdf {
    /// `null`: not a surface at all.
    PassThrough,
    Diffuse(DiffuseReflection),
    Translucent(DiffuseTranslucent),
    Conductor(Conductor),
    Dielectric(Dielectric),
    Glossy(Glossy),
}

impl Bxdf {
    pub fn is_specular(&self) -> bool {
        match self {
            Bxdf::PassThrough => true,
            Bxdf::Conductor(c) => c.is_specular(),
            Bxdf::Dielectric(d) => d.is_specular(),
            Bxdf::Diffuse(_) | Bxdf::Translucent(_) | Bxdf::Glossy(_) => false,
        }
    }

    /// Every variant but glass looks the same from both sides: a query from below is mirrored
    /// to the upper hemisphere, so those variants only handle wo.z >= 0.
    fn mirrors_back_face(&self, wo: Vec3) -> bool {
        wo.z < 0.0 && !matches!(self, Bxdf::Dielectric(_))
    }

    pub fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let (wo, wi) = if self.mirrors_back_face(wo) {
            (flip_z(wo), flip_z(wi))
        } else {
            (wo, wi)
        };
        match self {
            Bxdf::PassThrough => Vec3::ZERO,
            Bxdf::Diffuse(d) => d.f(wo, wi),
            Bxdf::Translucent(t) => t.f(wo, wi),
            Bxdf::Conductor(c) => c.f(wo, wi),
            Bxdf::Dielectric(d) => d.f(wo, wi),
            Bxdf::Glossy(g) => g.f(wo, wi),
        }
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = if self.mirrors_back_face(wo) {
            (flip_z(wo), flip_z(wi))
        } else {
            (wo, wi)
        };
        match self {
            Bxdf::PassThrough => 0.0,
            Bxdf::Diffuse(d) => d.pdf(wo, wi),
            Bxdf::Translucent(t) => t.pdf(wo, wi),
            Bxdf::Conductor(c) => c.pdf(wo, wi),
            Bxdf::Dielectric(d) => d.pdf(wo, wi),
            Bxdf::Glossy(g) => g.pdf(wo, wi),
        }
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        let mirrored = self.mirrors_back_face(wo);
        let wo = if mirrored { flip_z(wo) } else { wo };
        let sample = match self {
            Bxdf::PassThrough => None,
            Bxdf::Diffuse(d) => d.sample(wo, u),
            Bxdf::Translucent(t) => t.sample(wo, u_lobe, u),
            Bxdf::Conductor(c) => c.sample(wo, u),
            Bxdf::Dielectric(d) => d.sample(wo, u_lobe, u),
            Bxdf::Glossy(g) => g.sample(wo, u_lobe, u),
        }?;
        Some(if mirrored {
            LocalSample {
                wi: flip_z(sample.wi),
                ..sample
            }
        } else {
            sample
        })
    }
}
