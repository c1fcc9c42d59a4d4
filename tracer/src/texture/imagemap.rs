//! An image file looked up through a 2D mapping.
//!
//! ```text
//! Texture "name" "color"|"float" "imagemap" "string filename" "tex/wood.png" ...
//! ```
//!
//! | parameter         | default  | notes |
//! |-------------------|----------|-------|
//! | `string filename` | required | relative to the main file's folder; checked at parse time |
//! | `float gamma`     | 1        | the file's values are raised to this power |
//! | `float gain`      | 1        | texels are multiplied by it (not the black/white borders) |
//! | `string wrap`     | repeat   | repeat, black, white, clamp (an unknown name warns) |
//! | `string channel`  | mean     | float textures only; any other channel warns |
//! | mapping           | uv       | see [`super::mapping`] |
//!
//! Row convention (checked in LuxRender 1.x's source): its image reader stores rows top to
//! bottom (it reads FreeImage's bottom-up scanlines in reverse) and its MIPMap looks up texel
//! row t x height, so t = 0 is the top row of the file. Blender's exporter writes vscale -1 and
//! vdelta 1, i.e. t = 1 - v, and Blender's v = 0 is the bottom of the image, so the texture
//! comes out upright.
//!
//! Images are decoded once per scene by [`Textures::new`](super::Textures::new), shared by
//! every imagemap that names the same file with the same gamma.

use glam::{Vec2, Vec3};

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::mapping::Mapping2D;
use crate::diag::SourcePos;
use crate::image_io::{Edge, RgbImage};
use crate::parse::context::{ImageUse, ParseContext};
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

pub const DEFAULT_GAMMA: f32 = 1.0;
pub const DEFAULT_GAIN: f32 = 1.0;
pub const DEFAULT_WRAP: &str = "repeat";

/// What a lookup outside [0, 1]^2 reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    Repeat,
    Black,
    White,
    Clamp,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ImageMap {
    /// Path as written, relative to the main file's folder; listed in `assets`.
    pub filename: String,
    pub gamma: f32,
    pub gain: f32,
    pub wrap: Wrap,
    pub mapping: Mapping2D,
}

impl ImageMap {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let name = decl.name;
        let Some(filename) = params.string("filename")? else {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!("Texture \"{name}\": imagemap needs \"string filename\""),
            });
        };
        let gamma = params.float("gamma", DEFAULT_GAMMA)?;
        ctx.check_image(&filename, ImageUse::Texture { gamma }, pos)?;
        let wrap = match params.string_or("wrap", DEFAULT_WRAP)?.as_str() {
            "repeat" => Wrap::Repeat,
            "black" => Wrap::Black,
            "white" => Wrap::White,
            "clamp" => Wrap::Clamp,
            other => {
                ctx.warn(
                    pos,
                    format!("Texture \"{name}\": unknown wrap \"{other}\"; using repeat"),
                );
                Wrap::Repeat
            }
        };
        if !decl.is_color {
            if let Some(channel) = params.string("channel")? {
                if channel != "mean" {
                    ctx.warn(pos, format!("Texture \"{name}\": channel \"{channel}\" is not supported; using the mean"));
                }
            }
        }
        Ok(ImageMap {
            gamma,
            gain: params.float("gain", DEFAULT_GAIN)?,
            wrap,
            mapping: Mapping2D::read(params, pos, ctx)?,
            filename,
        })
    }

    /// The texel value at a surface point, `image` being this texture's decoded file.
    pub fn texel(&self, at: &LookupPoint, image: &RgbImage) -> Vec3 {
        lookup(image, self.mapping.map(at), self.wrap, self.gain)
    }
}

/// Bilinear interpolation of the texels around (s, t) under `wrap`, texels times `gain`. The
/// black and white borders are not scaled by the gain (as in LuxRender).
pub fn lookup(image: &RgbImage, st: Vec2, wrap: Wrap, gain: f32) -> Vec3 {
    let (edge, border) = match wrap {
        Wrap::Repeat => (Edge::Repeat, Vec3::ZERO),
        Wrap::Clamp => (Edge::Clamp, Vec3::ZERO),
        Wrap::Black => (Edge::Outside, Vec3::ZERO),
        Wrap::White => (Edge::Outside, Vec3::ONE),
    };
    let (inside, outside_weight) = image.bilinear(st, edge, edge);
    inside * gain + border * outside_weight

}

impl TextureType for ImageMap {
    fn name(&self) -> &'static str {
        "imagemap"
    }

    fn file(&self) -> Option<(&str, f32)> {
        Some((&self.filename, self.gamma))
    }

    fn mapping(&self) -> Option<&Mapping2D> {
        Some(&self.mapping)
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        self.texel(at, textures.image())
    }
}
