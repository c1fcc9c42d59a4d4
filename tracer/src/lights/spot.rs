//! The spot light: a point light inside a cone, with LuxRender's smoothstep falloff.
//!
//! ```text
//! LightSource "spot" "color L" [1 1 1] "float gain" [1] "point from" [0 0 0] "point to" [0 0 1]
//!     "float coneangle" [30] "float conedeltaangle" [5] "float power" [0] "float efficacy" [0]
//! ```
//!
//! | parameter        | default | meaning                                                    |
//! |------------------|---------|------------------------------------------------------------|
//! | `L`              | 1 1 1   | colour                                                     |
//! | `gain`           | 1       | multiplies `L`                                             |
//! | `from`, `to`     | 0 0 0, 0 0 1 | position and aim (must differ), in the current transform |
//! | `coneangle`      | 30      | degrees: no light outside                                  |
//! | `conedeltaangle` | 5       | degrees: width of the falloff band inside the cone's edge  |
//! | `power`          | 0       | watts; with `efficacy` > 0 the gain is scaled to emit that many lumens |
//! | `efficacy`       | 0       | lumens per watt                                            |

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};

use crate::diag::SourcePos;
use crate::math::{luminance, Frame};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

use super::emission::{emits, normalised_gain, Emission};
use super::error::LightError;
use super::kind::{LightKind, MapSource};
use super::point::PointLight;
use super::sample::{uniform_cone, DeltaSample, EmittedRay};

/// `from`.
pub const DEFAULT_FROM: Vec3 = Vec3::ZERO;
/// `to`.
pub const DEFAULT_TO: Vec3 = Vec3::Z;
/// `coneangle`, degrees.
pub const DEFAULT_CONE_ANGLE: f32 = 30.0;
/// `conedeltaangle`, degrees.
pub const DEFAULT_CONE_DELTA_ANGLE: f32 = 5.0;
/// `power` (0: no normalisation).
pub const DEFAULT_POWER: f32 = 0.0;
/// `efficacy` (0: no normalisation).
pub const DEFAULT_EFFICACY: f32 = 0.0;

#[derive(Clone, Debug, PartialEq)]
pub struct SpotLight {
    pub position: Vec3,
    /// Unit direction in world space.
    pub direction: Vec3,
    pub intensity: Vec3,
    /// Degrees, LuxRender semantics (full cone half-angle, and falloff width).
    pub cone_angle: f32,
    pub cone_delta_angle: f32,
}

impl SpotLight {
    pub(crate) fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let e = Emission::read(params, ctx)?;
        let from = params.vec3("from", DEFAULT_FROM)?;
        let to = params.vec3("to", DEFAULT_TO)?;
        let cone_angle = params.float("coneangle", DEFAULT_CONE_ANGLE)?;
        let cone_delta_angle = params.float("conedeltaangle", DEFAULT_CONE_DELTA_ANGLE)?;
        let ctm = ctx.ctm();
        let Some(direction) = ctm.transform_vector3(to - from).try_normalize() else {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: "LightSource \"spot\": \"from\" and \"to\" must differ".into(),
            });
        };
        let cos_total = libm::cosf(cone_angle.to_radians());
        let cos_falloff_start = libm::cosf((cone_angle - cone_delta_angle).to_radians());
        let gain = normalised_gain(
            e.gain,
            params.float("power", DEFAULT_POWER)?,
            params.float("efficacy", DEFAULT_EFFICACY)?,
            2.0 * PI * luminance(e.l) * (1.0 - 0.5 * (cos_falloff_start + cos_total)),
        );
        Ok(Self {
            position: ctm.transform_point3(from),
            direction,
            intensity: e.l * gain,
            cone_angle,
            cone_delta_angle,
        })
    }
}

impl LightKind for SpotLight {
    type Sampler = SpotCone;

    fn name(&self) -> &'static str {
        "spot"
    }

    /// The light to sample, if it emits.
    fn light(&self, _maps: &MapSource) -> Result<Option<SpotCone>, LightError> {
        Ok(emits(self.intensity).then(|| {
            SpotCone::new(
                self.position,
                self.direction,
                self.intensity,
                self.cone_angle,
                self.cone_delta_angle,
            )
        }))
    }
}

