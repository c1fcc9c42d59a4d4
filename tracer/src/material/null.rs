//! `Material "null"`: not a surface at all; rays pass through (used on emitters and to hide
//! shapes).
//!
//! ```text
//! Material "null"
//! ```
//!
//! It has no parameters.


use super::eval::HitTextures;
use super::kind::MaterialKind;
use crate::bxdf::pass_through::PassThrough;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::TextureId;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Debug, PartialEq)]
pub struct Null;

impl Null {
    pub fn read(
        _params: &ParamList,
        _pos: &SourcePos,
        _ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self)
    }
}

impl MaterialKind for Null {
    fn textures(&self) -> Vec<TextureId> {
        Vec::new()
    }

    fn bxdf(&self, _eval: &HitTextures, _u: f32) -> Bxdf {
        Bxdf::PassThrough(PassThrough)
    }
}
