//! The anisotropic Trowbridge-Reitz (GGX) microfacet distribution with Smith's
//! height-correlated masking-shadowing and Heitz's (2018) visible-normal sampling.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::local::sample_disk_polar;

/// Smallest alpha used: below it the distribution's peak overflows f32 arithmetic.
pub const MIN_ALPHA: f32 = 1e-3;

/// Slope, in alphas, within which [`TrowbridgeReitz::reflection_spread`] counts a microfacet
/// normal: a share t^2 / (1 + t^2) of them lies within slope t alphas, 95% for sqrt(19).
pub const LOBE_TAN_SPREAD: f32 = 4.358_899;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    alpha_x: f32,
    alpha_y: f32,
}

impl TrowbridgeReitz {
    /// From LuxRender's u/v roughness. LuxRender's own microfacet models differ per material;
    /// YAT uses alpha = roughness for all of them, clamped to [MIN_ALPHA, 1]. None when both
    /// roughnesses are zero (or negative): the surface is a perfectly specular lobe.
    pub fn from_roughness(u: f32, v: f32) -> Option<Self> {
        if !(u > 0.0 || v > 0.0) {
            return None;
        }
        Some(Self::rough(u, v))
    }

    /// From LuxRender's u/v roughness, clamped to [MIN_ALPHA, 1] (NaN to MIN_ALPHA): never a
    /// specular lobe, for the models that have no smooth limit.
    pub fn rough(u: f32, v: f32) -> Self {
        // NaN is not below MIN_ALPHA: clamp would keep it; the comparison does not.
        let alpha = |r: f32| {
            if r >= MIN_ALPHA {
                r.min(1.0)
            } else {
                MIN_ALPHA
            }
        };
        Self {
            alpha_x: alpha(u),
            alpha_y: alpha(v),
        }
    }

    /// The larger of the two alphas: how wide the lobe is at its widest.
    pub fn max_alpha(&self) -> f32 {
        self.alpha_x.max(self.alpha_y)
    }

    /// The half angle around the mirror direction that holds most of a reflection's lobe: where
    /// microfacet normals are within [`LOBE_TAN_SPREAD`] alphas' slope of the normal (95% of
    /// them at normal incidence), reflections within twice their angle.
    pub fn reflection_spread(&self) -> f32 {
        2.0 * libm::atanf(LOBE_TAN_SPREAD * self.max_alpha())
    }

