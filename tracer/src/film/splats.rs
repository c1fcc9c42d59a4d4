//! Light splats: what a bidirectional render's light subpaths, connected to the camera, add to
//! the film. Unlike a unit's sample sums they land anywhere on the film, so a unit carries them
//! as a sparse list of film pixels ([`LightSplats`]), summed while it renders ([`SplatSums`])
//! and merged into the film's own fixed-point sums ([`FilmSplats`]), as exactly and
//! order-independently as the sample sums.
//!
//! Bounds: a unit reports at most [`MAX_SPLAT_PIXELS`] pixels (16 bytes each on the wire, so
//! 4 MiB at most), and its [`SplatSums`] holds at most as many entries while it renders (16
//! bytes each: 4 MiB per render thread).

use glam::Vec3;

use super::{to_fixed, unit_sum, FIXED_ONE, MAX_UNIT_SUM};
use crate::render::unit::FilmFrame;

/// The most film pixels one unit's light splats reach, and the most entries its
/// [`SplatSums`] holds. A unit's reply stays under the message limit with this many (4 MiB at
/// 16 bytes a pixel on the wire, beside at most about 1 MiB of sample sums); the renderer
/// chooses units small enough that their light paths reach fewer pixels.
pub const MAX_SPLAT_PIXELS: usize = 1 << 18;

/// A unit's light splats: per film pixel its splats reach (indices `y * width + x`, strictly
/// increasing), the sum of their radiance, each component within [`MAX_UNIT_SUM`]. Empty for
/// the units of a film without light splats ([`FilmFrame::light_splats`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightSplats {
    pub pixels: Vec<u32>,
    /// As long as `pixels`.
    pub rgb: Vec<[f32; 3]>,
}

/// Why a unit's light splats are not ones an honest render of `frame` gives.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SplatMisfit {
    #[error("{0} light splats on a film that keeps none")]
    NotKept(usize),
    #[error("{pixels} light splat pixels but {values} values")]
    Lengths { pixels: usize, values: usize },
    #[error("{0} light splat pixels, more than the {MAX_SPLAT_PIXELS} a unit reports")]
    TooMany(usize),
    #[error("light splat pixel {pixel} follows pixel {previous}: not strictly increasing")]
    Unsorted { previous: u32, pixel: u32 },
    #[error("light splat pixel {pixel} lies outside the film's {pixels} pixels (of every plane)")]
    OutOfRange { pixel: u32, pixels: u64 },
    #[error(
        "light splat pixel {pixel} holds {value}, which is not finite or exceeds {MAX_UNIT_SUM}"
    )]
    Value { pixel: u32, value: f32 },
}

impl LightSplats {
    pub fn len(&self) -> usize {
        self.pixels.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pixels.is_empty()
    }

    /// Checks splats from a peer, hostile until they pass: none unless `frame` keeps light
    /// splats; as many values as pixels, at most [`MAX_SPLAT_PIXELS`]; pixels strictly
    /// increasing inside the film's planes ([`FilmFrame::splat_entries`]: so no pixel is named
    /// twice); finite values no larger in
    /// magnitude than a unit reports ([`unit_sum`]), so that no sum can saturate the film's.
    pub fn check(&self, frame: &FilmFrame) -> Result<(), SplatMisfit> {
        let count = self.pixels.len().max(self.rgb.len());
        if !frame.light_splats && count > 0 {
            return Err(SplatMisfit::NotKept(count));
        }
        if self.pixels.len() != self.rgb.len() {
            return Err(SplatMisfit::Lengths {
                pixels: self.pixels.len(),
                values: self.rgb.len(),
            });
        }
        if self.pixels.len() > MAX_SPLAT_PIXELS {
            return Err(SplatMisfit::TooMany(self.pixels.len()));
        }
        let film_pixels = frame.splat_entries();
        let mut previous = None;
        for (&pixel, rgb) in self.pixels.iter().zip(&self.rgb) {
            if let Some(previous) = previous.filter(|&p| p >= pixel) {
                return Err(SplatMisfit::Unsorted { previous, pixel });
            }
            if u64::from(pixel) >= film_pixels {
                return Err(SplatMisfit::OutOfRange {
                    pixel,
                    pixels: film_pixels,
                });
            }
            if let Some(&value) = rgb
                .iter()
                .find(|v| !v.is_finite() || v.abs() > MAX_UNIT_SUM)
            {
                return Err(SplatMisfit::Value { pixel, value });
            }
            previous = Some(pixel);
        }
        Ok(())
    }
}

