//! The point light (`goniometric` is read as one too: its distribution file is not modelled).
//!
//! ```text
//! LightSource "point" "color L" [1 1 1] "float gain" [1] "point from" [0 0 0]
//!     "float power" [0] "float efficacy" [0]
//! ```
//!
//! | parameter  | default | meaning                                                          |
//! |------------|---------|------------------------------------------------------------------|
//! | `L`        | 1 1 1   | colour                                                           |
//! | `gain`     | 1       | multiplies `L`                                                   |
//! | `from`     | 0 0 0   | position, added after the current transform (LuxRender)         |
//! | `power`    | 0       | watts; with `efficacy` > 0 the gain is scaled to emit that many lumens |
//! | `efficacy` | 0       | lumens per watt                                                  |

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::diag::SourcePos;
use crate::math::luminance;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

use super::emission::{emits, normalised_gain, Emission};
use super::error::LightError;
use super::kind::{LightKind, MapSource};
use super::sample::{uniform_sphere, DeltaSample, EmittedRay};

/// `from`.
pub const DEFAULT_FROM: Vec3 = Vec3::ZERO;
/// `power` (0: no normalisation).
pub const DEFAULT_POWER: f32 = 0.0;
/// `efficacy` (0: no normalisation).
pub const DEFAULT_EFFICACY: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    /// Radiant intensity (L x gain, normalised by power x efficacy when given).
    pub intensity: Vec3,
}

impl PointLight {
    pub(crate) fn read(
        params: &ParamList,
        _pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let e = Emission::read(params, ctx)?;
        let from = params.vec3("from", DEFAULT_FROM)?;
        let gain = normalised_gain(
            e.gain,
            params.float("power", DEFAULT_POWER)?,
            params.float("efficacy", DEFAULT_EFFICACY)?,
            4.0 * PI * luminance(e.l),
        );
        // LuxRender translates by `from` after the light's transform.
        Ok(Self {
            position: from + ctx.ctm().transform_point3(Vec3::ZERO),
            intensity: e.l * gain,
        })
    }

    pub fn sample(&self, from: Vec3) -> Option<DeltaSample> {
        let to_light = self.position - from;
        let dist2 = to_light.length_squared();
        (dist2 > 0.0).then(|| {
            let dist = dist2.sqrt();
            DeltaSample {
                wi: to_light / dist,
                li: self.intensity / dist2,
                dist,
            }
        })
    }

    pub fn power(&self) -> f32 {
        4.0 * PI * luminance(self.intensity)
    }

    /// A ray leaving the light, in a direction uniform over the sphere.
    pub fn sample_emission(&self, u: Vec2) -> EmittedRay {
        let (pdf_pos, pdf_dir) = self.emission_pdf();
        EmittedRay {
            origin: self.position,
            dir: uniform_sphere(u),
            normal: None,
            le: self.intensity,
            pdf_pos,
            pdf_dir,
            delta_position: true,
            delta_direction: false,
        }
    }

    /// The (position, direction) densities of [`Self::sample_emission`], the same for every
    /// ray: the position is a delta (its density is taken as 1).
    pub fn emission_pdf(&self) -> (f32, f32) {
        (1.0, 1.0 / (4.0 * PI))
    }
}

impl LightKind for PointLight {
    type Sampler = PointLight;

    fn name(&self) -> &'static str {
        "point"
    }

    /// The light to sample, if it emits.
    fn light(&self, _maps: &MapSource) -> Result<Option<PointLight>, LightError> {
        Ok(emits(self.intensity).then(|| self.clone()))
    }
}
