//! A Gaussian spectrum (a coloured filter or a narrow-band emitter) as its RGB colour.
//!
//! ```text
//! Texture "name" "color" "gaussian" "float wavelength" 600 "float width" 30 "float energy" 1
//! ```
//!
//! | parameter          | default | notes |
//! |--------------------|---------|-------|
//! | `float wavelength` | 550     | the peak, nm |
//! | `float width`      | 50      | the standard deviation, nm |
//! | `float energy`     | 1       | the peak value |
//!
//! energy x exp(-(lambda - wavelength)^2 / (2 width^2)), reduced to RGB by
//! [`spectrum_rgb`] (a flat spectrum keeps its value); read as a [`Constant`].

use super::constant::Constant;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::spectra::spectrum_rgb;

pub const DEFAULT_WAVELENGTH: f32 = 550.0;
pub const DEFAULT_WIDTH: f32 = 50.0;
pub const DEFAULT_ENERGY: f32 = 1.0;

pub fn read(params: &ParamList) -> Result<Constant, ParseError> {
    let mean = f64::from(params.float("wavelength", DEFAULT_WAVELENGTH)?);
    let width = f64::from(params.float("width", DEFAULT_WIDTH)?)
        .abs()
        .max(1e-3);
    let energy = f64::from(params.float("energy", DEFAULT_ENERGY)?);
    Ok(Constant {
        value: spectrum_rgb(|l| energy * libm::exp(-0.5 * ((l - mean) / width).powi(2))),
    })
}
