//! The distant light: parallel radiance from one direction (a delta direction; LuxRender's
//! soft `theta` cone is not modelled).
//!
//! ```text
//! LightSource "distant" "color L" [1 1 1] "float gain" [1] "point from" [0 0 0] "point to" [0 0 1]
//! ```
//!
//! | parameter    | default      | meaning                                                   |
//! |--------------|--------------|-----------------------------------------------------------|
//! | `L`          | 1 1 1        | colour                                                    |
//! | `gain`       | 1            | multiplies `L`                                            |
//! | `from`, `to` | 0 0 0, 0 0 1 | the light travels from `from` towards `to` (must differ)  |
//! | `theta`      | 0            | soft cone half-angle: anything else is a warning          |

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use crate::diag::SourcePos;
use crate::math::luminance;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

use super::emission::{emits, Emission};
use super::error::LightError;
use super::kind::{LightKind, MapSource};
use super::portals::Entry;
use super::sample::{DeltaSample, EmittedRay};

/// `from`.
pub const DEFAULT_FROM: Vec3 = Vec3::ZERO;
/// `to`.
pub const DEFAULT_TO: Vec3 = Vec3::Z;
/// `theta`: the only value modelled.
pub const DEFAULT_THETA: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct DistantLight {
    /// Unit direction the light travels *towards* the scene is `-to_light`.
    pub to_light: Vec3,
    pub radiance: Vec3,
}

impl DistantLight {
    pub(crate) fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let e = Emission::read(params, ctx)?;
        let from = params.vec3("from", DEFAULT_FROM)?;
        let to = params.vec3("to", DEFAULT_TO)?;
        if params.float("theta", DEFAULT_THETA)? != 0.0 {
            ctx.warn(pos, "LightSource \"distant\": \"theta\" (a soft cone) is not supported; the light is a delta direction".into());
        }
        let Some(to_light) = ctx.ctm().transform_vector3(from - to).try_normalize() else {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: "LightSource \"distant\": \"from\" and \"to\" must differ".into(),
            });
        };
        Ok(Self {
            to_light,
            radiance: e.l * e.gain,
        })
    }

    pub fn sample(&self) -> DeltaSample {
        DeltaSample {
            wi: self.to_light,
            li: self.radiance,
            dist: f32::INFINITY,
        }
    }

    /// The flux through a disk of the scene's size.
    pub fn power(&self, scene_radius: f32) -> f32 {
        PI * scene_radius * scene_radius * luminance(self.radiance)
    }

    /// A ray of the light entering the scene by `entry` (the disc of the scene's sphere, or
    /// the light's portals), from a point uniform on the disc or the portals as the light
    /// sees them (so its flux, irradiance x area, is what the rays carry). None when no portal
    /// faces the light.
    pub fn sample_emission(&self, entry: Entry<'_>, u: Vec2) -> Option<EmittedRay> {
        let dir = -self.to_light;
        let (origin, pdf_pos) = entry.sample(dir, u)?;
        Some(EmittedRay {
            origin,
            dir,
            normal: None,
            le: self.radiance,
            pdf_pos,
            pdf_dir: 1.0,
            delta_position: false,
            delta_direction: true,
        })
    }

    /// The (position, direction) densities of [`Self::sample_emission`] for the ray from
    /// `origin` along the light: the entry's, and 1 for the delta direction.
    pub fn emission_pdf(&self, entry: Entry<'_>, origin: Vec3) -> (f32, f32) {
        (entry.pdf_start(-self.to_light, origin), 1.0)
    }
}

impl LightKind for DistantLight {
    type Sampler = DistantLight;

    fn name(&self) -> &'static str {
        "distant"
    }

    /// The light to sample (with `to_light` normalised), if it emits.
    fn light(&self, _maps: &MapSource) -> Result<Option<DistantLight>, LightError> {
        let to_light = self.to_light.normalize_or_zero();
        Ok((emits(self.radiance) && to_light != Vec3::ZERO).then_some(DistantLight {
            to_light,
            radiance: self.radiance,
        }))
    }
}
