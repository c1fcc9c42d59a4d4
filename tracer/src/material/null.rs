//! `Material "null"`: not a surface at all; rays pass through (used on emitters and to hide
//! shapes).
//!
//! ```text
//! Material "null"
//! ```
//!
//! It has no parameters.

use crate::bxdf::Bxdf;
use crate::param::TextureId;

#[derive(Clone, Debug, PartialEq)]
pub struct Null;

impl Null {
    pub fn bxdf(&self) -> Bxdf {
        Bxdf::PassThrough
    }

    pub fn textures(&self) -> Vec<TextureId> {
        Vec::new()
    }
}
