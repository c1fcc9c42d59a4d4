//! A different colour for every primitive: shows how a mesh is cut into triangles.
//!
//! ```text
//! Texture "name" "color" "harlequin"
//! ```
//!
//! No parameters. LuxRender picks one of 31 colours (the 2, 3, 5 radical inverses of
//! 1, 4, 7, ...) from the primitive's memory address, which changes from run to run; YAT picks
//! it from the primitive's index, so images stay reproducible.

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::kind::TextureType;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// LuxRender's palette size.
pub const PALETTE_SIZE: u32 = 31;

#[derive(Clone, Debug, PartialEq)]
pub struct Harlequin;

/// The base-`base` radical inverse of `i` (digits mirrored about the radix point).
fn radical_inverse(mut i: u32, base: u32) -> f32 {
    let (mut result, mut scale) = (0.0f64, 1.0f64 / base as f64);
    while i > 0 {
        result += (i % base) as f64 * scale;
        i /= base;
        scale /= base as f64;
    }
    result as f32
}

impl Harlequin {
    pub fn read(
        _decl: &Declared,
        _params: &ParamList,
        _pos: &SourcePos,
        _ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self)
    }

    /// Palette entry `i` (LuxRender's table, built from 3i + 1).
    pub fn colour(i: u32) -> Vec3 {
        let n = i * 3 + 1;
        Vec3::new(
            radical_inverse(n, 2),
            radical_inverse(n, 3),
            radical_inverse(n, 5),
        )
    }
}

impl TextureType for Harlequin {
    fn name(&self) -> &'static str {
        "harlequin"
    }

    fn eval(&self, at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        Self::colour(at.prim % PALETTE_SIZE)
    }
}
