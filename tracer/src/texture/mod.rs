//! Textures: one file per LuxRender texture type, each with its `.lxs` statement, parameters,
//! defaults, reading and evaluation: [`imagemap`], [`normalmap`], [`checkerboard`] (2D and 3D),
//! [`constant`], [`scale`], [`arithmetic`] (add, subtract), [`mix`], [`band`], [`bilerp`],
//! [`uv`], [`harlequin`], [`dots`], [`brick`], [`fbm`], [`wrinkled`], [`windy`], [`marble`],
//! the [`blender`] family (blender_clouds, _wood, _marble, _musgrave, _stucci, _noise,
//! _voronoi, _distortednoise, _magic, _blend), [`blackbody`], [`gaussian`], [`equalenergy`], [`lampspectrum`] and [`tabulateddata`] (tabulateddata, irregulardata) (spectra, read as constant colours), and [`fresnel`] (the fresnel textures metal2 folds in).
//! [`mapping`] holds the 2D mappings (uv, spherical, cylindrical, planar) and the 3D mapping
//! (global, local, uv coordinates with scale, rotate, translate); [`noise`] the Perlin noise,
//! fBm and turbulence of the procedural textures; [`common`] the surface point, the evaluator
//! interface and the statement header every texture file shares.
//!
//! This file maps names to kinds (one line each in [`TextureKind::read`]), says what a kind is
//! called and what it references, and evaluates the scene's textures ([`Textures`]: built once
//! per scene, images decoded once and shared).
//!
//! Float textures are evaluated like colour textures and their value is splatted over RGB
//! (an image used as a float texture gives the mean of its channels, LuxRender's default
//! "channel").
//!
//! A new texture type is a new file here (struct, defaults, `read`, `eval`) plus its lines in
//! [`TextureKind`]: the variant, the name table, `name()`, `references()` and the dispatch in
//! [`Textures::eval`]. A texture that evaluates other textures takes `&impl TextureEval`.

pub mod arithmetic;
pub mod band;
pub mod bilerp;
pub mod blackbody;
pub mod blender;
pub mod brick;
pub mod checkerboard;
pub mod common;
pub mod constant;
pub mod dots;
pub mod equalenergy;
pub mod fbm;
pub mod fresnel;
pub mod gaussian;
pub mod harlequin;
pub mod imagemap;
pub mod lampspectrum;
pub mod mapping;
pub mod marble;
pub mod mix;
pub mod noise;
pub mod normalmap;
pub mod scale;
pub mod tabulateddata;
pub mod uv;
pub mod windy;
pub mod wrinkled;

#[cfg(test)]
mod procedural_tests;
#[cfg(test)]
mod tests;

use std::collections::HashMap;

use glam::Vec3;

use crate::assets::AssetSource;
use crate::diag::SourcePos;
use crate::image_io::{self, RgbImage};
use crate::param::{Fresnel, Tex, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub use arithmetic::{Arithmetic, Op};
pub use band::Band;
pub use bilerp::Bilerp;
pub use brick::{Bond, Brick};
pub use checkerboard::{Checkerboard, Checkerboard2D, Checkerboard3D};
pub use common::{Declared, TextureEval, TexturePoint};
pub use constant::Constant;
pub use dots::Dots;
pub use fbm::{Fbm, Octaves};
pub use harlequin::Harlequin;
pub use imagemap::{ImageMap, Wrap};
pub use mapping::{Coordinates, Mapping2D, Mapping3D};
pub use marble::Marble;
pub use mix::Mix;
pub use normalmap::NormalMap;
pub use scale::Scale;
pub use uv::Uv;
pub use windy::Windy;
pub use wrinkled::Wrinkled;

#[derive(Clone, Debug, PartialEq)]
pub struct TextureDesc {
    pub name: String,
    /// "float" or "color" textures: a float texture's value is splatted over RGB.
    pub is_color: bool,
    pub kind: TextureKind,
}

#[derive(Clone, Debug, PartialEq)]
pub enum TextureKind {
    ImageMap(ImageMap),
    Checkerboard2D(Checkerboard2D),
    Checkerboard3D(Checkerboard3D),
    Constant(Constant),
    Scale(Scale),
    Arithmetic(Arithmetic),
    Mix(Mix),
    Band(Band),
    Bilerp(Bilerp),
    Uv(Uv),
    Harlequin(Harlequin),
    Dots(Dots),
    Brick(Brick),
    Fbm(Fbm),
    Wrinkled(Wrinkled),
    Windy(Windy),
    Marble(Marble),
    NormalMap(NormalMap),
    Blender(blender::Blender),
}

/// What a `Texture` statement defines under its name.
#[derive(Clone, Debug, PartialEq)]
pub enum Defined {
    Texture(TextureDesc),
    /// A fresnel texture: bound by name, folded into metal2 (see [`fresnel`]).
    Fresnel(Fresnel),
}

/// Reads `Texture "name" "kind" "type" params`. An unknown kind is an error; an unsupported
/// type is a warning and defines nothing (`None`).
pub fn read(
    name: &str,
    kind: &str,
    class: &str,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Option<Defined>, ParseError> {
    let is_color = match kind {
        "color" | "spectrum" => true,
        "float" => false,
        "fresnel" => return Ok(fresnel::read(class, params, pos, ctx)?.map(Defined::Fresnel)),
        other => {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!(
                    "Texture \"{name}\": unknown texture kind \"{other}\" (expected \"float\", \"color\" or \"fresnel\")"
                ),
            })
        }
    };
    // LuxRender also accepts the fresnel texture types under "color".
    if fresnel::is_fresnel_type(class) {
        return Ok(fresnel::read(class, params, pos, ctx)?.map(Defined::Fresnel));
    }
    let decl = Declared { name, is_color };
    let Some(kind) = TextureKind::read(class, &decl, params, pos, ctx)? else {
        for p in &params.params {
            params.ignore(&p.name);
        }
        ctx.warn(
            pos,
            format!("Texture \"{name}\": type \"{class}\" is not supported; the texture is left undefined"),
        );
        return Ok(None);
    };
    Ok(Some(Defined::Texture(TextureDesc {
        name: name.to_string(),
        is_color,
        kind,
    })))
}

