//! A render that stops once its image stops changing: LuxRender 1.x's Film `haltthreshold`.
//!
//! LuxRender compares the displayed image with the one of its last test every
//! `convergencestep` samples per pixel (Yee's perceptual metric, [`super::perceptual_diff`]) and
//! halts once the share of pixels that changed visibly is at most the threshold. YAT runs the
//! same test at the same sample counts, but on the merged film alone: the render goes in
//! rounds of `step` samples of every pixel (`step` rounded up to whole packets,
//! [`UNIT_SAMPLE_STEP`]), and once every unit of a round is merged the round's image is
//! compared with the last round's. Which round a render ends at is therefore a function of the
//! scene and the settings, the same in-process, on any number of workers and after a resume;
//! the render's spp is the most any pixel gets.
//!
//! Between rounds a render keeps the round under way, the image of the last test (the
//! reference the next round is compared with) and how many pixels failed that test; a
//! checkpoint stores all three.

use super::perceptual_diff::{self, count_visible_differences};
use super::plan::{push_pass, TILE_SIZE, UNIT_SAMPLE_STEP};
use super::settings::{RenderOverrides, RenderSettings};
use super::unit::WorkUnit;
use crate::desc::SceneDesc;
use crate::film::{Film, FilmDesc};

/// Changes whenever the same settings would end at another round (the test, the rounds):
/// part of a converging render's identity.
pub const CONVERGENCE_VERSION: u32 = 1;

/// The convergence halt of a render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConvergenceHalt {
    /// The render ends once at most this share of its pixels changed visibly since the last
    /// test (in [0, 1]).
    pub threshold: f32,
    /// Samples of every pixel between tests: a multiple of [`UNIT_SAMPLE_STEP`].
    pub step: u32,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ConvergenceError {
    #[error("the halt threshold {0} must be a share of the pixels, from 0 to 1")]
    Threshold(f32),
    #[error("the convergence step {0} must be a positive multiple of {UNIT_SAMPLE_STEP}")]
    Step(u32),
}

impl ConvergenceHalt {
    /// The halt a render of `desc` takes: the threshold the command line or else the scene's
    /// `haltthreshold` sets, tested every `convergencestep` samples; None without one.
    pub fn resolve(desc: &SceneDesc, overrides: &RenderOverrides) -> Option<Self> {
        overrides
            .halt_threshold(desc)
            .map(|threshold| Self::new(threshold, desc.film.convergence_step))
    }

    /// Tests every `convergence_step` samples (LuxRender's figure, at least 4), rounded up to
    /// whole packets.
    pub fn new(threshold: f32, convergence_step: f32) -> Self {
        let step = libm::ceilf(convergence_step.clamp(1.0, u16::MAX as f32)) as u32;
        Self {
            threshold,
            step: step.next_multiple_of(UNIT_SAMPLE_STEP),
        }
    }

    pub fn check(&self) -> Result<(), ConvergenceError> {
        if !(0.0..=1.0).contains(&self.threshold) {
            return Err(ConvergenceError::Threshold(self.threshold));
        }
        if self.step == 0 || !self.step.is_multiple_of(UNIT_SAMPLE_STEP) {
            return Err(ConvergenceError::Step(self.step));
        }
        Ok(())
    }

    /// The samples of round `round`; None past the last (samples beyond spp).
    pub fn round_range(&self, round: u32, spp: u32) -> Option<(u32, u32)> {
        let start = u64::from(round) * u64::from(self.step);
        (start < u64::from(spp)).then(|| {
            (
                start as u32,
                (start + u64::from(self.step)).min(u64::from(spp)) as u32,
            )
        })
    }

    /// Rounds of a render of `spp` samples per pixel at most.
    pub fn round_count(&self, spp: u32) -> u32 {
        spp.div_ceil(self.step.max(1))
    }

    /// The units of round `round`: every tile of [`TILE_SIZE`], its samples, indexed from 0.
    pub fn round_units(&self, round: u32, settings: &RenderSettings) -> Vec<WorkUnit> {
        let mut units = Vec::new();
        if let Some(range) = self.round_range(round, settings.spp) {
            push_pass(&mut units, settings, range, TILE_SIZE);
        }
        units
    }

    /// The units of any round: one per tile.
    pub fn max_round_units(settings: &RenderSettings) -> usize {
        settings.width.div_ceil(TILE_SIZE) as usize * settings.height.div_ceil(TILE_SIZE) as usize
    }

    /// Bytes the halt takes beside the film at most: the reference, the image it is compared
    /// with, and the comparison's own.
    pub fn memory_bytes(settings: &RenderSettings) -> u64 {
        let pixels = u64::from(settings.width) * u64::from(settings.height);
        2 * pixels * std::mem::size_of::<[f32; 3]>() as u64 + perceptual_diff::memory_bytes(pixels)
    }
}

/// Where a converging render is: the round under way, and the last test's image and result.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvergenceRound {
    pub index: u32,
    /// The displayed image when the last round was complete (none before round 1), rows top to
    /// bottom.
    pub reference: Option<Vec<[f32; 3]>>,
    /// Pixels that changed visibly in the last comparison (none before there was one).
    pub unconverged: Option<u64>,
}

/// What the test at the end of a round decided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// Render the next round.
    GoOn,
    /// At most the threshold's share of pixels changed visibly: the render ends here.
    Converged,
    /// The render's spp is reached unconverged.
    SamplesSpent,
}

