//! Everything besides the scene that decides the image: the resolved render settings and the
//! command-line overrides they are resolved from.

use crate::desc::{LatLongConvention, SceneDesc};

/// Everything besides the scene that decides the image. Identical settings and scene give
/// bit-identical images whatever renders them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
    pub latlong: LatLongConvention,
}

/// Command-line overrides of what the scene file says.
#[derive(Clone, Debug, Default)]
pub struct RenderOverrides {
    pub spp: Option<u32>,
    pub max_depth: Option<u32>,
    pub seed: Option<u64>,
    pub resolution: Option<(u32, u32)>,
    pub latlong: LatLongConvention,
}

/// Samples per pixel when neither the file nor the command line says.
pub const DEFAULT_SPP: u32 = 64;

impl RenderSettings {
    pub fn resolve(desc: &SceneDesc, overrides: &RenderOverrides) -> Self {
        let (width, height) = overrides
            .resolution
            .unwrap_or((desc.film.xresolution, desc.film.yresolution));
        let spp = overrides
            .spp
            .or(desc.film.haltspp)
            .or(desc.sampler.pixel_samples)
            .unwrap_or(DEFAULT_SPP)
            .max(1);
        Self {
            width: width.max(1),
            height: height.max(1),
            spp,
            max_depth: overrides.max_depth.unwrap_or(desc.integrator.max_depth),
            seed: overrides.seed.unwrap_or(0),
            latlong: overrides.latlong,
        }
    }
}
