//! `Material "velvet"`: a thin layer of fibres that scatter light once (the
//! [`velvet`](crate::bxdf::velvet) lobe: asperity scattering).
//!
//! ```text
//! Material "velvet" "color Kd" [0.5 0.1 0.1] "float thickness" [0.1]
//!     "float p1" [-2] "float p2" [20] "float p3" [2]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kd` | color texture, the fibres' albedo, clamped to [0, 1] | 0.3 ([`DEFAULT_KD`]) |
//! | `p1`, `p2`, `p3` | float textures, Legendre coefficients of the phase function, clamped to [-100, 100] | -2, 20, 2 ([`DEFAULT_P`]) |
//! | `thickness` | float texture, the layer's optical depth, clamped to [0, 1] | 0.1 ([`DEFAULT_THICKNESS`]) |

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use crate::bxdf::velvet::Velvet as VelvetLobe;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KD: f32 = 0.3;
pub const DEFAULT_P: [f32; 3] = [-2.0, 20.0, 2.0];
pub const DEFAULT_THICKNESS: f32 = 0.1;
/// LuxRender's bound on |p1|, |p2|, |p3|.
pub const MAX_P: f32 = 100.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Velvet {
    pub kd: ConstOrTexture,
    pub p: [ConstOrTexture; 3],
    pub thickness: ConstOrTexture,
}

impl Velvet {
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kd: ctx.color_param(params, "Kd", DEFAULT_KD, true)?,
            p: [
                ctx.float_param(params, "p1", DEFAULT_P[0])?,
                ctx.float_param(params, "p2", DEFAULT_P[1])?,
                ctx.float_param(params, "p3", DEFAULT_P[2])?,
            ],
            thickness: ctx.float_param(params, "thickness", DEFAULT_THICKNESS)?,
        })
    }
}

impl MaterialKind for Velvet {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[
            &self.kd,
            &self.p[0],
            &self.p[1],
            &self.p[2],
            &self.thickness,
        ])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        let p = self.p.map(|t| eval.float(t).clamp(-MAX_P, MAX_P));
        Bxdf::Velvet(VelvetLobe::new(
            eval.color(self.kd),
            p,
            eval.float(self.thickness).clamp(0.0, 1.0),
        ))
    }
}
