//! `blender_magic`: Blender's magic, nested sines and cosines of the point as a colour.
//!
//! ```text
//! Texture "m" "float" "blender_magic" "integer noisedepth" 2 "float turbulence" 5
//! ```
//!
//! | parameter            | default | notes |
//! |----------------------|---------|-------|
//! | `integer noisedepth` | 2       | levels of nesting, 0 .. 10 |
//! | `float turbulence`   | 5       | |
//! | common               |         | see [`super::common`] |
//!
//! No noise: the pattern is exactly Blender's.

use glam::Vec3;

use super::common::{Pattern, DEFAULT_NOISEDEPTH, DEFAULT_TURBULENCE};

/// One nesting level: which coordinate it replaces (0 x, 1 y, 2 z) and by what wave of the
/// three.
type Level = fn(f32, f32, f32) -> (usize, f32);
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Debug, PartialEq)]
pub struct Magic {
    pub depth: i32,
    pub turbulence: f32,
}

impl Magic {
    pub fn read(params: &ParamList) -> Result<Self, ParseError> {
        Ok(Self {
            depth: params.int("noisedepth", DEFAULT_NOISEDEPTH)?,
            turbulence: params.float("turbulence", DEFAULT_TURBULENCE)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let turb = self.turbulence / 5.0;
        let mut x = libm::sinf((p.x + p.y + p.z) * 5.0);
        let mut y = libm::cosf((-p.x + p.y - p.z) * 5.0);
        let mut z = -libm::cosf((-p.x - p.y + p.z) * 5.0);
        if self.depth > 0 {
            x *= turb;
            y *= turb;
            z *= turb;
            // Each level replaces one coordinate by a wave of the three, in Blender's order.
            let levels: [Level; 10] = [
                |x, y, z| (1, -libm::cosf(x - y + z)),
                |x, y, z| (0, libm::cosf(x - y - z)),
                |x, y, z| (2, libm::sinf(-x - y - z)),
                |x, y, z| (0, -libm::cosf(-x + y - z)),
                |x, y, z| (1, -libm::sinf(-x + y + z)),
                |x, y, z| (1, -libm::cosf(-x + y + z)),
                |x, y, z| (0, libm::cosf(x + y + z)),
                |x, y, z| (2, libm::sinf(x + y - z)),
                |x, y, z| (0, -libm::cosf(-x - y + z)),
                |x, y, z| (1, -libm::sinf(x - y + z)),
            ];
            for level in levels.iter().take(self.depth.clamp(1, 10) as usize) {
                let (axis, v) = level(x, y, z);
                let v = v * turb;
                match axis {
                    0 => x = v,
                    1 => y = v,
                    _ => z = v,
                }
            }
        }
        if turb != 0.0 {
            let t = 2.0 * turb;
            x /= t;
            y /= t;
            z /= t;
        }
        Pattern::Rgb(Vec3::new(0.5 - x, 0.5 - y, 0.5 - z))
    }
}
