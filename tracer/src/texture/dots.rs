//! Polka dots on the 2D texture coordinates: each unit cell centred on an integer (s, t) holds
//! a dot of radius 0.35 or none, chosen and jittered by Perlin noise at the cell.
//!
//! ```text
//! Texture "name" "float"|"color" "dots" "texture inside" "a" "float outside" 0 "float uscale" 8
//! ```
//!
//! | parameter  | default | notes |
//! |------------|---------|-------|
//! | `inside`   | 1       | texture or constant of the declared kind: inside a dot |
//! | `outside`  | 0       | texture or constant of the declared kind: elsewhere |
//! | mapping    | uv      | see [`super::mapping`] |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::mapping::Mapping2D;
use super::noise::noise2;
use crate::diag::SourcePos;
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

pub const DEFAULT_INSIDE: f32 = 1.0;
pub const DEFAULT_OUTSIDE: f32 = 0.0;
/// A dot's radius in cells.
pub const RADIUS: f32 = 0.35;

#[derive(Clone, Debug, PartialEq)]
pub struct Dots {
    pub inside: ConstOrTexture,
    pub outside: ConstOrTexture,
    pub mapping: Mapping2D,
}

impl Dots {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            inside: decl.tex(ctx, params, "inside", DEFAULT_INSIDE)?,
            outside: decl.tex(ctx, params, "outside", DEFAULT_OUTSIDE)?,
            mapping: Mapping2D::read(params, pos, ctx)?,
        })
    }

    /// Whether (s, t) lies inside a dot (LuxRender's cell test, noise offsets and all).
    pub fn inside(s: f32, t: f32) -> bool {
        let cell_s = (s + 0.5).floor();
        let cell_t = (t + 0.5).floor();
        if noise2(cell_s + 0.5, cell_t + 0.5) <= 0.0 {
            return false;
        }
        let max_shift = 0.5 - RADIUS;
        let centre_s = cell_s + max_shift * noise2(cell_s + 1.5, cell_t + 2.8);
        let centre_t = cell_t + max_shift * noise2(cell_s + 4.5, cell_t + 9.8);
        let (ds, dt) = (s - centre_s, t - centre_t);
        ds * ds + dt * dt < RADIUS * RADIUS
    }
}

impl TextureType for Dots {
    fn name(&self) -> &'static str {
        "dots"
    }

    fn references(&self) -> Vec<ConstOrTexture> {
        vec![self.outside, self.inside]
    }

    fn mapping(&self) -> Option<&Mapping2D> {
        Some(&self.mapping)
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        let st = self.mapping.map(at);
        let tex = if Self::inside(st.x, st.y) {
            self.inside
        } else {
            self.outside
        };
        textures.eval(tex, at)
    }
}
