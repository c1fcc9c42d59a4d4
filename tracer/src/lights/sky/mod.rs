//! The daylight skies: LuxRender 1.x's `sky` (Preetham, [`preetham`]) and `sky2`
//! (Hosek-Wilkie, [`hosek`]). `sunsky` and `sunsky2` are a sun plus one of these, read from
//! the same parameters.
//!
//! ```text
//! LightSource "sky" "vector sundir" [0 0 1] "float turbidity" [2] "float gain" [1]
//! LightSource "sky2" "vector sundir" [0 0 1] "float turbidity" [2] "float gain" [1]
//! ```
//!
//! | parameter   | default | meaning                                                     |
//! |-------------|---------|-------------------------------------------------------------|
//! | `sundir`    | 0 0 1   | towards the sun, in light space (z up)                      |
//! | `turbidity` | 2       | haze (`sky2` clamps it to [1, 10])                          |
//! | `gain`      | 1       | multiplies the radiance                                     |
//! | `nsamples`  | 1       | a sampling hint: read and ignored                           |
//! | `aconst` ... `econst` | 1 | `sky` only: the Perez multipliers ([`preetham`])       |
//!
//! Units are LuxRender's (cd/m^2: a clear zenith is a few thousand). The sky is defined in
//! light space (z up), mapped to the world by the current transform, and covers the whole
//! sphere: below the horizon it repeats the horizon, as LuxRender's does.
//!
//! The model is tabulated once on a LatLong grid and served by the infinite light's map
//! machinery: bilinear lookups, importance sampling by luminance x sin(theta).

mod hosek;
mod preetham;

use std::f32::consts::{PI, TAU};

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use crate::diag::SourcePos;
use crate::image_io::{ImageCost, RgbImage};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

use super::emission::{self, emits};
use super::error::LightError;
use super::infinite::{map_cost, Environment};
use super::kind::{LatLongConvention, LightKind, MapSource};

pub use hosek::Hosek;
pub use preetham::Preetham;

/// `sundir`.
pub const DEFAULT_SUNDIR: Vec3 = Vec3::Z;
/// `turbidity`.
pub const DEFAULT_TURBIDITY: f32 = 2.0;

/// The tabulated grid: 0.35 degrees per texel, fine for the smooth sky and its circumsolar
/// glow, and (with the distribution) a few MB.
const TABLE_WIDTH: u32 = 1024;
const TABLE_HEIGHT: u32 = 512;

/// Which model, with its own parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum SkyModel {
    /// `sky`: Preetham, with the five Perez multipliers.
    Preetham { consts: [f32; 5] },
    /// `sky2`: Hosek-Wilkie.
    Hosek,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SkyLight {
    pub model: SkyModel,
    /// Unit light-space direction towards the sun.
    pub sundir: Vec3,
    pub turbidity: f32,
    pub gain: f32,
    /// Light space has z up; this maps it to world space.
    pub light_to_world: Mat4,
}

impl SkyLight {
    /// Texels of the table a sky is tabulated on when the scene is built (RGB f32, plus its
    /// sampling distribution): counted against the build budget like an image map's, so a
    /// small file repeating `LightSource "sky"` cannot ask for gigabytes.
    pub const TABLE_TEXELS: u64 = TABLE_WIDTH as u64 * TABLE_HEIGHT as u64;

    /// What the table takes in memory: linear texels and an environment map's sampling tables.
    pub fn table_cost() -> ImageCost {
        map_cost(
            ImageCost::linear(TABLE_WIDTH, TABLE_HEIGHT),
            TABLE_WIDTH,
            TABLE_HEIGHT,
        )
    }

    /// Reads `sky` (`hosek` false) or `sky2` (`hosek` true).
    /// `LightSource "sky"`: Preetham's model.
    pub(crate) fn read_preetham(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Self::read(false, params, pos, ctx)
    }

    /// `LightSource "sky2"`: Hosek and Wilkie's model.
    pub(crate) fn read_hosek(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Self::read(true, params, pos, ctx)
    }

    fn read(
        hosek: bool,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let gain = params.float("gain", emission::DEFAULT_GAIN)?;
        let name = if hosek { "sky2" } else { "sky" };
        let Some(sundir) = params.vec3("sundir", DEFAULT_SUNDIR)?.try_normalize() else {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!("LightSource \"{name}\": \"sundir\" must not be zero"),
            });
        };
        let turbidity = params.float("turbidity", DEFAULT_TURBIDITY)?;
        params.ignore("nsamples");
        let model = if hosek {
            SkyModel::Hosek
        } else {
            SkyModel::Preetham {
                consts: preetham::read_consts(params)?,
            }
        };
        Ok(Self {
            model,
            sundir,
            turbidity,
            gain,
            light_to_world: ctx.ctm(),
        })
    }

    /// Radiance per unit gain from a unit light-space direction: the model itself, before
    /// tabulation (None if the model refuses its parameters).
    pub fn model(&self) -> Option<impl Fn(Vec3) -> Vec3 + Sync> {
        enum Model {
            Preetham(Preetham),
            Hosek(Hosek),
        }
        let sun = self.sundir.normalize_or_zero();
        let model = match &self.model {
            SkyModel::Preetham { consts } => {
                Model::Preetham(Preetham::new(sun, self.turbidity, *consts))
            }
            SkyModel::Hosek => Model::Hosek(Hosek::new(sun, self.turbidity)?),
        };
        Some(move |dir: Vec3| match &model {
            Model::Preetham(m) => m.radiance(dir),
            Model::Hosek(m) => m.radiance(dir),
        })
    }

    /// The model tabulated on a LatLong grid in LuxRender's convention, if it emits.
    fn tabulated(&self) -> Option<Environment> {
        if !(self.gain > 0.0 && self.gain.is_finite()) {
            return None;
        }
        let model = self.model()?;
        let (w, h) = (TABLE_WIDTH, TABLE_HEIGHT);
        // Texel centres; rows in parallel (each texel depends only on its direction).
        let texels: Vec<Vec3> = (0..h)
            .into_par_iter()
            .flat_map_iter(|y| {
                let (sin_theta, cos_theta) = libm::sincosf((y as f32 + 0.5) / h as f32 * PI);
                let model = &model;
                (0..w).map(move |x| {
                    let (sin_phi, cos_phi) = libm::sincosf((x as f32 + 0.5) / w as f32 * TAU);
                    model(Vec3::new(
                        sin_theta * cos_phi,
                        sin_theta * sin_phi,
                        cos_theta,
                    ))
                })
            })
            .collect();
        if !texels.iter().any(|&t| emits(t)) {
            return None;
        }
        if Environment::is_singular(&self.light_to_world) {
            tracing::warn!(
                "{} light: singular transform, using the identity",
                self.name()
            );
        }
        Some(Environment::new(
            Vec3::splat(self.gain),
            Some(RgbImage::from_linear(w, h, texels)),
            &self.light_to_world,
            LatLongConvention::LuxRender,
        ))
    }
}

impl LightKind for SkyLight {
    type Sampler = Environment;

    /// The LuxRender type name.
    fn name(&self) -> &'static str {
        match self.model {
            SkyModel::Preetham { .. } => "sky",
            SkyModel::Hosek => "sky2",
        }
    }

    fn light(&self, _maps: &MapSource) -> Result<Option<Environment>, LightError> {
        Ok(self.tabulated())
    }
}
