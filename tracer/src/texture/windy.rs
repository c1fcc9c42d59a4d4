//! Wind-swept waves: small waves (6 octaves of fBm) whose height is modulated by a slowly
//! varying wind strength (3 octaves of fBm at a tenth of the frequency).
//!
//! ```text
//! Texture "name" "float" "windy" "vector scale" [0.5 0.5 0.5]
//! ```
//!
//! | parameter  | default | notes |
//! |------------|---------|-------|
//! | 3D mapping | global  | see [`super::mapping`]; windy has no other parameter |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::mapping::Mapping3D;
use super::noise::fbm;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

/// LuxRender's fixed wind and wave constants.
const WIND_FREQUENCY: f32 = 0.1;
const WIND_OCTAVES: u32 = 3;
const WAVE_OCTAVES: u32 = 6;
const OMEGA: f32 = 0.5;

#[derive(Clone, Debug, PartialEq)]
pub struct Windy {
    pub mapping: Mapping3D,
}

impl Windy {
    pub fn read(
        _decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            mapping: Mapping3D::read(params, pos, ctx)?,
        })
    }
}

impl TextureType for Windy {
    fn name(&self) -> &'static str {
        "windy"
    }

    fn eval(&self, at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        let p = self.mapping.map(at);
        let wind = fbm(WIND_FREQUENCY * p, OMEGA, WIND_OCTAVES);
        let waves = fbm(p, OMEGA, WAVE_OCTAVES);
        Vec3::splat(wind.abs() * waves)
    }
}