/// A unit's light splats while it renders: every splat appended as it comes, summed per pixel
/// at the end in the order they came. f32 sums in a fixed order give the same bits on every
/// machine that makes the same splats in the same order, which every node rendering the unit
/// does; the film then merges units exactly, in any order.
#[derive(Clone, Debug)]
pub struct SplatSums {
    entries: Vec<(u32, Vec3)>,
    /// Whether the list, once full, is compacted (summed per pixel in place); false once a
    /// compaction left it more than half full.
    compacts: bool,
    dropped: u64,
    refused: u64,
}

impl Default for SplatSums {
    fn default() -> Self {
        Self::new()
    }
}

impl SplatSums {
    pub fn new() -> Self {
        Self {
            entries: Vec::new(),
            compacts: true,
            dropped: 0,
            refused: 0,
        }
    }

    /// Adds a splat of `rgb` to film pixel `pixel` (`y * width + x`; the renderer's to keep
    /// inside the film, the film refuses a unit that is not). A non-finite `rgb` is dropped
    /// ([`SplatSums::dropped`]). The list holds at most [`MAX_SPLAT_PIXELS`] entries: full, it
    /// is summed per pixel in place, which gives the same bits as summing at the end (each
    /// pixel's partial sum stays ahead of its later splats, in order); when that leaves it more
    /// than half full, the unit's splats reach too many pixels and every splat that finds no
    /// room from then on is refused ([`SplatSums::refused`]), so the memory stays bounded and
    /// the work per splat amortised constant.
    pub fn add(&mut self, pixel: u32, rgb: Vec3) {
        if !rgb.is_finite() {
            self.dropped += 1;
            return;
        }
        if self.entries.len() == MAX_SPLAT_PIXELS && self.compacts {
            self.compact();
            self.compacts = self.entries.len() <= MAX_SPLAT_PIXELS / 2;
        }
        if self.entries.len() == MAX_SPLAT_PIXELS {
            self.refused += 1;
            return;
        }
        self.entries.push((pixel, rgb));
    }

    /// Splats dropped for a non-finite radiance.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Splats refused for want of room (the unit's splats reach too many pixels).
    pub fn refused(&self) -> u64 {
        self.refused
    }

    /// The unit's splats: sorted by pixel, each pixel's summed in the order they were added and
    /// clamped as a unit's sums are ([`unit_sum`]). A pixel whose sum is not a number (its
    /// splats overflowed f32 both ways) is left out.
    pub fn into_splats(mut self) -> LightSplats {
        self.compact();
        let (pixels, rgb) = self
            .entries
            .into_iter()
            .filter(|(_, sum)| !sum.is_nan())
            .map(|(pixel, sum)| (pixel, unit_sum(sum)))
            .unzip();
        LightSplats { pixels, rgb }
    }

    /// Sorts the entries by pixel, keeping each pixel's in the order they came (a stable
    /// sort), and replaces each pixel's with their sum in that order.
    fn compact(&mut self) {
        self.entries.sort_by_key(|&(pixel, _)| pixel);
        self.entries.dedup_by(|later, kept| {
            let same = later.0 == kept.0;
            if same {
                kept.1 += later.1;
            }
            same
        });
    }
}

/// A film's light splats: per pixel their R, G, B sums in the film's fixed point, and the light
/// subpaths they were made over. Saved and restored as they are ([`crate::film::Film::sums`]
/// and [`crate::film::Film::from_sums`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FilmSplats {
    /// Per pixel of the film, row-major, a plane for the total and one per light group kept
    /// apart ([`FilmFrame::splat_entries`]).
    pub sums: Vec<[i64; 3]>,
    /// Light subpaths of the units merged: one per camera sample of each
    /// ([`crate::render::WorkUnit::sample_count`]).
    pub light_paths: u64,
}

