//! What every kind of volume shares and what the shapes and the path tracer refer to: the
//! volume id, a shape's interior and exterior, the rule that picks the volume a ray is in
//! after it meets a surface, and the reading of the parameters every volume takes (`fresnel`,
//! perhaps varying with wavelength, and constant colours). A leaf: the kinds of volume, the scene description and the path tracer
//! import it.

use glam::Vec3;

use crate::diag::SourcePos;
use crate::parse::context::{BoundTexture, ParseContext};
use crate::parse::error::ParseError;
use crate::parse::params::{ConstOrTextureName, ParamList};
use crate::refs::Fresnel;
use crate::wavelength::IndexCurve;

/// Index into [`Volumes::media`](super::Volumes::media).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MediumId(pub u32);

/// LuxRender's default `fresnel` of a `clear` or `homogeneous` volume (`GetFresnelTexture
/// ("fresnel", 1.5)` in its volumes/*.cpp).
pub const DEFAULT_FRESNEL: f32 = 1.5;

/// The volumes on the two sides of a shape's surface (`Interior` and `Exterior` when the shape
/// was defined). None is LuxRender's "no volume": the side takes the volume of whatever ray
/// reaches the surface from it, and a ray leaving through it is in no known volume (vacuum
/// until it meets a surface that names one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ShapeMedia {
    pub interior: Option<MediumId>,
    pub exterior: Option<MediumId>,
}

impl ShapeMedia {
    pub fn is_empty(&self) -> bool {
        self.interior.is_none() && self.exterior.is_none()
    }

    /// The volume on the side of the surface (geometric normal `ng`, facing the exterior)
    /// that direction `w` points into.
    pub fn toward(&self, w: Vec3, ng: Vec3) -> Option<MediumId> {
        if w.dot(ng) > 0.0 {
            self.exterior
        } else {
            self.interior
        }
    }

    /// The sides as a ray travelling along `dir` in volume `current` meets them: the side it
    /// comes from, when the shape names no volume there, is the ray's (LuxRender's volume
    /// integrators fill the intersection's missing side so).
    pub fn met_by(&self, dir: Vec3, ng: Vec3, current: Option<MediumId>) -> Self {
        let mut sides = *self;
        if dir.dot(ng) > 0.0 {
            sides.interior = sides.interior.or(current);
        } else {
            sides.exterior = sides.exterior.or(current);
        }
        sides
    }
}

/// A volume's `fresnel`: a float, a constant float texture, or a fresnel texture holding a
/// real index, the last perhaps varying with wavelength (cauchy, abbe, sellmeier, sopra,
/// luxpop). The index is what glass2 refracts with: the curve where it varies (what glass2
/// with `dispersion` takes a wavelength of) and the one number glass2 uses where no wavelength
/// is taken (a curve's mean, as LuxRender's). Anything that varies in space (or a conductor's
/// complex index) warns and gives the default.
pub fn read_index(
    params: &ParamList,
    statement: &str,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<(f32, Option<IndexCurve>), ParseError> {
    let (index, curve) = match params.tex_float("fresnel", DEFAULT_FRESNEL)? {
        ConstOrTextureName::Const(c) => (Some(c.x), None),
        ConstOrTextureName::Named { name, pos: at } => {
            let found = match ctx.find_texture(&name, false) {
                Some(BoundTexture::Texture(id)) => ctx
                    .uniform_texture(crate::refs::ConstOrTexture::Texture(id))
                    .map(|v| (v.x, None)),
                Some(BoundTexture::Fresnel(Fresnel::Index(t))) => {
                    ctx.uniform_texture(t).map(|v| (v.x, None))
                }
                Some(BoundTexture::Fresnel(Fresnel::Dispersive(curve))) => {
                    Some((curve.mean(), curve.varies().then_some(curve)))
                }
                _ => None,
            };
            if found.is_none() {
                ctx.warn(
                    &at,
                    format!("{statement}: \"fresnel\" \"{name}\" is not a uniform real index; using {DEFAULT_FRESNEL}"),
                );
            }
            match found {
                Some((index, curve)) => (Some(index), curve),
                None => (None, None),
            }
        }
    };
    Ok(match index {
        Some(i) if i > 0.0 && i.is_finite() => (i, curve),
        Some(i) => {
            ctx.warn(
                pos,
                format!(
                    "{statement}: fresnel {i} is not a positive index; using {DEFAULT_FRESNEL}"
                ),
            );
            (DEFAULT_FRESNEL, None)
        }
        None => (DEFAULT_FRESNEL, None),
    })
}

/// A colour a volume takes as a constant (or a texture that is the same everywhere); a
/// varying texture warns and gives `default`. Negative components are clamped to 0 (LuxRender
/// clamps its absorption).
pub fn read_color(
    params: &ParamList,
    name: &str,
    default: f32,
    statement: &str,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Vec3, ParseError> {
    let tex = ctx.color_param(params, name, default, false)?;
    let value = match ctx.uniform_texture(tex) {
        Some(v) => v,
        None => {
            ctx.warn(
                pos,
                format!("{statement}: \"{name}\" varies in space, which this volume cannot; using {default}"),
            );
            Vec3::splat(default)
        }
    };
    Ok(if value.is_finite() {
        value.max(Vec3::ZERO)
    } else {
        ctx.warn(
            pos,
            format!("{statement}: \"{name}\" is not finite; using {default}"),
        );
        Vec3::splat(default)
    })
}

/// Beer-Lambert transmittance over `distance` through extinction `sigma_t` (per scene unit).
/// A zero coefficient is no extinction even over an infinite distance (LuxRender's rule,
/// which also keeps 0 x inf from making a NaN).
pub fn transmittance(sigma_t: Vec3, distance: f32) -> Vec3 {
    let channel = |s: f32| {
        if s > 0.0 {
            libm::expf(-s * distance)
        } else {
            1.0
        }
    };
    Vec3::new(channel(sigma_t.x), channel(sigma_t.y), channel(sigma_t.z))
}
