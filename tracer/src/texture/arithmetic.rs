//! The sum or the difference of two textures (channel by channel); their product is
//! [`super::scale`].
//!
//! ```text
//! Texture "name" "color"|"float" "add" "texture tex1" "a" "texture tex2" "b"
//! Texture "name" "color"|"float" "subtract" "texture tex1" "a" "float tex2" 0.5
//! ```
//!
//! | parameter | default | notes |
//! |-----------|---------|-------|
//! | `tex1`    | 1       | texture or constant of the declared kind |
//! | `tex2`    | 1       | texture or constant of the declared kind (subtracted from tex1 by "subtract") |

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

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Add,
    Subtract,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Arithmetic {
    pub op: Op,
    pub tex1: ConstOrTexture,
    pub tex2: ConstOrTexture,
}

impl Arithmetic {
    /// `Texture "name" "float"|"color" "add"`.
    pub fn read_add(
        decl: &Declared,
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Self::read(Op::Add, decl, params, ctx)
    }

    /// `Texture "name" "float"|"color" "subtract"`.
    pub fn read_subtract(
        decl: &Declared,
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Self::read(Op::Subtract, decl, params, ctx)
    }

    fn read(
        op: Op,
        decl: &Declared,
        params: &ParamList,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            op,
            tex1: decl.tex(ctx, params, "tex1", DEFAULT_TEX1)?,
            tex2: decl.tex(ctx, params, "tex2", DEFAULT_TEX2)?,
        })
    }

}

impl TextureType for Arithmetic {
    /// LuxRender's type name.
    fn name(&self) -> &'static str {
        match self.op {
            Op::Add => "add",
            Op::Subtract => "subtract",
        }
    }

    fn references(&self) -> Vec<ConstOrTexture> {
        vec![self.tex1, self.tex2]
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        let (a, b) = (textures.eval(self.tex1, at), textures.eval(self.tex2, at));
        match self.op {
            Op::Add => a + b,
            Op::Subtract => a - b,
        }
    }
}
