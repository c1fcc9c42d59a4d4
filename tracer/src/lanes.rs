//! Lane types: code written once over [`Lanes`] runs one value at a time (`f32`, with `u32`
//! integers) or several per instruction ([`Arr`], and on x86-64 AVX2's eight, which only code
//! run through [`Avx2Cpu`] gets: its operations are AVX2 instructions). Every operation is one
//! IEEE-exact or wrap-around operation per lane (add, subtract, multiply, divide, square root,
//! compare, select, integer multiply, shift, bit reversal; no fused multiply-add), so every lane
//! type gives the scalar type's bits, and a render that runs 8 paths per instruction on one
//! node and one at a time on another writes the same image (what it gains: `bench/lanes`).
//!
//! Code over an intrinsics type must be inlined into a function compiled with its target
//! features, chosen after run-time detection; helpers must be `#[inline(always)]` functions, not
//! closures (a closure does not inherit its caller's target features, and every intrinsic in it
//! becomes a call).

use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Not, Shr, Sub};

/// The widest lane type: buffers moving lanes in and out are this long.
pub const MAX_LANES: usize = 16;

pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    fn any(self) -> bool;
}

/// `N` lanes of `u32` with wrap-around arithmetic; `F` are as many lanes of `f32`.
pub trait U32Lanes:
    Copy
    + BitXor<Output = Self>
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + Shr<u32, Output = Self>
{
    type F: Lanes<U = Self, M = Self::M>;
    type M: Mask;
    fn splat(x: u32) -> Self;
    fn load(f: &[u32; MAX_LANES]) -> Self;
    fn store(self, out: &mut [u32; MAX_LANES]);
    fn wrapping_add(self, o: Self) -> Self;
    fn wrapping_mul(self, o: Self) -> Self;
    fn reverse_bits(self) -> Self;
    /// `self % d`, `d` > 0.
    fn remainder(self, d: u32) -> Self;
    /// The bits set in any lane.
    fn any_lane_bits(self) -> u32;
    fn equals(self, o: Self) -> Self::M;
    /// `self >= o`, unsigned.
    fn at_least(self, o: Self) -> Self::M;
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    /// As floats (values below 2^31).
    fn to_f32(self) -> Self::F;
}

/// `N` lanes of `f32`, with as many of `u32` ([`Lanes::U`]) and masks ([`Lanes::M`]).
pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    type M: Mask;
    type U: U32Lanes<F = Self, M = Self::M>;
    const N: usize;
    fn splat(x: f32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// Floor of values within +-2^31.
    fn floor(self) -> Self;
    fn lt(self, o: Self) -> Self::M;
    fn le(self, o: Self) -> Self::M;
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    fn mask(b: bool) -> Self::M;
    fn load(f: &[f32; MAX_LANES]) -> Self;
    fn store(self, out: &mut [f32; MAX_LANES]);
    /// `table[i]` for each lane's `i` (in range).
    fn gather(table: &[f32], index: Self::U) -> Self;
    /// Truncated to integers (values in 0..2^31).
    fn to_u32(self) -> Self::U;

    /// The lanes' values (past `N`: zeros).
    #[inline(always)]
    fn values(self) -> [f32; MAX_LANES] {
        let mut out = [0.0; MAX_LANES];
        self.store(&mut out);
        out
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Self::select(self.lt(o), self, o)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self::select(o.lt(self), self, o)
    }
}

#[inline(always)]
fn either<T>(m: bool, a: T, b: T) -> T {
    if m {
        a
    } else {
        b
    }
}

/// Floor of `x` within +-2^31 by truncation (baseline x86-64 has no rounding instruction:
/// `f32::floor` is a call there).
#[inline(always)]
fn floor_in_range(x: f32) -> f32 {
    let t = (x as i32) as f32;
    either(t > x, t - 1.0, t)
}

