//! The sample stream of one pixel sample ([`PixelSampler`]) and the six dimensions a
//! scattering vertex draws as eight lanes of one pass.

use glam::Vec2;

use super::sobol::{
    camera_point, laine_karras, mix64, pascal_parity, permutation_element, permutation_mask,
    permutation_offset, permutation_round, point_1d, point_2d, to_unit_float, walk_below,
};
use crate::lanes::U32Lanes;

/// The sample stream of one pixel sample.
#[derive(Clone, Debug)]
pub struct PixelSampler {
    pixel_hash: u64,
    pub(super) index: u32,
    /// The indices are permuted over `first..first + len`, which holds `index`.
    pub(super) first: u32,
    len: u32,
    /// [`permutation_mask`] of `len`.
    mask: u32,
    /// The next dimension times [`DIMENSION_STEP`].
    dimension_key: u64,
}

/// Dimension d's hash is that of the pixel's with d times this (2^64 / golden ratio).
const DIMENSION_STEP: u64 = 0x9e37_79b9_7f4a_7c15;

/// Keys the streams of a path's branches ([`PixelSampler::branch`]) apart from the pixel's.
const BRANCH_KEY: u64 = 0x6272_616e_6368_0000;

/// Keys a sample's light subpath stream ([`PixelSampler::light_subpath`]) apart from its
/// camera path's and its branches'.
const LIGHT_SUBPATH_KEY: u64 = 0x6c69_6768_7470_6174;

/// Keys a sample's wavelength number ([`PixelSampler::wavelength_number`]) apart from its
/// stream's dimensions.
const WAVELENGTH_KEY: u64 = 0x7761_7665_6c65_6e67;

/// The first block of [`PixelSampler::nested`]'s indices: the default first round of an
/// adaptive render, so that rounds of that default are exactly the blocks.
pub const NESTED_FIRST_BLOCK: u32 = 16;

impl PixelSampler {
    /// Sample `index` of a pixel that takes all of `spp` samples (`index < spp`).
    pub fn new(x: u32, y: u32, index: u32, spp: u32, seed: u64) -> Self {
        Self::over(x, y, index, 0, spp.max(1), seed)
    }

    /// Sample `index` of a pixel that may stop at any power of two times
    /// [`NESTED_FIRST_BLOCK`] samples: each prefix of that length is stratified.
    pub fn nested(x: u32, y: u32, index: u32, seed: u64) -> Self {
        let (first, len) = if index < NESTED_FIRST_BLOCK {
            (0, NESTED_FIRST_BLOCK)
        } else {
            let first = 1 << index.ilog2();
            (first, first)
        };
        Self::over(x, y, index, first, len, seed)
    }

    fn over(x: u32, y: u32, index: u32, first: u32, len: u32, seed: u64) -> Self {
        let pixel_hash = mix64(seed ^ mix64((u64::from(x) << 32) | u64::from(y)));
        Self {
            pixel_hash,
            index,
            first,
            len,
            mask: permutation_mask(len),
            dimension_key: 0,
        }
    }

    /// The Sobol index this sample uses in the dimension whose hash is `p`.
    fn sobol_index(&self, p: u32) -> u32 {
        self.sobol_index_of(self.index - self.first, p)
    }

    /// The Sobol indices, in the dimension whose hash is `p`, of the samples `offset` past the
    /// first of this sample's permutation range (several lanes of them at once).
    #[inline(always)]
    pub(super) fn sobol_index_of<U: U32Lanes>(&self, offset: U, p: u32) -> U {
        let element = permutation_element(offset, self.len, self.mask, U::splat(p));
        U::splat(self.first).wrapping_add(element)
    }

    pub fn get_1d(&mut self) -> f32 {
        let hash = self.next_dimension_hash();
        point_1d(self.sobol_index(hash as u32), hash)
    }

    pub fn get_2d(&mut self) -> Vec2 {
        let hash = self.next_dimension_hash();
        point_2d(self.sobol_index(hash as u32), hash)
    }

    /// The camera's film position (within the pixel) and lens position: the first two
    /// dimensions, drawn as one 4D Sobol point (Sobol dimensions 0 to 3 under the first
    /// dimension's index permutation, each coordinate Owen-scrambled by its own hash). The
    /// film position is the one [`Self::get_2d`] would draw; the lens position is stratified
    /// with it (16 samples take each of the 16 cells halving the four coordinates once),
    /// where a pair of its own would be independent of it.
    // Inlined into the render loop: a call away, it costs measurable speed (bench/RESULTS.md,
    // "The integrator's inlining").
    #[inline(always)]
    pub fn get_camera(&mut self) -> (Vec2, Vec2) {
        let film_hash = self.next_dimension_hash();
        let lens_hash = self.next_dimension_hash();
        let index = self.sobol_index(film_hash as u32);
        let (film, lens) = camera_point(index, film_hash, lens_hash);
        (Vec2::from(film), Vec2::from(lens))
    }

