//! Bilinear interpolation of four corner values over each unit cell of the 2D texture
//! coordinates.
//!
//! ```text
//! Texture "name" "color"|"float" "bilerp" "color v00" [1 0 0] "color v01" [0 1 0] ...
//! ```
//!
//! | parameter | default | notes |
//! |-----------|---------|-------|
//! | `v00`     | 0       | colour or float of the declared kind, at (s, t) = (0, 0) |
//! | `v01`     | 1       | at (0, 1) |
//! | `v10`     | 0       | at (1, 0) |
//! | `v11`     | 1       | at (1, 1) |
//! | mapping   | uv      | see [`super::mapping`]; the fractional part of (s, t) is used |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::mapping::Mapping2D;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

pub const DEFAULT_V00: f32 = 0.0;
pub const DEFAULT_V01: f32 = 1.0;
pub const DEFAULT_V10: f32 = 0.0;
pub const DEFAULT_V11: f32 = 1.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Bilerp {
    pub v00: Vec3,
    pub v01: Vec3,
    pub v10: Vec3,
    pub v11: Vec3,
    pub mapping: Mapping2D,
}

impl Bilerp {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let value = |name: &str, default: f32| {
            if decl.is_color {
                params.color(name, Vec3::splat(default))
            } else {
                params.float(name, default).map(Vec3::splat)
            }
        };
        Ok(Self {
            v00: value("v00", DEFAULT_V00)?,
            v01: value("v01", DEFAULT_V01)?,
            v10: value("v10", DEFAULT_V10)?,
            v11: value("v11", DEFAULT_V11)?,
            mapping: Mapping2D::read(params, pos, ctx)?,
        })
    }
}

impl TextureType for Bilerp {
    fn name(&self) -> &'static str {
        "bilerp"
    }

    fn mapping(&self) -> Option<&Mapping2D> {
        Some(&self.mapping)
    }

    fn eval(&self, at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        let st = self.mapping.map(at);
        let (s, t) = (st.x - st.x.floor(), st.y - st.y.floor());
        (1.0 - s) * (1.0 - t) * self.v00
            + (1.0 - s) * t * self.v01
            + s * (1.0 - t) * self.v10
            + s * t * self.v11
    }
}
