//! `blender_distortednoise`: one noise basis evaluated at a point moved by another.
//!
//! ```text
//! Texture "d" "float" "blender_distortednoise" "string type" "voronoi_f1" "float distamount" 2
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `string type`       | blender_original | the basis that is distorted (see [`super::noise_basis`]) |
//! | `string noisebasis` | blender_original | the basis that distorts |
//! | `float distamount`  | 1       | how far |
//! | `float noisesize`   | 0.25    | the point is divided by it |
//! | `float nabla`       | 0.025   | accepted and ignored (Blender's normal step) |
//! | common              |         | see [`super::common`] |

use glam::Vec3;

use super::common::{Pattern, DEFAULT_NOISESIZE};
use super::noise_basis::{distorted_noise, NoiseBasis};
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Debug, PartialEq)]
pub struct DistortedNoise {
    pub distorted: NoiseBasis,
    pub distortion: NoiseBasis,
    pub amount: f32,
    pub size: f32,
}

impl DistortedNoise {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        params.ignore("nabla");
        Ok(Self {
            distorted: NoiseBasis::read(params, "type", pos, ctx)?,
            distortion: NoiseBasis::read(params, "noisebasis", pos, ctx)?,
            amount: params.float("distamount", 1.0)?,
            size: params.float("noisesize", DEFAULT_NOISESIZE)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let p = if self.size != 0.0 { p / self.size } else { p };
        Pattern::Intensity(distorted_noise(
            p,
            self.amount,
            self.distortion,
            self.distorted,
        ))
    }
}
