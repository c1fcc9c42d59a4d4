//! A uniform value.
//!
//! ```text
//! Texture "name" "color" "constant" "color value" [0.8 0.1 0.1]
//! Texture "name" "float" "constant" "float value" 0.5
//! ```
//!
//! | parameter | default | notes |
//! |-----------|---------|-------|
//! | `value`   | 1       | a colour for "color" textures, a float (splatted) for "float" ones |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;

pub const DEFAULT_VALUE: f32 = 1.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Constant {
    pub value: Vec3,
}

impl Constant {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        _pos: &SourcePos,
        _ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let value = if decl.is_color {
            params.color("value", Vec3::splat(DEFAULT_VALUE))?
        } else {
            Vec3::splat(params.float("value", DEFAULT_VALUE)?)
        };
        Ok(Constant { value })
    }
}

impl TextureType for Constant {
    fn name(&self) -> &'static str {
        "constant"
    }

    fn eval(&self, _at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        self.value
    }
}
