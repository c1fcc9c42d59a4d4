//! Sample buffers and the film: per-pixel sums from units, merged in an order-independent way
//! (exact fixed-point sums), tone mapped and written as PNG or linear EXR.

use crate::render::WorkUnit;

/// A unit's result: per pixel of its tile (row-major), the sum of sample radiance and the sum
/// of sample weights. 16 bytes per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleBuffer {
    pub unit: WorkUnit,
    pub rgb: Vec<[f32; 3]>,
    pub weight: Vec<f32>,
}

pub struct Film {}
