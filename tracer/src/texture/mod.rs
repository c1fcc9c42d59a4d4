//! Textures: imagemap, checkerboard 2D/3D, constant, scale, mix, with uv, spherical,
//! cylindrical and planar mappings. Images are decoded once at build time.
//!
//! Float textures are evaluated like colour textures and their value is splatted over RGB
//! (an image used as a float texture gives the mean of its channels, LuxRender's default
//! "channel").

mod image;
mod mapping;

#[cfg(test)]
mod tests;

use std::collections::HashMap;

use glam::{Mat4, Vec2, Vec3};

use crate::assets::AssetSource;
use crate::desc::{SceneDesc, TextureDesc, TextureKind, Wrap};
use crate::image_io::{self, RgbImage};
use crate::param::{Tex, TextureId};
pub use mapping::Mapping;

/// What a texture lookup needs to know about the surface point.
#[derive(Clone, Copy, Debug)]
pub struct TexturePoint {
    /// Position in the shaded shape's object space: planar, spherical, cylindrical and 3D
    /// checkerboard mappings project it (then apply the Texture's own transform). The seed
    /// scenes are composed this way: their planar-mapped walls are scaled unit quads that show
    /// the image once per unit of object space, whatever their size in the world.
    pub p: Vec3,
    pub uv: Vec2,
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
enum Node {
    Image {
        image: usize,
        gain: f32,
        wrap: Wrap,
        mapping: Mapping,
    },
    Checkerboard2D {
        tex1: Tex,
        tex2: Tex,
        mapping: Mapping,
    },
    Checkerboard3D {
        tex1: Tex,
        tex2: Tex,
        world_to_texture: Mat4,
    },
    Constant(Vec3),
    Scale {
        tex1: Tex,
        tex2: Tex,
    },
    Mix {
        tex1: Tex,
        tex2: Tex,
        amount: Tex,
    },
}

#[derive(Clone, Debug)]
struct Texture {
    node: Node,
    /// Float textures splat the mean of their value over RGB.
    is_color: bool,
}

/// The scene's textures, ready to evaluate; decoded images are shared by every texture that
/// names the same file with the same gamma.
#[derive(Default)]
pub struct Textures {
    textures: Vec<Texture>,
    images: Vec<RgbImage>,
}

/// The textures a texture refers to.
fn references(kind: &TextureKind) -> Vec<Tex> {
    match kind {
        TextureKind::ImageMap { .. } | TextureKind::Constant(_) => Vec::new(),
        TextureKind::Checkerboard2D { tex1, tex2, .. }
        | TextureKind::Checkerboard3D { tex1, tex2, .. }
        | TextureKind::Scale { tex1, tex2 } => vec![*tex1, *tex2],
        TextureKind::Mix { tex1, tex2, amount } => vec![*tex1, *tex2, *amount],
    }
}

impl Textures {
    pub fn build(desc: &SceneDesc, source: &dyn AssetSource) -> Result<Self, TextureError> {
        Self::new(&desc.textures, source)
    }

    /// The textures indexed by [`TextureId`], reading image files through `source`.
    pub fn new(descs: &[TextureDesc], source: &dyn AssetSource) -> Result<Self, TextureError> {
        let mut images = Vec::new();
        let mut decoded: HashMap<(&str, u32), usize> = HashMap::new();
        let mut textures = Vec::with_capacity(descs.len());
        for (index, desc) in descs.iter().enumerate() {
            for tex in references(&desc.kind) {
                if let Tex::Texture(TextureId(used)) = tex {
                    if used as usize >= index {
                        return Err(TextureError::ForwardReference {
                            texture: desc.name.clone(),
                            used,
                        });
                    }
                }
            }
            let node = match &desc.kind {
                TextureKind::ImageMap {
                    filename,
                    gamma,
                    gain,
                    wrap,
                    mapping,
                } => {
                    let key = (filename.as_str(), gamma.to_bits());
                    let image = match decoded.get(&key) {
                        Some(&image) => image,
                        None => {
                            let bytes = source.read(filename)?;
                            images.push(image_io::decode(&bytes, filename, *gamma)?);
                            decoded.insert(key, images.len() - 1);
                            images.len() - 1
                        }
                    };
                    Node::Image {
                        image,
                        gain: *gain,
                        wrap: *wrap,
                        mapping: Mapping::new(mapping),
                    }
                }
                TextureKind::Checkerboard2D {
                    tex1,
                    tex2,
                    mapping,
                } => Node::Checkerboard2D {
                    tex1: *tex1,
                    tex2: *tex2,
                    mapping: Mapping::new(mapping),
                },
                TextureKind::Checkerboard3D {
                    tex1,
                    tex2,
                    world_to_texture,
                } => Node::Checkerboard3D {
                    tex1: *tex1,
                    tex2: *tex2,
                    world_to_texture: *world_to_texture,
                },
                TextureKind::Constant(c) => Node::Constant(*c),
                TextureKind::Scale { tex1, tex2 } => Node::Scale {
                    tex1: *tex1,
                    tex2: *tex2,
                },
                TextureKind::Mix { tex1, tex2, amount } => Node::Mix {
                    tex1: *tex1,
                    tex2: *tex2,
                    amount: *amount,
                },
            };
            textures.push(Texture {
                node,
                is_color: desc.is_color,
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
        let value = match &texture.node {
            Node::Image {
                image,
                gain,
                wrap,
                mapping,
            } => image::lookup(&self.images[*image], mapping.map(at), *wrap, *gain),
            Node::Checkerboard2D {
                tex1,
                tex2,
                mapping,
            } => {
                let st = mapping.map(at).floor();
                let first = (st.x + st.y).rem_euclid(2.0) == 0.0;
                self.eval(if first { *tex1 } else { *tex2 }, at)
            }
            Node::Checkerboard3D {
                tex1,
                tex2,
                world_to_texture,
            } => {
                let p = world_to_texture.transform_point3(at.p).floor();
                let first = (p.x + p.y + p.z).rem_euclid(2.0) == 0.0;
                self.eval(if first { *tex1 } else { *tex2 }, at)
            }
            Node::Constant(c) => *c,
            Node::Scale { tex1, tex2 } => self.eval(*tex1, at) * self.eval(*tex2, at),
            Node::Mix { tex1, tex2, amount } => {
                let t = self.eval(*amount, at).x;
                self.eval(*tex1, at) * (1.0 - t) + self.eval(*tex2, at) * t
            }
        };
        if texture.is_color {
            value
        } else {
            Vec3::splat(value.element_sum() / 3.0)
        }
    }
}
