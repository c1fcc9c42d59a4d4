//! The 2D texture coordinates as a colour: red = frac(s), green = frac(t), blue = 0 (for
//! checking a mesh's uv layout).
//!
//! ```text
//! Texture "name" "color" "uv" "float uscale" 4
//! ```
//!
//! | parameter | default | notes |
//! |-----------|---------|-------|
//! | mapping   | uv      | see [`super::mapping`] |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::mapping::Mapping2D;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

#[derive(Clone, Debug, PartialEq)]
pub struct Uv {
    pub mapping: Mapping2D,
}

impl Uv {
    pub fn read(
        _decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            mapping: Mapping2D::read(params, pos, ctx)?,
        })
    }
}

impl TextureType for Uv {
    fn name(&self) -> &'static str {
        "uv"
    }

    fn mapping(&self) -> Option<&Mapping2D> {
        Some(&self.mapping)
    }

    fn eval(&self, at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        let st = self.mapping.map(at);
        Vec3::new(st.x - st.x.floor(), st.y - st.y.floor(), 0.0)
    }
}
