//! `Material "mirror"`: a perfect specular reflector.
//!
//! ```text
//! Material "mirror" "color Kr" [0.9 0.9 0.9]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kr` | color texture (constants not clamped when read; clamped per hit) | 1 ([`DEFAULT_KR`]) |
//! | `film` | float | 0; thin-film interference is not supported (a warning otherwise) |

use super::eval::{texture_ids, HitTextures};
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
}

impl Mirror {
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        ctx.unsupported_unless(params, "film", 0.0);
        Ok(Self {
            kr: ctx.color_param(params, "Kr", DEFAULT_KR, false)?,
        })
    }
}

impl MaterialKind for Mirror {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[&self.kr])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        Bxdf::Conductor(Conductor {
            fresnel: ConductorFresnel::Constant(eval.color(self.kr)),
            distrib: None,
        })
    }
}
