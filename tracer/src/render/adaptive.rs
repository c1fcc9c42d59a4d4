//! Deterministic adaptive sampling: the render goes in rounds, and after each one the merged
//! film alone decides which blocks of pixels get the next round's samples.
//!
//! `yat render --noise-threshold E [--min-spp N] --spp MAX`
//!
//! | setting | meaning | default |
//! |---|---|---|
//! | `threshold` (`--noise-threshold`) | the error a block of pixels stops at (see below) | none: uniform |
//! | `min_spp` (`--min-spp`) | samples of round 0, which every pixel gets; even | [`DEFAULT_MIN_SPP`] |
//! | `spp` (`--spp`) | the most samples any pixel gets | the render's spp |
//!
//! **Rounds.** Round 0 renders samples [0, min_spp) of every pixel; round k >= 1 renders
//! samples [min_spp 2^(k-1), min_spp 2^k) (capped at spp) of the blocks still active, so each
//! round doubles an active block's samples. A block is [`BLOCK_SIZE`] pixels square on the
//! image's grid; the units of a round are the plan's 64-pixel tiles with a mask of their active
//! blocks ([`WorkUnit::mask`]), tiles with none left out.
//!
//! **Error estimate.** A masked unit also sums its odd-index samples, so the film holds per
//! pixel the mean `m` of all its samples and the mean `h` of the odd half (Cycles' and
//! Dammertz et al.'s "two buffers", 2010). Since every pixel's sample count is even, `m - h` is
//! half the difference of two independent half means: its variance is exactly the variance of
//! `m`, so `|m - h|` estimates the error of the pixel. The error of a pixel is that difference
//! (channel average) over the square root of the pixel's brightness, both relative to the
//! image's mean brightness `S`: `e = |m - h| / sqrt(S (|m| + DARK_FRACTION S))`. For a pixel of
//! average brightness it is the relative error; brighter pixels must get relatively cleaner (as
//! in Cycles' `|I - A| / sqrt(I)`: they dominate the squared error of a linear image, and the
//! square root is close to how display encoding spreads brightness), and black pixels are
//! compared with a small fraction of the mean rather than with zero. Dividing by `S` makes the
//! threshold independent of the scene's radiance units. A block's error is the mean of its
//! pixels' (one pixel's `|m - h|` is a single draw; 64 of them make a usable estimate).
//!
//! **Decision.** A block stays active for the next round only if it was active in this one and
//! the largest error of it and its eight neighbours exceeds the threshold: the neighbours keep
//! a block going at the edge of a noisy region (where its own estimate may be lucky). A block
//! that stops never restarts, so a block's samples are `[0, n)` for the `n` of the last round
//! it was in, and [`Round::planned`] says each one's `n`. Every number here comes from the
//! exact film sums in a fixed order, so the decision is the same bits on every machine, for
//! any number of workers and any order of arrival.

use crate::film::Film;

use super::plan::TILE_SIZE;
use super::settings::RenderSettings;
use super::unit::{WorkUnit, BLOCK_SIZE, MAX_MASKED_SIDE};

/// Samples of round 0 when `--min-spp` is not given: enough for the odd half (8 samples) to
/// say something about a block of 64 pixels.
pub const DEFAULT_MIN_SPP: u32 = 16;

// A mask covers a plan tile.
const _: () = assert!(TILE_SIZE == MAX_MASKED_SIDE);

/// Black and dark pixels are compared with this fraction of the image's mean brightness.
pub const DARK_FRACTION: f64 = 0.01;

/// A round's unit of a tile takes at most about this many samples (as many sample indices
/// as fit for the tile's active pixels): a full tile gets 64 per unit, a lone block 4096, so
/// late rounds of a few blocks are cut into units as even as round 0's.
pub const UNIT_SAMPLES: u64 = 1 << 18;

/// The adaptive settings of a render (its spp is the most any pixel gets).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveSettings {
    /// A block whose error (see the module doc) is at most this stops.
    pub threshold: f32,
    /// Samples of round 0.
    pub min_spp: u32,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AdaptiveError {
    #[error("the noise threshold {0} must be a positive number")]
    Threshold(f32),
    #[error("--min-spp {0} must be even and at least 2 (the error estimate halves the samples)")]
    MinSpp(u32),
}

