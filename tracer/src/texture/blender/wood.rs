//! `blender_wood`: Blender's wood, bands or rings of a wave form, optionally disturbed by
//! noise.
//!
//! ```text
//! Texture "w" "float" "blender_wood" "string type" "ringnoise" "float turbulence" 5
//! ```
//!
//! | parameter            | default | notes |
//! |----------------------|---------|-------|
//! | `string type`        | bands   | bands (along x + y + z), rings (around the origin), bandnoise, ringnoise |
//! | `string noisebasis2` | sin     | the wave: sin, saw, tri |
//! | `string noisebasis`  | blender_original | see [`super::noise_basis`] |
//! | `string noisetype`   | soft_noise | |
//! | `float noisesize`    | 0.25    | |
//! | `float turbulence`   | 5       | how far the noise moves the wave (noise types only) |
//! | common               |         | see [`super::common`] |

use glam::Vec3;

use super::common::{read_choice, read_hard, Pattern, Wave, DEFAULT_NOISESIZE, DEFAULT_TURBULENCE};
use super::noise_basis::NoiseBasis;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WoodType {
    Bands,
    Rings,
    BandNoise,
    RingNoise,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Wood {
    pub kind: WoodType,
    pub wave: Wave,
    pub basis: NoiseBasis,
    pub hard: bool,
    pub size: f32,
    pub turbulence: f32,
}

impl Wood {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let kinds = [
            WoodType::Bands,
            WoodType::Rings,
            WoodType::BandNoise,
            WoodType::RingNoise,
        ];
        let kind = kinds[read_choice(
            params,
            "type",
            &["bands", "rings", "bandnoise", "ringnoise"],
            pos,
            ctx,
        )?];
        Ok(Self {
            kind,
            wave: Wave::from_index(read_choice(params, "noisebasis2", &Wave::NAMES, pos, ctx)?),
            basis: NoiseBasis::read(params, "noisebasis", pos, ctx)?,
            hard: read_hard(params, pos, ctx)?,
            size: params.float("noisesize", DEFAULT_NOISESIZE)?,
            turbulence: params.float("turbulence", DEFAULT_TURBULENCE)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let noise = || self.turbulence * self.basis.g_noise(self.size, p, self.hard);
        let bands = (p.x + p.y + p.z) * 10.0;
        let rings = p.length() * 20.0;
        Pattern::Intensity(self.wave.eval(match self.kind {
            WoodType::Bands => bands,
            WoodType::Rings => rings,
            WoodType::BandNoise => bands + noise(),
            WoodType::RingNoise => rings + noise(),
        }))
    }
}
