//! Lane types: a path tracer written once over [`Lanes`] runs one path at a time (`f32`) or
//! several per instruction. Every operation is an IEEE-exact single operation per lane (add,
//! subtract, multiply, divide, square root, compare, select, integer wrap-around; no fused
//! multiply-add), so every lane type gives the scalar type's bits.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Not, Sub};

/// The widest lane type here: buffers for moving lanes in and out are this long.
pub const MAX_LANES: usize = 16;

pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {
    fn any(self) -> bool;
}

pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    type M: Mask;
    /// 32-bit integer lanes.
    type I: Copy;
    const N: usize;
    fn splat(x: f32) -> Self;
    fn sqrt(self) -> Self;
    /// Floor of values within +-2^31.
    fn floor(self) -> Self;
    fn lt(self, o: Self) -> Self::M;
    fn le(self, o: Self) -> Self::M;
    fn select(m: Self::M, a: Self, b: Self) -> Self;
    fn mask(b: bool) -> Self::M;
    /// Truncated to integers (values within +-2^31).
    fn to_int(self) -> Self::I;
    fn isplat(x: i32) -> Self::I;
    fn iand(a: Self::I, b: i32) -> Self::I;
    fn iadd(a: Self::I, b: i32) -> Self::I;
    fn ixor(a: Self::I, b: i32) -> Self::I;
    /// `a * mul + b`, wrapping.
    fn imad(a: Self::I, mul: i32, b: Self::I) -> Self::I;
    fn ieq(a: Self::I, b: i32) -> Self::M;
    fn iselect(m: Self::M, a: Self::I, b: Self::I) -> Self::I;
    /// [`hash32`] of each lane.
    fn hash(x: Self::I) -> Self::I;
    /// The top 24 bits of each lane as a float in [0, 1).
    fn unit(x: Self::I) -> Self;
    fn gather(table: &[f32], index: Self::I) -> Self;
    fn load(f: &[f32; MAX_LANES]) -> Self;
    fn store(self, out: &mut [f32; MAX_LANES]);
    fn iload(f: &[i32; MAX_LANES]) -> Self::I;

    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Self::select(self.lt(o), self, o)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self::select(o.lt(self), self, o)
    }
}

