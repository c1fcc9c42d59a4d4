//! `MakeNamedVolume "name" "homogeneous"`: a volume of uniform density that absorbs and
//! scatters (smoke, milk, fog), with Schlick's approximation of the Henyey-Greenstein phase
//! function ([`super::phase`]).
//!
//! ```text
//! MakeNamedVolume "smoke" "homogeneous" "color sigma_a" [0.1 0.1 0.1]
//!     "color sigma_s" [2 2 2] "color g" [0.3 0.3 0.3] "float fresnel" [1.0]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `fresnel` | float or fresnel texture: the index glass2 refracts with | 1.5 ([`DEFAULT_FRESNEL`](super::common::DEFAULT_FRESNEL)) |
//! | `sigma_a` | colour: absorption per scene unit | 0 ([`DEFAULT_SIGMA`]) |
//! | `sigma_s` | colour: scattering per scene unit | 0 ([`DEFAULT_SIGMA`]) |
//! | `g` | colour (a float is splatted): asymmetry, positive forward, clamped to +-0.99 | 0 ([`DEFAULT_G`]) |
//!
//! Free-flight distances are drawn as LuxRender draws them, exponentially with the mean of
//! sigma_s (so a volume that only absorbs never stops a ray), and weighted by the ratio of
//! the true density to the drawn one: unbiased for coloured media, and exactly 1 for a grey
//! one that does not absorb.

use glam::Vec3;

use super::common::{read_color, read_index, transmittance};
use super::phase::Phase;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::wavelength::IndexCurve;

pub const DEFAULT_SIGMA: f32 = 0.0;
pub const DEFAULT_G: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Homogeneous {
    /// The `fresnel` index (a dispersive texture's mean).
    pub index: f32,
    /// The `fresnel` texture's index over wavelength, where it varies.
    pub dispersion: Option<IndexCurve>,
    pub sigma_a: Vec3,
    pub sigma_s: Vec3,
    pub g: Vec3,
}

/// What happens to a ray crossing a segment of a volume.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flight {
    /// It reaches the segment's end; multiply the path by `weight`.
    Pass { weight: Vec3 },
    /// It scatters `distance` along the segment; multiply the path by `weight` (which
    /// includes the scattering coefficient: the phase function is all that is left).
    Scatter { distance: f32, weight: Vec3 },
}

impl Homogeneous {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let statement = "MakeNamedVolume \"homogeneous\"";
        let g = ctx.color_param(params, "g", DEFAULT_G, false)?;
        let g = match ctx.uniform_texture(g) {
            Some(g) if g.is_finite() => g,
            _ => {
                ctx.warn(
                    pos,
                    format!(
                        "{statement}: \"g\" must be a uniform finite asymmetry; using {DEFAULT_G}"
                    ),
                );
                Vec3::splat(DEFAULT_G)
            }
        };
        let (index, dispersion) = read_index(params, statement, pos, ctx)?;
        Ok(Self {
            index,
            dispersion,
            sigma_a: read_color(params, "sigma_a", DEFAULT_SIGMA, statement, pos, ctx)?,
            sigma_s: read_color(params, "sigma_s", DEFAULT_SIGMA, statement, pos, ctx)?,
            g,
        })
    }

    pub fn sigma_t(&self) -> Vec3 {
        self.sigma_a + self.sigma_s
    }

    /// The density free-flight distances are drawn with (LuxRender's `sigmaS->Filter()`).
    fn majorant(&self) -> f32 {
        self.sigma_s.element_sum() / 3.0
    }

    /// Whether a ray may scatter here (else [`Self::flight`] needs no random number).
    pub fn scatters(&self) -> bool {
        self.majorant() > 0.0
    }

    pub fn transmittance(&self, distance: f32) -> Vec3 {
        transmittance(self.sigma_t(), distance)
    }

    pub fn phase(&self) -> Phase {
        Phase::new(self.g)
    }

    /// The fate of a ray crossing `length` (possibly infinite) of this volume, from `u` in
    /// [0, 1).
    pub fn flight(&self, length: f32, u: f32) -> Flight {
        let k = self.majorant();
        if k <= 0.0 {
            return Flight::Pass {
                weight: self.transmittance(length),
            };
        }
        let distance = -libm::logf((1.0 - u).max(f32::MIN_POSITIVE)) / k;
        // The drawn density is k exp(-k d) for a scattering at d and exp(-k length) for none;
        // the true weights are sigma_s exp(-sigma_t d) and exp(-sigma_t length).
        let excess = self.sigma_t() - Vec3::splat(k);
        if distance < length {
            Flight::Scatter {
                distance,
                weight: self.sigma_s / k * (-excess * distance).exp(),
            }
        } else {
            Flight::Pass {
                weight: (-excess * length).exp(),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flight estimator is unbiased: averaged over u, the pass weight times the pass
    /// probability is the transmittance, and the scattering weights add up to the probability
    /// of scattering within the segment (sigma_s / sigma_t (1 - exp(-sigma_t L)) per channel).
    #[test]
    fn flight_weights_are_unbiased() {
        let medium = Homogeneous {
            index: 1.0,
            dispersion: None,
            sigma_a: Vec3::new(0.2, 0.0, 1.0),
            sigma_s: Vec3::new(1.0, 0.5, 0.3),
            g: Vec3::ZERO,
        };
        let length = 1.7;
        let n = 400_000;
        let (mut pass, mut scatter) = (Vec3::ZERO, Vec3::ZERO);
        for i in 0..n {
            match medium.flight(length, (i as f32 + 0.5) / n as f32) {
                Flight::Pass { weight } => pass += weight,
                Flight::Scatter { weight, distance } => {
                    assert!(distance < length);
                    scatter += weight;
                }
            }
        }
        let st = medium.sigma_t();
        let tr = medium.transmittance(length);
        let expected_scatter = medium.sigma_s / st * (Vec3::ONE - tr);
        assert!(
            (pass / n as f32 - tr).abs().max_element() < 2e-3,
            "{pass} vs {tr}"
        );
        assert!(
            (scatter / n as f32 - expected_scatter).abs().max_element() < 2e-3,
            "{scatter} vs {expected_scatter}"
        );
    }
}