/// The sine and cosine of `x` for |x| <= pi/4, as polynomials (Cephes' `sinf` and `cosf`
/// kernels' coefficients: within 2 ulp there) that every lane type evaluates with the same
/// operations, where the C library's `sincosf` might differ from a vector one in the last bit.
/// The range needs no reduction: callers fold their angles into it (the concentric disk
/// mapping swaps sine and cosine for its other half).
#[inline(always)]
pub fn sin_cos_quarter<L: Lanes>(x: L) -> (L, L) {
    let z = x * x;
    let sin_poly =
        (L::splat(-1.951_529_6e-4) * z + L::splat(8.332_161e-3)) * z - L::splat(1.666_665_5e-1);
    let sin = sin_poly * z * x + x;
    let cos_poly =
        (L::splat(2.443_315_7e-5) * z - L::splat(1.388_731_6e-3)) * z + L::splat(4.166_664_6e-2);
    let cos = cos_poly * z * z - L::splat(0.5) * z + L::splat(1.0);
    (sin, cos)
}

impl Mask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

impl Lanes for f32 {
    type M = bool;
    type U = u32;
    const N: usize = 1;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn floor(self) -> Self {
        floor_in_range(self)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        either(m, a, b)
    }
    #[inline(always)]
    fn mask(b: bool) -> bool {
        b
    }
    #[inline(always)]
    fn load(f: &[f32; MAX_LANES]) -> Self {
        f[0]
    }
    #[inline(always)]
    fn store(self, out: &mut [f32; MAX_LANES]) {
        out[0] = self;
    }
    #[inline(always)]
    fn gather(table: &[f32], index: u32) -> Self {
        table[index as usize]
    }
    #[inline(always)]
    fn to_u32(self) -> u32 {
        self as i32 as u32
    }
}

impl U32Lanes for u32 {
    type F = f32;
    type M = bool;
    #[inline(always)]
    fn splat(x: u32) -> u32 {
        x
    }
    #[inline(always)]
    fn load(f: &[u32; MAX_LANES]) -> u32 {
        f[0]
    }
    #[inline(always)]
    fn store(self, out: &mut [u32; MAX_LANES]) {
        out[0] = self;
    }
    #[inline(always)]
    fn wrapping_add(self, o: u32) -> u32 {
        u32::wrapping_add(self, o)
    }
    #[inline(always)]
    fn wrapping_mul(self, o: u32) -> u32 {
        u32::wrapping_mul(self, o)
    }
    #[inline(always)]
    fn reverse_bits(self) -> u32 {
        u32::reverse_bits(self)
    }
    #[inline(always)]
    fn remainder(self, d: u32) -> u32 {
        self % d
    }
    #[inline(always)]
    fn any_lane_bits(self) -> u32 {
        self
    }
    #[inline(always)]
    fn equals(self, o: u32) -> bool {
        self == o
    }
    #[inline(always)]
    fn at_least(self, o: u32) -> bool {
        self >= o
    }
    #[inline(always)]
    fn select(m: bool, a: u32, b: u32) -> u32 {
        either(m, a, b)
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self as i32 as f32
    }
}

/// `N` lanes as arrays, every operation a loop over them, which the compiler may vectorise
/// (in a function compiled for AVX2 or AVX-512); each lane does exactly the scalar operation.
#[derive(Clone, Copy)]
pub struct Arr<const N: usize>(pub [f32; N]);
#[derive(Clone, Copy)]
pub struct ArrMask<const N: usize>(pub [bool; N]);
#[derive(Clone, Copy)]
pub struct ArrU32<const N: usize>(pub [u32; N]);

macro_rules! array_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl<const N: usize> $tr for Arr<N> {
            type Output = Arr<N>;
            #[inline(always)]
            fn $f(self, o: Arr<N>) -> Arr<N> {
                Arr(std::array::from_fn(|i| self.0[i] $op o.0[i]))
            }
        }
    };
}
array_op!(Add, add, +);
array_op!(Sub, sub, -);
array_op!(Mul, mul, *);
array_op!(Div, div, /);

impl<const N: usize> BitAnd for ArrMask<N> {
    type Output = ArrMask<N>;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        ArrMask(std::array::from_fn(|i| self.0[i] & o.0[i]))
    }
}
impl<const N: usize> BitOr for ArrMask<N> {
    type Output = ArrMask<N>;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        ArrMask(std::array::from_fn(|i| self.0[i] | o.0[i]))
    }
}
impl<const N: usize> Not for ArrMask<N> {
    type Output = ArrMask<N>;
    #[inline(always)]
    fn not(self) -> Self {
        ArrMask(self.0.map(|m| !m))
    }
}
impl<const N: usize> Mask for ArrMask<N> {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().any(|&m| m)
    }
}

