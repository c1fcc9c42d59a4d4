//! `Material "shinymetal"`: a mirror reflection over a glossy metal, the two added (LuxRender's
//! ShinyMetal: specular reflection coloured by Kr plus microfacet reflection coloured by Ks).
//!
//! ```text
//! Material "shinymetal" "color Kr" [0.8 0.8 0.8] "color Ks" [0.4 0.4 0.4]
//!     "float uroughness" [0.05] "float vroughness" [0.05]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kr` | color texture, the mirror reflection's normal-incidence reflectance, clamped to [0, 1] | 1 ([`DEFAULT_KR`]) |
//! | `Ks` | color texture, the glossy reflection's, clamped to [0, 1] | 1 ([`DEFAULT_KS`]) |
//! | `uroughness`, `vroughness` | float textures | 0.1 ([`DEFAULT_ROUGHNESS`]) |
//! | `film`, `filmindex` | float textures | thin-film interference on the mirror reflection, as LuxRender's ([`super::film`]) |
//!
//! LuxRender adds the two lobes, each with a conductor Fresnel term that tends to 1 at grazing
//! angles, so the surface reflects up to twice what arrives. Here the lobes are mixed like a
//! `mix` material, chosen per hit in proportion to their strengths |Kr| and |Ks| (largest
//! channel) and each scaled so that the sum reflects Kr + Ks at normal incidence when that is
//! at most 1 (exactly LuxRender's value there), and in proportion otherwise. Both use
//! Schlick's Fresnel from their colour, which LuxRender's approximate complex index from a
//! reflectance follows closely.

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::film::FilmParams;
use super::kind::MaterialKind;
use crate::bxdf::conductor::{Conductor, ConductorFresnel};
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KR: f32 = 1.0;
pub const DEFAULT_KS: f32 = 1.0;
pub const DEFAULT_ROUGHNESS: f32 = 0.1;

#[derive(Clone, Debug, PartialEq)]
pub struct ShinyMetal {
    pub kr: ConstOrTexture,
    pub ks: ConstOrTexture,
    pub uroughness: ConstOrTexture,
    pub vroughness: ConstOrTexture,
    pub film: FilmParams,
}

impl ShinyMetal {
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kr: ctx.color_param(params, "Kr", DEFAULT_KR, true)?,
            ks: ctx.color_param(params, "Ks", DEFAULT_KS, true)?,
            uroughness: ctx.float_param(params, "uroughness", DEFAULT_ROUGHNESS)?,
            vroughness: ctx.float_param(params, "vroughness", DEFAULT_ROUGHNESS)?,
            film: FilmParams::read(params, ctx)?,
        })
    }
}

impl MaterialKind for ShinyMetal {
    fn textures(&self) -> Vec<TextureId> {
        let [film, index] = self.film.textures();
        texture_ids(&[
            &self.kr,
            &self.ks,
            &self.uroughness,
            &self.vroughness,
            film,
            index,
        ])
    }

    /// The lobe chosen by `u` in [0, 1): the mirror or the glossy metal.
    fn bxdf(&self, eval: &HitTextures, u: f32) -> Bxdf {
        let (kr, ks) = (eval.color(self.kr), eval.color(self.ks));
        let (sr, ss) = (kr.max_element(), ks.max_element());
        if sr + ss <= 0.0 {
            return Bxdf::Conductor(Conductor {
                fresnel: ConductorFresnel::Constant(Vec3::ZERO),
                distrib: None,
                film: None,
            });
        }
        let total = (sr + ss).max(1.0);
        let w_mirror = sr / (sr + ss);
        if u < w_mirror {
            Bxdf::Conductor(Conductor {
                fresnel: ConductorFresnel::Schlick {
                    r0: (kr / (total * w_mirror)).min(Vec3::ONE),
                },
                distrib: None,
                film: self.film.at(eval),
            })
        } else {
            Bxdf::Conductor(Conductor {
                fresnel: ConductorFresnel::Schlick {
                    r0: (ks / (total * (1.0 - w_mirror))).min(Vec3::ONE),
                },
                distrib: eval.roughness(self.uroughness, self.vroughness),
                film: None,
            })
        }
    }
}
