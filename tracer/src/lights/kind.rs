//! What every light kind says of itself, for the dispatch [`super`]'s kind list generates: its
//! name, the files it reads and the light it becomes in the scene's sampler. A leaf of the
//! light family, so the light files never import `lights/mod.rs`.

use crate::assets::AssetSource;

use super::error::LightError;

/// How a LatLong map is indexed (docs/architecture.md): the seed tracer's u = (pi + phi) / 2pi, or
/// LuxRender's s = phi / 2pi with phi in [0, 2pi). Both use t = theta / pi.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LatLongConvention {
    #[default]
    Seed,
    LuxRender,
}

/// Where the lights' maps come from: the scene's files, and the LatLong convention they are
/// indexed by.
pub struct MapSource<'a> {
    pub files: &'a dyn AssetSource,
    pub latlong: LatLongConvention,
}

pub trait LightKind {
    /// What the light becomes in the sampler (the list line says which [`super::Lights`]
    /// member holds it).
    type Sampler;

    /// The LuxRender type name.
    fn name(&self) -> &'static str;

    /// The files the light references (as written; the scene lists them in its assets).
    fn files(&self) -> Vec<&str> {
        Vec::new()
    }

    /// The light ready to sample, its maps read from `maps`; None when it emits nothing.
    fn light(&self, maps: &MapSource) -> Result<Option<Self::Sampler>, LightError>;
}
