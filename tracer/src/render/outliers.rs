//! LuxRender 1.x's outlier rejection (`Film "fleximage" "integer outlierrejection_k"`, 0: off),
//! as its film's `RejectTileOutliers` does it: each camera sample is a point (x, y, log(1 + Y))
//! in film coordinates over cells the pixel filter's width (`floor(2 width)` pixels, at least 1),
//! Y its luminance. The film keeps the outliers it has rejected, each in its cell and the eight
//! around it. A sample is kept when the outliers of its cell hold at least one point near it:
//! the mean squared distance to its `k` nearest (or all, when fewer) at most 1. Otherwise it is
//! an outlier: remembered, and dropped. So a lone bright sample (a firefly) is dropped; a
//! sample like others rejected before it is kept; and the first samples of each brightness in
//! a cell are dropped too, which biases the image slightly darker, as LuxRender's.
//!
//! LuxRender's film keeps its outliers for the whole render, shared by its threads in the order
//! their samples arrive; YAT keeps them per unit of work, in the unit's sample order, so a
//! unit's rejections are the same on every node (the image the same bytes anywhere). A unit
//! starts with none, as LuxRender's film does at the start of a render: YAT's renders drop a
//! few more samples at the start of each unit than LuxRender's at the start of the render.
//!
//! Bounds: `k` at most [`MAX_OUTLIER_K`] (a larger one is read as that, with a warning from the
//! Film's reader); a cell holds at most [`MAX_CELL_OUTLIERS`] points (an outlier past that is
//! still dropped, not remembered, as LuxRender's tree refuses a node it cannot split for), its
//! store (776 bytes) made at its first outlier, so a unit's store is at most its cells x 776
//! bytes: 3.4 MB for a 64-pixel tile under a filter of half-width 0.5 (1-pixel cells), 0.1 MB
//! under the seed scenes' width 2; a test measures one cell's points, at most 64.
//!
//! Cost: a test measures four distances an instruction and, for the one or two nearest that
//! scenes ask for, keeps the nearest lane by lane (no sorting); some 230 instructions a sample
//! on the seed Cornell box (k = 2), +2.8% of its render (bench/RESULTS.md, session 44).

use glam::{Vec2, Vec4, Vec4Swizzles};

use crate::math::floor_to_int;

use super::unit::PixelRect;

/// The most neighbours an outlier test asks for.
pub const MAX_OUTLIER_K: u32 = 64;

/// The most outliers a cell remembers.
pub const MAX_CELL_OUTLIERS: usize = 64;

/// A unit's outliers, over the cells its samples and their neighbours lie in.
pub struct OutlierFilter {
    k: usize,
    /// The inverse of the cell size in pixels, per axis (LuxRender multiplies by it).
    inv_cell: [f32; 2],
    /// The filter's half-widths: film x maps to cells from `x - 0.5 + width`.
    width: [f32; 2],
    /// The first cell column and row the grid holds, and its size in cells.
    first: [i64; 2],
    size: [usize; 2],
    /// Each cell's outliers, made at its first.
    cells: Vec<Option<Box<CellOutliers>>>,
}

/// Lanes of a cell's store: its points four at a time.
const CELL_CHUNKS: usize = MAX_CELL_OUTLIERS / 4;

/// A cell's outliers as (x, y, log(1 + Y)) in cell units, coordinate by coordinate, four to a
/// lane, so a test measures four distances an instruction. Slots past `len` hold infinity:
/// their distance is infinite, never among the nearest.
struct CellOutliers {
    len: usize,
    x: [Vec4; CELL_CHUNKS],
    y: [Vec4; CELL_CHUNKS],
    log_luminance: [Vec4; CELL_CHUNKS],
}

impl CellOutliers {
    fn new() -> Self {
        let empty = [Vec4::INFINITY; CELL_CHUNKS];
        Self {
            len: 0,
            x: empty,
            y: empty,
            log_luminance: empty,
        }
    }

    fn push(&mut self, p: [f32; 3]) {
        if self.len < MAX_CELL_OUTLIERS {
            let (chunk, lane) = (self.len / 4, self.len % 4);
            self.x[chunk][lane] = p[0];
            self.y[chunk][lane] = p[1];
            self.log_luminance[chunk][lane] = p[2];
            self.len += 1;
        }
    }

