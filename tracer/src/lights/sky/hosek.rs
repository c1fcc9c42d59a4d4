//! Hosek and Wilkie's sky model (2012), LuxRender 1.x's `sky2`, through the `hw-skymodel`
//! crate's RGB coefficients (the authors' data). LuxRender 1.x evaluates the spectral model
//! and integrates it on its film; the RGB model is that result fitted per channel (what
//! LuxCore's `sky2` uses), and its output x 683 is in the same cd/m^2 units.
//!
//! As in LuxRender: ground albedo 0, turbidity clamped to the model's [1, 10], a sun below the
//! horizon evaluated at elevation 0, and below the horizon the sky shows its horizon.

use std::f32::consts::FRAC_PI_2;

use glam::Vec3;
use hw_skymodel::rgb::{SkyParams, SkyState};

/// Lumens per watt: the model's radiometric RGB to LuxRender's photometric scale.
const LUMENS_PER_WATT: f32 = 683.0;
/// The model's turbidity range.
const TURBIDITY: (f32, f32) = (1.0, 10.0);

/// The model for one sun position and turbidity.
pub struct Hosek {
    /// The model's nine parameters per channel ([`SkyState::raw`]).
    params: [[f32; 9]; 3],
    /// Its radiance scale per channel.
    scales: [f32; 3],
    /// Unit light-space direction towards the sun.
    sun: Vec3,
}

impl Hosek {
    /// `sun`: unit light-space direction towards the sun. None if the model refuses the
    /// parameters (a non-finite turbidity or direction).
    pub fn new(sun: Vec3, turbidity: f32) -> Option<Self> {
        let elevation = (FRAC_PI_2 - libm::acosf(sun.z.clamp(-1.0, 1.0))).clamp(0.0, FRAC_PI_2);
        let state = SkyState::new(&SkyParams {
            elevation,
            turbidity: turbidity.clamp(TURBIDITY.0, TURBIDITY.1),
            albedo: [0.0; 3],
        })
        .ok()?;
        let (flat, scales) = state.raw();
        let mut params = [[0.0; 9]; 3];
        for (channel, p) in params.iter_mut().enumerate() {
            p.copy_from_slice(&flat[9 * channel..9 * channel + 9]);
        }
        Some(Self {
            params,
            scales,
            sun,
        })
    }

    /// Radiance (linear sRGB, cd/m^2 scale) from unit light-space direction `dir`.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let theta = libm::acosf(dir.z.clamp(-1.0, 1.0)).min(FRAC_PI_2);
        let gamma = libm::acosf(dir.dot(self.sun).clamp(-1.0, 1.0));
        let rgb = Vec3::from_array([0, 1, 2].map(|c| self.channel(c, theta, gamma)));
        if rgb.is_finite() {
            (rgb * LUMENS_PER_WATT).max(Vec3::ZERO)
        } else {
            Vec3::ZERO
        }
    }

    /// The model's radiance in `channel` at zenith angle `theta` and angle `gamma` from the
    /// sun: `SkyState::radiance`'s formula, with the float functions of the `libm` crate
    /// (the C library's differ between machines; clippy.toml).
    fn channel(&self, channel: usize, theta: f32, gamma: f32) -> f32 {
        let p = &self.params[channel];
        let cos_gamma = libm::cosf(gamma);
        let cos_gamma2 = cos_gamma * cos_gamma;
        let cos_theta = libm::cosf(theta).abs();
        let exp_m = libm::expf(p[4] * gamma);
        let mie_m =
            (1.0 + cos_gamma2) / libm::powf(1.0 + p[8] * p[8] - 2.0 * p[8] * cos_gamma, 1.5);
        let zenith = cos_theta.sqrt();
        let lhs = 1.0 + p[0] * libm::expf(p[1] / (cos_theta + 0.01));
        let rhs = p[2] + p[3] * exp_m + p[5] * cos_gamma2 + p[6] * mie_m + p[7] * zenith;
        self.scales[channel] * (lhs * rhs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hw_skymodel::rgb::Channel;

    /// The formula restated over `SkyState::raw` is the crate's `SkyState::radiance`, the
    /// float functions aside (ours are the `libm` crate's, the crate's the C library's: at most
    /// a few units in the last place apart).
    #[test]
    fn the_channels_are_the_crates_radiance() {
        let sun = Vec3::new(0.3, -0.5, 0.8).normalize();
        for turbidity in [1.5f32, 3.0, 9.0] {
            let model = Hosek::new(sun, turbidity).expect("a valid sky");
            let state = SkyState::new(&SkyParams {
                elevation: FRAC_PI_2 - libm::acosf(sun.z),
                turbidity,
                albedo: [0.0; 3],
            })
            .expect("a valid sky");
            for theta in [0.0f32, 0.4, 1.0, 1.5, FRAC_PI_2] {
                for gamma in [0.0f32, 0.05, 0.7, 2.0, 3.1] {
                    for (c, channel) in [Channel::R, Channel::G, Channel::B].into_iter().enumerate()
                    {
                        let ours = model.channel(c, theta, gamma);
                        let crates = state.radiance(theta, gamma, channel);
                        assert!(
                            (ours - crates).abs() <= 1e-5 * crates.abs(),
                            "channel {c} at theta {theta}, gamma {gamma}: {ours} vs {crates}"
                        );
                    }
                }
            }
        }
    }
}