    /// Microfacet normal density D(wm), normalised so that the projected area is 1.
    pub fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let x = wm.x / self.alpha_x;
        let y = wm.y / self.alpha_y;
        let s = x * x + y * y + wm.z * wm.z;
        1.0 / (PI * self.alpha_x * self.alpha_y * s * s)
    }

    /// Smith's Lambda: the masked microfacet area per visible area, seen from `w`.
    fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        if z2 == 0.0 {
            return f32::INFINITY;
        }
        let ax = self.alpha_x * w.x;
        let ay = self.alpha_y * w.y;
        let alpha2_tan2 = (ax * ax + ay * ay) / z2;
        0.5 * ((1.0 + alpha2_tan2).sqrt() - 1.0)
    }

    /// Masking: the fraction of microfacets facing `w` that `w` sees.
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing of the pair.
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Density of the normals visible from `w`. From below the surface (w.z < 0) the
    /// visible normals are those `-w` sees, as `sample_wm` draws them.
    pub fn d_visible(&self, w: Vec3, wm: Vec3) -> f32 {
        let cos = w.z.abs();
        if cos == 0.0 {
            return 0.0;
        }
        let facing = (w.dot(wm) * w.z.signum()).max(0.0);
        self.g1(w) / cos * self.d(wm) * facing
    }

    /// Samples a microfacet normal (upper hemisphere) visible from `w` with density
    /// `d_visible(w, wm)`.
    pub fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        // Stretch to the hemisphere configuration where the distribution is a unit sphere.
        let mut wh = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        if wh.z < 0.0 {
            wh = -wh;
        }
        let t1 = if wh.z < 0.99999 {
            Vec3::Z.cross(wh).normalize()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        // Sample the projected hemisphere: a disk whose far half is squashed by wh.z.
        let mut p = sample_disk_polar(u);
        let h = (1.0 - p.x * p.x).max(0.0).sqrt();
        let s = 0.5 * (1.0 + wh.z);
        p.y = (1.0 - s) * h + s * p.y;
        let pz = (1.0 - p.length_squared()).max(0.0).sqrt();
        let nh = t1 * p.x + t2 * p.y + wh * pz;
        Vec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::PixelSampler;

    fn uniform_sphere(u: Vec2) -> Vec3 {
        let z = 1.0 - 2.0 * u.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z)
    }

    #[test]
    fn projected_microfacet_area_is_one() {
        for (ax, ay) in [(0.05f32, 0.05f32), (0.3, 0.3), (0.8, 0.2), (1.0, 1.0)] {
            let d = TrowbridgeReitz::from_roughness(ax, ay).unwrap();
            let n = 1 << 18;
            let sum: f64 = (0..n)
                .map(|i| {
                    let wm = uniform_sphere(PixelSampler::new(1, 2, i, n, 3).get_2d());
                    f64::from(d.d(wm) * wm.z.max(0.0) * 4.0 * PI)
                })
                .sum();
            let integral = sum / f64::from(n);
            // Very narrow lobes are hard to hit uniformly; the test bounds are in proportion.
            let tol = if ax < 0.1 { 0.1 } else { 0.02 };
            assert!(
                (integral - 1.0).abs() < tol,
                "alpha ({ax},{ay}): {integral}"
            );
        }
    }

    #[test]
    fn visible_normal_density_integrates_to_one_and_matches_sampling() {
        let d = TrowbridgeReitz::from_roughness(0.5, 0.25).unwrap();
        let wo = Vec3::new(0.6, 0.3, 0.5).normalize();
        let n = 1 << 18;
        // Uniform integral of the density.
        let integral: f64 = (0..n)
            .map(|i| {
                let wm = uniform_sphere(PixelSampler::new(0, 0, i, n, 5).get_2d());
                f64::from(d.d_visible(wo, wm) * 4.0 * PI)
            })
            .sum::<f64>()
            / f64::from(n);
        assert!((integral - 1.0).abs() < 0.02, "{integral}");
        // Mean of wm.z under sampling equals the density-weighted mean.
        let sampled: f64 = (0..n)
            .map(|i| f64::from(d.sample_wm(wo, PixelSampler::new(0, 1, i, n, 5).get_2d()).z))
            .sum::<f64>()
            / f64::from(n);
        let weighted: f64 = (0..n)
            .map(|i| {
                let wm = uniform_sphere(PixelSampler::new(0, 2, i, n, 5).get_2d());
                f64::from(wm.z * d.d_visible(wo, wm) * 4.0 * PI)
            })
            .sum::<f64>()
            / f64::from(n);
        assert!((sampled - weighted).abs() < 0.01, "{sampled} vs {weighted}");
    }

    /// At normal incidence 95% of the sampled reflections lie within the spread of the mirror
    /// direction (a share t^2 / (1 + t^2) of visible normals within slope t alphas there).
    #[test]
    fn the_reflection_spread_holds_most_of_the_lobe() {
        for alpha in [0.02f32, 0.075, 0.2] {
            let d = TrowbridgeReitz::from_roughness(alpha, alpha).unwrap();
            let cos_spread = libm::cosf(d.reflection_spread());
            let n = 1 << 14;
            let inside = (0..n)
                .filter(|&i| {
                    let wm = d.sample_wm(Vec3::Z, PixelSampler::new(4, 4, i, n, 9).get_2d());
                    let wi = 2.0 * wm.z * wm - Vec3::Z;
                    wi.z >= cos_spread
                })
                .count();
            let share = inside as f32 / n as f32;
            assert!((share - 0.95).abs() < 0.005, "alpha {alpha}: {share}");
        }
    }

    #[test]
    fn zero_roughness_is_specular() {
        assert!(TrowbridgeReitz::from_roughness(0.0, 0.0).is_none());
        assert!(TrowbridgeReitz::from_roughness(0.0, 0.1).is_some());
    }
}
