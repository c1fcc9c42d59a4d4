//! What a material's evaluation sees at a hit: its texture-or-constant parameters evaluated at
//! the hit point. A leaf of the material family, so the material files never import
//! `material/mod.rs`.

use glam::Vec3;

use crate::bxdf::microfacet::TrowbridgeReitz;
use crate::refs::{ConstOrTexture, TextureId};
use crate::texture::{LookupPoint, Textures};

/// The scene's textures and the point they are evaluated at.
pub struct HitTextures<'a> {
    pub textures: &'a Textures,
    pub at: LookupPoint,
}

/// Reflectances are clamped to [0, 1] (as LuxRender does) so no texture can create energy;
/// NaN becomes 0.
fn unit(c: Vec3) -> Vec3 {
    c.max(Vec3::ZERO).min(Vec3::ONE)
}

impl HitTextures<'_> {
    /// A colour parameter, clamped to [0, 1].
    pub fn color(&self, t: ConstOrTexture) -> Vec3 {
        unit(self.textures.eval(t, &self.at))
    }

    /// A float parameter.
    pub fn float(&self, t: ConstOrTexture) -> f32 {
        self.float_at(t, &self.at)
    }

    /// A float parameter at another point (a bump map's finite differences).
    pub fn float_at(&self, t: ConstOrTexture, at: &LookupPoint) -> f32 {
        self.textures.eval(t, at).x
    }

    /// The microfacet distribution for (u, v) roughness; None is a perfectly smooth surface.
    pub fn roughness(&self, u: ConstOrTexture, v: ConstOrTexture) -> Option<TrowbridgeReitz> {
        TrowbridgeReitz::from_roughness(self.float(u), self.float(v))
    }
}

/// The textures among `params`, in order (what a material references).
pub fn texture_ids(params: &[&ConstOrTexture]) -> Vec<TextureId> {
    params
        .iter()
        .filter_map(|t| match t {
            ConstOrTexture::Texture(id) => Some(*id),
            ConstOrTexture::Const(_) => None,
        })
        .collect()
}
