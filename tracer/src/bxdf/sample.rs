//! The shared result type of every lobe's `sample`: a leaf module that both the lobes and the
//! [`Bxdf`](super::Bxdf) dispatch import.

use glam::{Vec2, Vec3};

use super::local::{cosine_hemisphere_pdf, same_hemisphere, sample_cosine_hemisphere};

/// A sampled direction in the local frame.
#[derive(Clone, Copy, Debug)]
pub struct LocalSample {
    pub wi: Vec3,
    pub f: Vec3,
    pub pdf: f32,
    pub specular: bool,
}

/// The density of [`LocalSample::cosine`]'s directions: the cosine over `wo`'s hemisphere.
pub fn cosine_pdf(wo: Vec3, wi: Vec3) -> f32 {
    if !same_hemisphere(wo, wi) {
        return 0.0;
    }
    cosine_hemisphere_pdf(wi.z.abs())
}

impl LocalSample {
    /// A direction drawn by the cosine (the sampling the matte-like lobes share: diffuse,
    /// velvet, cloth) for a lobe whose value at `wi` is `f(wi)`; `wo` is in the upper
    /// hemisphere.
    pub fn cosine(wo: Vec3, u: Vec2, f: impl FnOnce(Vec3) -> Vec3) -> Option<Self> {
        let wi = sample_cosine_hemisphere(u);
        Self::non_specular(wi, f(wi), cosine_pdf(wo, wi))
    }

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
