//! The low-discrepancy primitives the samplers are written over, once for one value or a lane
//! type's several: Sobol points (dimensions 0 to 3), Owen scrambling (Laine-Karras), index
//! permutations by cycle-walking, and the hash that keys them.

use glam::Vec2;

use crate::lanes::{Lanes, Mask, U32Lanes};

/// The largest f32 below 1: a sample stays in [0, 1).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

#[inline(always)]
pub(super) fn point_1d<U: U32Lanes>(index: U, hash: u64) -> U::F {
    to_unit_float(owen_scramble(
        van_der_corput(index),
        U::splat((hash >> 32) as u32),
    ))
}

/// Sobol point `index` of a 2D dimension whose hash is `hash` (Sobol dimensions 0 and 1), each
/// coordinate Owen-scrambled by its own part of the hash.
#[inline(always)]
pub(super) fn point_2d_lanes<U: U32Lanes>(index: U, hash: u64) -> [U::F; 2] {
    [
        point_1d(index, hash),
        to_unit_float(owen_scramble(
            sobol_dimension_1(index),
            U::splat(mix64(hash) as u32),
        )),
    ]
}

pub(super) fn point_2d(index: u32, hash: u64) -> Vec2 {
    Vec2::from(point_2d_lanes(index, hash))
}

/// [`PixelSampler::get_camera`]'s film and lens positions of Sobol index `index`.
#[inline(always)]
pub(super) fn camera_point<U: U32Lanes>(
    index: U,
    film_hash: u64,
    lens_hash: u64,
) -> ([U::F; 2], [U::F; 2]) {
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
pub(super) fn to_unit_float<U: U32Lanes>(bits: U) -> U::F {
    ((bits >> 8).to_f32() * U::F::splat(1.0 / 16_777_216.0)).min(U::F::splat(ONE_MINUS_EPSILON))
}

/// Sobol dimension 0: the base-2 radical inverse, as a 0.32 fixed-point fraction.
#[inline(always)]
pub(super) fn van_der_corput<U: U32Lanes>(index: U) -> U {
    index.reverse_bits()
}

/// Sobol dimension 1 (primitive polynomial x + 1), as a 0.32 fixed-point fraction.
#[inline(always)]
pub(super) fn sobol_dimension_1<U: U32Lanes>(index: U) -> U {
    pascal_parity(index).reverse_bits()
}

/// Sobol dimension 2: primitive polynomial x^2 + x + 1, initial direction integers 1, 3.
pub(super) const SOBOL_DIMENSION_2: [u32; 32] = generator_columns(2, 0b1, [1, 3, 0]);

/// Sobol dimension 3: primitive polynomial x^3 + x + 1, initial direction integers 1, 3, 1.
pub(super) const SOBOL_DIMENSION_3: [u32; 32] = generator_columns(3, 0b01, [1, 3, 1]);

/// The columns of a Sobol dimension's generator matrix as 0.32 fractions (column k is
/// direction integer m_k / 2^(k+1)), from its primitive polynomial of `degree` whose inner
/// coefficients are the bits of `inner` (highest power first) and its first `degree` direction
/// integers `m`. Bratley and Fox's recurrence: m_k = 2 a_1 m_(k-1) ^ 4 a_2 m_(k-2) ^ ... ^
/// 2^degree m_(k-degree) ^ m_(k-degree).
pub(super) const fn generator_columns(degree: usize, inner: u32, m: [u32; 3]) -> [u32; 32] {
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
pub(super) fn generated<U: U32Lanes>(index: U, columns: &[u32; 32]) -> U {
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
pub(super) fn pascal_parity<U: U32Lanes>(index: U) -> U {
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
pub(super) fn owen_scramble<U: U32Lanes>(v: U, seed: U) -> U {
    laine_karras(v.reverse_bits(), seed).reverse_bits()
}

/// [`owen_scramble`]'s permutation, on and to reversed bits.
#[inline(always)]
pub(super) fn laine_karras<U: U32Lanes>(mut x: U, seed: U) -> U {
    x = x ^ x.wrapping_mul(U::splat(0x3d20_adea));
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | U::splat(1));
    x = x ^ x.wrapping_mul(U::splat(0x0552_6c56));
    x ^ x.wrapping_mul(U::splat(0x53a2_2864))
}

/// The least all-ones mask covering 0..len, which [`permutation_element`] cycles within.
pub(super) fn permutation_mask(len: u32) -> u32 {
    u32::MAX
        .checked_shr(len.saturating_sub(1).leading_zeros())
        .unwrap_or(0)
}

/// Element `i` of a pseudo-random permutation of 0..len chosen by `p` (Kensler 2013,
/// "Correlated Multi-Jittered Sampling"); `w` is [`permutation_mask`] of `len`. A bijection on
/// 0..len for every p.
#[inline(always)]
pub(super) fn permutation_element<U: U32Lanes>(i: U, len: u32, w: u32, p: U) -> U {
    if len <= 1 {
        return U::splat(0);
    }
    let w = U::splat(w);
    permutation_offset(walk_below(permutation_round(i, w, p), len, w, p), len, p)
}

/// One round of [`permutation_element`]'s hash: a bijection on 0..=w.
#[inline(always)]
pub(super) fn permutation_round<U: U32Lanes>(mut i: U, w: U, p: U) -> U {
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
pub(super) fn walk_below<U: U32Lanes>(mut i: U, len: u32, w: U, p: U) -> U {
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
pub(super) fn permutation_offset<U: U32Lanes>(i: U, len: u32, p: U) -> U {
    // The common power-of-two sample counts need no division.
    if len.is_power_of_two() {
        i.wrapping_add(p) & U::splat(len - 1)
    } else {
        i.wrapping_add(p).remainder(len)
    }
}