impl AdaptiveSettings {
    pub fn check(&self) -> Result<(), AdaptiveError> {
        if !(self.threshold.is_finite() && self.threshold > 0.0) {
            return Err(AdaptiveError::Threshold(self.threshold));
        }
        if self.min_spp < 2 || self.min_spp % 2 == 1 {
            return Err(AdaptiveError::MinSpp(self.min_spp));
        }
        Ok(())
    }

    /// The sample range of round `round`; None past the last round (samples beyond spp).
    pub fn round_range(&self, round: u32, spp: u32) -> Option<(u32, u32)> {
        let at = |k: u32| {
            1u64.checked_shl(k)
                .map_or(u64::MAX, |p| p.saturating_mul(u64::from(self.min_spp)))
        };
        let (start, end) = match round {
            0 => (0, u64::from(self.min_spp)),
            k => (at(k - 1), at(k)),
        };
        (start < u64::from(spp)).then(|| (start as u32, end.min(u64::from(spp)) as u32))
    }

    /// How many rounds a render of `spp` samples per pixel has at most.
    pub fn round_count(&self, spp: u32) -> u32 {
        (0..u32::BITS + 1)
            .take_while(|&r| self.round_range(r, spp).is_some())
            .count() as u32
    }
}

/// The blocks of an image: `columns x rows` blocks of [`BLOCK_SIZE`], the last ones cut short.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockGrid {
    pub columns: u32,
    pub rows: u32,
}

impl BlockGrid {
    pub fn of(settings: &RenderSettings) -> Self {
        Self {
            columns: settings.width.div_ceil(BLOCK_SIZE),
            rows: settings.height.div_ceil(BLOCK_SIZE),
        }
    }

    pub fn len(&self) -> usize {
        self.columns as usize * self.rows as usize
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Where a render's rounds are: the round under way and, per block (row-major), the samples
/// per pixel the block has when this round is done. A block is active in this round when that
/// is the round's end. With the film, all the state an adaptive render has (a checkpoint keeps
/// it; the next round is a function of both).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Round {
    pub index: u32,
    pub planned: Vec<u32>,
}

impl Round {
    /// Round 0: every block, `min_spp` samples (or spp when that is fewer).
    pub fn first(settings: &RenderSettings, adaptive: &AdaptiveSettings) -> Self {
        let end = adaptive.min_spp.min(settings.spp);
        Self {
            index: 0,
            planned: vec![end; BlockGrid::of(settings).len()],
        }
    }

    /// The round's sample range (empty when the settings hold no such round: a state no
    /// decision makes, which then plans no units).
    pub fn range(&self, settings: &RenderSettings, adaptive: &AdaptiveSettings) -> (u32, u32) {
        adaptive
            .round_range(self.index, settings.spp)
            .unwrap_or((settings.spp, settings.spp))
    }

    /// Whether `planned` fits the settings: one entry per block, each a sample count a block can
    /// have after this round. A checkpoint's round is checked so before it is used.
    pub fn fits(&self, settings: &RenderSettings, adaptive: &AdaptiveSettings) -> bool {
        let Some((_, end)) = adaptive.round_range(self.index, settings.spp) else {
            return false;
        };
        let possible = |n: u32| {
            (0..=self.index)
                .filter_map(|k| adaptive.round_range(k, settings.spp))
                .any(|(_, e)| e == n)
        };
        self.planned.len() == BlockGrid::of(settings).len()
            && self.planned.iter().all(|&n| n <= end && possible(n))
    }

    /// Whether block `b` takes part in this round.
    pub fn is_active(
        &self,
        b: usize,
        settings: &RenderSettings,
        adaptive: &AdaptiveSettings,
    ) -> bool {
        let (start, end) = self.range(settings, adaptive);
        start < end && self.planned.get(b) == Some(&end)
    }

    /// Blocks active in this round.
    pub fn active_count(&self, settings: &RenderSettings, adaptive: &AdaptiveSettings) -> usize {
        (0..self.planned.len())
            .filter(|&b| self.is_active(b, settings, adaptive))
            .count()
    }

