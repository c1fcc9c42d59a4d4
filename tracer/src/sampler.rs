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
//! pixel's lens positions are stratified together with its film positions (depth of field
//! at 16 spp: 3% less squared error, the same film positions).
//!
//! Where the indices are permuted depends on how the samples are used. A uniform render takes
//! all `spp` samples of a pixel, so they are permuted over `[0, spp)`. An adaptive render
//! stops a pixel after any round, so every prefix it may stop at must be stratified on its
//! own: its samples are permuted only within the dyadic blocks `[0, 16)`, `[16, 32)`,
//! `[32, 64)`, ... (see [`PixelSampler::nested`]), each of which holds the Sobol points of an
//! elementary net, so the first 16 x 2^k samples are the first 16 x 2^k Sobol points. (Permuted
//! over the whole `[0, spp)`, a pixel stopped at n samples had a random subset of the points
//! and an error falling like independent sampling's: 1.6x the squared error of a stratified
//! prefix, measured on Captain Falcon and metal-mario-bg1.)

use glam::Vec2;

use crate::lanes::{Lanes, Mask, U32Lanes, MAX_LANES};
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
        for p in &params.params {
            params.ignore(&p.name);
        }
        Ok(Self {
            pixel_samples: (n > 0).then_some(n as u32),
            requested: ty,
        })
    }
}

