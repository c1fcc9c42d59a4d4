//! What every light shares when it is read: the `L` and `gain` parameters, and LuxRender's
//! power/efficacy normalisation (when power x efficacy > 0, the gain is scaled so the light
//! emits that many lumens), used by point, spot and area lights. A leaf: the light files
//! import it, it imports none of them.

use glam::Vec3;

use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// `L`: the emitted colour.
pub const DEFAULT_L: Vec3 = Vec3::ONE;
/// `gain`: multiplies `L`.
pub const DEFAULT_GAIN: f32 = 1.0;

/// `L` and `gain`, read first for every `LightSource` (so a malformed one is an error whatever
/// the type).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    pub l: Vec3,
    pub gain: f32,
}

impl Emission {
    pub(crate) fn read(params: &ParamList) -> Result<Self, ParseError> {
        Ok(Self {
            l: params.color("L", DEFAULT_L)?,
            gain: params.float("gain", DEFAULT_GAIN)?,
        })
    }
}

/// `gain x power x efficacy / denominator` when that factor is positive and finite
/// (LuxRender's rule), else `gain`.
pub fn normalised_gain(gain: f32, power: f32, efficacy: f32, denominator: f32) -> f32 {
    let factor = power * efficacy / denominator;
    if factor > 0.0 && factor.is_finite() {
        gain * factor
    } else {
        gain
    }
}

/// Whether a colour can light anything.
pub fn emits(c: Vec3) -> bool {
    c.is_finite() && c.max_element() > 0.0
}
