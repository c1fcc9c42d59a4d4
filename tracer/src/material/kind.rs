//! What every material kind says of itself, for the dispatch [`super`]'s kind list generates:
//! the textures and materials it references and the lobe and coat it makes at a hit. A leaf of
//! the material family, so the material files never import `material/mod.rs`.

use super::eval::HitTextures;
use crate::bxdf::coat_over_base::Coating;
use crate::bxdf::Bxdf;
use crate::refs::{MaterialId, TextureId};

pub trait MaterialKind {
    /// The textures the material reads directly, in parameter order.
    fn textures(&self) -> Vec<TextureId>;

    /// The materials it refers to (those a `mix` or `layered` chooses between, a
    /// glossycoating's base).
    fn materials(&self) -> Vec<MaterialId> {
        Vec::new()
    }

    /// The lobe at a hit, under [`MaterialKind::coating`]; `u` in [0, 1) chooses between
    /// lobes where a material has several.
    fn bxdf(&self, eval: &HitTextures, u: f32) -> Bxdf;

    /// The coat over [`MaterialKind::bxdf`], for the materials that have one.
    fn coating(&self, _eval: &HitTextures) -> Option<Coating> {
        None
    }

    /// Whether the material needs the multibounce albedo tables.
    fn multibounce(&self) -> bool {
        false
    }
}
