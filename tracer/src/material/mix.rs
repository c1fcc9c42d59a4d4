//! `Material "mix"`: one of two named materials, chosen per hit with probability `amount`
//! for the second (a stochastic blend: the image converges to the weighted mix).
//!
//! ```text
//! MakeNamedMaterial "rusty" "string type" ["mix"] "string namedmaterial1" ["paint"]
//!     "string namedmaterial2" ["rust"] "texture amount" "rustmask"
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `namedmaterial1` | string, a named material | the default matte |
//! | `namedmaterial2` | string, a named material | the default matte |
//! | `amount` | float texture, weight of `namedmaterial2`, clamped to [0, 1] per hit | 0.5 ([`DEFAULT_AMOUNT`]) |
//!
//! An undefined name warns and uses the default matte. The resolution down to a leaf material
//! is [`Materials`](super::Materials)' (it needs the other materials).

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use super::matte::Matte;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{MaterialId, ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_AMOUNT: f32 = 0.5;

#[derive(Clone, Debug, PartialEq)]
pub struct Mix {
    pub a: MaterialId,
    pub b: MaterialId,
    /// Weight of `b`.
    pub amount: ConstOrTexture,
}

impl Mix {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let a = params.string("namedmaterial1")?;
        let b = params.string("namedmaterial2")?;
        let a = match a {
            Some(n) => ctx.named_material(&n, pos),
            None => ctx.default_material(),
        };
        let b = match b {
            Some(n) => ctx.named_material(&n, pos),
            None => ctx.default_material(),
        };
        Ok(Self {
            a,
            b,
            amount: ctx.float_param(params, "amount", DEFAULT_AMOUNT)?,
        })
    }

    /// One level of the resolution: `u` chooses a side against the amount and is rescaled to
    /// [0, 1) within the chosen side, so nested mixes draw on the same number without
    /// correlation between levels. Returns the chosen material and the rescaled number.
    pub fn choose(&self, eval: &HitTextures, u: f32) -> (MaterialId, f32) {
        let mut u = u;
        let amount = eval.float(self.amount).clamp(0.0, 1.0);
        let next = if u < amount {
            u /= amount;
            self.b
        } else {
            u = (u - amount) / (1.0 - amount);
            self.a
        };
        u = u.clamp(0.0, 1.0 - f32::EPSILON);
        (next, u)
    }
}

impl MaterialKind for Mix {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[&self.amount])
    }

    /// The materials it mixes.
    fn materials(&self) -> Vec<MaterialId> {
        vec![self.a, self.b]
    }

    /// Resolved to one of its materials by [`super::Materials`]; alone it shows the default
    /// matte.
    fn bxdf(&self, _eval: &HitTextures, _u: f32) -> Bxdf {
        Matte::default_bxdf()
    }
}
