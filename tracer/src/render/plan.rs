//! The unit plan: how an image's pixels and samples are cut into work units.

use super::settings::RenderSettings;
use super::unit::WorkUnit;

/// Tiles of this many pixels on a side.
pub const TILE_SIZE: u32 = 64;

/// Sample ranges per tile: enough passes for useful previews and balancing, few enough that a
/// unit's work dwarfs its network round trip.
pub const PASSES: u32 = 8;

/// A unit's samples per pixel are a multiple of this (but the last pass's): whole packets of
/// the samples a pixel's camera paths are traced in together (8 lanes of AVX2,
/// `integrator::packet`). A render of fewer than 8 x `PASSES` samples a pixel has fewer passes.
pub const UNIT_SAMPLE_STEP: u32 = 8;

/// The last pass is cut into tiles of this side when its full-size units are long (see
/// `FINE_FINAL_PASS_SAMPLES`).
pub const FINAL_PASS_TILE_SIZE: u32 = TILE_SIZE / 2;

/// A full-size unit of at least this many samples (about half a core-second at a couple of
/// microseconds per sample) gets a finer last pass: the last units of a render then end close
/// together, instead of a few long ones keeping a farm waiting while every other worker idles.
/// Shorter units end close together anyway, and finer ones would only add round trips.
pub const FINE_FINAL_PASS_SAMPLES: u64 = 1 << 18;

/// Changes whenever the same settings would give another plan. A unit's buffer is summed in
/// f32 before it reaches the exact film, so another plan gives slightly different image bits:
/// a checkpoint of another plan must not be resumed (it is part of the render's identity).
/// Version 3: samples are splatted through the pixel filter into their neighbours. Version 4:
/// a unit's sample range is a multiple of [`UNIT_SAMPLE_STEP`].
pub const PLAN_VERSION: u32 = 4;

/// The unit plan: tiles of `TILE_SIZE` in scanline order, and `PASSES` sample ranges, ordered
/// by sample range first so that any prefix of the plan covers the whole image; the last range
/// in tiles of `FINAL_PASS_TILE_SIZE` when units are long. It depends on the settings only: a
/// pixel's sum is added up unit by unit, so the same plan everywhere is what makes in-process
/// and distributed images bit-identical.
pub fn plan_units(settings: &RenderSettings) -> Vec<WorkUnit> {
    let samples_per_unit = settings
        .spp
        .div_ceil(PASSES)
        .max(1)
        .next_multiple_of(UNIT_SAMPLE_STEP);
    let fine_final_pass =
        u64::from(TILE_SIZE * TILE_SIZE) * u64::from(samples_per_unit) >= FINE_FINAL_PASS_SAMPLES;
    let mut units = Vec::new();
    let mut start = 0u32;
    while start < settings.spp {
        let end = start.saturating_add(samples_per_unit).min(settings.spp);
        let tile = if end == settings.spp && fine_final_pass {
            FINAL_PASS_TILE_SIZE
        } else {
            TILE_SIZE
        };
        push_pass(&mut units, settings, (start, end), tile);
        start = end;
    }
    units
}