const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// The sample stream of one pixel sample.
#[derive(Clone, Debug)]
pub struct PixelSampler {
    pixel_hash: u64,
    index: u32,
    /// The indices are permuted over `first..first + len`, which holds `index`.
    first: u32,
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
    fn sobol_index_of<U: U32Lanes>(&self, offset: U, p: u32) -> U {
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
    // Inlined into the render loop (with the pilot a second caller, the compiler kept it and
    // get_vertex a call away: depth of field 2.6% slower).
    #[inline(always)]
    pub fn get_camera(&mut self) -> (Vec2, Vec2) {
        let film_hash = self.next_dimension_hash();
        let lens_hash = self.next_dimension_hash();
        let index = self.sobol_index(film_hash as u32);
        let (film, lens) = camera_point(index, film_hash, lens_hash);
        (Vec2::from(film), Vec2::from(lens))
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

    fn next_dimension_hash(&mut self) -> u64 {
        let hash = mix64(self.pixel_hash ^ self.dimension_key);
        self.dimension_key = self.dimension_key.wrapping_add(DIMENSION_STEP);
        hash
    }
}

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
        PixelSampler {
            index: self.pixel.index + lane as u32,
            ..self.pixel.clone()
        }
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

/// Sobol point `index` of a 1D dimension whose hash is `hash`, Owen-scrambled by the hash.
#[inline(always)]
fn point_1d<U: U32Lanes>(index: U, hash: u64) -> U::F {
    to_unit_float(owen_scramble(
        van_der_corput(index),
        U::splat((hash >> 32) as u32),
    ))
}

/// Sobol point `index` of a 2D dimension whose hash is `hash` (Sobol dimensions 0 and 1), each
/// coordinate Owen-scrambled by its own part of the hash.
#[inline(always)]
fn point_2d_lanes<U: U32Lanes>(index: U, hash: u64) -> [U::F; 2] {
    [
        point_1d(index, hash),
        to_unit_float(owen_scramble(
            sobol_dimension_1(index),
            U::splat(mix64(hash) as u32),
        )),
    ]
}

fn point_2d(index: u32, hash: u64) -> Vec2 {
    Vec2::from(point_2d_lanes(index, hash))
}

/// [`PixelSampler::get_camera`]'s film and lens positions of Sobol index `index`.
#[inline(always)]
fn camera_point<U: U32Lanes>(index: U, film_hash: u64, lens_hash: u64) -> ([U::F; 2], [U::F; 2]) {
    let lens = [
        to_unit_float(owen_scramble(
            generated(index, &SOBOL_DIMENSION_2),
            U::splat((lens_hash >> 32) as u32),
        )),
        to_unit_float(owen_scramble(
            generated(index, &SOBOL_DIMENSION_3),
            U::splat(mix64(lens_hash) as u32),
        )),
    ];
    (point_2d_lanes(index, film_hash), lens)
}

/// A 64-bit finaliser (splitmix64): every input bit affects every output bit.
pub fn mix64(mut v: u64) -> u64 {
    v ^= v >> 30;
    v = v.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    v ^= v >> 27;
    v = v.wrapping_mul(0x94d0_49bb_1331_11eb);
    v ^ (v >> 31)
}

#[inline(always)]
fn to_unit_float<U: U32Lanes>(bits: U) -> U::F {
    ((bits >> 8).to_f32() * U::F::splat(1.0 / 16_777_216.0)).min(U::F::splat(ONE_MINUS_EPSILON))
}

/// Sobol dimension 0: the base-2 radical inverse, as a 0.32 fixed-point fraction.
#[inline(always)]
fn van_der_corput<U: U32Lanes>(index: U) -> U {
    index.reverse_bits()
}

/// Sobol dimension 1 (primitive polynomial x + 1), as a 0.32 fixed-point fraction.
#[inline(always)]
fn sobol_dimension_1<U: U32Lanes>(index: U) -> U {
    pascal_parity(index).reverse_bits()
}

/// Sobol dimension 2: primitive polynomial x^2 + x + 1, initial direction integers 1, 3.
const SOBOL_DIMENSION_2: [u32; 32] = generator_columns(2, 0b1, [1, 3, 0]);

/// Sobol dimension 3: primitive polynomial x^3 + x + 1, initial direction integers 1, 3, 1.
const SOBOL_DIMENSION_3: [u32; 32] = generator_columns(3, 0b01, [1, 3, 1]);

/// The columns of a Sobol dimension's generator matrix as 0.32 fractions (column k is
/// direction integer m_k / 2^(k+1)), from its primitive polynomial of `degree` whose inner
/// coefficients are the bits of `inner` (highest power first) and its first `degree` direction
/// integers `m`. Bratley and Fox's recurrence: m_k = 2 a_1 m_(k-1) ^ 4 a_2 m_(k-2) ^ ... ^
/// 2^degree m_(k-degree) ^ m_(k-degree).
const fn generator_columns(degree: usize, inner: u32, m: [u32; 3]) -> [u32; 32] {
    let mut direction = [0u32; 32];
    let mut columns = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        direction[k] = if k < degree {
            m[k]
        } else {
            let oldest = direction[k - degree];
            let mut v = oldest ^ (oldest << degree);
            let mut j = 1;
            while j < degree {
                if (inner >> (degree - 1 - j)) & 1 == 1 {
                    v ^= direction[k - j] << j;
                }
                j += 1;
            }
            v
        };
        columns[k] = direction[k] << (31 - k);
        k += 1;
    }
    columns
}

/// Point `index` of the Sobol dimension whose generator matrix has `columns`: the columns of
/// the index's set bits, added in GF(2) (each lane's, over the bits set in any lane).
#[inline(always)]
fn generated<U: U32Lanes>(index: U, columns: &[u32; 32]) -> U {
    let one = U::splat(1);
    let mut x = U::splat(0);
    let mut bits = index.any_lane_bits();
    while bits != 0 {
        let k = bits.trailing_zeros();
        // The column times the lane's bit k (0 or 1).
        x = x ^ ((index >> k) & one).wrapping_mul(U::splat(columns[k as usize]));
        bits &= bits - 1;
    }
    x
}

/// Sobol dimension 1 with its bits reversed. Its generator matrix is Pascal's triangle mod 2:
/// fraction bit k is the parity of the index bits i with C(i, k) odd, which by Lucas' theorem
/// are the i whose bits include k's. That sum over supersets takes five masked shifts, one per
/// bit of a bit position, and no branches.
#[inline(always)]
fn pascal_parity<U: U32Lanes>(index: U) -> U {
    let mut x = index;
    for (shift, mask) in [
        (1, 0x5555_5555),
        (2, 0x3333_3333),
        (4, 0x0f0f_0f0f),
        (8, 0x00ff_00ff),
        (16, 0x0000_ffff),
    ] {
        x = x ^ ((x >> shift) & U::splat(mask));
    }
    x
}

/// Hash-based nested uniform (Owen) scrambling of a 0.32 fraction (Burley 2020, "Practical
/// Hash-based Owen Scrambling"): a Laine-Karras style permutation on the reversed bits.
#[inline(always)]
fn owen_scramble<U: U32Lanes>(v: U, seed: U) -> U {
    laine_karras(v.reverse_bits(), seed).reverse_bits()
}

/// [`owen_scramble`]'s permutation, on and to reversed bits.
#[inline(always)]
fn laine_karras<U: U32Lanes>(mut x: U, seed: U) -> U {
    x = x ^ x.wrapping_mul(U::splat(0x3d20_adea));
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | U::splat(1));
    x = x ^ x.wrapping_mul(U::splat(0x0552_6c56));
    x ^ x.wrapping_mul(U::splat(0x53a2_2864))
}

