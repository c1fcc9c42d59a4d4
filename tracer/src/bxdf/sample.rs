//! The shared result type of every lobe's `sample`: a leaf module that both the lobes and the
//! [`Bxdf`](super::Bxdf) dispatch import.

use glam::Vec3;

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
