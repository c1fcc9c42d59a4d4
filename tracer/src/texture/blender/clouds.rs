//! `blender_clouds`: Blender's clouds, turbulence of a noise basis.
//!
//! ```text
//! Texture "c" "float" "blender_clouds" "float noisesize" 0.25 "integer noisedepth" 2
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `string type`       | default | default (grey), color (three turbulences on permuted axes) |
//! | `string noisebasis` | blender_original | see [`super::noise_basis`] |
//! | `string noisetype`  | soft_noise | |
//! | `float noisesize`   | 0.25    | |
//! | `integer noisedepth`| 2       | clamped to [0, 25] |
//! | common              |         | see [`super::common`] |

use glam::Vec3;

use super::common::{read_choice, read_depth, read_hard, Pattern, DEFAULT_NOISESIZE};
use super::noise_basis::NoiseBasis;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Debug, PartialEq)]
pub struct Clouds {
    pub color: bool,
    pub basis: NoiseBasis,
    pub hard: bool,
    pub size: f32,
    pub depth: u32,
}

impl Clouds {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            color: read_choice(params, "type", &["default", "color"], pos, ctx)? == 1,
            basis: NoiseBasis::read(params, "noisebasis", pos, ctx)?,
            hard: read_hard(params, pos, ctx)?,
            size: params.float("noisesize", DEFAULT_NOISESIZE)?,
            depth: read_depth(params)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let turbulence = |q: Vec3| self.basis.g_turbulence(self.size, q, self.depth, self.hard);
        let grey = turbulence(p);
        if self.color {
            Pattern::Rgb(Vec3::new(
                grey,
                turbulence(Vec3::new(p.y, p.x, p.z)),
                turbulence(Vec3::new(p.y, p.z, p.x)),
            ))
        } else {
            Pattern::Intensity(grey)
        }
    }
}