    /// The units of this round: per sample chunk, the tiles (scanline order) with an active
    /// block, each with its mask; indexed from 0. A tile's chunk is at most [`UNIT_SAMPLES`]
    /// over its active pixels. Any prefix of a round covers its tiles evenly, as in the plan.
    pub fn units(&self, settings: &RenderSettings, adaptive: &AdaptiveSettings) -> Vec<WorkUnit> {
        let (start, end) = self.range(settings, adaptive);
        let grid = BlockGrid::of(settings);
        let per_tile = MAX_MASKED_SIDE / BLOCK_SIZE;
        let mut tiles = Vec::new();
        for y0 in (0..settings.height).step_by(TILE_SIZE as usize) {
            for x0 in (0..settings.width).step_by(TILE_SIZE as usize) {
                let mut unit = WorkUnit {
                    index: 0,
                    x0,
                    y0,
                    x1: (x0 + TILE_SIZE).min(settings.width),
                    y1: (y0 + TILE_SIZE).min(settings.height),
                    sample_start: start,
                    sample_end: end,
                    mask: Some(0),
                };
                let mut mask = 0u64;
                for by in 0..per_tile {
                    for bx in 0..per_tile {
                        let (gx, gy) = (x0 / BLOCK_SIZE + bx, y0 / BLOCK_SIZE + by);
                        if gx < grid.columns
                            && gy < grid.rows
                            && self.is_active((gy * grid.columns + gx) as usize, settings, adaptive)
                        {
                            mask |= 1 << (by * per_tile + bx);
                        }
                    }
                }
                if mask != 0 && start < end {
                    unit.mask = Some(mask);
                    let pixels = unit.active_pixel_count() as u64;
                    let chunk = (UNIT_SAMPLES / pixels).clamp(1, u64::from(end - start)) as u32;
                    tiles.push((unit, chunk));
                }
            }
        }
        let mut units = Vec::new();
        let chunks = tiles
            .iter()
            .map(|(_, chunk)| (end - start).div_ceil(*chunk))
            .max()
            .unwrap_or(0);
        for c in 0..chunks {
            for (tile, chunk) in &tiles {
                let from = start.saturating_add(c.saturating_mul(*chunk));
                if from >= end {
                    continue;
                }
                units.push(WorkUnit {
                    index: units.len() as u32,
                    sample_start: from,
                    sample_end: from.saturating_add(*chunk).min(end),
                    ..*tile
                });
            }
        }
        units
    }

    /// Camera samples: of the rounds before this one, of this round, and at most of the rounds
    /// after it (if every block active now stayed active to the end).
    pub fn samples(&self, settings: &RenderSettings, adaptive: &AdaptiveSettings) -> RoundSamples {
        let (start, end) = self.range(settings, adaptive);
        let grid = BlockGrid::of(settings);
        let mut counts = RoundSamples::default();
        for (b, &planned) in self.planned.iter().enumerate() {
            let pixels = block_pixels(grid, b as u32, settings);
            counts.before += pixels * u64::from(planned.min(start));
            if self.is_active(b, settings, adaptive) {
                counts.now += pixels * u64::from(end - start);
                counts.later += pixels * u64::from(settings.spp - end);
            }
        }
        counts
    }
}

/// Camera samples of an adaptive render, seen from a round: see [`Round::samples`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RoundSamples {
    pub before: u64,
    pub now: u64,
    pub later: u64,
}

/// The most units a round can have: a tile's round is cut into chunks of at least
/// `UNIT_SAMPLES / TILE_SIZE^2` samples (a full tile's), and no round has more than spp.
pub fn max_round_units(settings: &RenderSettings) -> usize {
    let tiles =
        settings.width.div_ceil(TILE_SIZE) as usize * settings.height.div_ceil(TILE_SIZE) as usize;
    let full_tile_chunk = UNIT_SAMPLES / u64::from(TILE_SIZE * TILE_SIZE);
    tiles * u64::from(settings.spp).div_ceil(full_tile_chunk) as usize
}

/// Pixels of block `b` (the last column and row are cut by the image's edge).
fn block_pixels(grid: BlockGrid, b: u32, settings: &RenderSettings) -> u64 {
    let (bx, by) = (b % grid.columns, b / grid.columns);
    let w = (settings.width - bx * BLOCK_SIZE).min(BLOCK_SIZE);
    let h = (settings.height - by * BLOCK_SIZE).min(BLOCK_SIZE);
    u64::from(w) * u64::from(h)
}

