//! Two textures alternating in a checkerboard: on the 2D texture coordinates (unit cells in
//! (s, t)) or in 3D texture space (unit cubes).
//!
//! ```text
//! Texture "name" "color"|"float" "checkerboard" "integer dimension" 2 "texture tex1" "a" ...
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `integer dimension` | 2       | 2 or 3; anything else is an error |
//! | `tex1`              | 1       | texture or constant of the declared kind: the cells whose coordinates sum to an even number |
//! | `tex2`              | 0       | the other cells |
//! | `string aamode`     | -       | accepted and ignored (no antialiasing) |
//! | mapping             | uv      | dimension 2: the 2D mapping, dimension 3: the 3D mapping (global coordinates by default), see [`super::mapping`] |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::kind::TextureType;
use super::mapping::{Mapping2D, Mapping3D};
use crate::diag::SourcePos;
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_DIMENSION: i32 = 2;
pub const DEFAULT_TEX1: f32 = 1.0;
pub const DEFAULT_TEX2: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Checkerboard2D {
    pub tex1: ConstOrTexture,
    pub tex2: ConstOrTexture,
    pub mapping: Mapping2D,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Checkerboard3D {
    pub tex1: ConstOrTexture,
    pub tex2: ConstOrTexture,
    pub mapping: Mapping3D,
}

/// What `"checkerboard"` reads as, by its dimension.
#[derive(Clone, Debug, PartialEq)]
pub enum Checkerboard {
    D2(Checkerboard2D),
    D3(Checkerboard3D),
}

impl Checkerboard {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let dimension = params.int("dimension", DEFAULT_DIMENSION)?;
        params.ignore("aamode");
        let tex1 = decl.tex(ctx, params, "tex1", DEFAULT_TEX1)?;
        let tex2 = decl.tex(ctx, params, "tex2", DEFAULT_TEX2)?;
        Ok(match dimension {
            2 => Checkerboard::D2(Checkerboard2D {
                tex1,
                tex2,
                mapping: Mapping2D::read(params, pos, ctx)?,
            }),
            3 => Checkerboard::D3(Checkerboard3D {
                tex1,
                tex2,
                mapping: Mapping3D::read(params, pos, ctx)?,
            }),
            d => {
                let p = params.find("dimension").expect("read above");
                return Err(params.error(p, format!("{d} is not 2 or 3")));
            }
        })
    }
}

impl Checkerboard2D {
    pub fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        let st = self.mapping.map(at).floor();
        let first = (st.x + st.y).rem_euclid(2.0) == 0.0;
        textures.eval(if first { self.tex1 } else { self.tex2 }, at)
    }
}

impl Checkerboard3D {
    pub fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        let p = self.mapping.map(at).floor();
        let first = (p.x + p.y + p.z).rem_euclid(2.0) == 0.0;
        textures.eval(if first { self.tex1 } else { self.tex2 }, at)
    }
}

impl TextureType for Checkerboard {
    fn name(&self) -> &'static str {
        "checkerboard"
    }

    fn references(&self) -> Vec<ConstOrTexture> {
        match self {
            Checkerboard::D2(t) => vec![t.tex1, t.tex2],
            Checkerboard::D3(t) => vec![t.tex1, t.tex2],
        }
    }

    fn mapping(&self) -> Option<&Mapping2D> {
        match self {
            Checkerboard::D2(t) => Some(&t.mapping),
            Checkerboard::D3(_) => None,
        }
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        match self {
            Checkerboard::D2(t) => t.eval(at, textures),
            Checkerboard::D3(t) => t.eval(at, textures),
        }
    }
}
