//! Textures: one file per LuxRender texture type, each with its `.lxs` statement, parameters,
//! defaults, reading and evaluation: [`imagemap`], [`normalmap`], [`checkerboard`] (2D and 3D),
//! [`constant`], [`scale`], [`arithmetic`] (add, subtract), [`mix`], [`band`], [`bilerp`],
//! [`uv`], [`harlequin`], [`dots`], [`brick`], [`fbm`], [`wrinkled`], [`windy`], [`marble`],
//! the [`blender`] family (blender_clouds, _wood, _marble, _musgrave, _stucci, _noise,
//! _voronoi, _distortednoise, _magic, _blend), [`blackbody`], [`gaussian`], [`equalenergy`], [`lampspectrum`] and [`tabulateddata`] (tabulateddata, irregulardata) (spectra, read as constant colours), and [`fresnel`] (the fresnel textures metal2 folds in and volumes take their index from).
//! [`mapping`] holds the 2D mappings (uv, spherical, cylindrical, planar) and the 3D mapping
//! (global, local, uv coordinates with scale, rotate, translate); [`noise`] the Perlin noise,
//! fBm and turbulence of the procedural textures; [`common`] the surface point, the evaluator
//! interface and the statement header every texture file shares.
//!
//! This file lists the types (one line each, from which a macro generates the name table and
//! the dispatch) and evaluates the scene's textures ([`Textures`]: built once per scene,
//! images decoded once and shared).
//!
//! Float textures are evaluated like colour textures and their value is splatted over RGB
//! (an image used as a float texture gives the mean of its channels, LuxRender's default
//! "channel").
//!
//! A new texture type is a new file here (struct, defaults, `read`, its [`TextureType`] impl)
//! plus one line in the type list below, which generates the rest. A texture that evaluates
//! other textures does so through the `&impl ReferencedTextures` its `eval` is given.

pub mod blackbody;
pub mod common;
pub mod equalenergy;
pub mod fresnel;
pub mod gaussian;
pub mod kind;
pub mod lampspectrum;
pub mod mapping;
pub mod noise;
pub mod tabulateddata;

#[cfg(test)]
mod procedural_tests;
#[cfg(test)]
mod tests;

use std::collections::HashMap;

use glam::Vec3;

use crate::assets::AssetSource;
use crate::diag::SourcePos;
use crate::image_io::{self, RgbImage};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, Fresnel, TextureId};

pub use arithmetic::Op;
pub use brick::Bond;
pub use checkerboard::{Checkerboard2D, Checkerboard3D};
pub use common::{Declared, LookupPoint, ReferencedTextures};
pub use fbm::Octaves;
pub use imagemap::Wrap;
pub use kind::TextureType;
pub use mapping::{Coordinates, Mapping2D, Mapping3D};

#[derive(Clone, Debug, PartialEq)]
pub struct TextureDesc {
    pub name: String,
    /// "float" or "color" textures: a float texture's value is splatted over RGB.
    pub is_color: bool,
    pub kind: TextureKind,
}

/// Generates the texture family from its type list (see [`textures!`]'s invocation below):
/// each type's module and re-export, the [`TextureKind`] variant, the name table from
/// LuxRender's texture types to the readers, and every dispatch `match`, each arm a call of
/// the type's [`TextureType`] method.
macro_rules! textures {
    ($($module:ident::$kind:ident { $($name:literal => $read:expr),* },)+) => {
        $(pub mod $module;)+
        $(pub use $module::$kind;)+

        #[derive(Clone, Debug, PartialEq)]
        pub enum TextureKind {
            $($kind($kind),)+
        }

        impl TextureKind {
            /// The reader of a LuxRender type the table names; None for another.
            fn reader(class: &str) -> Option<TextureReader> {
                Some(match class {
                    $($($name => |decl, params, pos, ctx| Ok(Self::$kind(($read)(decl, params, pos, ctx)?)),)*)+
                    _ => return None,
                })
            }

            /// The LuxRender type name (a texture read as a constant, as blackbody is, says
            /// "constant").
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$kind(t) => t.name(),)+
                }
            }

            /// The textures (or constants) this texture reads, in parameter order.
            pub fn references(&self) -> Vec<ConstOrTexture> {
                match self {
                    $(Self::$kind(t) => t.references(),)+
                }
            }

            /// The image file this texture reads, and the gamma it is decoded with.
            pub fn file(&self) -> Option<(&str, f32)> {
                match self {
                    $(Self::$kind(t) => t.file(),)+
                }
            }

            /// The 2D mapping this texture looks itself up with, if it has one.
            pub fn mapping(&self) -> Option<&Mapping2D> {
                match self {
                    $(Self::$kind(t) => t.mapping(),)+
                }
            }

            /// The value at `at` (see [`TextureType::eval`]).
            fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
                match self {
                    $(Self::$kind(t) => t.eval(at, textures),)+
                }
            }
        }
    };
}