    /// The stream of sample `index` of the same permutation range, at this stream's next
    /// dimension.
    pub(super) fn sample_at(&self, index: u32) -> Self {
        Self {
            index,
            ..self.clone()
        }
    }

    /// The stream of this sample's light subpath (bidirectional path tracing): dimensions of
    /// its own from the first, scrambled and permuted by hashes of their own, over the same
    /// permutation range as the camera path's, so a pixel's light subpaths are stratified
    /// as its camera paths are.
    pub fn light_subpath(&self) -> Self {
        Self {
            pixel_hash: mix64(self.pixel_hash ^ LIGHT_SUBPATH_KEY),
            dimension_key: 0,
            ..self.clone()
        }
    }

    /// The number this sample's wavelength is drawn from ([`crate::wavelength`]), for a path
    /// that meets a dispersive interface: a dimension keyed apart from the stream's, so drawing
    /// it moves no other dimension (and the light subpath's stream, keyed apart itself, sees
    /// the camera path's wavelength through the caller), stratified over the pixel's samples.
    pub fn wavelength_number(&self) -> f32 {
        let hash = mix64(self.pixel_hash ^ WAVELENGTH_KEY);
        point_1d(self.sobol_index(hash as u32), hash)
    }

    /// The stream of branch `k` of this sample's path: the same dimensions, scrambled and
    /// permuted by hashes of their own.
    pub fn branch(&self, k: u32) -> Self {
        Self {
            pixel_hash: mix64(self.pixel_hash ^ mix64(BRANCH_KEY + u64::from(k))),
            ..self.clone()
        }
    }

    /// A BSDF sample's lobe choice (a 1D dimension) and direction numbers (a 2D one) for a
    /// vertex that splits into `n` samples (`n <= N`; the values past the first `n` are 0):
    /// each dimension drawn `n` times, sample `index`'s Sobol point `s` becoming points
    /// `n s .. n s + n`. For `n` a power of two the `n` values are stratified among themselves
    /// and all of a pixel's `n spp` values together (what `n spp` samples of the dimension would
    /// be), where `n` separate dimensions would each be stratified alone. Only the `n` together
    /// are: value `j` of every sample lies in the same `1 / n` of the first coordinate, so a
    /// caller weighs all `n` alike: paths may go on along all of them (as branches do), never
    /// along one alone.
    pub fn get_split_draws<const N: usize>(&mut self, n: usize) -> ([f32; N], [Vec2; N]) {
        let n = n.min(N);
        let lobe_hash = self.next_dimension_hash();
        let dir_hash = self.next_dimension_hash();
        let lobe_first = self.split_index(lobe_hash, n);
        let dir_first = self.split_index(dir_hash, n);
        let lobes = std::array::from_fn(|i| {
            if i < n {
                point_1d(lobe_first + i as u32, lobe_hash)
            } else {
                0.0
            }
        });
        let dirs = std::array::from_fn(|i| {
            if i < n {
                point_2d(dir_first + i as u32, dir_hash)
            } else {
                Vec2::ZERO
            }
        });
        (lobes, dirs)
    }

    /// The first of the `n` Sobol indices a split draw takes in the dimension whose hash is
    /// `hash`. Indices wrap at 2^32 (past 2^32 / n samples a pixel), still valid points.
    fn split_index(&self, hash: u64, n: usize) -> u32 {
        self.sobol_index(hash as u32).wrapping_mul(n as u32)
    }

    /// The next six dimensions a scattering vertex uses, drawn together: the same values as
    /// `get_1d`, `get_1d`, `get_2d`, `get_1d`, `get_2d` and `get_1d` in turn. The eight values'
    /// index permutations and scrambles are computed as the lanes of one pass (AVX2 where the
    /// CPU has it): drawn one at a time they were most of the sampler's time.
    #[inline(always)]
    pub fn get_vertex(&mut self) -> VertexSamples {
        let v = self.vertex_lanes().draw();
        VertexSamples {
            mix: v[0],
            light_select: v[1],
            light: Vec2::new(v[2], v[3]),
            lobe: v[4],
            bsdf: Vec2::new(v[5], v[6]),
            roulette: v[7],
        }
    }

    /// Steps back after [`Self::get_vertex`] to the dimension after its first, for a vertex that
    /// used only [`VertexSamples::mix`] (a surface rays pass through).
    pub fn unread_after_mix(&mut self) {
        let unread = VERTEX_DIMENSIONS - 1;
        self.dimension_key = self
            .dimension_key
            .wrapping_sub(unread.wrapping_mul(DIMENSION_STEP));
    }

    /// The lanes of [`Self::get_vertex`]'s draw; steps over its dimensions.
    fn vertex_lanes(&mut self) -> VertexLanes {
        let h = [(); VERTEX_DIMENSIONS as usize].map(|()| self.next_dimension_hash());
        let scramble = |h: u64| (h >> 32) as u32;
        VertexLanes {
            offset: self.index - self.first,
            first: self.first,
            len: self.len,
            mask: self.mask,
            permutation: LANE_DIMENSION.map(|d| h[d] as u32),
            seeds: [
                scramble(h[0]),
                scramble(h[1]),
                scramble(h[2]),
                mix64(h[2]) as u32,
                scramble(h[3]),
                scramble(h[4]),
                mix64(h[4]) as u32,
                scramble(h[5]),
            ],
        }
    }

