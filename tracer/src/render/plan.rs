//! The unit plan: how an image's pixels and samples are cut into work units.

use super::settings::RenderSettings;
use super::unit::WorkUnit;

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