    /// The squared distances from `p` to the points, by chunk (those past `len` infinite).
    fn squared_distances(&self, p: [f32; 3]) -> impl Iterator<Item = Vec4> + '_ {
        let (px, py, pl) = (Vec4::splat(p[0]), Vec4::splat(p[1]), Vec4::splat(p[2]));
        let chunks = self.len.div_ceil(4);
        (0..chunks).map(move |c| {
            let (dx, dy, dl) = (px - self.x[c], py - self.y[c], pl - self.log_luminance[c]);
            dx * dx + dy * dy + dl * dl
        })
    }

    /// Whether the mean squared distance from `p` to its `m` nearest points (0 < m <= len) is
    /// at most 1. One and two nearest (what scenes ask for) are kept lane by lane; more go
    /// through [`Self::m_nearest_sum`].
    fn near_enough(&self, p: [f32; 3], m: usize) -> bool {
        let bound = m as f32;
        match m {
            1 => {
                let nearest = self
                    .squared_distances(p)
                    .fold(Vec4::INFINITY, |nearest, d2| nearest.min(d2));
                nearest.min_element() <= bound
            }
            2 => {
                let (mut first, mut second) = (Vec4::INFINITY, Vec4::INFINITY);
                for d2 in self.squared_distances(p) {
                    second = second.min(first.max(d2));
                    first = first.min(d2);
                }
                let (a, b) = two_smallest(first, second);
                a + b <= bound
            }
            _ => self.m_nearest_sum(p, m) <= bound,
        }
    }

    /// The sum of the squared distances from `p` to its `m` nearest points (0 < m <= len),
    /// smallest first. A point farther than m (squared) cannot be among m nearest summing to at
    /// most m, so such points are skipped and the sum is then infinite.
    fn m_nearest_sum(&self, p: [f32; 3], m: usize) -> f32 {
        let bound = m as f32;
        let mut nearest = [0.0f32; MAX_OUTLIER_K as usize];
        let mut found = 0;
        for d2 in self.squared_distances(p).flat_map(|d2| d2.to_array()) {
            if d2 > bound || (found == m && d2 >= nearest[m - 1]) {
                continue;
            }
            // Insert d2 among the sorted candidates, the largest falling off once there are m.
            let mut at = found.min(m - 1);
            while at > 0 && nearest[at - 1] > d2 {
                nearest[at] = nearest[at - 1];
                at -= 1;
            }
            nearest[at] = d2;
            found = (found + 1).min(m);
        }
        if found < m {
            return f32::INFINITY;
        }
        nearest[..m].iter().sum()
    }
}

/// The two smallest of eight distances, four lanes whose smallest are `first` and next
/// smallest `second`, ascending, on lanes. The smallest is the least `first` (lane j); the next
/// is `second[j]` or another lane's `first`, and no other lane's `second` is below that one's
/// `first`: so it is the least of every `second` and the second least `first`.
fn two_smallest(first: Vec4, second: Vec4) -> (f32, f32) {
    // Lanes 0 and 1 compared with 2 and 3, then the two pairs with each other.
    let swapped = first.zwxy();
    let (low, high) = (first.min(swapped), first.max(swapped));
    let (low_swapped, high_swapped) = (low.yxwz(), high.yxwz());
    let least = low.min(low_swapped);
    let next_first = low.max(low_swapped).min(high.min(high_swapped));
    (least.x, next_first.x.min(second.min_element()))
}

impl OutlierFilter {
    /// The filter of a unit whose samples lie in `tile` (film pixels), for a pixel filter of
    /// half-widths `width`; None when `k` is 0 (no rejection).
    pub fn new(k: u32, width: [f32; 2], tile: PixelRect) -> Option<Self> {
        if k == 0 {
            return None;
        }
        let k = k.min(MAX_OUTLIER_K) as usize;
        let inv_cell = width.map(|w| 1.0 / (2.0 * w).floor().max(1.0));
        let cell_of =
            |v: u32, axis: usize| floor_to_int((v as f32 - 0.5 + width[axis]) * inv_cell[axis]);
        // One cell of margin each side: a rejected sample is remembered in its neighbours too.
        let first = [cell_of(tile.x0, 0) - 1, cell_of(tile.y0, 1) - 1];
        let last = [cell_of(tile.x1, 0) + 1, cell_of(tile.y1, 1) + 1];
        let size = [0, 1].map(|a| (last[a] - first[a] + 1).max(1) as usize);
        Some(Self {
            k,
            inv_cell,
            width,
            first,
            size,
            cells: (0..size[0] * size[1]).map(|_| None).collect(),
        })
    }

    /// Whether the camera sample at film position `at` of luminance `luminance` is an outlier
    /// (and so remembered, and dropped).
    pub fn rejects(&mut self, at: Vec2, luminance: f32) -> bool {
        let x = (at.x - 0.5 + self.width[0]) * self.inv_cell[0];
        let y = (at.y - 0.5 + self.width[1]) * self.inv_cell[1];
        // Finite whatever the luminance (NaN and below zero as 0), so no distance is NaN.
        let luminance = if luminance > 0.0 {
            luminance.min(f32::MAX)
        } else {
            0.0
        };
        let p = [x, y, libm::logf(1.0 + luminance)];
        let column = floor_to_int(x) - self.first[0];
        let row = floor_to_int(y) - self.first[1];
        let Some(cell) = self.index(column, row) else {
            return false;
        };
        let near = match &self.cells[cell] {
            Some(points) => points.near_enough(p, self.k.min(points.len)),
            None => false,
        };
        if !near {
            self.remember(column, row, p);
        }
        !near
    }

    /// Remembers the outlier `p` of cell (`column`, `row`) in that cell and the eight around
    /// it (LuxRender's way: a test then looks at one cell only).
    fn remember(&mut self, column: i64, row: i64, p: [f32; 3]) {
        for dy in -1..=1 {
            for dx in -1..=1 {
                if let Some(around) = self.index(column + dx, row + dy) {
                    self.cells[around]
                        .get_or_insert_with(|| Box::new(CellOutliers::new()))
                        .push(p);
                }
            }
        }
    }