impl<const N: usize> Lanes for Arr<N> {
    type M = ArrMask<N>;
    type U = ArrU32<N>;
    const N: usize = N;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        Arr([x; N])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Arr(std::array::from_fn(|i| self.0[i].sqrt()))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Arr(std::array::from_fn(|i| self.0[i].abs()))
    }
    #[inline(always)]
    fn floor(self) -> Self {
        Arr(std::array::from_fn(|i| floor_in_range(self.0[i])))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> ArrMask<N> {
        ArrMask(std::array::from_fn(|i| self.0[i] < o.0[i]))
    }
    #[inline(always)]
    fn le(self, o: Self) -> ArrMask<N> {
        ArrMask(std::array::from_fn(|i| self.0[i] <= o.0[i]))
    }
    #[inline(always)]
    fn select(m: ArrMask<N>, a: Self, b: Self) -> Self {
        Arr(std::array::from_fn(|i| either(m.0[i], a.0[i], b.0[i])))
    }
    #[inline(always)]
    fn mask(b: bool) -> ArrMask<N> {
        ArrMask([b; N])
    }
    #[inline(always)]
    fn load(f: &[f32; MAX_LANES]) -> Self {
        Arr(std::array::from_fn(|i| f[i]))
    }
    #[inline(always)]
    fn store(self, out: &mut [f32; MAX_LANES]) {
        out[..N].copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn gather(table: &[f32], index: ArrU32<N>) -> Self {
        Arr(std::array::from_fn(|i| table[index.0[i] as usize]))
    }
    #[inline(always)]
    fn to_u32(self) -> ArrU32<N> {
        ArrU32(std::array::from_fn(|i| self.0[i] as i32 as u32))
    }
}

macro_rules! array_bit_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl<const N: usize> $tr for ArrU32<N> {
            type Output = ArrU32<N>;
            #[inline(always)]
            fn $f(self, o: ArrU32<N>) -> ArrU32<N> {
                ArrU32(std::array::from_fn(|i| self.0[i] $op o.0[i]))
            }
        }
    };
}
array_bit_op!(BitXor, bitxor, ^);
array_bit_op!(BitAnd, bitand, &);
array_bit_op!(BitOr, bitor, |);

impl<const N: usize> Shr<u32> for ArrU32<N> {
    type Output = ArrU32<N>;
    #[inline(always)]
    fn shr(self, s: u32) -> ArrU32<N> {
        ArrU32(std::array::from_fn(|i| self.0[i] >> s))
    }
}

impl<const N: usize> U32Lanes for ArrU32<N> {
    type F = Arr<N>;
    type M = ArrMask<N>;
    #[inline(always)]
    fn splat(x: u32) -> Self {
        ArrU32([x; N])
    }
    #[inline(always)]
    fn load(f: &[u32; MAX_LANES]) -> Self {
        ArrU32(std::array::from_fn(|i| f[i]))
    }
    #[inline(always)]
    fn store(self, out: &mut [u32; MAX_LANES]) {
        out[..N].copy_from_slice(&self.0);
    }
    #[inline(always)]
    fn wrapping_add(self, o: Self) -> Self {
        ArrU32(std::array::from_fn(|i| self.0[i].wrapping_add(o.0[i])))
    }
    #[inline(always)]
    fn wrapping_mul(self, o: Self) -> Self {
        ArrU32(std::array::from_fn(|i| self.0[i].wrapping_mul(o.0[i])))
    }
    #[inline(always)]
    fn reverse_bits(self) -> Self {
        ArrU32(std::array::from_fn(|i| self.0[i].reverse_bits()))
    }
    #[inline(always)]
    fn remainder(self, d: u32) -> Self {
        ArrU32(std::array::from_fn(|i| self.0[i] % d))
    }
    #[inline(always)]
    fn any_lane_bits(self) -> u32 {
        self.0.iter().fold(0, |a, &b| a | b)
    }
    #[inline(always)]
    fn equals(self, o: Self) -> ArrMask<N> {
        ArrMask(std::array::from_fn(|i| self.0[i] == o.0[i]))
    }
    #[inline(always)]
    fn at_least(self, o: Self) -> ArrMask<N> {
        ArrMask(std::array::from_fn(|i| self.0[i] >= o.0[i]))
    }
    #[inline(always)]
    fn select(m: ArrMask<N>, a: Self, b: Self) -> Self {
        ArrU32(std::array::from_fn(|i| either(m.0[i], a.0[i], b.0[i])))
    }
    #[inline(always)]
    fn to_f32(self) -> Arr<N> {
        Arr(std::array::from_fn(|i| self.0[i] as i32 as f32))
    }
}