    pub(super) fn next_dimension_hash(&mut self) -> u64 {
        let hash = mix64(self.pixel_hash ^ self.dimension_key);
        self.dimension_key = self.dimension_key.wrapping_add(DIMENSION_STEP);
        hash
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VertexSamples {
    /// The component of a mix material.
    pub mix: f32,
    /// The light's choice and its sample (next-event estimation).
    pub light_select: f32,
    pub light: Vec2,
    /// The BSDF's lobe choice and its direction sample.
    pub lobe: f32,
    pub bsdf: Vec2,
    /// Russian roulette.
    pub roulette: f32,
}

/// The dimension (of the six a vertex draw takes) each lane of the draw is a value of: its
/// first, or its second where [`LANE_SECOND`] says so.
const LANE_DIMENSION: [usize; 8] = [0, 1, 2, 2, 3, 4, 4, 5];

/// Dimensions a [`PixelSampler::get_vertex`] draw takes.
const VERTEX_DIMENSIONS: u64 = 6;

/// The lanes that draw a 2D dimension's y (Sobol dimension 1).
const LANE_SECOND: [bool; 8] = [false, false, false, true, false, false, true, false];

/// Eight sample values of one pixel sample: a lane's Sobol index is the sample's, permuted
/// by its `permutation` hash within `first..first + len`; its value that index's point
/// scrambled by its seed.
struct VertexLanes {
    /// The sample's index minus `first`.
    offset: u32,
    first: u32,
    len: u32,
    mask: u32,
    permutation: [u32; 8],
    seeds: [u32; 8],
}

impl VertexLanes {
    fn draw(&self) -> [f32; 8] {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU runs AVX2.
            return unsafe { self.draw_avx2() };
        }
        self.draw_lanes()
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn draw_avx2(&self) -> [f32; 8] {
        self.draw_lanes()
    }

    /// Written lane by lane for the compiler to vectorise; each lane does exactly what
    /// `sobol_index` and `owen_scramble` do for one value, so the values are the same bits.
    #[inline(always)]
    fn draw_lanes(&self) -> [f32; 8] {
        let (len, w, p) = (self.len, self.mask, self.permutation);
        let mut index = [self.first; 8];
        if len > 1 {
            let mut i = [0; 8];
            for l in 0..8 {
                i[l] = permutation_round(self.offset, w, p[l]);
            }
            // A round lands in len..=w only when len is not a power of two.
            if i.iter().any(|&i| i >= len) {
                for l in 0..8 {
                    i[l] = walk_below(i[l], len, w, p[l]);
                }
            }
            for l in 0..8 {
                index[l] += permutation_offset(i[l], len, p[l]);
            }
        }
        let mut values = [0.0; 8];
        for l in 0..8 {
            // Sobol dimension 0 is the index's bits reversed, and Owen scrambling works on
            // reversed bits: its input is the index itself (or dimension 1's parity form).
            let x = if LANE_SECOND[l] {
                pascal_parity(index[l])
            } else {
                index[l]
            };
            values[l] = to_unit_float(laine_karras(x, self.seeds[l]).reverse_bits());
        }
        values
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertex's batched draw gives the bits of the draws one at a time, on the portable
    /// kernel and on the one this CPU runs, for power-of-two and other sample counts (whose
    /// permutations cycle-walk), one sample, and nested samples.
    #[test]
    fn vertex_draws_equal_the_draws_one_at_a_time() {
        let mut samplers = Vec::new();
        for (x, y) in [(0, 0), (7, 3), (1919, 1079)] {
            for spp in [1, 2, 3, 16, 100, 1000] {
                for index in [0, 1, spp / 2, spp - 1] {
                    samplers.push(PixelSampler::new(x, y, index, spp, u64::from(x) + 5));
                }
            }
            for index in [0, 15, 16, 31, 200, 4095] {
                samplers.push(PixelSampler::nested(x, y, index, 3));
            }
        }
        for mut sampler in samplers {
            for vertex in 0..4 {
                let mut one_at_a_time = sampler.clone();
                let expected = VertexSamples {
                    mix: one_at_a_time.get_1d(),
                    light_select: one_at_a_time.get_1d(),
                    light: one_at_a_time.get_2d(),
                    lobe: one_at_a_time.get_1d(),
                    bsdf: one_at_a_time.get_2d(),
                    roulette: one_at_a_time.get_1d(),
                };
                let lanes = sampler.clone().vertex_lanes();
                assert_eq!(lanes.draw_lanes(), lanes.draw());
                assert_eq!(
                    sampler.get_vertex(),
                    expected,
                    "{sampler:?} vertex {vertex}"
                );
                // The next dimensions are where they were.
                assert_eq!(sampler.clone().get_2d(), one_at_a_time.get_2d());
            }
        }
    }
}
