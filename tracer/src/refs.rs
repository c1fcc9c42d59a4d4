//! The values scene descriptions refer to each other with, once the parser has resolved names:
//! texture and material ids, texture-or-constant parameters, and a metal's Fresnel term
//! (shared by the `fresnel` textures that define it and the metal materials that use it).
//! A leaf module: the descriptions of every family and the parser's context import it.

use glam::Vec3;

use crate::wavelength::IndexCurve;

/// Index into [`SceneDesc::textures`](crate::desc::SceneDesc::textures).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureId(pub u32);

/// Index into [`SceneDesc::materials`](crate::desc::SceneDesc::materials).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);

/// A material or texture parameter: a constant or a reference to a texture. Float parameters
/// store their constant splatted over the three channels and read `.x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConstOrTexture {
    Const(Vec3),
    Texture(TextureId),
}

impl ConstOrTexture {
    pub fn float(v: f32) -> Self {
        ConstOrTexture::Const(Vec3::splat(v))
    }
    pub fn color(c: Vec3) -> Self {
        ConstOrTexture::Const(c)
    }
}

/// How a metal material (or a volume's `fresnel`) gets its Fresnel term.
#[derive(Clone, Debug, PartialEq)]
pub enum Fresnel {
    /// Normal-incidence reflectance colour (a `fresnelcolor` texture, or the course's
    /// `color fresnel` / `color Kr` on metal2).
    Reflectance(ConstOrTexture),
    /// A real index of refraction with no absorption (`float fresnel`).
    Index(ConstOrTexture),
    /// Complex index of refraction per RGB channel (metal presets, `fresnelname`).
    Conductor { eta: Vec3, k: Vec3 },
    /// A real index that varies with wavelength (the `cauchy`, `abbe`, `sellmeier`, `sopra`
    /// and `luxpop` fresnel textures): glass2's volumes refract with it, metal2 with its mean.
    Dispersive(IndexCurve),
}