impl TextureKind {
    /// The texture of LuxRender type `class`; `None` for a type this renderer does not know.
    pub fn read(
        class: &str,
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Option<Self>, ParseError> {
        Ok(Some(match class {
            "imagemap" => Self::ImageMap(ImageMap::read(decl, params, pos, ctx)?),
            "checkerboard" => Checkerboard::read(decl, params, pos, ctx)?.into(),
            "constant" => Self::Constant(Constant::read(decl, params)?),
            "scale" => Self::Scale(Scale::read(decl, params, ctx)?),
            "add" => Self::Arithmetic(Arithmetic::read(Op::Add, decl, params, ctx)?),
            "subtract" => Self::Arithmetic(Arithmetic::read(Op::Subtract, decl, params, ctx)?),
            "mix" => Self::Mix(Mix::read(decl, params, ctx)?),
            "band" => Self::Band(Band::read(decl, params, pos, ctx)?),
            "bilerp" => Self::Bilerp(Bilerp::read(decl, params, pos, ctx)?),
            "uv" => Self::Uv(Uv::read(params, pos, ctx)?),
            "harlequin" => Self::Harlequin(Harlequin),
            "dots" => Self::Dots(Dots::read(decl, params, pos, ctx)?),
            "brick" => Self::Brick(Brick::read(decl, params, pos, ctx)?),
            "fbm" => Self::Fbm(Fbm::read(params, pos, ctx)?),
            "wrinkled" => Self::Wrinkled(Wrinkled::read(params, pos, ctx)?),
            "windy" => Self::Windy(Windy::read(params, pos, ctx)?),
            "marble" => Self::Marble(Marble::read(params, pos, ctx)?),
            "normalmap" => Self::NormalMap(NormalMap::read(decl, params, pos, ctx)?),
            "blackbody" => Self::Constant(blackbody::read(params)?),
            "gaussian" => Self::Constant(gaussian::read(params)?),
            "equalenergy" => Self::Constant(equalenergy::read(params)?),
            "lampspectrum" => Self::Constant(lampspectrum::read(params, pos, ctx)?),
            "tabulateddata" => Self::Constant(tabulateddata::read_file(params, pos, ctx)?),
            "irregulardata" => Self::Constant(tabulateddata::read_inline(params, pos, ctx)?),
            _ => match blender::Blender::read(class, decl, params, pos, ctx)? {
                Some(b) => Self::Blender(b),
                None => return Ok(None),
            },
        }))
    }

    /// The LuxRender type name (a blackbody reads as a constant).
    pub fn name(&self) -> &'static str {
        match self {
            Self::ImageMap(_) => "imagemap",
            Self::Checkerboard2D(_) | Self::Checkerboard3D(_) => "checkerboard",
            Self::Constant(_) => "constant",
            Self::Scale(_) => "scale",
            Self::Arithmetic(t) => t.name(),
            Self::Mix(_) => "mix",
            Self::Band(_) => "band",
            Self::Bilerp(_) => "bilerp",
            Self::Uv(_) => "uv",
            Self::Harlequin(_) => "harlequin",
            Self::Dots(_) => "dots",
            Self::Brick(_) => "brick",
            Self::Fbm(_) => "fbm",
            Self::Wrinkled(_) => "wrinkled",
            Self::Windy(_) => "windy",
            Self::Marble(_) => "marble",
            Self::NormalMap(_) => "normalmap",
            Self::Blender(t) => t.name(),
        }
    }