impl FilmSplats {
    /// No splats yet, over `entries` pixels (of every plane).
    pub fn new(entries: usize) -> Self {
        Self {
            sums: vec![[0; 3]; entries],
            light_paths: 0,
        }
    }

    /// Adds a unit's splats ([`LightSplats::check`]ed against the film), made over
    /// `light_paths` subpaths. Integer sums: any order of units gives the same bits.
    pub(super) fn add(&mut self, splats: &LightSplats, light_paths: u64) {
        for (&pixel, rgb) in splats.pixels.iter().zip(&splats.rgb) {
            let sum = &mut self.sums[pixel as usize];
            for (s, &v) in sum.iter_mut().zip(rgb) {
                *s = s.saturating_add(to_fixed(v));
            }
        }
        self.light_paths = self.light_paths.saturating_add(light_paths);
    }

    /// The light-tracing estimate of entry `at` (pixel `at % pixels` of plane `at / pixels`,
    /// on a film of `pixels` pixels): its splat sum times the film's pixels over the light paths
    /// (black before any). Each light path's splats are weighed for the pixel they
    /// land in as a camera sample of that pixel is (the camera's importance is normalised per
    /// pixel), so a pixel's estimate is the mean over the light paths *per pixel*: all the
    /// film's light paths reach every pixel alike, and there are `light_paths / pixels` of them
    /// per pixel, as there are `spp` camera samples. The same whichever units the splats came
    /// from, so it adds to the camera samples' weighted mean unchanged.
    pub(super) fn radiance(&self, at: usize, pixels: usize) -> Vec3 {
        if self.light_paths == 0 {
            return Vec3::ZERO;
        }
        let scale = pixels as f64 / (FIXED_ONE * self.light_paths as f64);
        let [r, g, b] = self.sums[at].map(|s| (s as f64 * scale) as f32);
        Vec3::new(r, g, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> FilmFrame {
        FilmFrame {
            light_splats: true,
            ..FilmFrame::unbordered(4, 2)
        }
    }

    /// Duplicates are summed in the order they were added (the other order gives other bits
    /// here), pixels come out sorted, each sum clamped and non-finite splats dropped.
    #[test]
    fn duplicates_sum_in_insertion_order_and_pixels_sort() {
        let mut sums = SplatSums::new();
        let (a, b, c) = (1.0e8f32, 3.0f32, -1.0e8f32);
        sums.add(7, Vec3::splat(a));
        sums.add(2, Vec3::new(0.5, 0.25, 0.125));
        sums.add(7, Vec3::splat(b));
        sums.add(0, Vec3::X);
        sums.add(7, Vec3::splat(c));
        sums.add(5, Vec3::new(f32::NAN, 0.0, 0.0));
        sums.add(5, Vec3::new(0.0, f32::INFINITY, 0.0));
        sums.add(3, Vec3::splat(MAX_UNIT_SUM));
        sums.add(3, Vec3::splat(MAX_UNIT_SUM));
        assert_eq!((sums.dropped(), sums.refused()), (2, 0));
        let splats = sums.into_splats();
        assert_eq!(splats.pixels, [0, 2, 3, 7]);
        let in_order = (a + b) + c;
        assert_eq!(in_order, 0.0, "1e8 + 3 rounds to 1e8 in f32");
        assert_ne!(in_order, (a + c) + b, "the order shows in the bits");
        assert_eq!(splats.rgb[3], [in_order; 3]);
        assert_eq!(splats.rgb[1], [0.5, 0.25, 0.125]);
        assert_eq!(splats.rgb[2], [MAX_UNIT_SUM; 3], "clamped as unit sums are");
        assert_eq!(splats.check(&frame()), Ok(()));
    }

    /// A list that fills up is compacted in place with the same bits as one summed at the end;
    /// one whose splats reach more distinct pixels than it holds refuses the rest.
    #[test]
    fn compaction_keeps_the_bits_and_room_is_bounded() {
        let n = MAX_SPLAT_PIXELS + 1000;
        let value = |i: usize| Vec3::new(1.0 + i as f32 * 1e-3, 1e6 / (1 + i % 7) as f32, 0.1);
        let mut sums = SplatSums::new();
        let mut by_hand = [Vec3::ZERO; 5];
        for i in 0..n {
            sums.add((i * 3 % 5) as u32, value(i));
            by_hand[i * 3 % 5] += value(i);
        }
        assert_eq!(sums.refused(), 0);
        let splats = sums.into_splats();
        assert_eq!(splats.pixels, [0, 1, 2, 3, 4]);
        for (got, want) in splats.rgb.iter().zip(by_hand) {
            assert_eq!(*got, want.to_array());
        }

        let mut spread = SplatSums::new();
        for pixel in 0..MAX_SPLAT_PIXELS as u32 + 3 {
            spread.add(pixel, Vec3::ONE);
        }
        spread.add(0, Vec3::ONE);
        assert_eq!(spread.refused(), 4);
        let splats = spread.into_splats();
        assert_eq!(splats.len(), MAX_SPLAT_PIXELS);
        assert_eq!(splats.rgb[0], [1.0; 3]);
    }

    /// Hostile splats are refused, naming what is wrong.
    #[test]
    fn hostile_splats_are_refused() {
        let splats = |pixels: Vec<u32>, rgb: Vec<[f32; 3]>| LightSplats { pixels, rgb };
        let ok = splats(vec![1, 4, 7], vec![[0.5; 3], [1.0; 3], [-2.0, 0.0, 3.0]]);
        assert_eq!(ok.check(&frame()), Ok(()));
        let cases = [
            (
                splats(vec![4, 1], vec![[1.0; 3]; 2]),
                SplatMisfit::Unsorted {
                    previous: 4,
                    pixel: 1,
                },
            ),
            (
                splats(vec![1, 1], vec![[1.0; 3]; 2]),
                SplatMisfit::Unsorted {
                    previous: 1,
                    pixel: 1,
                },
            ),
            (
                splats(vec![8], vec![[1.0; 3]]),
                SplatMisfit::OutOfRange {
                    pixel: 8,
                    pixels: 8,
                },
            ),
            (
                splats(vec![2], vec![[0.0, f32::NAN, 0.0]]),
                SplatMisfit::Value {
                    pixel: 2,
                    value: f32::NAN,
                },
            ),
            (
                splats(vec![2], vec![[f32::NEG_INFINITY, 0.0, 0.0]]),
                SplatMisfit::Value {
                    pixel: 2,
                    value: f32::NEG_INFINITY,
                },
            ),
            (
                splats(vec![2], vec![[MAX_UNIT_SUM.next_up(), 0.0, 0.0]]),
                SplatMisfit::Value {
                    pixel: 2,
                    value: MAX_UNIT_SUM.next_up(),
                },
            ),
            (
                splats(vec![2, 3], vec![[1.0; 3]]),
                SplatMisfit::Lengths {
                    pixels: 2,
                    values: 1,
                },
            ),
        ];
        for (splats, misfit) in cases {
            let got = splats.check(&frame()).unwrap_err();
            // NaN compares unequal to itself: compare what the error says.
            assert_eq!(got.to_string(), misfit.to_string());
        }
        let big = FilmFrame {
            light_splats: true,
            ..FilmFrame::unbordered(1024, 1024)
        };
        let too_many = MAX_SPLAT_PIXELS as u32 + 1;
        let long = splats((0..too_many).collect(), vec![[0.0; 3]; too_many as usize]);
        assert_eq!(
            long.check(&big),
            Err(SplatMisfit::TooMany(too_many as usize))
        );
        let without = FilmFrame::unbordered(4, 2);
        assert_eq!(ok.check(&without), Err(SplatMisfit::NotKept(3)));
        assert_eq!(LightSplats::default().check(&without), Ok(()));
        // With two light groups kept apart, three planes of the 8 pixels: 24 entries.
        let grouped = FilmFrame {
            layers: crate::render::layers::Layers {
                light_groups: 2,
                ..Default::default()
            },
            ..frame()
        };
        assert_eq!(grouped.splat_entries(), 24);
        assert_eq!(
            splats(vec![3, 11, 23], vec![[1.0; 3]; 3]).check(&grouped),
            Ok(())
        );
        assert_eq!(
            splats(vec![24], vec![[1.0; 3]]).check(&grouped),
            Err(SplatMisfit::OutOfRange {
                pixel: 24,
                pixels: 24
            })
        );
    }
}