/// Per block (row-major), the mean error of its pixels (see the module doc); 0 for a film
/// without half sums.
pub fn block_errors(film: &Film, settings: &RenderSettings) -> Vec<f64> {
    let grid = BlockGrid::of(settings);
    let width = film.width() as usize;
    let brightness = |c: glam::Vec3| f64::from(c.x.abs() + c.y.abs() + c.z.abs()) / 3.0;
    let pixels = film.width() as usize * film.height() as usize;
    if !film.has_half() || pixels == 0 {
        return vec![0.0; grid.len()];
    }
    let mean_brightness = (0..pixels)
        .map(|i| brightness(film.pixel((i % width) as u32, (i / width) as u32)))
        .sum::<f64>()
        / pixels as f64;
    // An all-black image: any noise is relative to nothing; compare with 1 instead.
    let scale = if mean_brightness > 0.0 {
        mean_brightness
    } else {
        1.0
    };
    let mut sums = vec![0.0f64; grid.len()];
    for i in 0..pixels {
        let (x, y) = ((i % width) as u32, (i / width) as u32);
        let m = film.pixel(x, y);
        let difference = brightness(m - film.half_pixel(i));
        let error = difference / (scale * (brightness(m) + DARK_FRACTION * scale)).sqrt();
        let b = (y / BLOCK_SIZE * grid.columns + x / BLOCK_SIZE) as usize;
        sums[b] += error;
    }
    sums.iter()
        .enumerate()
        .map(|(b, sum)| sum / block_pixels(grid, b as u32, settings) as f64)
        .collect()
}

/// The round after `round`, decided from the film once every unit of `round` is merged: the
/// blocks active in `round` whose own or a neighbour's error exceeds the threshold get the
/// next round's samples. None when no block goes on or the samples are spent: the render is
/// done.
pub fn next_round(
    film: &Film,
    round: &Round,
    settings: &RenderSettings,
    adaptive: &AdaptiveSettings,
) -> Option<Round> {
    let index = round.index + 1;
    let (_, end) = adaptive.round_range(index, settings.spp)?;
    let grid = BlockGrid::of(settings);
    let errors = block_errors(film, settings);
    let threshold = f64::from(adaptive.threshold);
    let mut planned = round.planned.clone();
    let mut any = false;
    for by in 0..grid.rows {
        for bx in 0..grid.columns {
            let b = (by * grid.columns + bx) as usize;
            if !round.is_active(b, settings, adaptive) {
                continue;
            }
            let noisy = (by.saturating_sub(1)..(by + 2).min(grid.rows))
                .flat_map(|y| {
                    (bx.saturating_sub(1)..(bx + 2).min(grid.columns)).map(move |x| (x, y))
                })
                .any(|(x, y)| errors[(y * grid.columns + x) as usize] > threshold);
            if noisy {
                planned[b] = end;
                any = true;
            }
        }
    }
    any.then_some(Round { index, planned })
}

/// Samples per pixel of every pixel (row-major) once `round` is done.
pub fn samples_per_pixel(round: &Round, settings: &RenderSettings) -> Vec<u32> {
    let grid = BlockGrid::of(settings);
    (0..settings.height)
        .flat_map(|y| (0..settings.width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let b = (y / BLOCK_SIZE * grid.columns + x / BLOCK_SIZE) as usize;
            round.planned.get(b).copied().unwrap_or(0)
        })
        .collect()
}