    /// The textures (or constants) this texture reads, in parameter order.
    pub fn references(&self) -> Vec<Tex> {
        match self {
            Self::ImageMap(_)
            | Self::Constant(_)
            | Self::Bilerp(_)
            | Self::Uv(_)
            | Self::Harlequin(_)
            | Self::Fbm(_)
            | Self::Wrinkled(_)
            | Self::Windy(_)
            | Self::Marble(_)
            | Self::NormalMap(_) => Vec::new(),
            Self::Checkerboard2D(t) => vec![t.tex1, t.tex2],
            Self::Checkerboard3D(t) => vec![t.tex1, t.tex2],
            Self::Scale(t) => vec![t.tex1, t.tex2],
            Self::Arithmetic(t) => vec![t.tex1, t.tex2],
            Self::Mix(t) => vec![t.tex1, t.tex2, t.amount],
            Self::Band(t) => t.textures.iter().copied().chain([t.amount]).collect(),
            Self::Dots(t) => vec![t.outside, t.inside],
            Self::Brick(t) => vec![t.brick, t.mortar, t.modulation],
            Self::Blender(t) => t.references(),
        }
    }

    /// The image file this texture reads, and the gamma it is decoded with.
    pub fn file(&self) -> Option<(&str, f32)> {
        match self {
            Self::ImageMap(t) | Self::NormalMap(NormalMap(t)) => Some((&t.filename, t.gamma)),
            _ => None,
        }
    }

    /// The 2D mapping this texture looks itself up with, if it has one.
    pub fn mapping(&self) -> Option<&Mapping2D> {
        match self {
            Self::ImageMap(ImageMap { mapping, .. })
            | Self::NormalMap(NormalMap(ImageMap { mapping, .. }))
            | Self::Checkerboard2D(Checkerboard2D { mapping, .. })
            | Self::Dots(Dots { mapping, .. })
            | Self::Bilerp(Bilerp { mapping, .. })
            | Self::Uv(Uv { mapping }) => Some(mapping),
            _ => None,
        }
    }
}