/// Code written over [`Lanes`], run on the lane type a caller picks: a render of a unit, a
/// check in the tests. Its `run` should be `#[inline(always)]`, so that run through
/// [`Avx2Cpu::run`] it is compiled for AVX2.
pub trait OnLanes {
    type Output;
    fn run<L: Lanes>(&self) -> Self::Output;
}

/// Proof that this CPU runs AVX2, and the only way to code on AVX2 lanes: their safe
/// operations are AVX2 instructions, so the type is private and only [`Self::run`] names it.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub struct Avx2Cpu(());

#[cfg(target_arch = "x86_64")]
impl Avx2Cpu {
    /// The proof, where the CPU has AVX2.
    pub fn detect() -> Option<Self> {
        std::arch::is_x86_feature_detected!("avx2").then_some(Self(()))
    }

    /// Runs `code` on eight AVX2 lanes, compiled for AVX2.
    pub fn run<C: OnLanes>(self, code: &C) -> C::Output {
        // SAFETY: `self` exists only where the CPU has AVX2.
        unsafe { run_avx2(code) }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2<C: OnLanes>(code: &C) -> C::Output {
    code.run::<avx2::Avx2>()
}

/// Eight lanes in AVX2 registers through `std::arch`; reached only through [`Avx2Cpu::run`],
/// whose target features the operations, all `#[inline(always)]`, are compiled with.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::*;
    use std::arch::x86_64::*;

    #[derive(Clone, Copy)]
    pub struct Avx2(__m256);
    #[derive(Clone, Copy)]
    pub struct Avx2Mask(__m256);
    #[derive(Clone, Copy)]
    pub struct Avx2U32(__m256i);

    // SAFETY (every `unsafe` block in this module): the instructions are AVX2, which
    // `Avx2Cpu` has detected before any value of these types exists; loads and stores stay
    // within the MAX_LANES buffers, and gathers within the table (asserted in debug builds,
    // which the tests are; the callers' indices are in range).
    macro_rules! vector_op {
        ($t:ident, $tr:ident, $f:ident, $intr:ident) => {
            impl $tr for $t {
                type Output = $t;
                #[inline(always)]
                fn $f(self, o: $t) -> $t {
                    unsafe { $t($intr(self.0, o.0)) }
                }
            }
        };
    }
    vector_op!(Avx2, Add, add, _mm256_add_ps);
    vector_op!(Avx2, Sub, sub, _mm256_sub_ps);
    vector_op!(Avx2, Mul, mul, _mm256_mul_ps);
    vector_op!(Avx2, Div, div, _mm256_div_ps);
    vector_op!(Avx2Mask, BitAnd, bitand, _mm256_and_ps);
    vector_op!(Avx2Mask, BitOr, bitor, _mm256_or_ps);

    impl Not for Avx2Mask {
        type Output = Avx2Mask;
        #[inline(always)]
        fn not(self) -> Self {
            unsafe {
                Avx2Mask(_mm256_xor_ps(
                    self.0,
                    _mm256_castsi256_ps(_mm256_set1_epi32(-1)),
                ))
            }
        }
    }

    impl Mask for Avx2Mask {
        #[inline(always)]
        fn any(self) -> bool {
            unsafe { _mm256_movemask_ps(self.0) != 0 }
        }
    }

    #[inline(always)]
    fn mask_of(a: __m256i) -> Avx2Mask {
        unsafe { Avx2Mask(_mm256_castsi256_ps(a)) }
    }

    impl Lanes for Avx2 {
        type M = Avx2Mask;
        type U = Avx2U32;
        const N: usize = 8;
        #[inline(always)]
        fn splat(x: f32) -> Self {
            unsafe { Avx2(_mm256_set1_ps(x)) }
        }
        #[inline(always)]
        fn sqrt(self) -> Self {
            unsafe { Avx2(_mm256_sqrt_ps(self.0)) }
        }
        #[inline(always)]
        fn abs(self) -> Self {
            unsafe { Avx2(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)) }
        }
        #[inline(always)]
        fn floor(self) -> Self {
            unsafe { Avx2(_mm256_floor_ps(self.0)) }
        }
        #[inline(always)]
        fn lt(self, o: Self) -> Avx2Mask {
            unsafe { Avx2Mask(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0)) }
        }
        #[inline(always)]
        fn le(self, o: Self) -> Avx2Mask {
            unsafe { Avx2Mask(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)) }
        }
        #[inline(always)]
        fn select(m: Avx2Mask, a: Self, b: Self) -> Self {
            unsafe { Avx2(_mm256_blendv_ps(b.0, a.0, m.0)) }
        }
        #[inline(always)]
        fn mask(b: bool) -> Avx2Mask {
            mask_of(unsafe { _mm256_set1_epi32(-i32::from(b)) })
        }
        #[inline(always)]
        fn load(f: &[f32; MAX_LANES]) -> Self {
            unsafe { Avx2(_mm256_loadu_ps(f.as_ptr())) }
        }
        #[inline(always)]
        fn store(self, out: &mut [f32; MAX_LANES]) {
            unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn gather(table: &[f32], index: Avx2U32) -> Self {
            debug_assert!(
                {
                    let mut at = [0; MAX_LANES];
                    index.store(&mut at);
                    at[..8].iter().all(|&i| (i as usize) < table.len())
                },
                "a gather outside its table of {}",
                table.len()
            );
            unsafe { Avx2(_mm256_i32gather_ps::<4>(table.as_ptr(), index.0)) }
        }
        #[inline(always)]
        fn to_u32(self) -> Avx2U32 {
            unsafe { Avx2U32(_mm256_cvttps_epi32(self.0)) }
        }
    }

    vector_op!(Avx2U32, BitXor, bitxor, _mm256_xor_si256);
    vector_op!(Avx2U32, BitAnd, bitand, _mm256_and_si256);
    vector_op!(Avx2U32, BitOr, bitor, _mm256_or_si256);

    impl Shr<u32> for Avx2U32 {
        type Output = Avx2U32;
        #[inline(always)]
        fn shr(self, s: u32) -> Avx2U32 {
            unsafe { Avx2U32(_mm256_srl_epi32(self.0, _mm_cvtsi32_si128(s as i32))) }
        }
    }

    impl U32Lanes for Avx2U32 {
        type F = Avx2;
        type M = Avx2Mask;
        #[inline(always)]
        fn splat(x: u32) -> Self {
            unsafe { Avx2U32(_mm256_set1_epi32(x as i32)) }
        }
        #[inline(always)]
        fn load(f: &[u32; MAX_LANES]) -> Self {
            unsafe { Avx2U32(_mm256_loadu_si256(f.as_ptr().cast())) }
        }
        #[inline(always)]
        fn store(self, out: &mut [u32; MAX_LANES]) {
            unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), self.0) }
        }
        #[inline(always)]
        fn wrapping_add(self, o: Self) -> Self {
            unsafe { Avx2U32(_mm256_add_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn wrapping_mul(self, o: Self) -> Self {
            unsafe { Avx2U32(_mm256_mullo_epi32(self.0, o.0)) }
        }
        #[inline(always)]
        fn reverse_bits(self) -> Self {
            unsafe {
                // Each nibble reversed through a table, the two swapped within each byte, then
                // the bytes of each lane in reverse order.
                let table = _mm256_setr_epi8(
                    0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
                    0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf,
                );
                let nibble = _mm256_set1_epi8(0x0f);
                let low = _mm256_shuffle_epi8(table, _mm256_and_si256(self.0, nibble));
                let high = _mm256_shuffle_epi8(
                    table,
                    _mm256_and_si256(_mm256_srli_epi16::<4>(self.0), nibble),
                );
                let bytes = _mm256_or_si256(_mm256_slli_epi16::<4>(low), high);
                let order = _mm256_setr_epi8(
                    3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4,
                    11, 10, 9, 8, 15, 14, 13, 12,
                );
                Avx2U32(_mm256_shuffle_epi8(bytes, order))
            }
        }
        /// Lane by lane: AVX2 has no integer division.
        #[inline(always)]
        fn remainder(self, d: u32) -> Self {
            let mut lanes = [0; MAX_LANES];
            self.store(&mut lanes);
            Self::load(&lanes.map(|x| x % d))
        }
        #[inline(always)]
        fn any_lane_bits(self) -> u32 {
            let mut lanes = [0; MAX_LANES];
            self.store(&mut lanes);
            lanes.iter().fold(0, |a, &b| a | b)
        }
        #[inline(always)]
        fn equals(self, o: Self) -> Avx2Mask {
            mask_of(unsafe { _mm256_cmpeq_epi32(self.0, o.0) })
        }
        #[inline(always)]
        fn at_least(self, o: Self) -> Avx2Mask {
            mask_of(unsafe { _mm256_cmpeq_epi32(_mm256_max_epu32(self.0, o.0), self.0) })
        }
        #[inline(always)]
        fn select(m: Avx2Mask, a: Self, b: Self) -> Self {
            unsafe {
                Avx2U32(_mm256_castps_si256(_mm256_blendv_ps(
                    _mm256_castsi256_ps(b.0),
                    _mm256_castsi256_ps(a.0),
                    m.0,
                )))
            }
        }
        #[inline(always)]
        fn to_f32(self) -> Avx2 {
            unsafe { Avx2(_mm256_cvtepi32_ps(self.0)) }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An operation's name, its lanes and its scalar form.
    type Case<U> = (&'static str, U, fn(u32) -> u32);

    /// Integer and float operations of a lane type against the scalar type, lane by lane.
    fn agrees_with_scalar<L: Lanes>() {
        let samples = [
            0x1234_5678,
            1,
            2,
            0x8000_0000,
            0xcafe_f00d,
            0xffff_ffff,
            0x0f0f_f0f0,
            7,
            1 << 20,
            99,
            0xdead_beef,
            3,
            0x7fff_ffff,
            12345,
            0x8000_0001,
            0,
        ];
        for chunk in samples.chunks(L::N) {
            let mut ints = [0u32; MAX_LANES];
            let mut floats = [0f32; MAX_LANES];
            for (i, &x) in chunk.iter().enumerate() {
                ints[i] = x;
                floats[i] = (x >> 4) as f32 * 3e-6 - 17.25;
            }
            let (a, b) = (L::U::load(&ints), L::U::splat(0x9e37_79b9));
            let all = chunk.iter().fold(0, |a, &b| a | b);
            assert_eq!(a.any_lane_bits(), all, "bits of {chunk:x?}");
            let ops: [Case<L::U>; 9] = [
                ("mul", a.wrapping_mul(b), |x| x.wrapping_mul(0x9e37_79b9)),
                ("add", a.wrapping_add(b), |x| x.wrapping_add(0x9e37_79b9)),
                ("xor", a ^ b, |x| x ^ 0x9e37_79b9),
                ("or", a | b, |x| x | 0x9e37_79b9),
                ("shr", a >> 13, |x| x >> 13),
                ("reverse", a.reverse_bits(), u32::reverse_bits),
                ("remainder", a.remainder(1000), |x| x % 1000),
                ("at least", L::U::select(a.at_least(b), a, b), |x| {
                    x.max(0x9e37_79b9)
                }),
                (
                    "equals",
                    L::U::select(a.equals(L::U::splat(0)), b, a & b),
                    |x| {
                        if x == 0 {
                            0x9e37_79b9
                        } else {
                            x & 0x9e37_79b9
                        }
                    },
                ),
            ];
            for (name, lanes, scalar) in ops {
                let mut out = [0u32; MAX_LANES];
                lanes.store(&mut out);
                for (i, &x) in chunk.iter().enumerate() {
                    assert_eq!(out[i], scalar(x), "{name} of {x:#x} on {} lanes", L::N);
                }
            }
            let mut out = [0f32; MAX_LANES];
            L::load(&floats).floor().store(&mut out);
            for (i, &x) in floats[..chunk.len()].iter().enumerate() {
                assert_eq!(out[i], x.floor(), "floor of {x} on {} lanes", L::N);
            }
            let angles = L::load(&floats.map(|x| x * 0.045));
            let (sin, cos) = sin_cos_quarter(angles);
            let mut sines = [0f32; MAX_LANES];
            sin.store(&mut sines);
            cos.store(&mut out);
            for (i, &x) in floats[..chunk.len()].iter().enumerate() {
                let scalar = sin_cos_quarter(x * 0.045);
                assert_eq!(
                    (sines[i], out[i]),
                    scalar,
                    "sin, cos of {x} on {} lanes",
                    L::N
                );
            }
            angles.abs().store(&mut out);
            for (i, &x) in floats[..chunk.len()].iter().enumerate() {
                assert_eq!(out[i], (x * 0.045).abs(), "|{x}| on {} lanes", L::N);
            }
            (a >> 1).to_f32().store(&mut out);
            for (i, &x) in chunk.iter().enumerate() {
                assert_eq!(
                    out[i],
                    (x >> 1) as f32,
                    "{x:#x} as a float on {} lanes",
                    L::N
                );
            }
        }
    }

    /// Runs `check` on one lane, arrays of 8 and 16, and AVX2 where the CPU has it.
    pub(crate) fn on_every_lane_type(check: &impl OnLanes<Output = ()>) {
        check.run::<f32>();
        check.run::<Arr<8>>();
        check.run::<Arr<16>>();
        #[cfg(target_arch = "x86_64")]
        if let Some(cpu) = Avx2Cpu::detect() {
            cpu.run(check);
        }
    }

    /// A gather outside its table panics on every lane type, the AVX2 one by its debug
    /// assertion: the tests run with debug assertions, and must.
    #[test]
    fn gathers_outside_their_table_panic() {
        // Built without debug assertions, the AVX2 gather would read outside the table.
        const {
            assert!(
                cfg!(debug_assertions),
                "the lanes are tested with debug assertions"
            )
        };
        struct Outside;
        impl OnLanes for Outside {
            type Output = ();
            fn run<L: Lanes>(&self) {
                let table = [1.0, 2.0];
                let inside = L::gather(&table, L::U::splat(1));
                assert_eq!(inside.values()[..L::N], [2.0; MAX_LANES][..L::N]);
                let outside = std::panic::catch_unwind(|| L::gather(&table, L::U::splat(2)));
                assert!(outside.is_err(), "{} lanes gathered past the table", L::N);
            }
        }
        on_every_lane_type(&Outside);
    }

    #[test]
    fn sine_and_cosine_are_within_two_ulp_over_their_range() {
        let ulp = |x: f32| f32::from_bits(x.abs().to_bits() + 1) - x.abs();
        let steps = 100_000;
        for i in -steps..=steps {
            let x = std::f32::consts::FRAC_PI_4 * i as f32 / steps as f32;
            let (sin, cos) = sin_cos_quarter(x);
            let (exact_sin, exact_cos) = libm::sincos(f64::from(x));
            for (got, exact) in [(sin, exact_sin), (cos, exact_cos)] {
                let error = (f64::from(got) - exact).abs();
                assert!(
                    error <= 2.0 * f64::from(ulp(exact as f32)),
                    "at {x}: {got} against {exact}"
                );
            }
        }
    }

    #[test]
    fn every_lane_type_computes_the_scalar_bits() {
        struct Agrees;
        impl OnLanes for Agrees {
            type Output = ();
            fn run<L: Lanes>(&self) {
                agrees_with_scalar::<L>();
            }
        }
        on_every_lane_type(&Agrees);
    }
}
