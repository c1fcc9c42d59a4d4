//! A colour ramp: a float texture `amount` picks a point on a piecewise-linear ramp through
//! textures placed at ascending offsets.
//!
//! ```text
//! Texture "name" "color"|"float" "band" "float offsets" [0 0.5 1] "float amount" 0.3
//!     "texture tex1" "a" "color tex2" [1 0 0] "color tex3" [0 0 1]
//! ```
//!
//! | parameter       | default  | notes |
//! |-----------------|----------|-------|
//! | `float offsets` | required | ascending (out of order is an error); one per `texN` |
//! | `texN`          | 0        | N = 1 .. number of offsets: texture or constant of the declared kind |
//! | `float amount`  | 0        | float texture or constant: below the first offset gives tex1, at or above the last gives the last texture |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use crate::diag::SourcePos;
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

pub const DEFAULT_TEX: f32 = 0.0;
pub const DEFAULT_AMOUNT: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    /// Ascending, at least one, as many as `textures`.
    pub offsets: Vec<f32>,
    pub textures: Vec<ConstOrTexture>,
    pub amount: ConstOrTexture,
}

impl Band {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let Some((offsets, param)) = params.floats("offsets")? else {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!("Texture \"{}\": band needs \"float offsets\"", decl.name),
            });
        };
        if offsets.is_empty() || offsets.windows(2).any(|w| w[0] > w[1]) {
            return Err(params.error(param, "the offsets must be ascending numbers, at least one"));
        }
        let textures = (1..=offsets.len())
            .map(|i| decl.tex(ctx, params, &format!("tex{i}"), DEFAULT_TEX))
            .collect::<Result<_, _>>()?;
        let amount = params.tex_float("amount", DEFAULT_AMOUNT)?;
        Ok(Self {
            offsets,
            textures,
            amount: ctx.tex(amount, false, Vec3::splat(DEFAULT_AMOUNT)),
        })
    }
}

impl TextureType for Band {
    fn name(&self) -> &'static str {
        "band"
    }

    fn references(&self) -> Vec<ConstOrTexture> {
        self.textures.iter().copied().chain([self.amount]).collect()
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        let a = textures.eval(self.amount, at).x;
        let (first, last) = (self.offsets[0], self.offsets[self.offsets.len() - 1]);
        if a.is_nan() || a < first {
            return textures.eval(self.textures[0], at);
        }
        if a >= last {
            return textures.eval(self.textures[self.textures.len() - 1], at);
        }
        // The first offset above a (exists: a < last), with one at or below it before.
        let upper = self.offsets.partition_point(|&o| o <= a);
        let (o0, o1) = (self.offsets[upper - 1], self.offsets[upper]);
        let t = (a - o0) / (o1 - o0);
        let (c0, c1) = (
            textures.eval(self.textures[upper - 1], at),
            textures.eval(self.textures[upper], at),
        );
        c0.lerp(c1, t)
    }
}
