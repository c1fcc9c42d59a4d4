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
//! | `energyconserving` | bool | false: Kt is transmitted as given, so Kr + Kt may exceed 1 as in LuxRender 1.x; true scales Kt by 1 - Kr (what is reflected cannot also be transmitted) |

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use crate::bxdf::diffuse::OrenNayar;
use crate::bxdf::translucent::DiffuseTranslucent;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KR: f32 = 1.0;
pub const DEFAULT_KT: f32 = 1.0;
/// Oren-Nayar sigma in degrees (0 is Lambertian).
pub const DEFAULT_SIGMA: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct MatteTranslucent {
    pub kr: ConstOrTexture,
    pub kt: ConstOrTexture,
    pub sigma: ConstOrTexture,
    pub energy_conserving: bool,
}

impl MatteTranslucent {
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kr: ctx.color_param(params, "Kr", DEFAULT_KR, true)?,
            kt: ctx.color_param(params, "Kt", DEFAULT_KT, true)?,
            sigma: ctx.float_param(params, "sigma", DEFAULT_SIGMA)?,
            energy_conserving: params.bool("energyconserving", false)?,
        })
    }
}

impl MaterialKind for MatteTranslucent {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[&self.kr, &self.kt, &self.sigma])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        let r = eval.color(self.kr);
        let kt = eval.color(self.kt);
        let t = if self.energy_conserving {
            kt * (Vec3::ONE - r)
        } else {
            kt
        };
        Bxdf::Translucent(DiffuseTranslucent {
            r,
            t,
            roughness: OrenNayar::new(eval.float(self.sigma)),
        })
    }
}
