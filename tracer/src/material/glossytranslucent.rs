//! `Material "glossytranslucent"`: a diffuse sheet that reflects Kd and transmits Kt, with a
//! glossy coat on each face (leaves, paper, lampshades).
//!
//! ```text
//! Material "glossytranslucent" "color Kd" [0.2 0.5 0.1] "color Kt" [0.4 0.8 0.2]
//!     "color Ks" [0.04 0.04 0.04] "float uroughness" [0.1] "float vroughness" [0.1]
//!     "bool onesided" ["false"] "color backface_Ks" [0.01 0.01 0.01]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kd` | color texture, diffuse reflectance, clamped to [0, 1] | 1 ([`DEFAULT_KD`]) |
//! | `Kt` | color texture, diffuse transmittance, clamped to [0, 1]; scaled by 1 - Kd | 1 ([`DEFAULT_KT`]) |
//! | `Ks`, `index`, `Ka`, `d`, `uroughness`, `vroughness`, `multibounce` | the front coat, as [`glossy`](super::glossy)'s | Ks 1, roughness 0.1 |
//! | `onesided` | bool: the back face has the front's coat | true |
//! | `backface_Ks`, `backface_index`, `backface_Ka`, `backface_d`, `backface_uroughness`, `backface_vroughness`, `backface_multibounce` | the back coat when `onesided` is false | Ks 0 ([`DEFAULT_BACKFACE_KS`]), roughness 0 ([`DEFAULT_BACKFACE_ROUGHNESS`]), the rest as glossy |
//!
//! Light crossing the sheet passes the coat of the face it enters and the coat of the face it
//! leaves (see [`coat_over_base`](crate::bxdf::coat_over_base)); what Kd reflects is not transmitted, as in
//! LuxRender's Kt (1 - Kd).

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use super::glossy::{CoatParams, DEFAULT_KS, DEFAULT_ROUGHNESS};
use crate::bxdf::coat_over_base::Coating;
use crate::bxdf::diffuse::OrenNayar;
use crate::bxdf::translucent::DiffuseTranslucent;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KD: f32 = 1.0;
pub const DEFAULT_KT: f32 = 1.0;
pub const DEFAULT_BACKFACE_KS: f32 = 0.0;
pub const DEFAULT_BACKFACE_ROUGHNESS: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct GlossyTranslucent {
    pub kd: ConstOrTexture,
    pub kt: ConstOrTexture,
    pub front: CoatParams,
    /// None: the back face has the front's coat (`onesided`).
    pub back: Option<CoatParams>,
}

impl GlossyTranslucent {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let kd = ctx.color_param(params, "Kd", DEFAULT_KD, true)?;
        let kt = ctx.color_param(params, "Kt", DEFAULT_KT, true)?;
        let front = CoatParams::read(params, pos, ctx, "", DEFAULT_KS, DEFAULT_ROUGHNESS)?;
        let back = if params.bool("onesided", true)? {
            for p in &params.params {
                if p.name.starts_with("backface_") {
                    params.ignore(&p.name);
                }
            }
            None
        } else {
            Some(CoatParams::read(
                params,
                pos,
                ctx,
                "backface_",
                DEFAULT_BACKFACE_KS,
                DEFAULT_BACKFACE_ROUGHNESS,
            )?)
        };
        Ok(Self {
            kd,
            kt,
            front,
            back,
        })
    }
}

impl MaterialKind for GlossyTranslucent {
    fn textures(&self) -> Vec<TextureId> {
        let mut params = vec![&self.kd, &self.kt];
        params.extend(self.front.textures());
        if let Some(b) = &self.back {
            params.extend(b.textures());
        }
        texture_ids(&params)
    }

    /// The diffuse sheet under the coats.
    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        let r = eval.color(self.kd);
        Bxdf::Translucent(DiffuseTranslucent {
            r,
            t: eval.color(self.kt) * (Vec3::ONE - r),
            roughness: OrenNayar::new(0.0),
        })
    }

    fn coating(&self, eval: &HitTextures) -> Option<Coating> {
        let front = self.front.coat(eval);
        Some(Coating {
            front,
            back: self.back.as_ref().map_or(front, |b| b.coat(eval)),
            diffuse_base: true,
        })
    }

    fn multibounce(&self) -> bool {
        self.front.multibounce || self.back.as_ref().is_some_and(|b| b.multibounce)
    }
}