impl From<Checkerboard> for TextureKind {
    fn from(c: Checkerboard) -> Self {
        match c {
            Checkerboard::D2(c) => Self::Checkerboard2D(c),
            Checkerboard::D3(c) => Self::Checkerboard3D(c),
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    #[error(transparent)]
    Asset(#[from] crate::assets::AssetError),
    #[error(transparent)]
    Decode(#[from] crate::image_io::DecodeError),
    /// Textures may only use textures defined before them (which also rules out cycles).
    #[error("texture \"{texture}\" uses texture #{used}, which is not defined before it")]
    ForwardReference { texture: String, used: u32 },
}

#[derive(Clone, Debug)]
struct Texture {
    kind: TextureKind,
    /// Float textures splat the mean of their value over RGB.
    is_color: bool,
    /// Index into [`Textures::images`] of the file [`TextureKind::file`] names.
    image: Option<usize>,
}

/// The scene's textures, ready to evaluate; decoded images are shared by every texture that
/// names the same file with the same gamma.
#[derive(Default)]
pub struct Textures {
    textures: Vec<Texture>,
    images: Vec<RgbImage>,
}

impl Textures {
    /// The textures indexed by [`TextureId`], reading image files through `source`.
    pub fn new(descs: &[TextureDesc], source: &dyn AssetSource) -> Result<Self, TextureError> {
        let mut images = Vec::new();
        let mut decoded: HashMap<(&str, u32), usize> = HashMap::new();
        let mut textures = Vec::with_capacity(descs.len());
        for (index, desc) in descs.iter().enumerate() {
            for tex in desc.kind.references() {
                if let Tex::Texture(TextureId(used)) = tex {
                    if used as usize >= index {
                        return Err(TextureError::ForwardReference {
                            texture: desc.name.clone(),
                            used,
                        });
                    }
                }
            }
            let image = match desc.kind.file() {
                Some((filename, gamma)) => {
                    let key = (filename, gamma.to_bits());
                    Some(match decoded.get(&key) {
                        Some(&image) => image,
                        None => {
                            let bytes = source.read(filename)?;
                            images.push(image_io::decode(&bytes, filename, gamma)?);
                            decoded.insert(key, images.len() - 1);
                            images.len() - 1
                        }
                    })
                }
                None => None,
            };
            textures.push(Texture {
                kind: desc.kind.clone(),
                is_color: desc.is_color,
                image,
            });
        }
        Ok(Self { textures, images })
    }

    /// The value of a parameter at a surface point. An id that names no texture gives black.
    pub fn eval(&self, tex: Tex, at: &TexturePoint) -> Vec3 {
        match tex {
            Tex::Const(c) => c,
            Tex::Texture(TextureId(id)) => match self.textures.get(id as usize) {
                Some(texture) => self.eval_texture(texture, at),
                None => Vec3::ZERO,
            },
        }
    }

    fn eval_texture(&self, texture: &Texture, at: &TexturePoint) -> Vec3 {
        let value = match &texture.kind {
            TextureKind::ImageMap(t) => t.eval(at, self.image(texture)),
            TextureKind::Checkerboard2D(t) => t.eval(at, self),
            TextureKind::Checkerboard3D(t) => t.eval(at, self),
            TextureKind::Constant(t) => t.eval(),
            TextureKind::Scale(t) => t.eval(at, self),
            TextureKind::Arithmetic(t) => t.eval(at, self),
            TextureKind::Mix(t) => t.eval(at, self),
            TextureKind::Band(t) => t.eval(at, self),
            TextureKind::Bilerp(t) => t.eval(at),
            TextureKind::Uv(t) => t.eval(at),
            TextureKind::Harlequin(t) => t.eval(at),
            TextureKind::Dots(t) => t.eval(at, self),
            TextureKind::Brick(t) => t.eval(at, self),
            TextureKind::Fbm(t) => t.eval(at),
            TextureKind::Wrinkled(t) => t.eval(at),
            TextureKind::Windy(t) => t.eval(at),
            TextureKind::Marble(t) => t.eval(at),
            // A normal map is no height: 0 wherever it is read as a value (LuxRender's too).
            TextureKind::NormalMap(_) => Vec3::ZERO,
            TextureKind::Blender(t) => t.eval(at, self),
        };
        if texture.is_color {
            value
        } else {
            Vec3::splat(value.element_sum() / 3.0)
        }
    }

    /// The tangent-space normal (x along u, y along v, z along the normal; not normalised) of
    /// `tex` at `at` when it is a normal map, else `None`.
    pub fn normal_map(&self, tex: Tex, at: &TexturePoint) -> Option<Vec3> {
        let Tex::Texture(TextureId(id)) = tex else {
            return None;
        };
        let texture = self.textures.get(id as usize)?;
        match &texture.kind {
            TextureKind::NormalMap(t) => Some(t.normal(at, self.image(texture))),
            _ => None,
        }
    }

    /// The decoded file of a texture that reads one.
    fn image(&self, texture: &Texture) -> &RgbImage {
        &self.images[texture.image.expect("decoded in Textures::new")]
    }

    /// The value of `tex` when it is the same at every point, from the descriptions alone:
    /// constants (and the spectral textures, read as one) and scale, mix, add or subtract of
    /// such. What a light colour
    /// given as a texture reads (LuxRender accepts a texture wherever a colour goes). None
    /// for a texture that varies over a surface or reads a file.
    pub fn uniform_value(descs: &[TextureDesc], tex: Tex) -> Option<Vec3> {
        fn uniform(descs: &[TextureDesc], tex: Tex) -> bool {
            let Tex::Texture(TextureId(id)) = tex else {
                return true;
            };
            descs.get(id as usize).is_some_and(|d| {
                matches!(
                    d.kind,
                    TextureKind::Constant(_)
                        | TextureKind::Scale(_)
                        | TextureKind::Mix(_)
                        | TextureKind::Arithmetic(_)
                ) && d.kind.references().into_iter().all(|r| match r {
                    // Only earlier textures: rules out cycles.
                    Tex::Texture(TextureId(used)) => used < id && uniform(descs, r),
                    Tex::Const(_) => true,
                })
            })
        }
        if !uniform(descs, tex) {
            return None;
        }
        // No texture reached reads a file, so none needs its image.
        let textures = Self {
            textures: descs
                .iter()
                .map(|d| Texture {
                    kind: d.kind.clone(),
                    is_color: d.is_color,
                    image: None,
                })
                .collect(),
            images: Vec::new(),
        };
        let origin = TexturePoint::new(Vec3::ZERO, glam::Vec2::ZERO);
        Some(textures.eval(tex, &origin))
    }
}

impl TextureEval for Textures {
    fn eval(&self, tex: Tex, at: &TexturePoint) -> Vec3 {
        Textures::eval(self, tex, at)
    }
}
