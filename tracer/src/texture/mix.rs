//! A blend of two textures by a float texture.
//!
//! ```text
//! Texture "name" "color"|"float" "mix" "texture tex1" "a" "texture tex2" "b" "float amount" 0.3
//! ```
//!
//! | parameter      | default | notes |
//! |----------------|---------|-------|
//! | `tex1`         | 0       | texture or constant of the declared kind |
//! | `tex2`         | 1       | texture or constant of the declared kind |
//! | `float amount` | 0.5     | texture or constant: the weight of `tex2` |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;
use crate::diag::SourcePos;

pub const DEFAULT_TEX1: f32 = 0.0;
pub const DEFAULT_TEX2: f32 = 1.0;
pub const DEFAULT_AMOUNT: f32 = 0.5;

#[derive(Clone, Debug, PartialEq)]
pub struct Mix {
    pub tex1: ConstOrTexture,
    pub tex2: ConstOrTexture,
    /// Weight of `tex2` (a float texture: its first channel).
    pub amount: ConstOrTexture,
}

impl Mix {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let amount = params.tex_float("amount", DEFAULT_AMOUNT)?;
        Ok(Mix {
            tex1: decl.tex(ctx, params, "tex1", DEFAULT_TEX1)?,
            tex2: decl.tex(ctx, params, "tex2", DEFAULT_TEX2)?,
            amount: ctx.tex(amount, false, Vec3::splat(DEFAULT_AMOUNT)),
        })
    }
}

impl TextureType for Mix {
    fn name(&self) -> &'static str {
        "mix"
    }

    fn references(&self) -> Vec<ConstOrTexture> {
        vec![self.tex1, self.tex2, self.amount]
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        let t = textures.eval(self.amount, at).x;
        textures.eval(self.tex1, at) * (1.0 - t) + textures.eval(self.tex2, at) * t
    }
}
