//! Fractional Brownian motion noise: signed octaves of Perlin noise in 3D texture space.
//!
//! ```text
//! Texture "name" "float" "fbm" "integer octaves" 8 "float roughness" 0.5 "vector scale" [4 4 4]
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `integer octaves`   | 8       | clamped to [0, [`MAX_OCTAVES`]] |
//! | `float roughness`   | 0.5     | each octave's amplitude is this times the previous one |
//! | 3D mapping          | global  | see [`super::mapping`] |
//!
//! The value has mean 0 and is signed (roughly within +-1 for the defaults).

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::mapping::Mapping3D;
use super::noise::{fbm, MAX_OCTAVES};
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

pub const DEFAULT_OCTAVES: i32 = 8;
pub const DEFAULT_ROUGHNESS: f32 = 0.5;

/// The octave and roughness parameters fbm and wrinkled share.
#[derive(Clone, Debug, PartialEq)]
pub struct Octaves {
    pub octaves: u32,
    pub roughness: f32,
    pub mapping: Mapping3D,
}

impl Octaves {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            octaves: params
                .int("octaves", DEFAULT_OCTAVES)?
                .clamp(0, MAX_OCTAVES as i32) as u32,
            roughness: params.float("roughness", DEFAULT_ROUGHNESS)?,
            mapping: Mapping3D::read(params, pos, ctx)?,
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Fbm(pub Octaves);

impl Fbm {
    pub fn read(
        _decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self(Octaves::read(params, pos, ctx)?))
    }
}

impl TextureType for Fbm {
    fn name(&self) -> &'static str {
        "fbm"
    }

    fn eval(&self, at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        let o = &self.0;
        Vec3::splat(fbm(o.mapping.map(at), o.roughness, o.octaves))
    }
}