/// A 32-bit integer hash (Chris Wellons' lowbias32).
#[inline(always)]
pub fn hash32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Floor of `x` within +-2^31, by truncation (baseline x86-64 has no rounding instruction:
/// `f32::floor` is a call there).
#[inline(always)]
fn floor_in_range(x: f32) -> f32 {
    let t = (x as i32) as f32;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

#[inline(always)]
fn unit_of(x: i32) -> f32 {
    ((x as u32 >> 8) as i32) as f32 * (1.0 / 16_777_216.0)
}

#[inline(always)]
fn either<T>(m: bool, a: T, b: T) -> T {
    if m {
        a
    } else {
        b
    }
}

impl Mask for bool {
    #[inline(always)]
    fn any(self) -> bool {
        self
    }
}

impl Lanes for f32 {
    type M = bool;
    type I = i32;
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
    fn to_int(self) -> i32 {
        self as i32
    }
    #[inline(always)]
    fn isplat(x: i32) -> i32 {
        x
    }
    #[inline(always)]
    fn iand(a: i32, b: i32) -> i32 {
        a & b
    }
    #[inline(always)]
    fn iadd(a: i32, b: i32) -> i32 {
        a.wrapping_add(b)
    }
    #[inline(always)]
    fn ixor(a: i32, b: i32) -> i32 {
        a ^ b
    }
    #[inline(always)]
    fn imad(a: i32, mul: i32, b: i32) -> i32 {
        a.wrapping_mul(mul).wrapping_add(b)
    }
    #[inline(always)]
    fn ieq(a: i32, b: i32) -> bool {
        a == b
    }
    #[inline(always)]
    fn iselect(m: bool, a: i32, b: i32) -> i32 {
        either(m, a, b)
    }
    #[inline(always)]
    fn hash(x: i32) -> i32 {
        hash32(x as u32) as i32
    }
    #[inline(always)]
    fn unit(x: i32) -> Self {
        unit_of(x)
    }
    #[inline(always)]
    fn gather(table: &[f32], index: i32) -> Self {
        table[index as usize]
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
    fn iload(f: &[i32; MAX_LANES]) -> i32 {
        f[0]
    }
}

/// `N` lanes as arrays, every operation a loop over them: in a function compiled for AVX2 or
/// AVX-512 the compiler turns the loops into vector instructions, and each lane still does
/// exactly the scalar operation.
#[derive(Clone, Copy)]
pub struct Arr<const N: usize>(pub [f32; N]);
#[derive(Clone, Copy)]
pub struct ArrMask<const N: usize>(pub [i32; N]);
#[derive(Clone, Copy)]
pub struct ArrInt<const N: usize>(pub [i32; N]);

macro_rules! array_op {
    ($tr:ident, $f:ident, $op:tt) => {
        impl<const N: usize> $tr for Arr<N> {
            type Output = Arr<N>;
            #[inline(always)]
            fn $f(self, o: Arr<N>) -> Arr<N> {
                let mut r = [0f32; N];
                for i in 0..N {
                    r[i] = self.0[i] $op o.0[i];
                }
                Arr(r)
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
        ArrMask(std::array::from_fn(|i| !self.0[i]))
    }
}
impl<const N: usize> Mask for ArrMask<N> {
    #[inline(always)]
    fn any(self) -> bool {
        self.0.iter().fold(0, |a, &b| a | b) != 0
    }
}

fn all_ones(b: bool) -> i32 {
    -i32::from(b)
}

impl<const N: usize> Lanes for Arr<N> {
    type M = ArrMask<N>;
    type I = ArrInt<N>;
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
    fn floor(self) -> Self {
        Arr(std::array::from_fn(|i| floor_in_range(self.0[i])))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> ArrMask<N> {
        ArrMask(std::array::from_fn(|i| all_ones(self.0[i] < o.0[i])))
    }
    #[inline(always)]
    fn le(self, o: Self) -> ArrMask<N> {
        ArrMask(std::array::from_fn(|i| all_ones(self.0[i] <= o.0[i])))
    }
    #[inline(always)]
    fn select(m: ArrMask<N>, a: Self, b: Self) -> Self {
        Arr(std::array::from_fn(|i| either(m.0[i] != 0, a.0[i], b.0[i])))
    }
    #[inline(always)]
    fn mask(b: bool) -> ArrMask<N> {
        ArrMask([all_ones(b); N])
    }
    #[inline(always)]
    fn to_int(self) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| self.0[i] as i32))
    }
    #[inline(always)]
    fn isplat(x: i32) -> ArrInt<N> {
        ArrInt([x; N])
    }
    #[inline(always)]
    fn iand(a: ArrInt<N>, b: i32) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| a.0[i] & b))
    }
    #[inline(always)]
    fn iadd(a: ArrInt<N>, b: i32) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| a.0[i].wrapping_add(b)))
    }
    #[inline(always)]
    fn ixor(a: ArrInt<N>, b: i32) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| a.0[i] ^ b))
    }
    #[inline(always)]
    fn imad(a: ArrInt<N>, mul: i32, b: ArrInt<N>) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| {
            a.0[i].wrapping_mul(mul).wrapping_add(b.0[i])
        }))
    }
    #[inline(always)]
    fn ieq(a: ArrInt<N>, b: i32) -> ArrMask<N> {
        ArrMask(std::array::from_fn(|i| all_ones(a.0[i] == b)))
    }
    #[inline(always)]
    fn iselect(m: ArrMask<N>, a: ArrInt<N>, b: ArrInt<N>) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| either(m.0[i] != 0, a.0[i], b.0[i])))
    }
    #[inline(always)]
    fn hash(x: ArrInt<N>) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| hash32(x.0[i] as u32) as i32))
    }
    #[inline(always)]
    fn unit(x: ArrInt<N>) -> Self {
        Arr(std::array::from_fn(|i| unit_of(x.0[i])))
    }
    #[inline(always)]
    fn gather(table: &[f32], index: ArrInt<N>) -> Self {
        Arr(std::array::from_fn(|i| table[index.0[i] as usize]))
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
    fn iload(f: &[i32; MAX_LANES]) -> ArrInt<N> {
        ArrInt(std::array::from_fn(|i| f[i]))
    }
}

#[cfg(target_arch = "x86_64")]
pub use avx2::Avx2;

