//! `blender_stucci`: Blender's stucco, a noise sampled slightly above the point.
//!
//! ```text
//! Texture "s" "float" "blender_stucci" "string type" "wall_in" "float turbulence" 5
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `string type`       | plastic | plastic, wall_in, wall_out (inverted) |
//! | `string noisebasis` | blender_original | see [`super::noise_basis`] |
//! | `string noisetype`  | soft_noise | |
//! | `float noisesize`   | 0.25    | |
//! | `float turbulence`  | 5       | the offset along z is turbulence / 200 (wall types: times the noise squared) |
//! | common              |         | see [`super::common`]; Blender applies no brightness or contrast to stucci |

use glam::Vec3;

use super::common::{read_choice, read_hard, Pattern, DEFAULT_NOISESIZE, DEFAULT_TURBULENCE};
use super::noise_basis::NoiseBasis;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Debug, PartialEq)]
pub struct Stucci {
    /// 0 plastic, 1 wall_in, 2 wall_out.
    pub kind: usize,
    pub basis: NoiseBasis,
    pub hard: bool,
    pub size: f32,
    pub turbulence: f32,
}

impl Stucci {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kind: read_choice(
                params,
                "type",
                &["plastic", "wall_in", "wall_out"],
                pos,
                ctx,
            )?,
            basis: NoiseBasis::read(params, "noisebasis", pos, ctx)?,
            hard: read_hard(params, pos, ctx)?,
            size: params.float("noisesize", DEFAULT_NOISESIZE)?,
            turbulence: params.float("turbulence", DEFAULT_TURBULENCE)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let b2 = self.basis.g_noise(self.size, p, self.hard);
        let mut offset = self.turbulence / 200.0;
        if self.kind != 0 {
            offset *= b2 * b2;
        }
        let mut v = self
            .basis
            .g_noise(self.size, p + Vec3::new(0.0, 0.0, offset), self.hard);
        if self.kind == 2 {
            v = 1.0 - v;
        }
        Pattern::Raw(v.max(0.0))
    }
}
