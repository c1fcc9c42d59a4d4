//! Marble: bands along y in 3D texture space, perturbed by fBm and coloured by a cubic
//! Bezier through LuxRender's fixed palette of greys and a dark blue vein.
//!
//! ```text
//! Texture "name" "color" "marble" "integer octaves" 8 "float roughness" 0.5 "float scale" 1 "float variation" 0.2
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `integer octaves`   | 8       | clamped to [0, 32] |
//! | `float roughness`   | 0.5     | fBm amplitude ratio per octave |
//! | `float scale`       | 1       | the texture-space point is multiplied by it |
//! | `float variation`   | 0.2     | how far the fBm bends the bands |
//! | 3D mapping          | global  | see [`super::mapping`] |
//!
//! Every value lies in the convex hull of the palette times 1.5: each channel within
//! [0.3, 0.9].

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::fbm::Octaves;
use super::noise::fbm;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

pub const DEFAULT_SCALE: f32 = 1.0;
pub const DEFAULT_VARIATION: f32 = 0.2;

/// LuxRender's marble palette (the Bezier control points), and the gain it applies.
const PALETTE: [Vec3; 9] = [
    Vec3::new(0.58, 0.58, 0.6),
    Vec3::new(0.58, 0.58, 0.6),
    Vec3::new(0.58, 0.58, 0.6),
    Vec3::new(0.5, 0.5, 0.5),
    Vec3::new(0.6, 0.59, 0.58),
    Vec3::new(0.58, 0.58, 0.6),
    Vec3::new(0.58, 0.58, 0.6),
    Vec3::new(0.2, 0.2, 0.33),
    Vec3::new(0.58, 0.58, 0.6),
];
const GAIN: f32 = 1.5;

#[derive(Clone, Debug, PartialEq)]
pub struct Marble {
    pub octaves: Octaves,
    pub scale: f32,
    pub variation: f32,
}

impl Marble {
    pub fn read(
        _decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            octaves: Octaves::read(params, pos, ctx)?,
            // Beside the mapping's "vector scale".
            scale: params.float_typed("scale", DEFAULT_SCALE)?,
            variation: params.float("variation", DEFAULT_VARIATION)?,
        })
    }
}

impl TextureType for Marble {
    fn name(&self) -> &'static str {
        "marble"
    }

    fn eval(&self, at: &LookupPoint, _textures: &impl ReferencedTextures) -> Vec3 {
        let o = &self.octaves;
        let p = o.mapping.map(at) * self.scale;
        let marble = p.y + self.variation * fbm(p, o.roughness, o.octaves);
        let t = 0.5 + 0.5 * libm::sinf(marble);
        // Six overlapping cubic segments over the nine control points.
        let segments = (PALETTE.len() - 3) as f32;
        let first = ((t * segments).floor() as usize).min(PALETTE.len() - 4);
        let t = t * segments - first as f32;
        let c = &PALETTE[first..first + 4];
        let (s0, s1, s2) = (c[0].lerp(c[1], t), c[1].lerp(c[2], t), c[2].lerp(c[3], t));
        let (s0, s1) = (s0.lerp(s1, t), s1.lerp(s2, t));
        GAIN * s0.lerp(s1, t)
    }
}
