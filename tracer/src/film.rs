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

/// The accumulated image.
pub struct Film {}

impl Film {
    pub fn new(_width: u32, _height: u32) -> Self {
        todo!("renderer")
    }

    /// Adds a unit's buffer. Exact and order-independent: adding the same buffers in any order
    /// gives the same bits.
    pub fn add(&mut self, _buffer: &SampleBuffer) {
        todo!("renderer")
    }

    /// Tone maps as the scene's film asks and writes an sRGB PNG.
    pub fn write_png(
        &self,
        _path: &std::path::Path,
        _film: &crate::desc::FilmDesc,
    ) -> Result<(), image::ImageError> {
        todo!("renderer")
    }
}
