//! `Material "mattetranslucent"`: a diffuse surface that also transmits diffusely.
//!
//! ```text
//! Material "mattetranslucent" "color Kr" [0.5 0.5 0.5] "color Kt" [0.3 0.3 0.3]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kr` | color texture, clamped to [0, 1] | 1 ([`DEFAULT_KR`]) |
//! | `Kt` | color texture, clamped to [0, 1] | 1 ([`DEFAULT_KT`]) |
//! | `sigma` | float texture, degrees | 0 ([`DEFAULT_SIGMA`]) |
//! | `energyconserving` | bool | false in LuxRender, which then transmits Kt unscaled; YAT always scales Kt by 1 - Kr, so false (or absent) with both Kr and Kt non-zero is a warning |

use glam::Vec3;

use super::eval::{texture_ids, TextureEval};
use crate::bxdf::diffuse::{DiffuseTranslucent, OrenNayar};
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::param::{Tex, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KR: f32 = 1.0;
pub const DEFAULT_KT: f32 = 1.0;
/// Oren-Nayar sigma in degrees (0 is Lambertian).
pub const DEFAULT_SIGMA: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct MatteTranslucent {
    pub kr: Tex,
    pub kt: Tex,
    pub sigma: Tex,
}

impl MatteTranslucent {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let m = Self {
            kr: ctx.color_param(params, "Kr", DEFAULT_KR, true)?,
            kt: ctx.color_param(params, "Kt", DEFAULT_KT, true)?,
            sigma: ctx.float_param(params, "sigma", DEFAULT_SIGMA)?,
        };
        // Scaling by 1 - Kr changes nothing only when either colour is black.
        let black = |t: &Tex| matches!(t, Tex::Const(c) if *c == Vec3::ZERO);
        if !params.bool("energyconserving", false)? && !black(&m.kr) && !black(&m.kt) {
            let pos = params.find("energyconserving").map_or(pos, |p| &p.pos);
            ctx.warn(
                pos,
                "Material \"mattetranslucent\": without \"energyconserving\" LuxRender transmits Kt as given; YAT always scales it by 1 - Kr".into(),
            );
        }
        Ok(m)
    }

    pub fn bxdf(&self, eval: &TextureEval) -> Bxdf {
        let r = eval.color(self.kr);
        // LuxRender's "energyconserving" rule, always on: what is reflected cannot also be
        // transmitted.
        let t = eval.color(self.kt) * (Vec3::ONE - r);
        Bxdf::Translucent(DiffuseTranslucent {
            r,
            t,
            roughness: OrenNayar::new(eval.float(self.sigma)),
        })
    }

    pub fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[&self.kr, &self.kt, &self.sigma])
    }
}