/// Eight lanes in AVX2 registers through `std::arch` intrinsics. Only used inside functions
/// compiled with `#[target_feature(enable = "avx2")]` on a CPU that has it; helpers must be
/// `#[inline(always)]` functions, not closures (a closure does not inherit its caller's target
/// features, and every intrinsic in it becomes a call).
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::*;
    use std::arch::x86_64::*;

    #[derive(Clone, Copy)]
    pub struct Avx2(__m256);
    #[derive(Clone, Copy)]
    pub struct Avx2Mask(__m256);
    #[derive(Clone, Copy)]
    pub struct Avx2Int(__m256i);

    macro_rules! vector_op {
        ($t:ident, $tr:ident, $f:ident, $intr:ident) => {
            impl $tr for $t {
                type Output = $t;
                #[inline(always)]
                fn $f(self, o: $t) -> $t {
                    // SAFETY: only run on CPUs with AVX2 (see the module's doc).
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

    // SAFETY (every `unsafe` block below): only run on CPUs with AVX2 (see the module's doc);
    // loads and stores stay within the MAX_LANES buffers, gathers within the table (the
    // caller's indices are in range).
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

    impl Lanes for Avx2 {
        type M = Avx2Mask;
        type I = Avx2Int;
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
            unsafe { Avx2Mask(_mm256_castsi256_ps(_mm256_set1_epi32(all_ones(b)))) }
        }
        #[inline(always)]
        fn to_int(self) -> Avx2Int {
            unsafe { Avx2Int(_mm256_cvttps_epi32(self.0)) }
        }
        #[inline(always)]
        fn isplat(x: i32) -> Avx2Int {
            unsafe { Avx2Int(_mm256_set1_epi32(x)) }
        }
        #[inline(always)]
        fn iand(a: Avx2Int, b: i32) -> Avx2Int {
            unsafe { Avx2Int(_mm256_and_si256(a.0, _mm256_set1_epi32(b))) }
        }
        #[inline(always)]
        fn iadd(a: Avx2Int, b: i32) -> Avx2Int {
            unsafe { Avx2Int(_mm256_add_epi32(a.0, _mm256_set1_epi32(b))) }
        }
        #[inline(always)]
        fn ixor(a: Avx2Int, b: i32) -> Avx2Int {
            unsafe { Avx2Int(_mm256_xor_si256(a.0, _mm256_set1_epi32(b))) }
        }
        #[inline(always)]
        fn imad(a: Avx2Int, mul: i32, b: Avx2Int) -> Avx2Int {
            unsafe {
                Avx2Int(_mm256_add_epi32(
                    _mm256_mullo_epi32(a.0, _mm256_set1_epi32(mul)),
                    b.0,
                ))
            }
        }
        #[inline(always)]
        fn ieq(a: Avx2Int, b: i32) -> Avx2Mask {
            unsafe {
                Avx2Mask(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
                    a.0,
                    _mm256_set1_epi32(b),
                )))
            }
        }
        #[inline(always)]
        fn iselect(m: Avx2Mask, a: Avx2Int, b: Avx2Int) -> Avx2Int {
            unsafe {
                Avx2Int(_mm256_castps_si256(_mm256_blendv_ps(
                    _mm256_castsi256_ps(b.0),
                    _mm256_castsi256_ps(a.0),
                    m.0,
                )))
            }
        }
        #[inline(always)]
        fn hash(x: Avx2Int) -> Avx2Int {
            unsafe {
                let mut x = x.0;
                x = _mm256_xor_si256(x, _mm256_srli_epi32::<16>(x));
                x = _mm256_mullo_epi32(x, _mm256_set1_epi32(0x7feb_352d));
                x = _mm256_xor_si256(x, _mm256_srli_epi32::<15>(x));
                x = _mm256_mullo_epi32(x, _mm256_set1_epi32(0x846c_a68b_u32 as i32));
                x = _mm256_xor_si256(x, _mm256_srli_epi32::<16>(x));
                Avx2Int(x)
            }
        }
        #[inline(always)]
        fn unit(x: Avx2Int) -> Self {
            unsafe {
                Avx2(_mm256_mul_ps(
                    _mm256_cvtepi32_ps(_mm256_srli_epi32::<8>(x.0)),
                    _mm256_set1_ps(1.0 / 16_777_216.0),
                ))
            }
        }
        #[inline(always)]
        fn gather(table: &[f32], index: Avx2Int) -> Self {
            unsafe { Avx2(_mm256_i32gather_ps::<4>(table.as_ptr(), index.0)) }
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
        fn iload(f: &[i32; MAX_LANES]) -> Avx2Int {
            unsafe { Avx2Int(_mm256_loadu_si256(f.as_ptr().cast())) }
        }
    }
}
