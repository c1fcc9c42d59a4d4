//! Velvet: asperity scattering (Koenderink and Pont 2002, "The secret of velvety skin"), the
//! light scattered once by a thin layer of fibres over a dark base.
//!
//! The layer's phase function is LuxRender's: 1 + p1 P1(c) + p2 P2(c) + p3 P3(c) in Legendre
//! polynomials of the scattering angle's cosine, negative values clamped to 0, over 4 pi. The
//! clamping can make it integrate to more than 1 over the sphere (about 3 with the defaults);
//! it is then scaled down to 1, so the layer never scatters more than it receives.
//!
//! The layer is a slab of optical depth `thickness`; its single scattering is
//! R p (1 - exp(-t (1/cos_i + 1/cos_o))) / (cos_i + cos_o) (Hanrahan and Krueger 1993). For a
//! thin layer that is R p t / (cos_i cos_o): the bright rim of velvet at grazing views.
//! LuxRender divides by cos_i only, which is not reciprocal and has no rim from the view
//! side; this form is reciprocal and its albedo is at most R (the layer scatters at most what
//! enters it). Sampling is cosine-weighted, as in LuxRender.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::local::same_hemisphere;
use super::lobe::Lobe;
use super::sample::{cosine_pdf, LocalSample};

/// Midpoints used to integrate the clamped phase polynomial over the cosine.
const PHASE_STEPS: usize = 64;

#[derive(Clone, Copy, Debug)]
pub struct Velvet {
    r: Vec3,
    /// p1, p2, p3: the Legendre coefficients after the constant 1.
    p: [f32; 3],
    /// Scale that makes the clamped phase function integrate to at most 1.
    norm: f32,
    thickness: f32,
}

/// 1 + p1 P1(c) + p2 P2(c) + p3 P3(c), clamped to 0.
fn polynomial(p: [f32; 3], c: f32) -> f32 {
    let p2 = 0.5 * (3.0 * c * c - 1.0);
    let p3 = 0.5 * (5.0 * c * c * c - 3.0 * c);
    (1.0 + p[0] * c + p[1] * p2 + p[2] * p3).max(0.0)
}

impl Velvet {
    /// `r` the colour, `p` LuxRender's p1-p3, `thickness` the layer's optical depth.
    pub fn new(r: Vec3, p: [f32; 3], thickness: f32) -> Self {
        // Integral over the sphere of polynomial / (4 pi) = half its integral over c in [-1, 1].
        let step = 2.0 / PHASE_STEPS as f32;
        let integral: f32 = (0..PHASE_STEPS)
            .map(|i| polynomial(p, -1.0 + (i as f32 + 0.5) * step))
            .sum::<f32>()
            * step
            * 0.5;
        Self {
            r,
            p,
            norm: 1.0 / integral.max(1.0),
            thickness: thickness.max(0.0),
        }
    }
}

impl Lobe for Velvet {
    const GATHERS_BROADLY: bool = true;

    /// What it reflects at most, for lobe selection under a coat.
    fn albedo_hint(&self, _cos_o: f32) -> Vec3 {
        self.r
    }

    /// `wo` is in the upper hemisphere (the BSDF mirrors back-face queries).
    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !same_hemisphere(wo, wi) {
            return Vec3::ZERO;
        }
        let (cos_o, cos_i) = (wo.z.abs(), wi.z.abs());
        if cos_o == 0.0 || cos_i == 0.0 {
            return Vec3::ZERO;
        }
        // The light travels along -wi and leaves along wo.
        let phase = polynomial(self.p, (-wi).dot(wo)) * self.norm / (4.0 * PI);
        let scattered = -libm::expm1f(-self.thickness * (1.0 / cos_i + 1.0 / cos_o));
        self.r * (phase * scattered / (cos_i + cos_o))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        cosine_pdf(wo, wi)
    }

    fn sample(&self, wo: Vec3, _u_lobe: f32, u: Vec2) -> Option<LocalSample> {
        LocalSample::cosine(wo, u, |wi| self.f(wo, wi))
    }
}
