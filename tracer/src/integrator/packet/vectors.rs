//! A packet's vectors in memory lane by lane, and its masks as lane sets.

use glam::Vec3;

use crate::lanes::{Lanes, MAX_LANES};
use crate::vec3_lanes::V3;

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
