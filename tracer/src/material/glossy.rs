//! `Material "glossy"` and `"glossy2"` (LuxRender's Glossy2): a diffuse base under a glossy
//! coat (the [`coated`](crate::bxdf::coated) lobe).
//!
//! ```text
//! Material "glossy" "color Kd" [0.5 0.1 0.1] "color Ks" [0.04 0.04 0.04]
//!     "float uroughness" [0.05] "float vroughness" [0.05]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kd` | color texture, clamped to [0, 1] | 1 ([`DEFAULT_KD`]) |
//! | `Ks` | color texture, the coat's normal-incidence reflectance | 1 ([`DEFAULT_KS`]) |
//! | `index` | float | 0 ([`DEFAULT_INDEX`]); > 0 multiplies Ks by ((index-1)/(index+1))^2 (a textured Ks through a new scale texture); a textured index warns and is ignored |
//! | `Ka` | color texture, coat absorption, clamped to [0, 1] | 0 ([`DEFAULT_KA`]) |
//! | `d` | float texture, coat thickness | 0 ([`DEFAULT_DEPTH`]) |
//! | `uroughness`, `vroughness` | float textures | 0.1 ([`DEFAULT_ROUGHNESS`]) |
//! | `multibounce` | bool | false |
//! | `sigma` | float | 0; Oren-Nayar base is not supported (a warning otherwise) |
//!
//! A constant Ks is clamped to [0, 1] after the index is folded in.

use glam::Vec3;

use super::eval::{texture_ids, TextureEval};
use crate::bxdf::coated::Coated;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::param::{Tex, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KD: f32 = 1.0;
pub const DEFAULT_KS: f32 = 1.0;
pub const DEFAULT_KA: f32 = 0.0;
/// No index: Ks is used as given.
pub const DEFAULT_INDEX: f32 = 0.0;
pub const DEFAULT_DEPTH: f32 = 0.0;
pub const DEFAULT_ROUGHNESS: f32 = 0.1;

/// Kd, Ks (already multiplied by ((i-1)/(i+1))^2 when index > 0), absorption Ka with depth d,
/// anisotropic roughness.
#[derive(Clone, Debug, PartialEq)]
pub struct Glossy {
    pub kd: Tex,
    pub ks: Tex,
    pub ka: Tex,
    pub depth: Tex,
    pub uroughness: Tex,
    pub vroughness: Tex,
    pub multibounce: bool,
}

impl Glossy {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let kd = ctx.color_param(params, "Kd", DEFAULT_KD, true)?;
        let ks = ctx.color_param(params, "Ks", DEFAULT_KS, false)?;
        let ka = ctx.color_param(params, "Ka", DEFAULT_KA, true)?;
        let index = ctx.float_param(params, "index", DEFAULT_INDEX)?;
        let ks = match index {
            Tex::Const(i) if i.x > 0.0 => {
                let f = ((i.x - 1.0) / (i.x + 1.0)).powi(2);
                match ks {
                    Tex::Const(c) => Tex::Const(c * f),
                    Tex::Texture(id) => Tex::Texture(ctx.scaled_texture(id, f)),
                }
            }
            Tex::Const(_) => ks,
            Tex::Texture(_) => {
                ctx.warn(
                    pos,
                    format!(
                        "{}: a textured \"index\" is not supported; Ks is used as given",
                        params.statement
                    ),
                );
                ks
            }
        };
        let ks = match ks {
            Tex::Const(c) => Tex::Const(c.clamp(Vec3::ZERO, Vec3::ONE)),
            t => t,
        };
        ctx.unsupported_unless(params, "sigma", 0.0);
        Ok(Self {
            kd,
            ks,
            ka,
            depth: ctx.float_param(params, "d", DEFAULT_DEPTH)?,
            uroughness: ctx.float_param(params, "uroughness", DEFAULT_ROUGHNESS)?,
            vroughness: ctx.float_param(params, "vroughness", DEFAULT_ROUGHNESS)?,
            multibounce: params.bool("multibounce", false)?,
        })
    }

    pub fn bxdf(&self, eval: &TextureEval) -> Bxdf {
        let distrib = eval.roughness(self.uroughness, self.vroughness);
        let multibounce_alpha = match (self.multibounce, distrib) {
            (true, Some(_)) => {
                let (u, v) = (eval.float(self.uroughness), eval.float(self.vroughness));
                Some((u.max(0.0) * v.max(0.0)).sqrt().clamp(0.0, 1.0))
            }
            _ => None,
        };
        Bxdf::Coated(Coated {
            kd: eval.color(self.kd),
            ks: eval.color(self.ks),
            ka: eval.color(self.ka),
            depth: eval.float(self.depth).max(0.0),
            distrib,
            multibounce_alpha,
        })
    }

    pub fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[
            &self.kd,
            &self.ks,
            &self.ka,
            &self.depth,
            &self.uroughness,
            &self.vroughness,
        ])
    }
}
