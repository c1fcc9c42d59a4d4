//! `blender_musgrave`: Musgrave's fractal terrains over a noise basis.
//!
//! ```text
//! Texture "t" "float" "blender_musgrave" "string type" "ridged_multifractal" "float octs" 4
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `string type`       | multifractal | multifractal, ridged_multifractal, hybrid_multifractal, hetero_terrain, fbm |
//! | `string noisebasis` | blender_original | see [`super::noise_basis`] |
//! | `float h`           | 1       | fractal increment: each octave's amplitude is lacu^-h times the previous |
//! | `float lacu`        | 2       | frequency ratio of octaves |
//! | `float octs`        | 2       | octaves (fractional: the last one partly), clamped to [0, 25] |
//! | `float gain`        | 1       | ridged and hybrid |
//! | `float offset`      | 1       | ridged, hybrid and hetero terrain |
//! | `float noisesize`   | 0.25    | the point is divided by it |
//! | `float outscale`    | 1       | the sum is multiplied by it |
//! | common              |         | see [`super::common`] |

use glam::Vec3;

use super::common::{read_choice, Pattern, DEFAULT_NOISESIZE};
use super::noise_basis::{Fractal, NoiseBasis};
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const TYPES: [&str; 5] = [
    "multifractal",
    "ridged_multifractal",
    "hybrid_multifractal",
    "hetero_terrain",
    "fbm",
];

#[derive(Clone, Debug, PartialEq)]
pub struct Musgrave {
    /// Index into [`TYPES`].
    pub kind: usize,
    pub fractal: Fractal,
    pub gain: f32,
    pub offset: f32,
    pub size: f32,
    pub outscale: f32,
}

impl Musgrave {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kind: read_choice(params, "type", &TYPES, pos, ctx)?,
            fractal: Fractal {
                basis: NoiseBasis::read(params, "noisebasis", pos, ctx)?,
                h: params.float("h", 1.0)?,
                lacunarity: params.float("lacu", 2.0)?,
                octaves: params.float("octs", 2.0)?,
            },
            gain: params.float("gain", 1.0)?,
            offset: params.float("offset", 1.0)?,
            size: params.float("noisesize", DEFAULT_NOISESIZE)?,
            outscale: params.float("outscale", 1.0)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let p = if self.size != 0.0 { p / self.size } else { p };
        let f = &self.fractal;
        let v = match self.kind {
            0 => f.multifractal(p),
            1 => f.ridged_multifractal(p, self.offset, self.gain),
            2 => f.hybrid_multifractal(p, self.offset, self.gain),
            3 => f.hetero_terrain(p, self.offset),
            _ => f.fbm(p),
        };
        Pattern::Intensity(self.outscale * v)
    }
}