/// Reads a texture type from a statement's header and parameters.
type TextureReader =
    fn(&Declared, &ParamList, &SourcePos, &mut dyn ParseContext) -> Result<TextureKind, ParseError>;

// The types: `module::Type { "luxrender type" => reader, ... },`; the blender_* types are read
// by [`Blender::read`], which knows their names.
textures! {
    imagemap::ImageMap { "imagemap" => ImageMap::read },
    checkerboard::Checkerboard { "checkerboard" => Checkerboard::read },
    constant::Constant {
        "constant" => Constant::read,
        "blackbody" => |_, params, _, _| blackbody::read(params),
        "gaussian" => |_, params, _, _| gaussian::read(params),
        "equalenergy" => |_, params, _, _| equalenergy::read(params),
        "lampspectrum" => lampspectrum::read,
        "tabulateddata" => tabulateddata::read_file,
        "irregulardata" => tabulateddata::read_inline
    },
    scale::Scale { "scale" => Scale::read },
    arithmetic::Arithmetic { "add" => Arithmetic::read_add, "subtract" => Arithmetic::read_subtract },
    mix::Mix { "mix" => Mix::read },
    band::Band { "band" => Band::read },
    bilerp::Bilerp { "bilerp" => Bilerp::read },
    uv::Uv { "uv" => Uv::read },
    harlequin::Harlequin { "harlequin" => Harlequin::read },
    dots::Dots { "dots" => Dots::read },
    brick::Brick { "brick" => Brick::read },
    fbm::Fbm { "fbm" => Fbm::read },
    wrinkled::Wrinkled { "wrinkled" => Wrinkled::read },
    windy::Windy { "windy" => Windy::read },
    marble::Marble { "marble" => Marble::read },
    normalmap::NormalMap { "normalmap" => NormalMap::read },
    blender::Blender {},
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
        params.ignore_all();
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
        if let Some(read) = Self::reader(class) {
            return Ok(Some(read(decl, params, pos, ctx)?));
        }
        Ok(Blender::read(class, decl, params, pos, ctx)?.map(Self::Blender))
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
                if let ConstOrTexture::Texture(TextureId(used)) = tex {
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
    pub fn eval(&self, tex: ConstOrTexture, at: &LookupPoint) -> Vec3 {
        match tex {
            ConstOrTexture::Const(c) => c,
            ConstOrTexture::Texture(TextureId(id)) => match self.textures.get(id as usize) {
                Some(texture) => self.eval_texture(texture, at),
                None => Vec3::ZERO,
            },
        }
    }

    fn eval_texture(&self, texture: &Texture, at: &LookupPoint) -> Vec3 {
        let value = texture.kind.eval(
            at,
            &Evaluating {
                textures: self,
                texture,
            },
        );
        if texture.is_color {
            value
        } else {
            Vec3::splat(value.element_sum() / 3.0)
        }
    }

    /// The tangent-space normal (x along u, y along v, z along the normal; not normalised) of
    /// `tex` at `at` when it is a normal map, else `None`.
    pub fn normal_map(&self, tex: ConstOrTexture, at: &LookupPoint) -> Option<Vec3> {
        let ConstOrTexture::Texture(TextureId(id)) = tex else {
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
    pub fn uniform_value(descs: &[TextureDesc], tex: ConstOrTexture) -> Option<Vec3> {
        fn uniform(descs: &[TextureDesc], tex: ConstOrTexture) -> bool {
            let ConstOrTexture::Texture(TextureId(id)) = tex else {
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
                    ConstOrTexture::Texture(TextureId(used)) => used < id && uniform(descs, r),
                    ConstOrTexture::Const(_) => true,
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
        let origin = LookupPoint::new(Vec3::ZERO, glam::Vec2::ZERO);
        Some(textures.eval(tex, &origin))
    }
}

/// What a texture sees of the scene's textures while it is evaluated: the others, and its own
/// decoded file.
struct Evaluating<'a> {
    textures: &'a Textures,
    texture: &'a Texture,
}

impl ReferencedTextures for Evaluating<'_> {
    fn eval(&self, tex: ConstOrTexture, at: &LookupPoint) -> Vec3 {
        self.textures.eval(tex, at)
    }

    fn image(&self) -> &RgbImage {
        self.textures.image(self.texture)
    }
}