/// A spot light ready to sample.
pub struct SpotCone {
    point: PointLight,
    direction: Vec3,
    /// cos(coneangle): no light outside.
    cos_total: f32,
    /// cos(coneangle - conedeltaangle): full intensity inside.
    cos_falloff_start: f32,
    /// Around `direction`, for rays leaving the light.
    frame: Frame,
    /// 1 - cos(coneangle), without the cancellation of a narrow cone.
    one_minus_cos_total: f32,
}

impl SpotCone {
    /// Angles in degrees.
    pub fn new(
        position: Vec3,
        direction: Vec3,
        intensity: Vec3,
        cone_angle: f32,
        cone_delta_angle: f32,
    ) -> Self {
        let cone = cone_angle.clamp(0.0, 180.0);
        let start = (cone - cone_delta_angle.max(0.0)).max(0.0);
        let direction = direction.normalize_or(Vec3::Z);
        let half_sin = libm::sinf(0.5 * cone.to_radians());
        Self {
            point: PointLight {
                position,
                intensity,
            },
            direction,
            cos_total: libm::cosf(cone.to_radians()),
            cos_falloff_start: libm::cosf(start.to_radians()),
            frame: Frame::from_normal(direction),
            one_minus_cos_total: 2.0 * half_sin * half_sin,
        }
    }

    pub fn position(&self) -> Vec3 {
        self.point.position
    }

    pub fn sample(&self, from: Vec3) -> Option<DeltaSample> {
        let s = self.point.sample(from)?;
        let falloff = self.falloff(-s.wi.dot(self.direction));
        (falloff > 0.0).then(|| DeltaSample {
            li: s.li * falloff,
            ..s
        })
    }

    /// Smoothstep from the cone's edge to where the falloff starts.
    fn falloff(&self, cos_theta: f32) -> f32 {
        if self.cos_falloff_start <= self.cos_total {
            return if cos_theta >= self.cos_total {
                1.0
            } else {
                0.0
            };
        }
        let t = ((cos_theta - self.cos_total) / (self.cos_falloff_start - self.cos_total))
            .clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }

    /// A ray leaving the light, in a direction uniform inside the cone (pbrt-v4 samples
    /// only to where the falloff ends, which is the cone's edge here); None where the falloff
    /// leaves nothing, on the edge.
    pub fn sample_emission(&self, u: Vec2) -> Option<EmittedRay> {
        let dir = self
            .frame
            .to_world(uniform_cone(u, self.one_minus_cos_total))
            .normalize_or_zero();
        let falloff = self.falloff(dir.dot(self.direction));
        let (pdf_pos, pdf_dir) = self.emission_pdf(dir);
        (falloff > 0.0 && pdf_dir > 0.0).then(|| EmittedRay {
            origin: self.point.position,
            dir,
            normal: None,
            le: self.point.intensity * falloff,
            pdf_pos,
            pdf_dir,
            delta_position: true,
            delta_direction: false,
        })
    }

    /// The (position, direction) densities of [`Self::sample_emission`] along unit `dir`:
    /// the delta position's 1, and 1 / the cone's solid angle inside it, 0 outside (where the
    /// falloff is 0 too: a sample with light is always inside).
    pub fn emission_pdf(&self, dir: Vec3) -> (f32, f32) {
        let solid_angle = TAU * self.one_minus_cos_total;
        let inside = dir.dot(self.direction) >= self.cos_total && solid_angle > 0.0;
        (1.0, if inside { 1.0 / solid_angle } else { 0.0 })
    }

    /// pbrt-v4's estimate: the full cone to where the falloff starts, half of the falloff band.
    pub fn power(&self) -> f32 {
        luminance(self.point.intensity)
            * 2.0
            * PI
            * (1.0 - 0.5 * (self.cos_falloff_start + self.cos_total))
    }
}
