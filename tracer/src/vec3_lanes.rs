//! Three coordinates in lanes ([`crate::lanes`]): the vector operations code written over lane
//! types uses, each lane's the bits of glam's `Vec3` operation on it, and the offset of a ray's
//! origin off its surface, written once for one lane ([`crate::math::offset_origin`]) or
//! several.

use crate::lanes::Lanes;

/// Three coordinates in lanes.
pub type V3<L> = [L; 3];

#[inline(always)]
pub fn dot<L: Lanes>(a: V3<L>, b: V3<L>) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub fn scale<L: Lanes>(a: V3<L>, k: L) -> V3<L> {
    [a[0] * k, a[1] * k, a[2] * k]
}

#[inline(always)]
pub fn times<L: Lanes>(a: V3<L>, b: V3<L>) -> V3<L> {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

#[inline(always)]
pub fn plus<L: Lanes>(a: V3<L>, b: V3<L>) -> V3<L> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `-a`, exactly (the sign of a zero too).
#[inline(always)]
pub fn negate<L: Lanes>(a: V3<L>) -> V3<L> {
    scale(a, L::splat(-1.0))
}

#[inline(always)]
pub fn select3<L: Lanes>(m: L::M, a: V3<L>, b: V3<L>) -> V3<L> {
    [
        L::select(m, a[0], b[0]),
        L::select(m, a[1], b[1]),
        L::select(m, a[2], b[2]),
    ]
}

/// Offsets ray origins `p` along the geometric normals `ng` so they do not re-hit their own
/// surface, to the side of `dir`; the offset scales with the magnitude of the point
/// (floating-point error grows with it).
#[inline(always)]
pub fn offset_origin<L: Lanes>(p: V3<L>, ng: V3<L>, dir: V3<L>) -> V3<L> {
    let a = [p[0].abs(), p[1].abs(), p[2].abs()];
    let largest = a[0].max(a[1].max(a[2]));
    let eps = L::splat(1e-4) * (L::splat(1.0) + largest);
    let step = scale(ng, eps);
    let ahead = L::splat(0.0).le(dot(dir, ng));
    select3(
        ahead,
        plus(p, step),
        [p[0] - step[0], p[1] - step[1], p[2] - step[2]],
    )
}