    fn index(&self, column: i64, row: i64) -> Option<usize> {
        let (c, r) = (usize::try_from(column).ok()?, usize::try_from(row).ok()?);
        (c < self.size[0] && r < self.size[1]).then(|| r * self.size[0] + c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filter(k: u32) -> OutlierFilter {
        let tile = PixelRect {
            x0: 0,
            y0: 0,
            x1: 16,
            y1: 16,
        };
        OutlierFilter::new(k, [2.0, 2.0], tile).unwrap()
    }

    /// The first sample of a cell is an outlier; one like it then is kept; a lone bright one
    /// (4 more in log luminance: 16 in squared distance) is dropped, and a second like that
    /// one is kept; the outliers are remembered in the cells around too; k = 0 rejects nothing.
    #[test]
    fn samples_are_kept_near_earlier_outliers() {
        let mut f = filter(1);
        let at = Vec2::new(5.3, 6.1);
        assert!(f.rejects(at, 0.5));
        assert!(!f.rejects(at + Vec2::new(0.5, 0.2), 0.52));
        let bright = 1.5 * libm::expf(4.0) - 1.0;
        assert!(f.rejects(at, bright));
        assert!(!f.rejects(at + Vec2::new(0.1, 0.1), bright));
        // Cells are 4 pixels (x = 5.3 is 1.7 cells: (5.3 - 0.5 + 2) / 4); 2 pixels on is the
        // next cell, half a cell from the first outlier: 0.25 in squared distance.
        assert!(!f.rejects(at + Vec2::new(2.0, 0.0), 0.5));
        let tile = PixelRect {
            x0: 0,
            y0: 0,
            x1: 1,
            y1: 1,
        };
        assert!(OutlierFilter::new(0, [2.0, 2.0], tile).is_none());
    }

    /// The mean squared distance to the k nearest decides: outliers at 0 and 3 in log
    /// luminance; a sample at 0.9 is 0.81 and 4.41 from them: kept with k = 1 (0.81 <= 1),
    /// an outlier with k = 2 (a mean of 2.61 > 1).
    #[test]
    fn the_k_nearest_mean_decides() {
        for (k, rejected) in [(1, false), (2, true)] {
            let mut f = filter(k);
            let at = Vec2::new(5.3, 6.1);
            let lum = |log: f32| libm::expf(log) - 1.0;
            assert!(f.rejects(at, lum(0.0)));
            assert!(f.rejects(at, lum(3.0)));
            assert_eq!(f.rejects(at, lum(0.9)), rejected, "k {k}");
        }
    }

    /// The lane-wise tests for one and two nearest decide as the general k-nearest sum does, and
    /// that one (up to 8 nearest) as the sorted distances do, over random stores of 1 to 64
    /// points (ties included: coordinates on a coarse grid); the two smallest of eight lanes
    /// are the sorted array's first two.
    #[test]
    fn the_lane_tests_agree_with_the_general_one() {
        let mut rng = fastrand::Rng::with_seed(7);
        let coarse = |rng: &mut fastrand::Rng, scale: f32| (rng.u32(0..16) as f32) * scale / 16.0;
        let mut decided = [0usize; 2];
        for _ in 0..4000 {
            let mut cell = CellOutliers::new();
            for _ in 0..rng.usize(1..=MAX_CELL_OUTLIERS) {
                let q = [0.0, 0.0, 0.0].map(|_: f32| coarse(&mut rng, 3.0) - 1.0);
                cell.push(q);
            }
            let p = [
                coarse(&mut rng, 1.0),
                coarse(&mut rng, 1.0),
                coarse(&mut rng, 2.0),
            ];
            for m in 1..=2.min(cell.len) {
                let general = cell.m_nearest_sum(p, m) <= m as f32;
                assert_eq!(
                    cell.near_enough(p, m),
                    general,
                    "m {m}, {} points",
                    cell.len
                );
                decided[usize::from(general)] += 1;
            }
            // The general sum decides as the sum of the m smallest of all distances, sorted.
            let lanes: Vec<Vec4> = cell.squared_distances(p).collect();
            let mut sorted: Vec<f32> = lanes.iter().flat_map(|d| d.to_array()).collect();
            sorted.sort_by(f32::total_cmp);
            for m in 1..=8.min(cell.len) {
                let brute = sorted[..m].iter().sum::<f32>() <= m as f32;
                assert_eq!(cell.m_nearest_sum(p, m) <= m as f32, brute, "m {m}");
            }
            let (mut first, mut second) = (Vec4::INFINITY, Vec4::INFINITY);
            for &d2 in &lanes {
                second = second.min(first.max(d2));
                first = first.min(d2);
            }
            assert_eq!(two_smallest(first, second), (sorted[0], sorted[1]));
        }
        // Both answers are common, so the agreement is not one-sided.
        assert!(decided.iter().all(|&n| n > 500), "{decided:?}");
    }
}
