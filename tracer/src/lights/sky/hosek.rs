//! Hosek and Wilkie's sky model (2012), LuxRender 1.x's `sky2`, through the `hw-skymodel`
//! crate's RGB coefficients (the authors' data). LuxRender 1.x evaluates the spectral model
//! and integrates it on its film; the RGB model is that result fitted per channel (what
//! LuxCore's `sky2` uses), and its output x 683 is in the same cd/m^2 units.
//!
//! As in LuxRender: ground albedo 0, turbidity clamped to the model's [1, 10], a sun below the
//! horizon evaluated at elevation 0, and below the horizon the sky shows its horizon.

use std::f32::consts::FRAC_PI_2;

use glam::Vec3;
use hw_skymodel::rgb::{Channel, SkyParams, SkyState};

/// Lumens per watt: the model's radiometric RGB to LuxRender's photometric scale.
const LUMENS_PER_WATT: f32 = 683.0;
/// The model's turbidity range.
const TURBIDITY: (f32, f32) = (1.0, 10.0);

/// The model for one sun position and turbidity.
pub struct Hosek {
    state: SkyState,
    /// Unit light-space direction towards the sun.
    sun: Vec3,
}

impl Hosek {
    /// `sun`: unit light-space direction towards the sun. None if the model refuses the
    /// parameters (a non-finite turbidity or direction).
    pub fn new(sun: Vec3, turbidity: f32) -> Option<Self> {
        let elevation = (FRAC_PI_2 - sun.z.clamp(-1.0, 1.0).acos()).clamp(0.0, FRAC_PI_2);
        let state = SkyState::new(&SkyParams {
            elevation,
            turbidity: turbidity.clamp(TURBIDITY.0, TURBIDITY.1),
            albedo: [0.0; 3],
        })
        .ok()?;
        Some(Self { state, sun })
    }

    /// Radiance (linear sRGB, cd/m^2 scale) from unit light-space direction `dir`.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let theta = dir.z.clamp(-1.0, 1.0).acos().min(FRAC_PI_2);
        let gamma = dir.dot(self.sun).clamp(-1.0, 1.0).acos();
        let rgb = Vec3::new(
            self.state.radiance(theta, gamma, Channel::R),
            self.state.radiance(theta, gamma, Channel::G),
            self.state.radiance(theta, gamma, Channel::B),
        );
        if rgb.is_finite() {
            (rgb * LUMENS_PER_WATT).max(Vec3::ZERO)
        } else {
            Vec3::ZERO
        }
    }
}
