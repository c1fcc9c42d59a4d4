//! Three coordinates in lanes, and their form in memory lane by lane.

use glam::Vec3;

use crate::lanes::{Lanes, MAX_LANES};

/// Three coordinates in lanes.
pub(super) type V3<L> = [L; 3];

#[inline(always)]
pub(super) fn dot<L: Lanes>(a: V3<L>, b: V3<L>) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub(super) fn scale<L: Lanes>(a: V3<L>, k: L) -> V3<L> {
    [a[0] * k, a[1] * k, a[2] * k]
}

#[inline(always)]
pub(super) fn times<L: Lanes>(a: V3<L>, b: V3<L>) -> V3<L> {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

#[inline(always)]
pub(super) fn plus<L: Lanes>(a: V3<L>, b: V3<L>) -> V3<L> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `-a`, exactly (the sign of a zero too).
#[inline(always)]
pub(super) fn negate<L: Lanes>(a: V3<L>) -> V3<L> {
    scale(a, L::splat(-1.0))
}

#[inline(always)]
pub(super) fn select3<L: Lanes>(m: L::M, a: V3<L>, b: V3<L>) -> V3<L> {
    [
        L::select(m, a[0], b[0]),
        L::select(m, a[1], b[1]),
        L::select(m, a[2], b[2]),
    ]
}

/// Per-lane vectors as lanes hold them: a row of x, one of y, one of z, filled and read lane
/// by lane (lanes past `L::N` are not read).
#[derive(Clone, Copy)]
pub(super) struct LaneVec3s([[f32; MAX_LANES]; 3]);

impl LaneVec3s {
    pub(super) const fn splat(v: Vec3) -> Self {
        Self([[v.x; MAX_LANES], [v.y; MAX_LANES], [v.z; MAX_LANES]])
    }

    #[inline(always)]
    pub(super) fn set(&mut self, i: usize, v: Vec3) {
        (self.0[0][i], self.0[1][i], self.0[2][i]) = (v.x, v.y, v.z);
    }

    #[inline(always)]
    pub(super) fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.0[0][i], self.0[1][i], self.0[2][i])
    }

    #[inline(always)]
    pub(super) fn load<L: Lanes>(&self) -> V3<L> {
        [
            L::load(&self.0[0]),
            L::load(&self.0[1]),
            L::load(&self.0[2]),
        ]
    }

    #[inline(always)]
    pub(super) fn of<L: Lanes>(v: V3<L>) -> Self {
        let mut rows = [[0.0; MAX_LANES]; 3];
        for (lanes, row) in v.iter().zip(&mut rows) {
            lanes.store(row);
        }
        Self(rows)
    }
}

/// `x == 0` (either zero).
#[inline(always)]
pub(super) fn is_zero<L: Lanes>(x: L) -> L::M {
    let zero = L::splat(0.0);
    x.le(zero) & zero.le(x)
}

/// The mask of the lanes `set` names.
#[inline(always)]
pub(super) fn mask_of<L: Lanes>(set: &[bool; MAX_LANES]) -> L::M {
    let mut ones = [0.0; MAX_LANES];
    for (one, &set) in ones.iter_mut().zip(set) {
        *one = if set { 1.0 } else { 0.0 };
    }
    L::splat(0.0).lt(L::load(&ones))
}

/// Which lanes a mask sets.
#[inline(always)]
pub(super) fn lanes_set<L: Lanes>(m: L::M) -> [bool; MAX_LANES] {
    let ones = L::select(m, L::splat(1.0), L::splat(0.0)).values();
    let mut set = [false; MAX_LANES];
    for (set, one) in set.iter_mut().zip(ones) {
        *set = one > 0.0;
    }
    set
}

/// [`crate::math::offset_origin`] in lanes.
#[inline(always)]
pub(super) fn offset_origin<L: Lanes>(p: V3<L>, ng: V3<L>, dir: V3<L>) -> V3<L> {
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