impl ConvergenceRound {
    pub fn first() -> Self {
        Self {
            index: 0,
            reference: None,
            unconverged: None,
        }
    }

    /// Whether this state can be a render's of these settings: the reference one image of
    /// display values (in [0, 1]) from round 1 on, and the round one of the render's. A
    /// checkpoint's is checked so before it is used.
    pub fn fits(&self, settings: &RenderSettings, halt: &ConvergenceHalt) -> bool {
        let pixels = settings.width as usize * settings.height as usize;
        let reference_fits = match &self.reference {
            None => self.index == 0,
            Some(image) => {
                self.index > 0
                    && image.len() == pixels
                    && image.iter().flatten().all(|v| (0.0..=1.0).contains(v))
            }
        };
        reference_fits
            && self.unconverged.is_none_or(|n| n <= pixels as u64)
            && halt.round_range(self.index, settings.spp).is_some()
    }

    /// The test once every unit of this round is merged into `film`: compares its image (as
    /// the scene's `desc` displays it) with the last round's, keeps it as the next reference and
    /// moves to the next round when the render goes on.
    pub fn test(
        &mut self,
        film: &Film,
        desc: &FilmDesc,
        settings: &RenderSettings,
        halt: &ConvergenceHalt,
    ) -> Verdict {
        let image = film.display_values(desc);
        let (width, height) = (film.width() as usize, film.height() as usize);
        if let Some(reference) = &self.reference {
            let failed = count_visible_differences(reference, &image, width, height);
            self.unconverged = Some(failed);
            let pixels = (width * height).max(1) as f64;
            if failed as f64 / pixels <= f64::from(halt.threshold) {
                return Verdict::Converged;
            }
        }
        if halt.round_range(self.index + 1, settings.spp).is_none() {
            return Verdict::SamplesSpent;
        }
        self.reference = Some(image);
        self.index += 1;
        Verdict::GoOn
    }

    /// Samples per pixel merged once this round is complete.
    pub fn samples_per_pixel(&self, settings: &RenderSettings, halt: &ConvergenceHalt) -> u32 {
        halt.round_range(self.index, settings.spp)
            .map_or(settings.spp, |(_, end)| end)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(width: u32, height: u32, spp: u32) -> RenderSettings {
        RenderSettings::for_tests(width, height, spp)
    }

    #[test]
    fn steps_are_whole_packets_and_rounds_cover_the_samples_once() {
        assert_eq!(ConvergenceHalt::new(0.1, 32.0).step, 32);
        assert_eq!(ConvergenceHalt::new(0.1, 4.0).step, 8);
        assert_eq!(ConvergenceHalt::new(0.1, 33.5).step, 40);
        let halt = ConvergenceHalt::new(0.1, 32.0);
        let s = settings(130, 70, 100);
        assert_eq!(halt.round_count(100), 4);
        let mut covered = vec![0u32; (130 * 70 * 100) as usize];
        for round in 0..halt.round_count(100) {
            let units = halt.round_units(round, &s);
            assert_eq!(units.len(), ConvergenceHalt::max_round_units(&s));
            assert!(units.iter().enumerate().all(|(i, u)| u.index == i as u32));
            for u in units {
                for y in u.y0..u.y1 {
                    for x in u.x0..u.x1 {
                        for i in u.sample_start..u.sample_end {
                            covered[((y * 130 + x) * 100 + i) as usize] += 1;
                        }
                    }
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
        assert_eq!(halt.round_range(3, 100), Some((96, 100)));
        assert_eq!(halt.round_range(4, 100), None);
        assert!(halt.round_units(4, &s).is_empty());
    }

    #[test]
    fn thresholds_outside_a_share_are_refused() {
        assert_eq!(ConvergenceHalt::new(0.0, 32.0).check(), Ok(()));
        assert_eq!(ConvergenceHalt::new(1.0, 32.0).check(), Ok(()));
        for bad in [-0.1, 1.5, f32::NAN] {
            assert!(ConvergenceHalt::new(bad, 32.0).check().is_err(), "{bad}");
        }
        let step = ConvergenceHalt {
            threshold: 0.1,
            step: 12,
        };
        assert_eq!(step.check(), Err(ConvergenceError::Step(12)));
    }

    /// A checkpoint's state is checked as if hostile: a reference of the wrong size, with
    /// values no display has, or at round 0, and a round past the render's, do not fit.
    #[test]
    fn only_states_a_render_can_reach_fit() {
        let s = settings(4, 2, 64);
        let halt = ConvergenceHalt::new(0.1, 32.0);
        let image = vec![[0.5f32; 3]; 8];
        let state = |index, reference: Option<Vec<[f32; 3]>>, unconverged| ConvergenceRound {
            index,
            reference,
            unconverged,
        };
        assert!(state(0, None, None).fits(&s, &halt));
        assert!(state(1, Some(image.clone()), Some(8)).fits(&s, &halt));
        assert!(!state(1, None, None).fits(&s, &halt));
        assert!(!state(0, Some(image.clone()), None).fits(&s, &halt));
        assert!(!state(1, Some(image[..7].to_vec()), None).fits(&s, &halt));
        assert!(!state(1, Some(vec![[2.0; 3]; 8]), None).fits(&s, &halt));
        assert!(!state(1, Some(vec![[f32::NAN; 3]; 8]), None).fits(&s, &halt));
        assert!(!state(1, Some(image.clone()), Some(9)).fits(&s, &halt));
        assert!(!state(2, Some(image), None).fits(&s, &halt));
    }
}
