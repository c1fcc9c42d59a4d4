//! The render API every node uses: settings, the unit plan, the built scene and rendering one
//! unit into a sample buffer.

use crate::assets::AssetSource;
use crate::desc::{LatLongConvention, SceneDesc};
use crate::film::SampleBuffer;

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

/// A tile of pixels x a range of sample indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WorkUnit {
    /// Position in the plan; results are keyed by it.
    pub index: u32,
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    pub sample_start: u32,
    pub sample_end: u32,
}

impl WorkUnit {
    pub fn pixel_count(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }

    pub fn sample_count(&self) -> u64 {
        self.pixel_count() as u64 * u64::from(self.sample_end - self.sample_start)
    }
}

/// Counters a unit's render reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UnitStats {
    pub samples: u64,
    pub rays: u64,
    /// NaN or infinite samples dropped instead of entering the film.
    pub dropped: u64,
}

impl std::ops::AddAssign for UnitStats {
    fn add_assign(&mut self, o: Self) {
        self.samples += o.samples;
        self.rays += o.rays;
        self.dropped += o.dropped;
    }
}

#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error(transparent)]
    Texture(#[from] crate::texture::TextureError),
    #[error(transparent)]
    Light(#[from] crate::lights::LightError),
}

/// Tiles of this many pixels on a side.
pub const TILE_SIZE: u32 = 64;

/// Sample ranges per tile: enough passes for useful previews and balancing, few enough that a
/// unit's work dwarfs its network round trip.
pub const PASSES: u32 = 8;

/// The unit plan: tiles of `TILE_SIZE` in scanline order, and `PASSES` sample ranges, ordered
/// by sample range first so that any prefix of the plan covers the whole image. It depends on
/// the settings only: a pixel's sum is added up unit by unit, so the same plan everywhere is
/// what makes in-process and distributed images bit-identical.
pub fn plan_units(settings: &RenderSettings) -> Vec<WorkUnit> {
    let samples_per_unit = settings.spp.div_ceil(PASSES).max(1);
    let mut units = Vec::new();
    let mut start = 0;
    while start < settings.spp {
        let end = (start + samples_per_unit).min(settings.spp);
        for y0 in (0..settings.height).step_by(TILE_SIZE as usize) {
            for x0 in (0..settings.width).step_by(TILE_SIZE as usize) {
                units.push(WorkUnit {
                    index: units.len() as u32,
                    x0,
                    y0,
                    x1: (x0 + TILE_SIZE).min(settings.width),
                    y1: (y0 + TILE_SIZE).min(settings.height),
                    sample_start: start,
                    sample_end: end,
                });
            }
        }
        start = end;
    }
    units
}

/// The scene ready to render: world-space geometry and BVH, textures, materials, lights.
pub struct RenderScene {}

impl RenderScene {
    pub fn build(
        _desc: &SceneDesc,
        _source: &dyn AssetSource,
        _settings: &RenderSettings,
    ) -> Result<Self, BuildError> {
        todo!("renderer")
    }

    pub fn settings(&self) -> &RenderSettings {
        todo!("renderer")
    }

    pub fn triangle_count(&self) -> usize {
        todo!("renderer")
    }

    /// Renders one unit on the calling thread. Deterministic: the same unit gives the same
    /// buffer bytes on any machine and thread.
    pub fn render_unit(&self, _unit: &WorkUnit) -> (SampleBuffer, UnitStats) {
        todo!("renderer")
    }
}
