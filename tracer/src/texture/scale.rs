//! The product of two textures (channel by channel).
//!
//! ```text
//! Texture "name" "color"|"float" "scale" "texture tex1" "a" "float tex2" 0.5
//! ```
//!
//! | parameter | default | notes |
//! |-----------|---------|-------|
//! | `tex1`    | 1       | texture or constant of the declared kind |
//! | `tex2`    | 1       | texture or constant of the declared kind |
//!
//! The parser also makes scale textures itself: glossy's textured `Ks` times the reflectance
//! of its constant `index`.

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;
use crate::diag::SourcePos;

pub const DEFAULT_TEX1: f32 = 1.0;
pub const DEFAULT_TEX2: f32 = 1.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Scale {
    pub tex1: ConstOrTexture,
    pub tex2: ConstOrTexture,
}

impl Scale {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Scale {
            tex1: decl.tex(ctx, params, "tex1", DEFAULT_TEX1)?,
            tex2: decl.tex(ctx, params, "tex2", DEFAULT_TEX2)?,
        })
    }
}

impl TextureType for Scale {
    fn name(&self) -> &'static str {
        "scale"
    }

    fn references(&self) -> Vec<ConstOrTexture> {
        vec![self.tex1, self.tex2]
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        textures.eval(self.tex1, at) * textures.eval(self.tex2, at)
    }
}
