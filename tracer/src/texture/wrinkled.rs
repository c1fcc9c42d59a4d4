//! Turbulence: octaves of |Perlin noise| in 3D texture space, a wrinkled, always positive
//! pattern.
//!
//! ```text
//! Texture "name" "float" "wrinkled" "integer octaves" 8 "float roughness" 0.5
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `integer octaves`   | 8       | clamped to [0, 32] |
//! | `float roughness`   | 0.5     | each octave's amplitude is this times the previous one |
//! | 3D mapping          | global  | see [`super::mapping`] |
//!
//! The parameters are fbm's ([`Octaves`]).

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::fbm::Octaves;
use super::noise::turbulence;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

#[derive(Clone, Debug, PartialEq)]
pub struct Wrinkled(pub Octaves);

impl Wrinkled {
    pub fn read(
        _decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self(Octaves::read(params, pos, ctx)?))
    }
}

impl TextureType for Wrinkled {
    fn name(&self) -> &'static str {
        "wrinkled"
    }

    fn eval(&self, at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        let o = &self.0;
        Vec3::splat(turbulence(o.mapping.map(at), o.roughness, o.octaves))
    }
}
