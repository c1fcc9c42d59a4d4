//! `Material "matte"`: a diffuse surface, Lambertian or (with sigma) Oren-Nayar.
//!
//! ```text
//! Material "matte" "color Kd" [0.5 0.5 0.5] "float sigma" [10]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `Kd` | color texture, clamped to [0, 1] | 0.9 ([`DEFAULT_KD`]) |
//! | `sigma` | float texture, degrees | 0 ([`DEFAULT_SIGMA`]) |
//!
//! With [`DEFAULT_KD`] it is also LuxRender's default material: what a shape without a material,
//! a dangling material name, an unsupported material type and an unresolvable mix show.

use glam::Vec3;

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use crate::bxdf::diffuse::{DiffuseReflection, OrenNayar};
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// The diffuse reflectance of `matte`, and of the default material.
pub const DEFAULT_KD: f32 = 0.9;
/// Oren-Nayar sigma in degrees (0 is Lambertian).
pub const DEFAULT_SIGMA: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Matte {
    pub kd: ConstOrTexture,
    /// Oren-Nayar sigma in degrees.
    pub sigma: ConstOrTexture,
}

impl Default for Matte {
    /// LuxRender's default material.
    fn default() -> Self {
        Self {
            kd: ConstOrTexture::color(Vec3::splat(DEFAULT_KD)),
            sigma: ConstOrTexture::float(DEFAULT_SIGMA),
        }
    }
}

impl Matte {
    pub fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kd: ctx.color_param(params, "Kd", DEFAULT_KD, true)?,
            sigma: ctx.float_param(params, "sigma", DEFAULT_SIGMA)?,
        })
    }

    /// What a hit on an undefined material (an out-of-range id, or a mix cycle) shows: the
    /// default matte, without evaluating anything.
    pub fn default_bxdf() -> Bxdf {
        Bxdf::Diffuse(DiffuseReflection {
            r: Vec3::splat(DEFAULT_KD),
            roughness: OrenNayar::new(DEFAULT_SIGMA),
        })
    }
}

impl MaterialKind for Matte {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[&self.kd, &self.sigma])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        Bxdf::Diffuse(DiffuseReflection {
            r: eval.color(self.kd),
            roughness: OrenNayar::new(eval.float(self.sigma)),
        })
    }
}
