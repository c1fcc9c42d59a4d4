//! What every texture file shares, and nothing else (a leaf of the texture family): the
//! surface point a lookup sees, the evaluator a texture uses for the textures it references,
//! and the facts of the `Texture` statement a reader needs.

use glam::{Vec2, Vec3};

use crate::image_io::RgbImage;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::ConstOrTexture;

/// What a texture lookup needs to know about the surface point.
#[derive(Clone, Copy, Debug)]
pub struct LookupPoint {
    /// Position in the shaded shape's object space: planar, spherical, cylindrical and 3D
    /// checkerboard mappings project it (then apply the Texture's own transform). The seed
    /// scenes are composed this way: their planar-mapped walls are scaled unit quads that show
    /// the image once per unit of object space, whatever their size in the world.
    pub p: Vec3,
    /// Position in world space: what LuxRender's "global" 3D mapping (the default of the
    /// procedural textures) transforms.
    pub p_world: Vec3,
    pub uv: Vec2,
    /// The primitive hit (harlequin colours each one differently).
    pub prim: u32,
}

impl LookupPoint {
    /// A point whose object and world positions coincide (tests, bakes).
    pub fn new(p: Vec3, uv: Vec2) -> Self {
        Self {
            p,
            p_world: p,
            uv,
            prim: 0,
        }
    }
}

/// Evaluates a texture-or-constant parameter: what a texture that combines other textures
/// (scale, mix, checkerboard, ...) calls for its inputs. [`Textures`](super::Textures)
/// implements it.
pub trait ReferencedTextures {
    /// The value of `tex` at `at` (a constant is itself; an id naming no texture is black).
    fn eval(&self, tex: ConstOrTexture, at: &LookupPoint) -> Vec3;

    /// The decoded file of the texture being evaluated (one whose
    /// [`TextureType::file`](super::kind::TextureType::file) names one).
    fn image(&self) -> &RgbImage;
}

/// The `Texture "name" "float"|"color" "type"` header a texture reader is given with the
/// parameters.
#[derive(Clone, Copy, Debug)]
pub struct Declared<'a> {
    pub name: &'a str,
    /// "color" (or "spectrum"), else "float".
    pub is_color: bool,
}

impl Declared<'_> {
    /// A texture-or-constant parameter of the declared kind (colour or float) with a default.
    pub fn tex(
        &self,
        ctx: &mut dyn ParseContext,
        params: &ParamList,
        name: &str,
        default: f32,
    ) -> Result<ConstOrTexture, ParseError> {
        if self.is_color {
            ctx.color_param(params, name, default, false)
        } else {
            ctx.float_param(params, name, default)
        }
    }
}
