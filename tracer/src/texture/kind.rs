//! What every texture type says of itself, for the dispatch [`super`]'s type list generates: its
//! name, what it references, the file it reads and its value at a point. A leaf of the
//! texture family, so the texture files never import `texture/mod.rs`.

use glam::Vec3;

use super::common::{LookupPoint, ReferencedTextures};
use super::mapping::Mapping2D;
use crate::refs::ConstOrTexture;

pub trait TextureType {
    /// The LuxRender type name.
    fn name(&self) -> &'static str;

    /// The textures (or constants) this texture reads, in parameter order; a texture that
    /// reads others must list them (they are checked to be defined before it).
    fn references(&self) -> Vec<ConstOrTexture> {
        Vec::new()
    }

    /// The image file this texture reads, and the gamma it is decoded with.
    fn file(&self) -> Option<(&str, f32)> {
        None
    }

    /// The 2D mapping this texture looks itself up with, if it has one.
    fn mapping(&self) -> Option<&Mapping2D> {
        None
    }

    /// The value at `at`; `textures` evaluates the textures it references and gives its
    /// [`TextureType::file`] decoded.
    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3;
}