/// The sample map: a grey image of samples per pixel on a log scale, white for the most any
/// pixel got, and each halving one step darker (`1 + log2(n / least)` over
/// `1 + log2(most / least)`); returns the image with the least and the most.
pub fn sample_map(round: &Round, settings: &RenderSettings) -> (image::GrayImage, u32, u32) {
    let spp = samples_per_pixel(round, settings);
    let least = spp.iter().copied().min().unwrap_or(0).max(1);
    let most = spp.iter().copied().max().unwrap_or(0).max(1);
    let steps = 1.0 + f64::from(most / least).log2();
    let grey = spp
        .iter()
        .map(|&n| {
            let v = (1.0 + (f64::from(n.max(1)) / f64::from(least)).log2()) / steps;
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        })
        .collect();
    let image = image::GrayImage::from_raw(settings.width, settings.height, grey)
        .expect("a value per pixel");
    (image, least, most)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::SampleBuffer;
    use crate::render::unit::FilmFrame;

    fn settings(width: u32, height: u32, spp: u32) -> RenderSettings {
        RenderSettings::for_tests(width, height, spp)
    }

    const ADAPTIVE: AdaptiveSettings = AdaptiveSettings {
        threshold: 0.05,
        min_spp: 16,
    };

    /// A cheap deterministic uniform random number in [0, 1) from a counter.
    fn hash01(n: u64) -> f64 {
        let mut z = n.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        (z ^ (z >> 31)) as f64 / 2f64.powi(64)
    }

    /// Renders a synthetic image into `film` for `units`: pixel values `mean(x) + noise(x) u`
    /// with u uniform in [-1, 1] per sample (so the standard deviation is noise / sqrt 3).
    fn render(
        film: &mut Film,
        units: &[WorkUnit],
        mean: impl Fn(u32) -> f64,
        noise: impl Fn(u32) -> f64,
    ) {
        for unit in units {
            let mut buffer = SampleBuffer::new(*unit, &film.frame());
            let w = unit.x1 - unit.x0;
            for y in unit.y0..unit.y1 {
                for x in unit.x0..unit.x1 {
                    if !unit.renders(x, y) {
                        continue;
                    }
                    let i = ((y - unit.y0) * w + (x - unit.x0)) as usize;
                    for s in unit.sample_start..unit.sample_end {
                        let u = 2.0
                            * hash01((u64::from(y) << 40) ^ (u64::from(x) << 20) ^ u64::from(s))
                            - 1.0;
                        let v = (mean(x) + noise(x) * u) as f32;
                        let add = |rgb: &mut [f32; 3], wt: &mut f32| {
                            rgb.iter_mut().for_each(|c| *c += v);
                            *wt += 1.0;
                        };
                        add(&mut buffer.rgb[i], &mut buffer.weight[i]);
                        if s % 2 == 1 {
                            add(&mut buffer.half_rgb[i], &mut buffer.half_weight[i]);
                        }
                    }
                }
            }
            film.add(&buffer).unwrap();
        }
    }

    #[test]
    fn rounds_double_the_samples_up_to_the_maximum() {
        let a = ADAPTIVE;
        let ranges: Vec<_> = (0..8).map(|k| a.round_range(k, 200)).collect();
        assert_eq!(
            ranges,
            [
                Some((0, 16)),
                Some((16, 32)),
                Some((32, 64)),
                Some((64, 128)),
                Some((128, 200)),
                None,
                None,
                None
            ]
        );
        assert_eq!(a.round_range(0, 10), Some((0, 10)));
        assert_eq!(a.round_range(1, 10), None);
        assert_eq!(a.round_range(40, u32::MAX), None, "no overflow");
        assert!(AdaptiveSettings { min_spp: 3, ..a }.check().is_err());
        assert!(AdaptiveSettings {
            threshold: 0.0,
            ..a
        }
        .check()
        .is_err());
        assert!(a.check().is_ok());
    }

    #[test]
    fn round_units_cover_each_active_pixel_once_per_sample() {
        let s = settings(150, 70, 64);
        let grid = BlockGrid::of(&s);
        assert_eq!((grid.columns, grid.rows), (19, 9));
        let mut round = Round {
            index: 1,
            planned: vec![16; grid.len()],
        };
        // Every third block goes on to 32 samples.
        for b in (0..grid.len()).step_by(3) {
            round.planned[b] = 32;
        }
        assert!(round.fits(&s, &ADAPTIVE));
        let units = round.units(&s, &ADAPTIVE);
        assert!(units.iter().enumerate().all(|(i, u)| u.index as usize == i));
        let mut count = vec![0u32; (s.width * s.height) as usize];
        for u in &units {
            assert_eq!(u.sample_start, 16);
            assert_eq!(u.sample_end, 32);
            for y in u.y0..u.y1 {
                for x in u.x0..u.x1 {
                    if u.renders(x, y) {
                        count[(y * s.width + x) as usize] += u.sample_end - u.sample_start;
                    }
                }
            }
        }
        let expected = samples_per_pixel(&round, &s);
        for (i, (&c, &e)) in count.iter().zip(&expected).enumerate() {
            assert_eq!(c, e - 16, "pixel {i}");
        }
        let counts = round.samples(&s, &ADAPTIVE);
        assert_eq!(
            counts.now,
            units.iter().map(WorkUnit::sample_count).sum::<u64>()
        );
        assert_eq!(
            counts.later,
            counts.now / 16 * 32,
            "32 more samples each to reach 64"
        );
        assert_eq!(counts.before, 16 * u64::from(s.width * s.height));
        assert!(units.len() <= max_round_units(&s));
        let wrong = Round {
            index: 1,
            planned: vec![20; grid.len()],
        };
        assert!(!wrong.fits(&s, &ADAPTIVE), "20 is no round's end");
    }

    #[test]
    fn a_flat_region_stops_and_a_noisy_one_goes_on() {
        // 128 x 64: the left half flat (no noise), the right half very noisy.
        let s = settings(128, 64, 1024);
        let mut film = Film::with_half(FilmFrame::unbordered(s.width, s.height));
        let mut round = Round::first(&s, &ADAPTIVE);
        let noise = |x: u32| if x < 64 { 0.0 } else { 0.73 };
        let mut history = Vec::new();
        loop {
            render(&mut film, &round.units(&s, &ADAPTIVE), |_| 0.5, noise);
            history.push(round.active_count(&s, &ADAPTIVE));
            match next_round(&film, &round, &s, &ADAPTIVE) {
                Some(next) => round = next,
                None => break,
            }
        }
        let spp = samples_per_pixel(&round, &s);
        // The flat blocks away from the noisy half stop after round 0; the noisy ones (and the
        // flat column beside them) go on until their error is under the threshold.
        assert_eq!(spp[0], 16, "{history:?}");
        assert_eq!(spp[(s.width * 10 + 40) as usize], 16);
        // The pixel standard deviation is 0.73 / sqrt 3 = 0.42 relative to 0.5: the error
        // estimate (~ 0.73 / sqrt n) falls under 0.05 between 128 and 256 samples (0.059,
        // 0.042); a block's neighbours may keep it one round more.
        let noisy: Vec<u32> = (64..128)
            .step_by(8)
            .map(|x| spp[(s.width * 30 + x) as usize])
            .collect();
        assert!(
            noisy.iter().all(|n| [256, 512].contains(n)),
            "{noisy:?} {history:?}"
        );
        assert!(
            noisy.iter().filter(|&&n| n == 256).count() >= 4,
            "{noisy:?}"
        );
        assert!(spp[(s.width * 10 + 60) as usize] >= 128, "dilated");
        assert!(history.windows(2).all(|w| w[1] <= w[0]), "{history:?}");
    }

    #[test]
    fn the_estimate_follows_the_known_standard_error() {
        // One flat-mean block of noise with a known standard deviation: the block's error
        // estimate is the mean of |m - h|, whose expected value for Gaussian-ish noise is
        // sqrt(2 / pi) x sigma / sqrt(n); uniform noise is close (the ratio is checked at 15%).
        for (n, amplitude) in [(16u32, 0.3f64), (64, 0.3), (256, 0.6)] {
            let s = settings(64, 64, n);
            let mut film = Film::with_half(FilmFrame::unbordered(64, 64));
            let round = Round::first(
                &s,
                &AdaptiveSettings {
                    min_spp: n,
                    ..ADAPTIVE
                },
            );
            render(
                &mut film,
                &round.units(
                    &s,
                    &AdaptiveSettings {
                        min_spp: n,
                        ..ADAPTIVE
                    },
                ),
                |_| 1.0,
                |_| amplitude,
            );
            let errors = block_errors(&film, &s);
            let mean_error = errors.iter().sum::<f64>() / errors.len() as f64;
            let sigma = amplitude / 3f64.sqrt();
            let expected = (2.0 / std::f64::consts::PI).sqrt() * sigma
                / f64::from(n).sqrt()
                / (1.0 + DARK_FRACTION).sqrt();
            let ratio = mean_error / expected;
            assert!(
                (0.85..1.15).contains(&ratio),
                "n {n}: {mean_error} vs {expected}"
            );
        }
    }

    #[test]
    fn the_sample_map_is_a_log_scale_of_the_samples() {
        let s = settings(16, 8, 64);
        let round = Round {
            index: 2,
            planned: vec![16, 64],
        };
        let (map, least, most) = sample_map(&round, &s);
        assert_eq!((least, most), (16, 64));
        assert_eq!(map.get_pixel(0, 0).0[0], 85, "1 of 3 steps");
        assert_eq!(map.get_pixel(15, 7).0[0], 255);
    }
}
