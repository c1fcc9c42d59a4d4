//! A normal map: an image whose texels are tangent-space normals, (r, g, b) = (n + 1) / 2,
//! x along the surface's u direction, y along v, z along the normal. Used as a material's
//! `"texture bumpmap"` (see [`crate::material::bump`]); as a plain float texture it is 0, as
//! in LuxRender.
//!
//! ```text
//! Texture "nmap" "float" "normalmap" "string filename" "tex/normals.png"
//! Material "matte" "texture bumpmap" "nmap"
//! ```
//!
//! | parameter | default | notes |
//! |-----------|---------|-------|
//! | `string filename`, `gamma`, `gain`, `wrap`, mapping | as [`super::imagemap`] | gamma should stay 1: the texels are vectors, not colours |

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::imagemap::ImageMap;
use super::kind::TextureType;
use super::mapping::Mapping2D;
use crate::diag::SourcePos;
use crate::image_io::RgbImage;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap(pub ImageMap);

impl NormalMap {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        // Read as a colour image: the float texture's "channel" means nothing here.
        let colour = Declared {
            is_color: true,
            ..*decl
        };
        Ok(Self(ImageMap::read(&colour, params, pos, ctx)?))
    }

    /// The tangent-space normal at a surface point (not normalised; `image` is the decoded
    /// file).
    pub fn normal(&self, at: &LookupPoint, image: &RgbImage) -> Vec3 {
        self.0.texel(at, image) * 2.0 - Vec3::ONE
    }
}

impl TextureType for NormalMap {
    fn name(&self) -> &'static str {
        "normalmap"
    }

    fn file(&self) -> Option<(&str, f32)> {
        self.0.file()
    }

    fn mapping(&self) -> Option<&Mapping2D> {
        self.0.mapping()
    }

    /// A normal map is no height: 0 wherever it is read as a value (LuxRender's too).
    fn eval(&self, _at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        Vec3::ZERO
    }
}
