//! What every light shares when it is read: the `L` and `gain` parameters, and LuxRender's
//! power/efficacy normalisation (when power x efficacy > 0, the gain is scaled so the light
//! emits that many lumens), used by point, spot and area lights. A leaf: the light files
//! import it, it imports none of them.
//!
//! `L` may name a texture, as in LuxRender (`"texture L" "name"`, or a colour parameter given
//! a texture name). An area light keeps it and evaluates it on its surface
//! ([`surface_color`]); the other lights need one colour ([`light_color`]): a texture that is
//! the same everywhere (constant, blackbody, scale or mix of such) gives it; one that varies
//! over a surface (an image, a checkerboard) is a warning and the default colour is used.

use glam::Vec3;

use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::{ConstOrTextureName, ParamList};
use crate::refs::ConstOrTexture;

/// `L`: the emitted colour.
pub const DEFAULT_L: Vec3 = Vec3::ONE;
/// `gain`: multiplies `L`.
pub const DEFAULT_GAIN: f32 = 1.0;

/// `L` and `gain`, read first for every `LightSource` (so a malformed one is an error whatever
/// the type).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    pub l: Vec3,
    pub gain: f32,
}

impl Emission {
    pub(crate) fn read(params: &ParamList, ctx: &mut dyn ParseContext) -> Result<Self, ParseError> {
        Ok(Self {
            l: light_color(params, "L", DEFAULT_L, ctx)?,
            gain: params.float("gain", DEFAULT_GAIN)?,
        })
    }
}

/// An area light's colour parameter: a constant (a texture with one value everywhere becomes
/// its value, so that the light costs no texture evaluation), or a varying texture.
pub(crate) fn surface_color(
    params: &ParamList,
    name: &str,
    default: Vec3,
    ctx: &mut dyn ParseContext,
) -> Result<ConstOrTexture, ParseError> {
    let value = params.tex_color(name, default)?;
    Ok(match ctx.tex(value, true, default) {
        ConstOrTexture::Texture(id) => ctx
            .uniform_texture(ConstOrTexture::Texture(id))
            .map_or(ConstOrTexture::Texture(id), ConstOrTexture::Const),
        constant => constant,
    })
}

/// A light's colour parameter: a colour, or a texture with one value everywhere.
pub(crate) fn light_color(
    params: &ParamList,
    name: &str,
    default: Vec3,
    ctx: &mut dyn ParseContext,
) -> Result<Vec3, ParseError> {
    let value = params.tex_color(name, default)?;
    let (texture, pos) = match &value {
        ConstOrTextureName::Const(c) => return Ok(*c),
        ConstOrTextureName::Named { name, pos } => (name.clone(), pos.clone()),
    };
    Ok(match ctx.tex(value, true, default) {
        ConstOrTexture::Const(c) => c,
        tex => ctx.uniform_texture(tex).unwrap_or_else(|| {
            ctx.warn(
                &pos,
                format!(
                    "light colour \"{name}\": texture \"{texture}\" varies over the surface, which a light colour does not model; using the default"
                ),
            );
            default
        }),
    })
}

/// `gain x power x efficacy / denominator` when that factor is positive and finite
/// (LuxRender's rule), else `gain`.
pub fn normalised_gain(gain: f32, power: f32, efficacy: f32, denominator: f32) -> f32 {
    let factor = power * efficacy / denominator;
    if factor > 0.0 && factor.is_finite() {
        gain * factor
    } else {
        gain
    }
}

/// Whether a colour can light anything.
pub fn emits(c: Vec3) -> bool {
    c.is_finite() && c.max_element() > 0.0
}
