//! The colour of a blackbody: a constant hue, scaled to luminance 1 (a light's gain sets the
//! brightness).
//!
//! ```text
//! Texture "name" "color" "blackbody" "float temperature" 3000
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `float temperature` | 6500    | kelvin |
//!
//! It reads as a [`Constant`] texture (the colour is computed once, at parse time, by
//! [`blackbody_rgb`]).

use super::constant::Constant;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::spectra::blackbody_rgb;

pub const DEFAULT_TEMPERATURE: f32 = 6500.0;

pub fn read(params: &ParamList) -> Result<Constant, ParseError> {
    Ok(Constant {
        value: blackbody_rgb(params.float("temperature", DEFAULT_TEMPERATURE)?),
    })
}
