//! How a render's samples are planned, and where its rounds are: every pixel `spp` samples in
//! one plan ([`plan_units`]), adaptive rounds ([`super::adaptive`]), or rounds of every pixel
//! until the image stops changing ([`super::convergence`]). Every decision between rounds is
//! made from the merged film alone.

use super::adaptive::{self, AdaptiveSettings, Round};
use super::convergence::{ConvergenceHalt, ConvergenceRound, Verdict};
use super::plan::plan_units;
use super::settings::RenderSettings;
use super::unit::WorkUnit;
use crate::film::{Film, FilmDesc};

/// How a render's samples are planned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sampling {
    /// Every pixel `spp` samples, in one plan.
    Uniform,
    /// Rounds doubling the samples of the blocks still noisy (settings.spp the most a pixel
    /// gets).
    Adaptive(AdaptiveSettings),
    /// Rounds of every pixel until the image stops changing visibly (LuxRender's
    /// `haltthreshold`; settings.spp the most a pixel gets).
    Converging(ConvergenceHalt),
}

impl Sampling {
    pub fn adaptive(&self) -> Option<&AdaptiveSettings> {
        match self {
            Self::Adaptive(a) => Some(a),
            _ => None,
        }
    }

    /// Whether the render goes in rounds, each decided once the last is merged.
    pub fn has_rounds(&self) -> bool {
        !matches!(self, Self::Uniform)
    }

    /// Rounds a render of these settings has at most (1 for a uniform one).
    pub fn round_count(&self, settings: &RenderSettings) -> u32 {
        match self {
            Self::Uniform => 1,
            Self::Adaptive(a) => a.round_count(settings.spp),
            Self::Converging(halt) => halt.round_count(settings.spp),
        }
    }

    /// The most units the plan or any round has: the room a checkpoint's bitmap keeps.
    pub fn max_units(&self, settings: &RenderSettings) -> usize {
        match self {
            Self::Uniform => plan_units(settings).len(),
            Self::Adaptive(_) => adaptive::max_round_units(settings),
            Self::Converging(_) => ConvergenceHalt::max_round_units(settings),
        }
    }
}

/// Where a render's rounds are, with the settings that decide them.
#[derive(Clone, Debug, PartialEq)]
pub enum Rounds {
    Uniform,
    Adaptive(AdaptiveSettings, Round),
    Converging(ConvergenceHalt, ConvergenceRound),
}

/// How a render's last round ended, for its summary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RoundsEnd {
    /// Every unit of the plan, or the adaptive rounds until no block went on.
    Planned,
    /// A converging render's test passed at `spp` samples per pixel: `unconverged` of
    /// `pixels` changed visibly since the last.
    Converged {
        spp: u32,
        unconverged: u64,
        pixels: u64,
    },
    /// A converging render reached its spp before its test passed (`unconverged` of `pixels`
    /// changed visibly in the last test, if there was one).
    SamplesSpent {
        spp: u32,
        unconverged: Option<u64>,
        pixels: u64,
    },
}

impl Rounds {
    /// Nothing rendered yet: the plan, or the first round.
    pub fn first(settings: &RenderSettings, sampling: &Sampling) -> Self {
        match *sampling {
            Sampling::Uniform => Self::Uniform,
            Sampling::Adaptive(a) => Self::Adaptive(a, Round::first(settings, &a)),
            Sampling::Converging(halt) => Self::Converging(halt, ConvergenceRound::first()),
        }
    }

    pub fn sampling(&self) -> Sampling {
        match self {
            Self::Uniform => Sampling::Uniform,
            Self::Adaptive(a, _) => Sampling::Adaptive(*a),
            Self::Converging(halt, _) => Sampling::Converging(*halt),
        }
    }

    /// The round under way's number; None for a uniform render.
    pub fn index(&self) -> Option<u32> {
        match self {
            Self::Uniform => None,
            Self::Adaptive(_, round) => Some(round.index),
            Self::Converging(_, round) => Some(round.index),
        }
    }

    /// The adaptive round under way.
    pub fn adaptive_round(&self) -> Option<&Round> {
        match self {
            Self::Adaptive(_, round) => Some(round),
            _ => None,
        }
    }

    /// The units of the plan, or of the round under way (indexed from 0).
    pub fn units(&self, settings: &RenderSettings) -> Vec<WorkUnit> {
        match self {
            Self::Uniform => plan_units(settings),
            Self::Adaptive(a, round) => round.units(settings, a),
            Self::Converging(halt, round) => halt.round_units(round.index, settings),
        }
    }

    /// Camera samples of the rounds before this one, and at most all the render takes (as if
    /// every block active now stayed so, or the image never converged), given `this_round`
    /// merged of the round under way's units.
    pub fn samples(&self, settings: &RenderSettings, this_round: u64) -> (u64, u64) {
        let pixels = u64::from(settings.width) * u64::from(settings.height);
        match self {
            Self::Uniform => {
                let all = plan_units(settings)
                    .iter()
                    .map(WorkUnit::sample_count)
                    .sum();
                (this_round, all)
            }
            Self::Adaptive(a, round) => {
                let counts = round.samples(settings, a);
                (
                    counts.before + this_round,
                    counts.before + counts.now + counts.later,
                )
            }
            Self::Converging(halt, round) => {
                let before = halt
                    .round_range(round.index, settings.spp)
                    .map_or(0, |(start, _)| u64::from(start));
                (
                    before * pixels + this_round,
                    u64::from(settings.spp) * pixels,
                )
            }
        }
    }

    /// Once every unit of the round is in `film`: moves to the next round, decided from the
    /// film alone; None when the render is done, with how it ended. `desc` is the scene's film
    /// (a converging render compares images as they are displayed).
    pub fn advance(
        &mut self,
        film: &Film,
        desc: &FilmDesc,
        settings: &RenderSettings,
    ) -> Result<(), RoundsEnd> {
        match self {
            Self::Uniform => Err(RoundsEnd::Planned),
            Self::Adaptive(a, round) => match adaptive::next_round(film, round, settings, a) {
                Some(next) => {
                    *round = next;
                    Ok(())
                }
                None => Err(RoundsEnd::Planned),
            },
            Self::Converging(halt, round) => {
                let pixels = u64::from(settings.width) * u64::from(settings.height);
                let spp = round.samples_per_pixel(settings, halt);
                match round.test(film, desc, settings, halt) {
                    Verdict::GoOn => Ok(()),
                    Verdict::Converged => Err(RoundsEnd::Converged {
                        spp,
                        unconverged: round.unconverged.unwrap_or(0),
                        pixels,
                    }),
                    Verdict::SamplesSpent => Err(RoundsEnd::SamplesSpent {
                        spp,
                        unconverged: round.unconverged,
                        pixels,
                    }),
                }
            }
        }
    }
}
