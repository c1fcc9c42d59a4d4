//! `Material "glossycoating"`: the Glossy2 coat over any other material (the
//! [`coat_over_base`](crate::bxdf::coat_over_base) composition).
//!
//! ```text
//! MakeNamedMaterial "lacquered" "string type" ["glossycoating"] "string basematerial" ["wood"]
//!     "color Ks" [0.04 0.04 0.04] "float uroughness" [0.02] "float vroughness" [0.02]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `basematerial` | string, a named material | the default matte; an undefined name warns |
//! | `Ks`, `index`, `Ka`, `d`, `uroughness`, `vroughness`, `multibounce` | as [`glossy`](super::glossy)'s coat | Ks 0.5 ([`DEFAULT_KS`]), the rest as glossy |
//!
//! The base is resolved per hit like a `mix`'s side ([`Materials`](super::Materials) does
//! it). A base that has a coat of its own (glossy, carpaint, glossytranslucent, another
//! glossycoating) keeps its lobes but loses that inner coat: one coat per surface.

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use super::matte::Matte;
use super::glossy::{CoatParams, DEFAULT_ROUGHNESS};
use crate::bxdf::Bxdf;
use crate::bxdf::coat_over_base::Coating;
use crate::diag::SourcePos;
use crate::refs::{MaterialId, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// LuxRender's glossycoating default Ks (glossy's is 1 in YAT).
pub const DEFAULT_KS: f32 = 0.5;

#[derive(Clone, Debug, PartialEq)]
pub struct GlossyCoating {
    pub base: MaterialId,
    pub coat: CoatParams,
}

impl GlossyCoating {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let base = match params.string("basematerial")? {
            Some(n) => ctx.named_material(&n, pos),
            None => ctx.default_material(),
        };
        Ok(Self {
            base,
            coat: CoatParams::read(params, pos, ctx, "", DEFAULT_KS, DEFAULT_ROUGHNESS)?,
        })
    }

    /// The coat over a base whose lobe is `diffuse` (Lambert) or not.
    pub fn coat_over(&self, eval: &HitTextures, diffuse: bool) -> Coating {
        Coating::two_sided(self.coat.coat(eval), diffuse)
    }
}

impl MaterialKind for GlossyCoating {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&self.coat.textures())
    }

    fn materials(&self) -> Vec<MaterialId> {
        vec![self.base]
    }

    /// Resolved with its base by [`super::Materials`]; alone it shows the default matte.
    fn bxdf(&self, _eval: &HitTextures, _u: f32) -> Bxdf {
        Matte::default_bxdf()
    }

    fn multibounce(&self) -> bool {
        self.coat.multibounce
    }
}
