//! `blender_marble`: Blender's marble, a wave along x + y + z disturbed by turbulence.
//!
//! ```text
//! Texture "m" "float" "blender_marble" "string type" "sharp" "float turbulence" 5
//! ```
//!
//! | parameter            | default | notes |
//! |----------------------|---------|-------|
//! | `string type`        | soft    | soft, sharp (square root), sharper (fourth root) |
//! | `string noisebasis2` | sin     | the wave: sin, saw, tri |
//! | `string noisebasis`  | blender_original | see [`super::noise_basis`] |
//! | `string noisetype`   | soft_noise | |
//! | `float noisesize`    | 0.25    | |
//! | `integer noisedepth` | 2       | clamped to [0, 25] |
//! | `float turbulence`   | 5       | |
//! | common               |         | see [`super::common`] |

use glam::Vec3;

use super::common::{
    read_choice, read_depth, read_hard, Pattern, Wave, DEFAULT_NOISESIZE, DEFAULT_TURBULENCE,
};
use super::noise_basis::NoiseBasis;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Debug, PartialEq)]
pub struct Marble {
    /// 0 soft, 1 sharp, 2 sharper.
    pub sharpness: usize,
    pub wave: Wave,
    pub basis: NoiseBasis,
    pub hard: bool,
    pub size: f32,
    pub depth: u32,
    pub turbulence: f32,
}

impl Marble {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            sharpness: read_choice(params, "type", &["soft", "sharp", "sharper"], pos, ctx)?,
            wave: Wave::from_index(read_choice(params, "noisebasis2", &Wave::NAMES, pos, ctx)?),
            basis: NoiseBasis::read(params, "noisebasis", pos, ctx)?,
            hard: read_hard(params, pos, ctx)?,
            size: params.float("noisesize", DEFAULT_NOISESIZE)?,
            depth: read_depth(params)?,
            turbulence: params.float("turbulence", DEFAULT_TURBULENCE)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let n = 5.0 * (p.x + p.y + p.z);
        let m = n + self.turbulence * self.basis.g_turbulence(self.size, p, self.depth, self.hard);
        let m = self.wave.eval(m);
        Pattern::Intensity(match self.sharpness {
            0 => m,
            1 => m.sqrt(),
            _ => m.sqrt().sqrt(),
        })
    }
}
