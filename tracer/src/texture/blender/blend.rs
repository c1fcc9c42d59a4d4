//! `blender_blend`: Blender's gradients.
//!
//! ```text
//! Texture "b" "float" "blender_blend" "string type" "radial" "bool flipxy" "true"
//! ```
//!
//! | parameter      | default | notes |
//! |----------------|---------|-------|
//! | `string type`  | lin     | lin ((1 + x) / 2), quad (its square), ease (smoothstep), diag ((2 + x + y) / 4), sphere (1 - abs(p)), halo (its square), radial (the angle around z) |
//! | `bool flipxy`  | false   | swaps x and y |
//! | common         |         | see [`super::common`] |
//!
//! No noise: the pattern is exactly Blender's.

use std::f32::consts::TAU;

use glam::Vec3;

use super::common::{read_choice, Pattern};
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const TYPES: [&str; 7] = ["lin", "quad", "ease", "diag", "sphere", "halo", "radial"];

#[derive(Clone, Debug, PartialEq)]
pub struct Blend {
    /// Index into [`TYPES`].
    pub kind: usize,
    pub flip: bool,
}

impl Blend {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            kind: read_choice(params, "type", &TYPES, pos, ctx)?,
            flip: params.bool("flipxy", false)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let (x, y) = if self.flip { (p.y, p.x) } else { (p.x, p.y) };
        let lin = (1.0 + x) / 2.0;
        Pattern::Intensity(match TYPES[self.kind] {
            "lin" => lin,
            "quad" => lin.max(0.0).powi(2),
            "ease" => {
                let t = lin.clamp(0.0, 1.0);
                t * t * (3.0 - 2.0 * t)
            }
            "diag" => (2.0 + x + y) / 4.0,
            "radial" => libm::atan2f(y, x) / TAU + 0.5,
            kind => {
                let s = (1.0 - (x * x + y * y + p.z * p.z).sqrt()).max(0.0);
                if kind == "halo" {
                    s * s
                } else {
                    s
                }
            }
        })
    }
}
