//! `Material "layered"`: up to four named materials stacked, each covering the surface with
//! an opacity; where no layer covers it, the surface is not there (as `null`).
//!
//! ```text
//! MakeNamedMaterial "decal" "string type" ["layered"] "string namedmaterial1" ["label"]
//!     "texture opacity1" "labelmask" "string namedmaterial2" ["bottle"] "float opacity2" [1]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `namedmaterial1` ... `namedmaterial4` | string, a named material (1 is the top) | absent: no layer; an undefined name warns and is the default matte |
//! | `opacity1` ... `opacity4` | float texture, clamped to [0, 1] per hit | 1 ([`DEFAULT_OPACITY`]) |
//!
//! A ray meets the top layer first: it scatters there with the layer's opacity, else goes on
//! to the next, and passes through when no layer caught it. So layer i is chosen per hit with
//! probability opacity_i times the transparency of the layers above it, like a `mix`. That is
//! LuxRender's layered BSDF when the layers are opaque materials (decals, labels, paint over a
//! base); LuxRender, which calls it experimental, also walks light back and forth between
//! translucent layers, which this does not.

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use super::matte::Matte;
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{MaterialId, ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// LuxRender's number of layers.
pub const MAX_LAYERS: usize = 4;
pub const DEFAULT_OPACITY: f32 = 1.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Layered {
    /// The layers present, top first, with their opacities.
    pub layers: Vec<(MaterialId, ConstOrTexture)>,
}

impl Layered {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let mut layers = Vec::new();
        for i in 1..=MAX_LAYERS {
            let opacity = ctx.float_param(params, &format!("opacity{i}"), DEFAULT_OPACITY)?;
            if let Some(name) = params.string(&format!("namedmaterial{i}"))? {
                layers.push((ctx.named_material(&name, pos), opacity));
            }
        }
        Ok(Self { layers })
    }

    /// One level of the resolution: the layer `u` falls in, or None when it passes every layer,
    /// and `u` rescaled to [0, 1) within the chosen layer (see [`super::mix::Mix::choose`]).
    pub fn choose(&self, eval: &HitTextures, u: f32) -> (Option<MaterialId>, f32) {
        // The probability mass not yet taken by the layers above.
        let (mut start, mut left) = (0.0f32, 1.0f32);
        for &(id, opacity) in &self.layers {
            let p = left * eval.float(opacity).clamp(0.0, 1.0);
            if u < start + p {
                let u = ((u - start) / p).clamp(0.0, 1.0 - f32::EPSILON);
                return (Some(id), u);
            }
            start += p;
            left -= p;
        }
        let u = if left > 0.0 {
            ((u - start) / left).clamp(0.0, 1.0 - f32::EPSILON)
        } else {
            u
        };
        (None, u)
    }
}

impl MaterialKind for Layered {
    fn textures(&self) -> Vec<TextureId> {
        let opacities: Vec<&ConstOrTexture> = self.layers.iter().map(|(_, t)| t).collect();
        texture_ids(&opacities)
    }

    fn materials(&self) -> Vec<MaterialId> {
        self.layers.iter().map(|(id, _)| *id).collect()
    }

    /// Resolved to one of its layers by [`super::Materials`]; alone it shows the default
    /// matte.
    fn bxdf(&self, _eval: &HitTextures, _u: f32) -> Bxdf {
        Matte::default_bxdf()
    }
}
