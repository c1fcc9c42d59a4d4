//! `Material "mirror"`: a perfect specular reflector.
//!
//! ```text
//! Material "mirror" "color Kr" [0.9 0.9 0.9]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kr` | color texture (constants not clamped when read; clamped per hit) | 1 ([`DEFAULT_KR`]) |
//! | `film`, `filmindex` | float textures | thin-film interference on the reflection ([`super::film`]) |

use super::eval::{texture_ids, HitTextures};
use super::film::FilmParams;
use super::kind::MaterialKind;
use crate::bxdf::conductor::{Conductor, ConductorFresnel};
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KR: f32 = 1.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Mirror {
    pub kr: ConstOrTexture,
    pub film: FilmParams,
}

impl Mirror {
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kr: ctx.color_param(params, "Kr", DEFAULT_KR, false)?,
            film: FilmParams::read(params, ctx)?,
        })
    }
}

impl MaterialKind for Mirror {
    fn textures(&self) -> Vec<TextureId> {
        let [film, index] = self.film.textures();
        texture_ids(&[&self.kr, film, index])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        Bxdf::Conductor(Conductor {
            fresnel: ConductorFresnel::Constant(eval.color(self.kr)),
            distrib: None,
            film: self.film.at(eval),
        })
    }
}
