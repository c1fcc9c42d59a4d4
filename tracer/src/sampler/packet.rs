//! The streams of a packet's consecutive samples of one pixel, drawn in lanes.

use glam::Vec2;

use super::pixel::{PixelSampler, VertexSamples, NESTED_FIRST_BLOCK};
use super::sobol::{camera_point, point_1d, point_2d_lanes};
use crate::lanes::{Lanes, U32Lanes, MAX_LANES};

/// The streams of `L::N` consecutive samples of one pixel, drawn together: lane `i` is sample
/// `index + i` of [`PixelSampler::new`], and draws its values bit for bit. The dimensions'
/// hashes are the pixel's, so each is computed once for all lanes. For a renderer that runs
/// paths in lanes (`bench/lanes` measures one).
#[derive(Clone)]
pub struct PacketSampler<L: Lanes> {
    /// The first lane's stream: the pixel's hash, permutation range and next dimension.
    pixel: PixelSampler,
    /// Each lane's index less the permutation range's first.
    offset: L::U,
}

/// The values a scattering vertex draws, as [`VertexSamples`], for a packet's lanes.
#[derive(Clone, Copy)]
pub struct VertexPacket<L> {
    pub mix: L,
    pub light_select: L,
    pub light: [L; 2],
    pub lobe: L,
    pub bsdf: [L; 2],
    pub roulette: L,
}

impl<L: Lanes> VertexPacket<L> {
    /// Each lane's values (lanes past `L::N` are zero).
    #[inline(always)]
    pub fn by_lane(&self) -> [VertexSamples; MAX_LANES] {
        let (mix, light_select) = (self.mix.values(), self.light_select.values());
        let light = [self.light[0].values(), self.light[1].values()];
        let (lobe, roulette) = (self.lobe.values(), self.roulette.values());
        let bsdf = [self.bsdf[0].values(), self.bsdf[1].values()];
        let mut out = [VertexSamples::default(); MAX_LANES];
        for (i, v) in out.iter_mut().enumerate() {
            *v = VertexSamples {
                mix: mix[i],
                light_select: light_select[i],
                light: Vec2::new(light[0][i], light[1][i]),
                lobe: lobe[i],
                bsdf: Vec2::new(bsdf[0][i], bsdf[1][i]),
                roulette: roulette[i],
            };
        }
        out
    }
}

impl<L: Lanes> PacketSampler<L> {
    /// Samples `index .. index + L::N` of a pixel that takes all of `spp` samples
    /// (`index + L::N <= spp`).
    pub fn new(x: u32, y: u32, index: u32, spp: u32, seed: u64) -> Self {
        debug_assert!(
            index as usize + L::N <= spp.max(1) as usize,
            "lanes past spp"
        );
        Self::of(PixelSampler::new(x, y, index, spp, seed))
    }

    /// Samples `index .. index + L::N` of [`PixelSampler::nested`] (`index` a multiple of
    /// `L::N`, which divides [`NESTED_FIRST_BLOCK`]: the lanes share a permutation range).
    pub fn nested(x: u32, y: u32, index: u32, seed: u64) -> Self {
        debug_assert!(
            (index as usize).is_multiple_of(L::N)
                && (NESTED_FIRST_BLOCK as usize).is_multiple_of(L::N),
            "lanes across nested blocks"
        );
        Self::of(PixelSampler::nested(x, y, index, seed))
    }

    /// The packet whose first lane is `pixel`.
    fn of(pixel: PixelSampler) -> Self {
        let index = pixel.index;
        let mut offsets = [0; MAX_LANES];
        for (lane, offset) in offsets.iter_mut().enumerate() {
            *offset = (index - pixel.first).wrapping_add(lane as u32);
        }
        Self {
            pixel,
            offset: L::U::load(&offsets),
        }
    }

    #[inline(always)]
    fn sobol_index(&self, p: u32) -> L::U {
        self.pixel.sobol_index_of(self.offset, p)
    }

    /// Lane `lane`'s own stream, at the packet's next dimension: where a path that leaves the
    /// packet goes on.
    pub fn lane(&self, lane: usize) -> PixelSampler {
        self.pixel.sample_at(self.pixel.index + lane as u32)
    }

    /// [`PixelSampler::branch`] of every lane.
    pub fn branch(&self, k: u32) -> Self {
        Self {
            pixel: self.pixel.branch(k),
            offset: self.offset,
        }
    }

    /// [`PixelSampler::get_split_draws`] in every lane.
    #[inline(always)]
    pub fn get_split_draws<const N: usize>(&mut self, n: usize) -> ([L; N], [[L; 2]; N]) {
        let n = n.min(N);
        let lobe_hash = self.pixel.next_dimension_hash();
        let dir_hash = self.pixel.next_dimension_hash();
        let count = L::U::splat(n as u32);
        let lobe_first = self.sobol_index(lobe_hash as u32).wrapping_mul(count);
        let dir_first = self.sobol_index(dir_hash as u32).wrapping_mul(count);
        // Loops, not `from_fn`: a closure would not inherit an AVX2 caller's target features.
        let zero = L::splat(0.0);
        let (mut lobes, mut dirs) = ([zero; N], [[zero; 2]; N]);
        for i in 0..n {
            let step = L::U::splat(i as u32);
            lobes[i] = point_1d(lobe_first.wrapping_add(step), lobe_hash);
            dirs[i] = point_2d_lanes(dir_first.wrapping_add(step), dir_hash);
        }
        (lobes, dirs)
    }

    /// [`PixelSampler::get_1d`] in every lane.
    #[inline(always)]
    pub fn get_1d(&mut self) -> L {
        let hash = self.pixel.next_dimension_hash();
        point_1d(self.sobol_index(hash as u32), hash)
    }

    /// [`PixelSampler::get_2d`] in every lane.
    #[inline(always)]
    pub fn get_2d(&mut self) -> [L; 2] {
        let hash = self.pixel.next_dimension_hash();
        point_2d_lanes(self.sobol_index(hash as u32), hash)
    }

    /// [`PixelSampler::get_camera`] in every lane.
    #[inline(always)]
    pub fn get_camera(&mut self) -> ([L; 2], [L; 2]) {
        let film_hash = self.pixel.next_dimension_hash();
        let lens_hash = self.pixel.next_dimension_hash();
        camera_point(self.sobol_index(film_hash as u32), film_hash, lens_hash)
    }

    /// [`PixelSampler::get_vertex`] in every lane.
    #[inline(always)]
    pub fn get_vertex(&mut self) -> VertexPacket<L> {
        VertexPacket {
            mix: self.get_1d(),
            light_select: self.get_1d(),
            light: self.get_2d(),
            lobe: self.get_1d(),
            bsdf: self.get_2d(),
            roulette: self.get_1d(),
        }
    }
}
