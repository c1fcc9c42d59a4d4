//! `Material "metal"` and `"metal2"`: a microfacet conductor (a specular one at zero
//! roughness).
//!
//! ```text
//! Material "metal" "string name" ["gold"] "float uroughness" [0.05] "float vroughness" [0.05]
//! Material "metal2" "texture fresnel" "gold_fresnel" "float uroughness" [0.05]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `name` (metal) | string, a built-in preset or an `.nk` data file ([`nk`]; `filename` takes precedence) | "aluminium" ([`DEFAULT_PRESET`]); an unknown name or unreadable file warns and uses aluminium, a malformed file is an error |
//! | `fresnel` (metal2) | fresnel texture, float texture or float (an index), or color (normal-incidence reflectance) | index 5 ([`DEFAULT_METAL2_INDEX`]) |
//! | `Kr` (metal2, without `fresnel`) | color texture: normal-incidence reflectance | - |
//! | `uroughness`, `vroughness` | float textures | 0.1 ([`DEFAULT_ROUGHNESS`]) |
//!
//! A complex index (presets, `fresnelname` textures) uses the conductor Fresnel equations; an
//! index alone a conductor without absorption (a dispersive fresnel texture's, `cauchy`,
//! `sellmeier`..., at its mean index); a reflectance colour Schlick's approximation.

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use super::nk;
use crate::assets::AssetKind;
use crate::bxdf::conductor::{Conductor, ConductorFresnel};
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{Fresnel, ConstOrTexture, TextureId};
use crate::parse::context::{ParseContext, BoundTexture};
use crate::parse::error::ParseError;
use crate::parse::params::{ParamList, ParamType, ConstOrTextureName};

pub const DEFAULT_PRESET: &str = "aluminium";
/// LuxRender's metal2 default Fresnel term: index 5, no absorption.
pub const DEFAULT_METAL2_INDEX: f32 = 5.0;
pub const DEFAULT_ROUGHNESS: f32 = 0.1;

/// metal and metal2 both become a microfacet conductor.
#[derive(Clone, Debug, PartialEq)]
pub struct Metal {
    pub fresnel: Fresnel,
    pub uroughness: ConstOrTexture,
    pub vroughness: ConstOrTexture,
}

impl Metal {
    /// `Material "metal"`: a named preset.
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let name = match params.string("filename")? {
            Some(f) => f,
            None => params.string_or("name", DEFAULT_PRESET)?,
        };
        let (eta, k) = if name.to_ascii_lowercase().ends_with(".nk") {
            read_nk(&name, pos, ctx)?
        } else {
            ctx.metal_by_name(&name, pos)
        };
        Ok(Self {
            fresnel: Fresnel::Conductor { eta, k },
            uroughness: ctx.float_param(params, "uroughness", DEFAULT_ROUGHNESS)?,
            vroughness: ctx.float_param(params, "vroughness", DEFAULT_ROUGHNESS)?,
        })
    }

    /// `Material "metal2"`.
    pub fn read_metal2(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            fresnel: metal2_fresnel(params, ctx)?,
            uroughness: ctx.float_param(params, "uroughness", DEFAULT_ROUGHNESS)?,
            vroughness: ctx.float_param(params, "vroughness", DEFAULT_ROUGHNESS)?,
        })
    }
}

impl MaterialKind for Metal {
    fn textures(&self) -> Vec<TextureId> {
        let fresnel = match &self.fresnel {
            Fresnel::Reflectance(x) | Fresnel::Index(x) => Some(x),
            Fresnel::Conductor { .. } | Fresnel::Dispersive(_) => None,
        };
        let mut params: Vec<&ConstOrTexture> = fresnel.into_iter().collect();
        params.extend([&self.uroughness, &self.vroughness]);
        texture_ids(&params)
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        let fresnel = match &self.fresnel {
            &Fresnel::Conductor { eta, k } => ConductorFresnel::Complex { eta, k },
            Fresnel::Dispersive(curve) => ConductorFresnel::Complex {
                eta: Vec3::splat(curve.mean().max(1e-3)),
                k: Vec3::ZERO,
            },
            &Fresnel::Index(index) => ConductorFresnel::Complex {
                eta: Vec3::splat(eval.float(index).max(1e-3)),
                k: Vec3::ZERO,
            },
            &Fresnel::Reflectance(r0) => ConductorFresnel::Schlick { r0: eval.color(r0) },
        };
        Bxdf::Conductor(Conductor {
            fresnel,
            distrib: eval.roughness(self.uroughness, self.vroughness),
            film: None,
        })
    }
}

/// The complex index of an `.nk` file. As in LuxRender, a file that cannot be read warns and
/// gives aluminium; one that is malformed is an error naming the file and line.
fn read_nk(
    name: &str,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<(Vec3, Vec3), ParseError> {
    let bytes = match ctx.read_asset(name, AssetKind::Nk, pos) {
        Ok(bytes) => bytes,
        Err(ParseError::Asset { error, .. }) => {
            ctx.note(
                pos,
                format!("metal data file \"{name}\" cannot be read ({error}); using aluminium"),
            );
            return Ok(ctx.metal_by_name(DEFAULT_PRESET, pos));
        }
        Err(e) => return Err(e),
    };
    nk::read(&bytes).map_err(|e| ParseError::Invalid {
        pos: pos.clone(),
        message: match e.line {
            0 => format!("metal data file \"{name}\": {}", e.message),
            line => format!("metal data file \"{name}\" line {line}: {}", e.message),
        },
    })
}

/// metal2's Fresnel term: `texture fresnel` (a fresnel texture, or a float texture giving an
/// index), `float fresnel` (an index), the course's `color fresnel` and `color Kr`
/// (normal-incidence reflectance); LuxRender's default is index 5.
fn metal2_fresnel(params: &ParamList, ctx: &mut dyn ParseContext) -> Result<Fresnel, ParseError> {
    if let Some(p) = params.find("fresnel") {
        if p.ty == ParamType::Color {
            return Ok(Fresnel::Reflectance(
                ctx.color_param(params, "fresnel", 1.0, true)?,
            ));
        }
        return Ok(match params.tex_float("fresnel", DEFAULT_METAL2_INDEX)? {
            ConstOrTextureName::Const(c) => Fresnel::Index(ConstOrTexture::Const(c)),
            ConstOrTextureName::Named { name, pos } => match ctx.find_texture(&name, true) {
                Some(BoundTexture::Fresnel(f)) => f,
                Some(BoundTexture::Texture(id)) if !ctx.texture_is_color(id) => {
                    Fresnel::Index(ConstOrTexture::Texture(id))
                }
                Some(BoundTexture::Texture(id)) => Fresnel::Reflectance(ConstOrTexture::Texture(id)),
                None => {
                    ctx.warn(
                        &pos,
                        format!("no fresnel texture named \"{name}\"; using index 5"),
                    );
                    Fresnel::Index(ConstOrTexture::float(DEFAULT_METAL2_INDEX))
                }
            },
        });
    }
    if params.count("Kr").is_some() {
        return Ok(Fresnel::Reflectance(
            ctx.color_param(params, "Kr", 1.0, true)?,
        ));
    }
    Ok(Fresnel::Index(ConstOrTexture::float(DEFAULT_METAL2_INDEX)))
}
