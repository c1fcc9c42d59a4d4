//! What every lobe says of itself, for the dispatch [`super`]'s lobe list generates: its value,
//! density and sampling in the local shading frame, and the facts the path tracer asks of it.
//! A leaf of the lobe family, so the lobe files never import `bxdf/mod.rs`.

use glam::{Vec2, Vec3};

use super::sample::LocalSample;

pub trait Lobe {
    /// Whether the lobe looks the same from both sides: [`super::Bxdf`] then mirrors a query
    /// from below to the upper hemisphere, so the lobe only handles wo.z >= 0.
    const TWO_SIDED: bool = true;

    /// Whether the lobe is a delta distribution (light samples never find it).
    fn is_specular(&self) -> bool {
        false
    }

    /// Whether the lobe reflects only (light reaches the surface from the side it is seen
    /// from) and spreads over the hemisphere much as the cosine does (see
    /// [`super::Bxdf::gathers_broadly`]).
    const GATHERS_BROADLY: bool = false;

    /// For a narrow glossy lobe, the half angle around the mirror direction that holds most of
    /// it (see [`super::Bxdf::glossy_spread`]).
    fn glossy_spread(&self) -> Option<f32> {
        None
    }

    /// Roughly what the lobe reflects and transmits of the light arriving at `cos_o`: what a
    /// coat over it weighs it by when choosing which to sample.
    fn albedo_hint(&self, cos_o: f32) -> Vec3;

    fn f(&self, wo: Vec3, wi: Vec3) -> Vec3;

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// A direction sampled for `wo`: `u_lobe` chooses between reflection and transmission
    /// where the lobe has both, `u` the direction.
    fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<LocalSample>;
}
