//! Deterministic adaptive sampling: the render goes in rounds, and after each one the merged
//! film alone decides which blocks of pixels get the next round's samples.
//!
//! `yat render --noise-threshold E [--min-spp N] --spp MAX`
//!
//! | setting | meaning | default |
//! |---|---|---|
//! | `threshold` (`--noise-threshold`) | the relative error the image aims at (see below) | none: uniform |
//! | `min_spp` (`--min-spp`) | samples of round 0, which every pixel gets; even | [`DEFAULT_MIN_SPP`] |
//! | `spp` (`--spp`) | the most samples any pixel gets | the render's spp |
//!
//! **Rounds.** Round 0 renders samples [0, min_spp) of every pixel; round k >= 1 renders
//! samples [min_spp 2^(k-1), min_spp 2^k) (capped at spp) of the blocks still active, so each
//! round doubles an active block's samples. A block is [`BLOCK_SIZE`] pixels square on the
//! image's grid; the units of a round are tiles of [`MAX_MASKED_SIDE`] pixels with a mask of
//! their active blocks ([`WorkUnit::mask`]), tiles with none left out.
//!
//! **The film.** A pixel filter wider than a pixel (the seed scenes' blackmanharris reaches 2
//! pixels each side, half a block) adds each sample to its neighbours too, and a plain weighted mean of
//! what reaches a pixel leans toward the block that has more samples: by a block of 1024
//! samples per pixel, a block of 16 is mostly its neighbour's image near their edge, a bias
//! that more samples never remove (it made adaptive renders lose to uniform ones). So an
//! adaptive film keeps each sample's sums in the source plane of the block it was taken in
//! (blocks of one plane are as many blocks apart as a filter reaches across: 2 for the seed
//! scenes, 3 to 5 for wider filters, [`super::unit::FilmFrame::plane_period`]; so a pixel gets
//! at most one block per plane), counts each block's samples, and divides each plane's sums by
//! its block's samples per pixel before adding them up ([`Film::pixel`]): every block weighs as
//! in a uniform render.
//!
//! **Noise estimate.** A masked unit also sums its odd-index samples, so the film holds per
//! pixel the mean `m` of all its `n` samples and the mean `h` of the odd half (the "two
//! buffers" of Cycles and of Dammertz et al. 2010; both plain means of what reaches the pixel,
//! so they lean alike). Since `n` is even, `m - h` is half the
//! difference of two independent half means: `E[(m - h)^2]` is exactly the variance of `m`,
//! `sigma^2 / n`. A block's `sigma_b`, the standard deviation of one sample, is so estimated as
//! `sqrt(n_b x mean of (m - h)^2 over its pixels and channels)` ([`Noise`]).
//!
//! **Decision.** The threshold `E` is the image's error aimed at: its root-mean-square error
//! (over pixels and channels, linear radiance) over its mean brightness `S`, so it does not
//! depend on the scene's radiance units. For a number of samples, the squared error
//! `sum_b P_b sigma_b^2 / n_b` (`P_b` pixels per block) is least when `n_b` is proportional
//! to `sigma_b`; it is then `(E S)^2` per pixel when `n_b = sigma_b mean(sigma) / (E S)^2`
//! (`mean(sigma)` over pixels) ([`Noise::samples_wanted`]). A block active in a round goes on
//! to the next while it wants more than [`GO_ON`] times the samples it has. (Stopping each
//! block at one relative error instead, `n_b ~ sigma_b^2 / |m_b|^2`, spends the most on dark
//! noisy corners that add least to the error: no fewer samples than a uniform render for the
//! same squared error, and often more.) A block that stops never restarts, so a block's samples
//! are `[0, n)` for the `n` of the last round it was in, and [`Round::planned`] says each one's
//! `n`. Every number here comes from the exact film sums in a fixed order, so the decision is
//! the same bits on every machine, for any number of workers and any order of arrival.

use crate::film::Film;
use crate::sampler::NESTED_FIRST_BLOCK;

use super::settings::RenderSettings;
use super::unit::{WorkUnit, BLOCK_SIZE, MAX_MASKED_SIDE};

/// Samples of round 0 when `--min-spp` is not given: enough for the odd half (8 samples) to
/// say something about a block of 16 pixels, and the sampler's first nested block, so that
/// every round's samples are stratified on their own.
pub const DEFAULT_MIN_SPP: u32 = NESTED_FIRST_BLOCK;

