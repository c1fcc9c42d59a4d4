//! `blender_noise`: Blender's white noise, a random intensity per point from products of
//! random 2-bit numbers.
//!
//! ```text
//! Texture "n" "float" "blender_noise" "integer noisedepth" 2
//! ```
//!
//! | parameter            | default | notes |
//! |----------------------|---------|-------|
//! | `integer noisedepth` | 2       | clamped to [0, 14] (the random number's bits) |
//! | common               |         | see [`super::common`] |
//!
//! Blender and LuxRender draw the random number from a global generator, so their pattern
//! changes with the order of evaluation; YAT hashes the texture-space point instead, so an
//! image stays the same for any thread count (it is white noise either way).

use glam::Vec3;

use super::common::{Pattern, DEFAULT_NOISEDEPTH};
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// 2 bits per level out of a 31-bit random number.
pub const MAX_DEPTH: i32 = 14;

#[derive(Clone, Debug, PartialEq)]
pub struct Noise {
    pub depth: u32,
}

/// A 31-bit hash of a point's bits (a splitmix-style mix: any change of any bit changes it).
fn random(p: Vec3) -> u32 {
    let mut h: u64 = 0x9E37_79B9_7F4A_7C15;
    for v in p.to_array() {
        h ^= v.to_bits() as u64;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 31;
    }
    (h >> 33) as u32
}

impl Noise {
    pub fn read(params: &ParamList) -> Result<Self, ParseError> {
        Ok(Self {
            depth: params
                .int("noisedepth", DEFAULT_NOISEDEPTH)?
                .clamp(0, MAX_DEPTH) as u32,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let mut ran = random(p);
        let mut value = ran & 3;
        let mut div = 3.0;
        for _ in 0..self.depth {
            ran >>= 2;
            value *= ran & 3;
            div *= 3.0;
        }
        Pattern::Intensity(value as f32 / div)
    }
}