/// The least all-ones mask covering 0..len, which [`permutation_element`] cycles within.
fn permutation_mask(len: u32) -> u32 {
    u32::MAX
        .checked_shr(len.saturating_sub(1).leading_zeros())
        .unwrap_or(0)
}

/// Element `i` of a pseudo-random permutation of 0..len chosen by `p` (Kensler 2013,
/// "Correlated Multi-Jittered Sampling"); `w` is [`permutation_mask`] of `len`. A bijection on
/// 0..len for every p.
#[inline(always)]
fn permutation_element<U: U32Lanes>(i: U, len: u32, w: u32, p: U) -> U {
    if len <= 1 {
        return U::splat(0);
    }
    let w = U::splat(w);
    permutation_offset(walk_below(permutation_round(i, w, p), len, w, p), len, p)
}

/// One round of [`permutation_element`]'s hash: a bijection on 0..=w.
#[inline(always)]
fn permutation_round<U: U32Lanes>(mut i: U, w: U, p: U) -> U {
    let k = U::splat;
    i = i ^ p;
    i = i.wrapping_mul(k(0xe170_893d));
    i = i ^ (p >> 16);
    i = i ^ ((i & w) >> 4);
    i = i ^ (p >> 8);
    i = i.wrapping_mul(k(0x0929_eb3f));
    i = i ^ (p >> 23);
    i = i ^ ((i & w) >> 1);
    i = i.wrapping_mul(k(1) | (p >> 27));
    i = i.wrapping_mul(k(0x6935_fa69));
    i = i ^ ((i & w) >> 11);
    i = i.wrapping_mul(k(0x74dc_b303));
    i = i ^ ((i & w) >> 2);
    i = i.wrapping_mul(k(0x9e50_1cc3));
    i = i ^ ((i & w) >> 2);
    i = i.wrapping_mul(k(0xc860_a3df));
    i = i & w;
    i ^ (i >> 5)
}

/// Cycle walking: more rounds from the first round's `i` until it falls in 0..len.
#[inline(always)]
fn walk_below<U: U32Lanes>(mut i: U, len: u32, w: U, p: U) -> U {
    loop {
        let over = i.at_least(U::splat(len));
        if !over.any() {
            return i;
        }
        i = U::select(over, permutation_round(i, w, p), i);
    }
}

/// The walk's end rotated by `p` within 0..len.
#[inline(always)]
fn permutation_offset<U: U32Lanes>(i: U, len: u32, p: U) -> U {
    // The common power-of-two sample counts need no division.
    if len.is_power_of_two() {
        i.wrapping_add(p) & U::splat(len - 1)
    } else {
        i.wrapping_add(p).remainder(len)
    }
}

