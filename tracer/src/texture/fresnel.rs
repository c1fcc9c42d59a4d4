//! Fresnel textures: not evaluated per hit, but a [`Fresnel`] term bound to the texture's name
//! that metal2 (`"texture fresnel" "name"`) folds into its description.
//!
//! ```text
//! Texture "name" "fresnel" "fresnelcolor" "color Kr" [0.9 0.6 0.2]
//! Texture "name" "fresnel" "fresnelname" "string name" "copper"
//! Texture "name" "fresnel" "constant" "float value" 1.5
//! ```
//!
//! | type                   | parameter                    | default   | gives |
//! |------------------------|------------------------------|-----------|-------|
//! | `fresnelcolor`         | `Kr` (texture or colour)     | 0.5       | a normal-incidence reflectance |
//! | `fresnelname`, `preset`| `string filename` or `string name` | aluminium | a built-in metal's complex index (an unknown name or an .nk file warns and gives aluminium) |
//! | `constant`             | `float value`                | 1.5       | a real index of refraction |
//!
//! LuxRender also accepts the `fresnelcolor`, `fresnelname` and `preset` types declared
//! "color" (or "float"); any other type declared "fresnel" warns and leaves the name undefined.

use glam::Vec3;

use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, Fresnel};

pub const DEFAULT_KR: f32 = 0.5;
pub const DEFAULT_METAL: &str = "aluminium";
pub const DEFAULT_INDEX: f32 = 1.5;

/// The fresnel texture types LuxRender accepts under any declared kind.
pub fn is_fresnel_type(class: &str) -> bool {
    matches!(class, "fresnelcolor" | "fresnelname" | "preset")
}

/// The Fresnel term of a fresnel texture of type `class`; `None` (with a warning) for a type
/// this renderer does not know.
pub fn read(
    class: &str,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Option<Fresnel>, ParseError> {
    Ok(Some(match class {
        "fresnelcolor" => {
            let kr = params.tex_color("Kr", Vec3::splat(DEFAULT_KR))?;
            Fresnel::Reflectance(ctx.tex(kr, true, Vec3::splat(DEFAULT_KR)))
        }
        "fresnelname" | "preset" => {
            let name = match params.string("filename")? {
                Some(f) => f,
                None => params.string_or("name", DEFAULT_METAL)?,
            };
            let (eta, k) = ctx.metal_by_name(&name, pos);
            Fresnel::Conductor { eta, k }
        }
        "constant" => Fresnel::Index(ConstOrTexture::float(params.float("value", DEFAULT_INDEX)?)),
        other => {
            for p in &params.params {
                params.ignore(&p.name);
            }
            ctx.warn(pos, format!("fresnel texture type \"{other}\" is not supported; the texture is left undefined"));
            return Ok(None);
        }
    }))
}