/// Side of a round's tiles: the most a mask covers.
const ROUND_TILE: u32 = MAX_MASKED_SIDE;

/// A block goes on while it wants more than this many times its samples: the geometric middle
/// of its samples now and after one more round, so it ends as near as doubling allows to what
/// it wants.
pub const GO_ON: f64 = std::f64::consts::SQRT_2;

/// A round's unit of a tile takes at most about this many samples (as many sample indices
/// as fit for the tile's active pixels): a full tile gets 256 per unit, a lone block 16384, so
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
        let mut tiles = Vec::new();
        for y0 in (0..settings.height).step_by(ROUND_TILE as usize) {
            for x0 in (0..settings.width).step_by(ROUND_TILE as usize) {
                let mut unit = WorkUnit {
                    index: 0,
                    x0,
                    y0,
                    x1: (x0 + ROUND_TILE).min(settings.width),
                    y1: (y0 + ROUND_TILE).min(settings.height),
                    sample_start: start,
                    sample_end: end,
                    mask: None,
                };
                let mask = unit
                    .tile_blocks()
                    .filter(|&(x, y, _)| {
                        let b = y / BLOCK_SIZE * grid.columns + x / BLOCK_SIZE;
                        self.is_active(b as usize, settings, adaptive)
                    })
                    .fold(0, |mask, (_, _, bit)| mask | bit);
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
/// `UNIT_SAMPLES / ROUND_TILE^2` samples (a full tile's), and no round has more than spp.
pub fn max_round_units(settings: &RenderSettings) -> usize {
    let tiles = settings.width.div_ceil(ROUND_TILE) as usize
        * settings.height.div_ceil(ROUND_TILE) as usize;
    let full_tile_chunk = UNIT_SAMPLES / u64::from(ROUND_TILE * ROUND_TILE);
    tiles * u64::from(settings.spp).div_ceil(full_tile_chunk) as usize
}

/// Pixels of block `b` (the last column and row are cut by the image's edge).
fn block_pixels(grid: BlockGrid, b: u32, settings: &RenderSettings) -> u64 {
    let (bx, by) = (b % grid.columns, b / grid.columns);
    let w = (settings.width - bx * BLOCK_SIZE).min(BLOCK_SIZE);
    let h = (settings.height - by * BLOCK_SIZE).min(BLOCK_SIZE);
    u64::from(w) * u64::from(h)
}

/// What the merged film says about the noise of each block, read in one pass over its pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Noise {
    /// Per block (row-major): the estimated standard deviation of one sample of its pixels,
    /// `sigma_b` (see the module doc).
    pub sigma: Vec<f64>,
    /// The image's mean brightness `S` (channel mean of |pixel|); 1 for a black image, whose
    /// noise is then compared with 1 rather than with nothing.
    pub brightness: f64,
}

impl Noise {
    /// The estimate from the film once `round` is merged (every block has its planned samples);
    /// no noise for a film without half sums.
    pub fn of(film: &Film, round: &Round, settings: &RenderSettings) -> Self {
        let grid = BlockGrid::of(settings);
        let (width, height) = (film.width(), film.height());
        let pixels = width as usize * height as usize;
        let mut variance = vec![0.0f64; grid.len()];
        let mut brightness = 0.0f64;
        if film.has_half() {
            for y in 0..height {
                for x in 0..width {
                    let i = (y * width + x) as usize;
                    let m = film.plain_pixel(i).as_dvec3();
                    let d = m - film.half_pixel(i).as_dvec3();
                    brightness += m.abs().element_sum() / 3.0;
                    variance[(y / BLOCK_SIZE * grid.columns + x / BLOCK_SIZE) as usize] +=
                        d.length_squared() / 3.0;
                }
            }
        }
        let sigma = variance
            .iter()
            .enumerate()
            .map(|(b, &v)| {
                let n = round.planned.get(b).copied().unwrap_or(0);
                (f64::from(n) * v / block_pixels(grid, b as u32, settings) as f64).sqrt()
            })
            .collect();
        let mean = brightness / pixels.max(1) as f64;
        Self {
            sigma,
            brightness: if mean > 0.0 { mean } else { 1.0 },
        }
    }

    /// Per block, the samples per pixel that bring the image to the relative error
    /// `threshold` at the least cost: `sigma_b mean(sigma) / (threshold S)^2` (the module doc).
    pub fn samples_wanted(&self, threshold: f64, settings: &RenderSettings) -> Vec<f64> {
        let grid = BlockGrid::of(settings);
        let pixels = u64::from(settings.width) * u64::from(settings.height);
        let mean_sigma = self
            .sigma
            .iter()
            .enumerate()
            .map(|(b, s)| s * block_pixels(grid, b as u32, settings) as f64)
            .sum::<f64>()
            / pixels.max(1) as f64;
        let scale = mean_sigma / (threshold * self.brightness).powi(2);
        self.sigma.iter().map(|s| s * scale).collect()
    }
}

/// The round after `round`, decided from the film once every unit of `round` is merged: the
/// blocks active in `round` that want more samples than they have (see the module doc) get
/// the next round's. None when no block goes on or the samples are spent: the render is done.
pub fn next_round(
    film: &Film,
    round: &Round,
    settings: &RenderSettings,
    adaptive: &AdaptiveSettings,
) -> Option<Round> {
    let index = round.index + 1;
    let (_, end) = adaptive.round_range(index, settings.spp)?;
    let wanted =
        Noise::of(film, round, settings).samples_wanted(f64::from(adaptive.threshold), settings);
    let mut planned = round.planned.clone();
    let mut any = false;
    for (b, &want) in wanted.iter().enumerate() {
        if round.is_active(b, settings, adaptive) && want > GO_ON * f64::from(planned[b]) {
            planned[b] = end;
            any = true;
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
    let steps = 1.0 + libm::log2(f64::from(most / least));
    let grey = spp
        .iter()
        .map(|&n| {
            let v = (1.0 + libm::log2(f64::from(n.max(1)) / f64::from(least))) / steps;
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
                    let plane = film.frame().source_plane(x, y) * buffer.region.pixel_count();
                    for s in unit.sample_start..unit.sample_end {
                        let u = 2.0
                            * hash01((u64::from(y) << 40) ^ (u64::from(x) << 20) ^ u64::from(s))
                            - 1.0;
                        let v = (mean(x) + noise(x) * u) as f32;
                        let add = |rgb: &mut [f32; 3], wt: &mut f32| {
                            rgb.iter_mut().for_each(|c| *c += v);
                            *wt += 1.0;
                        };
                        add(&mut buffer.rgb[plane + i], &mut buffer.weight[plane + i]);
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
        assert_eq!((grid.columns, grid.rows), (38, 18));
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

    /// Renders round after round until the render is done; returns the last round and the
    /// active blocks per round.
    fn render_to_the_end(
        film: &mut Film,
        s: &RenderSettings,
        a: &AdaptiveSettings,
        mean: impl Fn(u32) -> f64 + Copy,
        noise: impl Fn(u32) -> f64 + Copy,
    ) -> (Round, Vec<usize>) {
        let mut round = Round::first(s, a);
        let mut history = Vec::new();
        loop {
            render(film, &round.units(s, a), mean, noise);
            history.push(round.active_count(s, a));
            match next_round(film, &round, s, a) {
                Some(next) => round = next,
                None => return (round, history),
            }
        }
    }

    #[test]
    fn samples_follow_the_noise_and_the_image_reaches_the_threshold() {
        // 128 x 64 of mean 0.5: columns [0, 16) exact, [16, 64) noisy, [64, 128) four times as
        // noisy (standard deviations 0.2 / sqrt 3 and 0.8 / sqrt 3, mean sigma 0.274). The
        // cheapest samples for a relative error E are n ~ sigma: with E = 0.0445 (E S = 0.02224)
        // the noisy blocks want 64, the noisier 256, each the geometric middle of the rounds
        // around it (a margin of sqrt 2 against the estimate's noise).
        let s = settings(128, 64, 1 << 14);
        let a = AdaptiveSettings {
            threshold: 0.0445,
            min_spp: 16,
        };
        let noise = |x: u32| match x {
            0..16 => 0.0,
            16..64 => 0.2,
            _ => 0.8,
        };
        let mut film = Film::adaptive(FilmFrame::unbordered(s.width, s.height));
        let (round, history) = render_to_the_end(&mut film, &s, &a, |_| 0.5, noise);
        let spp = samples_per_pixel(&round, &s);
        let at = |x: u32| -> Vec<u32> {
            (0..64)
                .step_by(8)
                .map(|y| spp[(y * s.width + x) as usize])
                .collect()
        };
        assert!(at(3).iter().all(|&n| n == 16), "{:?} {history:?}", at(3));
        assert!(at(40).iter().all(|&n| n == 64), "{:?} {history:?}", at(40));
        assert!(
            at(100).iter().all(|&n| n == 256),
            "{:?} {history:?}",
            at(100)
        );
        assert!(history.windows(2).all(|w| w[1] <= w[0]), "{history:?}");
        // The image's error (against the exact 0.5) is the threshold, relative to its mean
        // brightness, and well under a uniform render's with as many samples.
        let squared: f64 = film
            .radiance()
            .iter()
            .map(|p| (f64::from(p.x) - 0.5).powi(2))
            .sum::<f64>()
            / f64::from(s.width * s.height);
        let relative = squared.sqrt() / 0.5;
        assert!(
            (0.9 * 0.0445..1.1 * 0.0445).contains(&relative),
            "relative error {relative}"
        );
        let mean_spp = spp.iter().map(|&n| f64::from(n)).sum::<f64>() / spp.len() as f64;
        let uniform = (3.0 / 8.0 * 0.04 / 3.0 + 0.5 * 0.64 / 3.0) / mean_spp;
        assert!(
            squared < 0.75 * uniform,
            "{squared} vs uniform {uniform} at {mean_spp} spp"
        );
    }

    #[test]
    fn the_estimate_follows_the_known_standard_deviation() {
        // Flat noise of a known standard deviation: E[(m - h)^2] is the variance of m, so
        // sigma = sqrt(n mean (m - h)^2) estimates amplitude / sqrt 3 whatever n is.
        for (n, amplitude) in [(16u32, 0.3f64), (64, 0.3), (256, 0.6)] {
            let s = settings(64, 64, n);
            let a = AdaptiveSettings {
                min_spp: n,
                ..ADAPTIVE
            };
            let mut film = Film::adaptive(FilmFrame::unbordered(64, 64));
            let round = Round::first(&s, &a);
            render(&mut film, &round.units(&s, &a), |_| 1.0, |_| amplitude);
            let noise = Noise::of(&film, &round, &s);
            let blocks = noise.sigma.len();
            assert_eq!(blocks, 256);
            let mean = noise.sigma.iter().sum::<f64>() / blocks as f64;
            let expected = amplitude / 3f64.sqrt();
            assert!(
                (0.95..1.05).contains(&(mean / expected)),
                "n {n}: {mean} vs {expected}"
            );
            // One block's estimate averages 16 pixels' (m - h)^2, each sigma^2 / n times a
            // chi-square of one degree (the channels are equal here): its square is off by
            // sqrt(2 / 16) = 35% and itself by about half that, 18%; no block by 60%.
            let spread = (noise
                .sigma
                .iter()
                .map(|&b| (b / mean - 1.0).powi(2))
                .sum::<f64>()
                / blocks as f64)
                .sqrt();
            assert!((0.12..0.24).contains(&spread), "n {n}: spread {spread}");
            assert!(
                noise
                    .sigma
                    .iter()
                    .all(|&b| (0.4..1.6).contains(&(b / expected))),
                "n {n}: {:?}",
                noise.sigma
            );
            assert!(
                (noise.brightness - 1.0).abs() < 0.02,
                "{}",
                noise.brightness
            );
        }
        // A black image has no noise: the render stops after round 0.
        let s = settings(16, 16, 64);
        let mut film = Film::adaptive(FilmFrame::unbordered(16, 16));
        let round = Round::first(&s, &ADAPTIVE);
        render(&mut film, &round.units(&s, &ADAPTIVE), |_| 0.0, |_| 0.0);
        assert_eq!(Noise::of(&film, &round, &s).brightness, 1.0);
        assert_eq!(next_round(&film, &round, &s, &ADAPTIVE), None);
    }

    #[test]
    fn the_sample_map_is_a_log_scale_of_the_samples() {
        let s = settings(8, 4, 64);
        let round = Round {
            index: 2,
            planned: vec![16, 64],
        };
        let (map, least, most) = sample_map(&round, &s);
        assert_eq!((least, most), (16, 64));
        assert_eq!(map.get_pixel(0, 0).0[0], 85, "1 of 3 steps");
        assert_eq!(map.get_pixel(7, 3).0[0], 255);
    }
}
