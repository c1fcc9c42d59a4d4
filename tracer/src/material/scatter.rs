//! `Material "scatter"`: a surface that scatters like a particle of a volume, into the whole
//! sphere (the [`scatter`](crate::bxdf::scatter) lobe).
//!
//! ```text
//! Material "scatter" "color Kd" [0.8 0.8 0.8] "color g" [0.3 0.3 0.3]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kd` | color texture, the albedo, clamped to [0, 1] | 0.9 ([`DEFAULT_KD`]) |
//! | `g` | color texture, the asymmetry per channel (-1 back, 0 isotropic, 1 forward), clamped to [-1, 1] | 0 ([`DEFAULT_G`]) |
//!
//! LuxRender does not clamp Kd here; YAT does, as for every reflectance, so that the surface
//! never scatters more than it receives.

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use crate::bxdf::scatter::Scatter as ScatterLobe;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_KD: f32 = 0.9;
pub const DEFAULT_G: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Scatter {
    pub kd: ConstOrTexture,
    pub g: ConstOrTexture,
}

impl Scatter {
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kd: ctx.color_param(params, "Kd", DEFAULT_KD, true)?,
            g: ctx.color_param(params, "g", DEFAULT_G, false)?,
        })
    }
}

impl MaterialKind for Scatter {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[&self.kd, &self.g])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        // The asymmetry may be negative: read it unclamped, then bound it to [-1, 1].
        let g = eval
            .textures
            .eval(self.g, &eval.at)
            .clamp(Vec3::splat(-1.0), Vec3::ONE);
        let g = Vec3::select(g.cmpeq(g), g, Vec3::ZERO);
        Bxdf::Scatter(ScatterLobe::new(eval.color(self.kd), g))
    }
}
