//! A flat spectrum: every wavelength has the same value.
//!
//! ```text
//! Texture "name" "color" "equalenergy" "float energy" 0.8
//! ```
//!
//! | parameter      | default | notes |
//! |----------------|---------|-------|
//! | `float energy` | 1       | the value; the colour is (energy, energy, energy) |
//!
//! Read as a [`Constant`].

use glam::Vec3;

use super::constant::Constant;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_ENERGY: f32 = 1.0;

pub fn read(params: &ParamList) -> Result<Constant, ParseError> {
    Ok(Constant {
        value: Vec3::splat(params.float("energy", DEFAULT_ENERGY)?),
    })
}
