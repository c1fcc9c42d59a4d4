//! Textures: imagemap, checkerboard 2D/3D, constant, scale, mix, with uv, spherical,
//! cylindrical and planar mappings. Images are decoded once at build time.
//!
//! OWNER: materials helper. Interface used by materials and the integrator; keep the
//! signatures.

use glam::{Vec2, Vec3};

use crate::assets::AssetSource;
use crate::desc::{SceneDesc, Tex};

/// What a texture lookup needs to know about the surface point.
#[derive(Clone, Copy, Debug)]
pub struct TexturePoint {
    pub p: Vec3,
    pub uv: Vec2,
}

#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    #[error(transparent)]
    Asset(#[from] crate::assets::AssetError),
    #[error(transparent)]
    Decode(#[from] crate::image_io::DecodeError),
}

pub struct Textures {}

impl Textures {
    pub fn build(_desc: &SceneDesc, _source: &dyn AssetSource) -> Result<Self, TextureError> {
        todo!("materials helper")
    }

    pub fn eval(&self, _tex: Tex, _at: &TexturePoint) -> Vec3 {
        todo!("materials helper")
    }
}
