//! `Material "glossy"` and `"glossy2"` (LuxRender's Glossy2): a Lambert base under a glossy
//! coat (the [`coat`](crate::bxdf::coat) layer, put together by
//! [`coat_over_base`](crate::bxdf::coat_over_base)). The coat's parameters are also glossycoating's and
//! glossytranslucent's ([`CoatParams`]).
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

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use crate::bxdf::coat::Coat;
use crate::bxdf::coat_over_base::Coating;
use crate::bxdf::diffuse::{DiffuseReflection, OrenNayar};
use crate::bxdf::microfacet::TrowbridgeReitz;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
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

/// The Glossy2 coat's parameters, shared by glossy, glossycoating and glossytranslucent (whose
/// back face reads them with the prefix `backface_`): Ks (already multiplied by
/// ((i-1)/(i+1))^2 when index > 0), absorption Ka with depth d, anisotropic roughness.
#[derive(Clone, Debug, PartialEq)]
pub struct CoatParams {
    pub ks: ConstOrTexture,
    pub ka: ConstOrTexture,
    pub depth: ConstOrTexture,
    pub uroughness: ConstOrTexture,
    pub vroughness: ConstOrTexture,
    pub multibounce: bool,
}

impl CoatParams {
    /// Reads `{prefix}Ks`, `{prefix}index`, `{prefix}Ka`, `{prefix}d`, `{prefix}uroughness`,
    /// `{prefix}vroughness` and `{prefix}multibounce`, with Ks and the roughnesses defaulting
    /// to `ks_default` and `roughness_default`.
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
        prefix: &str,
        ks_default: f32,
        roughness_default: f32,
    ) -> Result<Self, ParseError> {
        let name = |n: &str| format!("{prefix}{n}");
        let ks = read_ks(params, pos, ctx, prefix, ks_default)?;
        Ok(Self {
            ks,
            ka: ctx.color_param(params, &name("Ka"), DEFAULT_KA, true)?,
            depth: ctx.float_param(params, &name("d"), DEFAULT_DEPTH)?,
            uroughness: ctx.float_param(params, &name("uroughness"), roughness_default)?,
            vroughness: ctx.float_param(params, &name("vroughness"), roughness_default)?,
            multibounce: params.bool(&name("multibounce"), false)?,
        })
    }

    /// The coat at a hit.
    pub fn coat(&self, eval: &HitTextures) -> Coat {
        // Each roughness texture is read once: the lobe and the multibounce term share it.
        let (u, v) = (eval.float(self.uroughness), eval.float(self.vroughness));
        let distrib = TrowbridgeReitz::from_roughness(u, v);
        let multibounce_alpha = (self.multibounce && distrib.is_some())
            .then(|| (u.max(0.0) * v.max(0.0)).sqrt().clamp(0.0, 1.0));
        Coat::single(
            eval.color(self.ks),
            distrib,
            eval.color(self.ka),
            eval.float(self.depth),
            multibounce_alpha,
        )
    }

    pub fn textures(&self) -> Vec<&ConstOrTexture> {
        vec![
            &self.ks,
            &self.ka,
            &self.depth,
            &self.uroughness,
            &self.vroughness,
        ]
    }
}

/// Glossy2's `{prefix}Ks` with `{prefix}index` folded in (a positive index multiplies it by
/// ((index-1)/(index+1))^2, a textured Ks through a new scale texture; a textured index warns
/// and is ignored), a constant clamped to [0, 1]: also the specular reflectance of LuxRender's
/// older Glossy ([`super::glossy_lossy`]).
pub fn read_ks(
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
    prefix: &str,
    ks_default: f32,
) -> Result<ConstOrTexture, ParseError> {
    let name = |n: &str| format!("{prefix}{n}");
    let ks = ctx.color_param(params, &name("Ks"), ks_default, false)?;
    let index = ctx.float_param(params, &name("index"), DEFAULT_INDEX)?;
    let ks = match index {
        ConstOrTexture::Const(i) if i.x > 0.0 => {
            let f = ((i.x - 1.0) / (i.x + 1.0)).powi(2);
            match ks {
                ConstOrTexture::Const(c) => ConstOrTexture::Const(c * f),
                ConstOrTexture::Texture(id) => ConstOrTexture::Texture(ctx.scaled_texture(id, f)),
            }
        }
        ConstOrTexture::Const(_) => ks,
        ConstOrTexture::Texture(_) => {
            ctx.warn(
                pos,
                format!(
                    "{}: a textured \"{}\" is not supported; Ks is used as given",
                    params.statement,
                    name("index")
                ),
            );
            ks
        }
    };
    Ok(match ks {
        ConstOrTexture::Const(c) => ConstOrTexture::Const(c.clamp(Vec3::ZERO, Vec3::ONE)),
        t => t,
    })
}

/// A Lambert base Kd under a [`CoatParams`] coat.
#[derive(Clone, Debug, PartialEq)]
pub struct Glossy {
    pub kd: ConstOrTexture,
    pub coat: CoatParams,
}

impl Glossy {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let kd = ctx.color_param(params, "Kd", DEFAULT_KD, true)?;
        let coat = CoatParams::read(params, pos, ctx, "", DEFAULT_KS, DEFAULT_ROUGHNESS)?;
        ctx.unsupported_unless(params, "sigma", 0.0);
        Ok(Self { kd, coat })
    }
}

impl MaterialKind for Glossy {
    fn textures(&self) -> Vec<TextureId> {
        let mut params = vec![&self.kd];
        params.extend(self.coat.textures());
        texture_ids(&params)
    }

    /// The base under the coat.
    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        Bxdf::Diffuse(DiffuseReflection {
            r: eval.color(self.kd),
            roughness: OrenNayar::new(0.0),
        })
    }

    fn coating(&self, eval: &HitTextures) -> Option<Coating> {
        Some(Coating::two_sided(self.coat.coat(eval), true))
    }

    fn multibounce(&self) -> bool {
        self.coat.multibounce
    }
}
