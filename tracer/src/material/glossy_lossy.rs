//! `Material "glossy_lossy"`, and its older names `substrate` (LuxRender 0.x) and `plastic`
//! (pbrt's, which LuxRender 1.x reads as this): LuxRender's Glossy before Glossy2, a
//! [`FresnelBlend`] of a diffuse and a glossy reflection with an optional absorbing layer.
//!
//! ```text
//! Material "substrate" "color Kd" [0.6 0.1 0.1] "color Ks" [0.06 0.06 0.06]
//!     "float uroughness" [0.1] "float vroughness" [0.1]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kd` | color texture, clamped to [0, 1] | 1 ([`DEFAULT_KD`]) |
//! | `Ks` | color texture, the glossy normal-incidence reflectance | 1 ([`DEFAULT_KS`]) |
//! | `index` | float | 0; > 0 multiplies Ks by ((index-1)/(index+1))^2, as glossy's |
//! | `Ka` | color texture, the layer's absorption, clamped to [0, 1] | 0 ([`DEFAULT_KA`]) |
//! | `d` | float texture, the layer's depth | 0 ([`DEFAULT_DEPTH`]) |
//! | `uroughness`, `vroughness` | float textures | 0.1 ([`DEFAULT_ROUGHNESS`]) |
//!
//! Ks is clamped to [0, 1] after the index is folded in. pbrt's `plastic` had a single
//! `roughness`, which LuxRender 1.x does not read (and neither does this).

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::glossy::read_ks;
use super::kind::MaterialKind;
use crate::bxdf::fresnel_blend::FresnelBlend;
use crate::bxdf::microfacet::TrowbridgeReitz;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, TextureId};

pub const DEFAULT_KD: f32 = 1.0;
pub const DEFAULT_KS: f32 = 1.0;
pub const DEFAULT_KA: f32 = 0.0;
pub const DEFAULT_DEPTH: f32 = 0.0;
pub const DEFAULT_ROUGHNESS: f32 = 0.1;

#[derive(Clone, Debug, PartialEq)]
pub struct GlossyLossy {
    pub kd: ConstOrTexture,
    pub ks: ConstOrTexture,
    pub ka: ConstOrTexture,
    pub depth: ConstOrTexture,
    pub uroughness: ConstOrTexture,
    pub vroughness: ConstOrTexture,
}

impl GlossyLossy {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kd: ctx.color_param(params, "Kd", DEFAULT_KD, true)?,
            ks: read_ks(params, pos, ctx, "", DEFAULT_KS)?,
            ka: ctx.color_param(params, "Ka", DEFAULT_KA, true)?,
            depth: ctx.float_param(params, "d", DEFAULT_DEPTH)?,
            uroughness: ctx.float_param(params, "uroughness", DEFAULT_ROUGHNESS)?,
            vroughness: ctx.float_param(params, "vroughness", DEFAULT_ROUGHNESS)?,
        })
    }
}

impl MaterialKind for GlossyLossy {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[
            &self.kd,
            &self.ks,
            &self.ka,
            &self.depth,
            &self.uroughness,
            &self.vroughness,
        ])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        let unit = |c: Vec3| c.clamp(Vec3::ZERO, Vec3::ONE);
        // LuxRender's old Glossy has no smooth limit: a zero roughness is the narrowest lobe.
        let distrib =
            TrowbridgeReitz::rough(eval.float(self.uroughness), eval.float(self.vroughness));
        Bxdf::FresnelBlend(FresnelBlend {
            rd: unit(eval.color(self.kd)),
            rs: unit(eval.color(self.ks)),
            absorption: unit(eval.color(self.ka)),
            depth: eval.float(self.depth),
            distrib,
        })
    }
}