/// Appends the units of one pass, samples `range` of every pixel, in tiles of side `tile` in
/// scanline order, indexed on from the units already there.
pub fn push_pass(
    units: &mut Vec<WorkUnit>,
    settings: &RenderSettings,
    range: (u32, u32),
    tile: u32,
) {
    for y0 in (0..settings.height).step_by(tile as usize) {
        for x0 in (0..settings.width).step_by(tile as usize) {
            units.push(WorkUnit {
                index: u32::try_from(units.len()).unwrap_or(u32::MAX),
                x0,
                y0,
                x1: x0.saturating_add(tile).min(settings.width),
                y1: y0.saturating_add(tile).min(settings.height),
                sample_start: range.0,
                sample_end: range.1,
                mask: None,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(width: u32, height: u32, spp: u32) -> RenderSettings {
        RenderSettings::for_tests(width, height, spp)
    }

    /// How many units hold each (pixel, sample index).
    fn coverage(s: &RenderSettings, units: &[WorkUnit]) -> Vec<u32> {
        let mut count = vec![0; (s.width * s.height * s.spp) as usize];
        for u in units {
            for y in u.y0..u.y1 {
                for x in u.x0..u.x1 {
                    for i in u.sample_start..u.sample_end {
                        count[((y * s.width + x) * s.spp + i) as usize] += 1;
                    }
                }
            }
        }
        count
    }

    #[test]
    fn every_sample_of_every_pixel_is_in_one_unit_in_pass_order() {
        for s in [
            settings(130, 70, 16),
            settings(100, 40, 1000),
            settings(7, 5, 3),
        ] {
            let units = plan_units(&s);
            assert!(coverage(&s, &units).iter().all(|&c| c == 1), "{s:?}");
            assert!(units.iter().enumerate().all(|(i, u)| u.index == i as u32));
            assert!(units
                .windows(2)
                .all(|w| w[0].sample_start <= w[1].sample_start));
        }
    }

    /// Every sample of every pixel once at the largest settings `check` accepts.
    #[test]
    fn the_plan_covers_every_sample_at_the_limits() {
        use crate::render::settings::{MAX_SIDE, MAX_SPP};
        for s in [
            settings(64, 64, MAX_SPP),
            settings(MAX_SIDE, 1, 7),
            settings(1, MAX_SIDE, MAX_SPP),
        ] {
            s.check().unwrap();
            let units = plan_units(&s);
            let samples: u64 = units.iter().map(WorkUnit::sample_count).sum();
            let pixels = u64::from(s.width) * u64::from(s.height);
            assert_eq!(samples, pixels * u64::from(s.spp), "{s:?}");
            assert!(units.iter().enumerate().all(|(i, u)| u.index as usize == i));
        }
    }

    /// Units hold whole packets of a pixel's samples: 16 samples are two passes of 8, 1000 are
    /// seven of 128 and one of 104, 3 one pass.
    #[test]
    fn units_hold_whole_packets_of_samples() {
        for (spp, passes) in [(16, 2), (64, 8), (1000, 8), (3, 1)] {
            let units = plan_units(&settings(64, 64, spp));
            let mut starts: Vec<_> = units.iter().map(|u| u.sample_start).collect();
            starts.dedup();
            assert_eq!(starts.len(), passes, "{spp} spp");
            for u in units.iter().filter(|u| u.sample_end < spp) {
                assert_eq!(
                    (u.sample_end - u.sample_start) % UNIT_SAMPLE_STEP,
                    0,
                    "{u:?}"
                );
            }
        }
    }

    /// An spp `check` refuses still plans without overflowing: the last pass ends at u32::MAX.
    #[test]
    fn an_unchecked_spp_does_not_overflow() {
        let units = plan_units(&settings(1, 1, u32::MAX));
        assert_eq!(units.len(), PASSES as usize);
        assert_eq!(units.last().unwrap().sample_end, u32::MAX);
    }

    #[test]
    fn only_long_units_get_a_finer_last_pass() {
        // 64x64 x 16 samples per pass = 65536 samples: short units, one tile size.
        let short = plan_units(&settings(128, 96, 128));
        assert_eq!(short.len(), 4 * PASSES as usize);
        // 64x64 x 128 samples per pass: the last pass in 32-pixel tiles (4 x 3 of them).
        let long = plan_units(&settings(128, 96, 1000));
        assert_eq!(long.len(), 4 * (PASSES as usize - 1) + 12);
        let last = long.last().unwrap();
        assert_eq!((last.sample_start, last.sample_end), (896, 1000));
        assert_eq!(last.x1 - last.x0, FINAL_PASS_TILE_SIZE);
        assert!(long[..28].iter().all(|u| u.x1 - u.x0 == TILE_SIZE));
    }
}