/// The values a scattering vertex draws with [`PixelSampler::get_vertex`].
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

    /// Lane `i` of a packet draws what sample `index + i` draws alone, for power-of-two and
    /// other sample counts (whose permutations cycle-walk), on every lane type.
    fn packet_draws_equal_the_pixel_draws<L: Lanes>() {
        let lane = |v: L, i: usize| {
            let mut out = [0.0; MAX_LANES];
            v.store(&mut out);
            out[i]
        };
        // (x, y, spp, seed), spp 0 for nested samples.
        let runs = [
            (0, 0, 16, 0),
            (7, 3, 48, 5),
            (1919, 1079, 256, 9),
            (5, 6, 0, 2),
        ];
        for (x, y, spp, seed) in runs {
            let samples = if spp == 0 { 64 } else { spp };
            for index in (0..samples).step_by(L::N) {
                let new_alone = |i| match spp {
                    0 => PixelSampler::nested(x, y, i, seed),
                    _ => PixelSampler::new(x, y, i, spp, seed),
                };
                let mut packet = match spp {
                    0 => PacketSampler::<L>::nested(x, y, index, seed),
                    _ => PacketSampler::<L>::new(x, y, index, spp, seed),
                };
                let (film, lens) = packet.get_camera();
                let vertices = [packet.get_vertex(), packet.get_vertex()];
                let mut branch = packet.branch(2);
                let (branch_lobes, branch_dirs) = branch.get_split_draws::<4>(3);
                let streams: Vec<_> = (0..L::N).map(|i| packet.lane(i)).collect();
                let after = packet.get_2d();
                for (i, stream) in streams.into_iter().enumerate() {
                    let mut alone = new_alone(index + i as u32);
                    let both = |v: [L; 2]| Vec2::new(lane(v[0], i), lane(v[1], i));
                    let at = format!("pixel ({x}, {y}) sample {} of {spp}", index + i as u32);
                    assert_eq!((both(film), both(lens)), alone.get_camera(), "{at}");
                    for v in vertices {
                        let drawn = VertexSamples {
                            mix: lane(v.mix, i),
                            light_select: lane(v.light_select, i),
                            light: both(v.light),
                            lobe: lane(v.lobe, i),
                            bsdf: both(v.bsdf),
                            roulette: lane(v.roulette, i),
                        };
                        assert_eq!(drawn, alone.get_vertex(), "{at}");
                    }
                    let (lobes, dirs) = alone.branch(2).get_split_draws::<4>(3);
                    for k in 0..4 {
                        assert_eq!(lane(branch_lobes[k], i), lobes[k], "{at}: split lobe {k}");
                        assert_eq!(both(branch_dirs[k]), dirs[k], "{at}: split direction {k}");
                    }
                    assert_eq!(stream.clone().get_2d(), alone.clone().get_2d(), "{at}");
                    assert_eq!(both(after), alone.get_2d(), "{at}");
                }
            }
        }
    }

    #[test]
    fn packets_draw_each_samples_own_values() {
        struct PacketDraws;
        impl crate::lanes::tests::OnLanes for PacketDraws {
            fn run<L: Lanes>(&self) {
                packet_draws_equal_the_pixel_draws::<L>();
            }
        }
        crate::lanes::tests::on_every_lane_type(&PacketDraws);
    }

    /// After a vertex that used only its mix choice, the next draws are those that follow a
    /// single `get_1d`.
    #[test]
    fn unread_vertex_dimensions_are_drawn_again() {
        let start = PixelSampler::new(3, 4, 5, 16, 9);
        let mut vertex = start.clone();
        let mix = vertex.get_vertex().mix;
        vertex.unread_after_mix();
        let mut one = start.clone();
        assert_eq!(mix, one.get_1d());
        assert_eq!(vertex.get_vertex(), one.get_vertex());
    }

    #[test]
    fn permutation_masks_cover_the_range_with_the_fewest_bits() {
        for (len, mask) in [(0, 0), (1, 0), (2, 1), (3, 3), (7, 7), (64, 63), (65, 127)] {
            assert_eq!(permutation_mask(len), mask, "len {len}");
        }
        assert_eq!(permutation_mask(u32::MAX), u32::MAX);
    }

    #[test]
    fn permutation_is_a_bijection() {
        for len in [1u32, 2, 7, 64, 100, 1000] {
            for p in [0u32, 1, 0xdead_beef] {
                let mut seen = vec![false; len as usize];
                for i in 0..len {
                    let j = permutation_element(i, len, permutation_mask(len), p) as usize;
                    assert!(!seen[j], "len {len} p {p}: {j} twice");
                    seen[j] = true;
                }
            }
        }
    }

    /// The branch-free form equals the definition by direction numbers (the recurrence of
    /// x + 1 from m_1 = 1: v1 = 1/2, v(k+1) = v(k) xor v(k)/2), the value the xor of the v(k)
    /// of the index's set bits: the Pascal-triangle parity and `generator_columns` agree.
    #[test]
    fn sobol_dimension_1_matches_its_direction_numbers() {
        let columns = generator_columns(1, 0, [1, 0, 0]);
        let by_direction_numbers = |index: u32| generated(index, &columns);
        let mut state = 1u64;
        let indices = (0..4096u32).chain((0..4096).map(|_| {
            state = mix64(state);
            state as u32
        }));
        for index in indices.chain([u32::MAX]) {
            assert_eq!(
                sobol_dimension_1(index),
                by_direction_numbers(index),
                "index {index:#x}"
            );
        }
    }

    #[test]
    fn samples_are_deterministic_and_in_range() {
        let draw = |x, y, i| {
            let mut s = PixelSampler::new(x, y, i, 64, 7);
            (s.get_2d(), s.get_1d(), s.get_2d())
        };
        assert_eq!(draw(3, 4, 5), draw(3, 4, 5));
        assert_ne!(draw(3, 4, 5), draw(4, 3, 5));
        for i in 0..64 {
            let (a, b, c) = draw(10, 20, i);
            for v in [a.x, a.y, b, c.x, c.y] {
                assert!((0.0..1.0).contains(&v));
            }
        }
    }

    /// Every 2D pair of a pixel's 64 samples puts exactly one sample in each cell of an 8x8
    /// grid: the Sobol (0,2)-sequence property survives permutation and Owen scrambling.
    #[test]
    fn pixel_samples_are_stratified_in_each_2d_pair() {
        for pair in 0..4 {
            let mut cells = [0u32; 64];
            for i in 0..64 {
                let mut s = PixelSampler::new(5, 9, i, 64, 1);
                for _ in 0..pair {
                    s.get_2d();
                }
                let u = s.get_2d();
                cells[(u.y * 8.0) as usize * 8 + (u.x * 8.0) as usize] += 1;
            }
            assert!(cells.iter().all(|&c| c == 1), "pair {pair}: {cells:?}");
        }
    }

    /// The generator matrices' first columns are the direction integers the recurrence gives
    /// by hand: 1, 3, 3, 9, 29 (x^2 + x + 1) and 1, 3, 1, 5, 31, 29 (x^3 + x + 1).
    #[test]
    fn sobol_dimensions_2_and_3_follow_their_recurrences() {
        let expect =
            |m: &[u32]| -> Vec<u32> { m.iter().enumerate().map(|(k, &m)| m << (31 - k)).collect() };
        assert_eq!(SOBOL_DIMENSION_2[..5], expect(&[1, 3, 3, 9, 29]));
        assert_eq!(SOBOL_DIMENSION_3[..6], expect(&[1, 3, 1, 5, 31, 29]));
        // Column k ends at fraction bit k (odd direction integers): the matrix is triangular
        // with a full diagonal, so each 2^k points take each of 2^k values once.
        for columns in [SOBOL_DIMENSION_2, SOBOL_DIMENSION_3] {
            for (k, c) in columns.iter().enumerate() {
                assert_eq!(c.trailing_zeros() as usize, 31 - k, "{columns:x?}");
            }
        }
        assert_eq!(generated(0b101, &SOBOL_DIMENSION_2), (1 << 31) ^ (3 << 29));
    }

    /// The camera's draw: its film position is `get_2d`'s; 16 samples of a pixel put one point
    /// in each of the 16 cells halving all four coordinates (two padded pairs do not), and 16,
    /// 64 or 256 put one in each cell of the square grids pairing the lens's first coordinate
    /// with either film coordinate; for a uniform pixel and the prefixes an adaptive render
    /// may stop at.
    #[test]
    fn camera_samples_stratify_film_and_lens_together() {
        let sampler = |nested: bool, i: u32, n: u32| {
            if nested {
                PixelSampler::nested(3, 4, i, 11)
            } else {
                PixelSampler::new(3, 4, i, n, 11)
            }
        };
        let one_per_cell = |points: &[[f32; 4]], cells_per_axis: [u32; 4]| {
            let mut seen = std::collections::HashSet::new();
            points.iter().all(|p| {
                seen.insert(std::array::from_fn::<u32, 4, _>(|k| {
                    (p[k] * cells_per_axis[k] as f32) as u32
                }))
            })
        };
        for nested in [true, false] {
            for (n, side) in [(16u32, 4u32), (64, 8), (256, 16)] {
                let points: Vec<[f32; 4]> = (0..n)
                    .map(|i| {
                        let (film, lens) = sampler(nested, i, n).get_camera();
                        assert_eq!(film, sampler(nested, i, n).get_2d());
                        [film.x, film.y, lens.x, lens.y]
                    })
                    .collect();
                assert!(
                    one_per_cell(&points, [side, 1, side, 1]),
                    "{n}: film x, lens x"
                );
                assert!(
                    one_per_cell(&points, [1, side, side, 1]),
                    "{n}: film y, lens x"
                );
                if n == 16 {
                    assert!(one_per_cell(&points, [2; 4]), "nested {nested}: 4D");
                    let padded: Vec<[f32; 4]> = (0..n)
                        .map(|i| {
                            let mut s = sampler(nested, i, n);
                            let (film, lens) = (s.get_2d(), s.get_2d());
                            [film.x, film.y, lens.x, lens.y]
                        })
                        .collect();
                    assert!(!one_per_cell(&padded, [2; 4]));
                }
            }
        }
    }

    /// Every prefix of a nested pixel's samples that an adaptive render may stop at (16, 32,
    /// 64, 128, 256) puts one sample in each elementary interval of its size in every 2D pair:
    /// checked on the square grids (4x4, 8x8, 16x16) and the 2:1 ones (8x4, 16x8).
    #[test]
    fn nested_prefixes_are_stratified_in_each_2d_pair() {
        for (n, cols, rows) in [
            (16u32, 4u32, 4u32),
            (32, 8, 4),
            (64, 8, 8),
            (128, 16, 8),
            (256, 16, 16),
        ] {
            for pair in 0..3 {
                let mut cells = vec![0u32; n as usize];
                for i in 0..n {
                    let mut s = PixelSampler::nested(3, 4, i, 11);
                    for _ in 0..pair {
                        s.get_2d();
                    }
                    let u = s.get_2d();
                    let cell = (u.y * rows as f32) as u32 * cols + (u.x * cols as f32) as u32;
                    cells[cell as usize] += 1;
                }
                assert!(
                    cells.iter().all(|&c| c == 1),
                    "n {n} pair {pair}: {cells:?}"
                );
            }
        }
    }

    /// A split draw's values: each sample's eight are stratified among themselves, and all of
    /// a pixel's 16 x 8 together, as 128 samples of a 2D pair (or a 1D dimension) would be.
    #[test]
    fn split_draws_are_stratified_alone_and_together() {
        const N: usize = 8;
        let spp = 16;
        let (mut all_2d, mut all_1d) = ([0u32; 128], [0u32; 128]);
        for i in 0..spp {
            let mut s = PixelSampler::new(5, 9, i, spp, 3);
            s.get_2d();
            let (values, points) = s.get_split_draws::<N>(N);
            let (mut own_2d, mut own_1d) = ([0u32; N], [0u32; N]);
            for (v, u) in values.into_iter().zip(points) {
                own_1d[(v * 8.0) as usize] += 1;
                own_2d[(u.y * 2.0) as usize * 4 + (u.x * 4.0) as usize] += 1;
                all_1d[(v * 128.0) as usize] += 1;
                all_2d[(u.y * 8.0) as usize * 16 + (u.x * 16.0) as usize] += 1;
            }
            assert!(own_1d.iter().chain(&own_2d).all(|&c| c == 1), "sample {i}");
        }
        assert!(all_1d.iter().chain(&all_2d).all(|&c| c == 1));
    }

    /// A draw of 2 of at most 4 (a path branching in two): each sample's two values lie in
    /// the two halves, a pixel's 16 x 2 together one in each 32nd (and each 8x4 cell of the
    /// square for the directions), and the values past the two are zero.
    #[test]
    fn split_draws_of_fewer_than_their_most_are_stratified() {
        let (mut all_1d, mut all_2d) = ([0u32; 32], [0u32; 32]);
        for i in 0..16 {
            let (values, points) = PixelSampler::new(3, 4, i, 16, 7).get_split_draws::<4>(2);
            assert_eq!(values[2..], [0.0; 2]);
            assert_eq!(points[2..], [Vec2::ZERO; 2]);
            assert_ne!(
                (values[0] * 2.0) as u32,
                (values[1] * 2.0) as u32,
                "sample {i}"
            );
            for (v, u) in values[..2].iter().zip(&points[..2]) {
                all_1d[(v * 32.0) as usize] += 1;
                all_2d[(u.y * 4.0) as usize * 8 + (u.x * 8.0) as usize] += 1;
            }
        }
        assert_eq!(all_1d, [1; 32]);
        assert_eq!(all_2d, [1; 32]);
    }

    /// A branch's stream is the same for the same branch, differs from the path's own and from
    /// another branch's in every dimension, and is stratified over a pixel's samples.
    #[test]
    fn branch_streams_are_their_own() {
        let sampler = PixelSampler::new(3, 4, 5, 16, 7);
        let draw = |mut s: PixelSampler| [s.get_1d(), s.get_2d().x, s.get_2d().y, s.get_1d()];
        assert_eq!(draw(sampler.branch(1)), draw(sampler.branch(1)));
        let (own, one, two) = (
            draw(sampler.clone()),
            draw(sampler.branch(1)),
            draw(sampler.branch(2)),
        );
        for d in 0..4 {
            assert!(
                own[d] != one[d] && one[d] != two[d] && own[d] != two[d],
                "{d}"
            );
        }
        let mut strata = [0; 16];
        for i in 0..16 {
            let mut branch = PixelSampler::new(3, 4, i, 16, 7).branch(1);
            branch.get_1d();
            strata[(branch.get_1d() * 16.0) as usize] += 1;
        }
        assert_eq!(strata, [1; 16]);
    }

    /// Integrating a smooth function with 256 stratified samples beats independent random
    /// sampling's expected error by a wide margin.
    #[test]
    fn stratified_estimate_is_accurate() {
        let f = |u: Vec2| libm::sinf(u.x * 3.0) * libm::cosf(u.y * 2.0) + u.x * u.y;
        let exact = (1.0 - libm::cosf(3f32)) / 3.0 * (libm::sinf(2f32) / 2.0) + 0.25;
        let n = 256;
        let mean: f32 = (0..n)
            .map(|i| f(PixelSampler::new(1, 2, i, n, 3).get_2d()))
            .sum::<f32>()
            / n as f32;
        // Independent sampling would have a standard error of about 0.02 here.
        assert!((mean - exact).abs() < 2e-3, "{mean} vs {exact}");
    }
}
