//! `Sampler "sobol" "integer pixelsamples" [16]`: only the sample count carries over from the
//! file; the algorithm is always ours.
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `pixelsamples` | integer | none: the film's `haltspp`, the command line or 64 decide |
//!
//! Every other parameter is accepted and ignored. Without a `Sampler` statement the scene
//! records `"random"`, LuxRender's default.
//!
//! The deterministic sampler: the value for (pixel, sample index, dimension, seed) is a pure
//! function of those four numbers, so any thread, tile or machine that renders a sample draws
//! the same numbers (pbrt-v4's padded Sobol design).
//!
//! Each pair of dimensions uses the first two Sobol dimensions (well stratified in 2D) with
//! sample indices permuted and values Owen-scrambled per (pixel, dimension, seed), which keeps
//! every 2D projection stratified while decorrelating the pairs from each other.
//!
//! The camera's four dimensions (film and lens position) are one 4D Sobol point instead of two
//! such pairs ([`PixelSampler::get_camera`]): one index permutation for all four, so that a
//! pixel's lens positions are stratified together with its film positions (what it gains:
//! bench/RESULTS.md, "Session 17").
//!
//! Where the indices are permuted depends on how the samples are used. A uniform render takes
//! all `spp` samples of a pixel, so they are permuted over `[0, spp)`. An adaptive render
//! stops a pixel after any round, so every prefix it may stop at must be stratified on its
//! own: its samples are permuted only within the dyadic blocks `[0, 16)`, `[16, 32)`,
//! `[32, 64)`, ... (see [`PixelSampler::nested`]), each of which holds the Sobol points of an
//! elementary net, so the first 16 x 2^k samples are the first 16 x 2^k Sobol points. (Permuted
//! over the whole `[0, spp)`, a pixel stopped at n samples would hold a random subset of the
//! points, its error falling like independent sampling's.)

mod packet;
mod pixel;
mod sobol;
#[cfg(test)]
mod tests;

pub use packet::{PacketSampler, VertexPacket};
pub use pixel::{PixelSampler, VertexSamples, NESTED_FIRST_BLOCK};
pub use sobol::mix64;

use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// The sampler a scene without a `Sampler` statement records.
pub const DEFAULT_SAMPLER: &str = "random";

#[derive(Clone, Debug, PartialEq)]
pub struct SamplerDesc {
    /// `pixelsamples` when the file gives it; the film's haltspp or the command line win.
    pub pixel_samples: Option<u32>,
    pub requested: String,
}

impl Default for SamplerDesc {
    fn default() -> Self {
        Self {
            pixel_samples: None,
            requested: DEFAULT_SAMPLER.into(),
        }
    }
}

impl SamplerDesc {
    /// Reads `Sampler "ty"`.
    pub fn read(ty: String, params: &ParamList) -> Result<Self, ParseError> {
        let n = params.int("pixelsamples", 0)?;
        // The sampler's algorithm is ours; only its sample count carries over.
        params.ignore_all();
        Ok(Self {
            pixel_samples: (n > 0).then_some(n as u32),
            requested: ty,
        })
    }
}
