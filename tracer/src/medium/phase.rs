//! The phase function of a scattering volume: Schlick's approximation of Henyey-Greenstein,
//! as LuxRender uses for its homogeneous volumes (their scattering events get the
//! `SchlickScatter` lobe) and for the `scatter` material.
//!
//! p(c) = (1 - k^2) / (4 pi (1 - k c)^2), where c is the cosine between the light's travel
//! before and after the event (1 is straight on) and k = g (1.55 - 0.55 g^2) approximates the
//! Henyey-Greenstein asymmetry g (positive scatters forward). It integrates to 1 over the
//! sphere. The asymmetry may differ per channel; directions are drawn from the channels' mean.
//! A leaf: the volumes and the `scatter` lobe import it.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

/// |g| is kept below this, where the phase function is finite.
const MAX_ASYMMETRY: f32 = 0.99;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    /// Schlick's k per channel, and their mean for sampling.
    k: Vec3,
    k_mean: f32,
}

fn schlick(k: f32, c: f32) -> f32 {
    let d = 1.0 - k * c;
    (1.0 - k * k) / (4.0 * PI * d * d)
}

impl Phase {
    /// `g` the Henyey-Greenstein asymmetry per channel.
    pub fn new(g: Vec3) -> Self {
        let g = g.clamp(Vec3::splat(-MAX_ASYMMETRY), Vec3::splat(MAX_ASYMMETRY));
        let k = g * (Vec3::splat(1.55) - 0.55 * g * g);
        Self {
            k,
            k_mean: k.element_sum() / 3.0,
        }
    }

    /// The phase function per channel for a path that arrived along `-wo` and leaves along
    /// `wi` (both unit).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let c = (-wo).dot(wi);
        Vec3::new(
            schlick(self.k.x, c),
            schlick(self.k.y, c),
            schlick(self.k.z, c),
        )
    }

    /// The solid-angle density [`Self::sample`] draws `wi` with.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        schlick(self.k_mean, (-wo).dot(wi))
    }

    /// A unit direction drawn with density [`Self::pdf`].
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let k = self.k_mean;
        // Inverse of the cumulative distribution in c.
        let c = if k.abs() < 1e-4 {
            2.0 * u.x - 1.0
        } else {
            (2.0 * u.x + k - 1.0) / (2.0 * k * u.x - k + 1.0)
        }
        .clamp(-1.0, 1.0);
        let s = (1.0 - c * c).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let axis = -wo;
        let t1 = axis.any_orthonormal_vector();
        let t2 = axis.cross(t1);
        (axis * c + (t1 * libm::cosf(phi) + t2 * libm::sinf(phi)) * s).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(
            libm::sinf(theta) * libm::cosf(phi),
            libm::sinf(theta) * libm::sinf(phi),
            libm::cosf(theta),
        )
    }

    /// The phase function integrates to 1 over the sphere (midpoint rule in theta and phi),
    /// for backward, isotropic and forward asymmetries and a mixed-channel one.
    #[test]
    fn phase_integrates_to_one() {
        let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
        for g in [
            Vec3::splat(-0.7),
            Vec3::ZERO,
            Vec3::splat(0.5),
            Vec3::new(0.8, 0.0, -0.3),
        ] {
            let phase = Phase::new(g);
            let (nt, np) = (800, 400);
            let mut sum = Vec3::ZERO;
            let mut pdf_sum = 0.0f64;
            for i in 0..nt {
                let theta = (i as f32 + 0.5) * PI / nt as f32;
                let dw = libm::sinf(theta) * (PI / nt as f32) * (2.0 * PI / np as f32);
                for j in 0..np {
                    let wi = unit(theta, (j as f32 + 0.5) * 2.0 * PI / np as f32);
                    sum += phase.eval(wo, wi) * dw;
                    pdf_sum += (phase.pdf(wo, wi) * dw) as f64;
                }
            }
            for c in sum.to_array() {
                assert!((c - 1.0).abs() < 2e-3, "g {g}: integral {sum}");
            }
            assert!(
                (pdf_sum - 1.0).abs() < 2e-3,
                "g {g}: pdf integral {pdf_sum}"
            );
        }
    }

    /// With one asymmetry for every channel the sampling density equals the phase function,
    /// and the drawn directions follow it: the mean cosine with the forward direction matches
    /// the analytic mean of Schlick's function, and a histogram of c matches the density.
    #[test]
    fn sampling_matches_the_phase_function() {
        let wo = Vec3::new(-0.4, 0.1, 0.8).normalize();
        for g in [-0.6f32, 0.0, 0.3, 0.9] {
            let phase = Phase::new(Vec3::splat(g));
            let n = 200_000;
            let mut rng = fastrand::Rng::with_seed(7);
            let bins = 20;
            let mut hist = vec![0u32; bins];
            let mut mean_c = 0.0f64;
            for _ in 0..n {
                let wi = phase.sample(wo, Vec2::new(rng.f32(), rng.f32()));
                assert!((wi.length() - 1.0).abs() < 1e-4);
                let value = phase.eval(wo, wi).x;
                let pdf = phase.pdf(wo, wi);
                assert!((value - pdf).abs() <= 1e-4 * pdf, "g {g}: {value} vs {pdf}");
                let c = (-wo).dot(wi);
                mean_c += c as f64;
                hist[(((c + 1.0) / 2.0 * bins as f32) as usize).min(bins - 1)] += 1;
            }
            // Density of c is 2 pi p(c); integrate it over each bin numerically.
            for (b, &count) in hist.iter().enumerate() {
                let steps = 200;
                let width = 2.0 / bins as f32;
                let expected: f32 = (0..steps)
                    .map(|s| {
                        let c = -1.0 + width * (b as f32 + (s as f32 + 0.5) / steps as f32);
                        2.0 * PI * schlick(phase.k_mean, c) * width / steps as f32
                    })
                    .sum();
                let got = count as f32 / n as f32;
                let sigma = (expected / n as f32).sqrt();
                assert!(
                    (got - expected).abs() < 5.0 * sigma + 1e-4,
                    "g {g} bin {b}: {got} vs {expected}"
                );
            }
            // Mean cosine: integral of c 2 pi p(c) dc, numerically.
            let steps = 100_000;
            let analytic: f64 = (0..steps)
                .map(|s| {
                    let c = -1.0 + 2.0 * (s as f32 + 0.5) / steps as f32;
                    (c * 2.0 * PI * schlick(phase.k_mean, c) * 2.0 / steps as f32) as f64
                })
                .sum();
            assert!((mean_c / n as f64 - analytic).abs() < 0.01, "g {g}");
        }
    }
}
