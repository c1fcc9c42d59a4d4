//! An environment map's sampling tables for surfaces that face one way. A reflecting surface
//! takes light from the hemisphere it faces only, weighed by the cosine there; a table over the
//! map's luminance alone sends half its samples behind the surface, and among the others
//! weighs grazing light as much as light from straight above. Under an even, room-like map
//! (Captain Falcon's) that made the light samples worse than the cosine-weighted BSDF samples
//! they are weighed against, and the map's direct light most of that scene's noise.
//!
//! So the directions a surface may face are split into [`FACING_BINS`] bins (a cube's faces,
//! [`BINS_PER_EDGE`] x [`BINS_PER_EDGE`] each), and each bin has a table of the map's luminance
//! times the clamped cosine about the bin's centre, over blocks of the map's distribution cells
//! (at most [`MAX_FACING_CELLS`] a table); inside a block, a cell is picked by its luminance
//! alone. The density of a direction is exact for the bin of the facing direction it was asked
//! for, so samples and the densities MIS weighs them by agree; directions a bin's table gives no
//! density (just behind the bin's horizon, inside the surface's) are the BSDF samples' to find,
//! weighted in fully.

use glam::{Vec2, Vec3};

use super::distribution::{AliasTables, Distribution2D};
use crate::math::{bin_at, count_f32};

/// Bins along each edge of a cube face: 54 bins, a surface normal within some 20 degrees of
/// its bin's centre.
const BINS_PER_EDGE: usize = 3;

/// Bins of facing directions.
pub(super) const FACING_BINS: usize = 6 * BINS_PER_EDGE * BINS_PER_EDGE;

/// The most blocks a bin's table holds (16 bytes each: 32 KiB a table, 1.7 MiB for all): the
/// tables of the surfaces in view stay in cache.
pub(super) const MAX_FACING_CELLS: usize = 2048;

/// The largest f32 below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// The facing tables of one map.
pub(super) struct FacingTables {
    /// The map's distribution cells across and down.
    cells: (usize, usize),
    /// Cells along a block's side.
    block: usize,
    /// Blocks across and down (the last ones partial where `block` does not divide).
    blocks: (usize, usize),
    /// Per bin, over blocks.
    tables: Vec<Distribution2D>,
    /// Per block, over its `block` x `block` cells (row by row; cells past the map's edge
    /// weigh nothing).
    within: AliasTables,
}

impl FacingTables {
    /// `func` holds the map's distribution cells (`across` x `down`, row 0 at v = 0, each
    /// weighed as its sampling density wants); `direction(uv)` is the light-space direction at
    /// map coordinates `uv`.
    pub fn new(func: &[f32], across: usize, down: usize, direction: impl Fn(Vec2) -> Vec3) -> Self {
        let (across, down) = (across.max(1), down.max(1));
        let mut block = 1;
        while across.div_ceil(block) * down.div_ceil(block) > MAX_FACING_CELLS {
            block *= 2;
        }
        let blocks = (across.div_ceil(block), down.div_ceil(block));
        let (blocks_across, blocks_down) = blocks;
        let at = |x: usize, y: usize| func.get(y * across + x).copied().unwrap_or(0.0).max(0.0);

        let mut within = Vec::with_capacity(blocks_across * blocks_down * block * block);
        // Per block, its cells' weights and centre directions.
        let mut members: Vec<Vec<(f32, Vec3)>> = Vec::with_capacity(blocks_across * blocks_down);
        for by in 0..blocks_down {
            for bx in 0..blocks_across {
                let mut member = Vec::with_capacity(block * block);
                for jy in 0..block {
                    for jx in 0..block {
                        let (x, y) = (bx * block + jx, by * block + jy);
                        if x < across && y < down {
                            let f = at(x, y);
                            within.push(f);
                            let centre = Vec2::new(
                                (count_f32(x) + 0.5) / count_f32(across),
                                (count_f32(y) + 0.5) / count_f32(down),
                            );
                            if f > 0.0 {
                                member.push((f, direction(centre)));
                            }
                        } else {
                            within.push(0.0);
                        }
                    }
                }
                members.push(member);
            }
        }
        let tables = (0..FACING_BINS)
            .map(|bin| {
                let n = bin_centre(bin);
                let weights: Vec<f32> = members
                    .iter()
                    .map(|member| member.iter().map(|&(f, d)| f * d.dot(n).max(0.0)).sum())
                    .collect();
                Distribution2D::new(&weights, blocks_across, blocks_down)
            })
            .collect();
        Self {
            cells: (across, down),
            block,
            blocks,
            tables,
            within: AliasTables::new(&within, block * block),
        }
    }

    /// A point of the map in [0, 1)^2 for a surface facing light-space direction `facing`, and
    /// its density there. `reading(row, column)` is called with the distribution cell whose
    /// record is about to be read, the cell picked unless its alias is: a caller that reads its
    /// own data at the picked point can start loading it while the record's cache miss is
    /// under way (as [`Distribution2D::sample`]'s `reading`).
    pub fn sample(
        &self,
        facing: Vec3,
        u: Vec2,
        reading: impl FnOnce(usize, usize),
    ) -> Option<(Vec2, f32)> {
        let (blocks_across, blocks_down) = self.blocks;
        let (uv, block_pdf) = self.tables[facing_bin(facing)].sample(u, |_, _| {})?;
        let (bx, fx) = split(uv.x, blocks_across);
        let (by, fy) = split(uv.y, blocks_down);
        let block = self.block;
        let (entry, density, within_x) = self.within.sample(by * blocks_across + bx, fx, |slot| {
            reading(by * block + slot / block, bx * block + slot % block);
        });
        let (x, y) = (
            bx * self.block + entry % self.block,
            by * self.block + entry / self.block,
        );
        let (across, down) = self.cells;
        // Only an all-zero table (uniform) reaches past the edge.
        if x >= across || y >= down {
            return None;
        }
        let uv = Vec2::new(
            ((count_f32(x) + within_x) / count_f32(across)).min(ONE_BELOW),
            ((count_f32(y) + fy) / count_f32(down)).min(ONE_BELOW),
        );
        Some((uv, block_pdf * density * self.cell_scale()))
    }

    /// The density [`Self::sample`] gives map point `uv` for a surface facing `facing`.
    pub fn pdf(&self, facing: Vec3, uv: Vec2) -> f32 {
        let (across, down) = self.cells;
        let (x, y) = (
            bin_at(uv.x * count_f32(across), across),
            bin_at(uv.y * count_f32(down), down),
        );
        let (bx, by) = (x / self.block, y / self.block);
        let entry = (y % self.block) * self.block + x % self.block;
        self.tables[facing_bin(facing)].cell_pdf(by, bx)
            * self.within.density(by * self.blocks.0 + bx, entry)
            * self.cell_scale()
    }

    /// A block's density times a cell's density within it, to a density over the map: the
    /// block's share of the map's area over its cells' (partial blocks hold fewer cells).
    fn cell_scale(&self) -> f32 {
        let (across, down) = self.cells;
        let (blocks_across, blocks_down) = self.blocks;
        (count_f32(across) * count_f32(down))
            / (count_f32(blocks_across * blocks_down) * count_f32(self.block * self.block))
    }
}

/// `t` in [0, 1) over `n` equal parts: the part, and where in it `t` lies, in [0, 1).
fn split(t: f32, n: usize) -> (usize, f32) {
    let scaled = t * count_f32(n);
    let part = bin_at(scaled, n);
    (part, (scaled - count_f32(part)).clamp(0.0, ONE_BELOW))
}

/// The two axes of a cube face across the major axis `axis`.
fn face_axes(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// The bin of a facing direction (any length; zero or NaN land in some bin): its cube face,
/// then the cell of the face its projection falls in.
pub(super) fn facing_bin(d: Vec3) -> usize {
    let a = d.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let major = d[axis];
    let face = 2 * axis + usize::from(major < 0.0);
    let (b, c) = face_axes(axis);
    let cell = |t: f32| {
        let t = (t / a[axis] + 1.0) * 0.5 * BINS_PER_EDGE as f32;
        bin_at(t.max(0.0), BINS_PER_EDGE)
    };
    (face * BINS_PER_EDGE + cell(d[b])) * BINS_PER_EDGE + cell(d[c])
}

/// The unit direction through the centre of bin `bin`'s cell of the cube.
pub(super) fn bin_centre(bin: usize) -> Vec3 {
    let (face, rest) = (
        bin / (BINS_PER_EDGE * BINS_PER_EDGE),
        bin % (BINS_PER_EDGE * BINS_PER_EDGE),
    );
    let (axis, negative) = (face / 2, face % 2 == 1);
    let (b, c) = face_axes(axis);
    let coord = |i: usize| (2.0 * (i as f32 + 0.5) / BINS_PER_EDGE as f32) - 1.0;
    let mut d = Vec3::ZERO;
    d[axis] = if negative { -1.0 } else { 1.0 };
    d[b] = coord(rest / BINS_PER_EDGE);
    d[c] = coord(rest % BINS_PER_EDGE);
    d.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample reports the distribution cell whose record it reads (for the caller's
    /// prefetch): the cell it picks unless the alias is taken, so always in the picked cell's
    /// block, and the picked cell itself where every cell keeps its slot (an even map).
    #[test]
    fn a_sample_reports_the_cell_it_reads() {
        // 8,192 cells: blocks of 2 x 2, so the block and the cell within it both matter.
        let (across, down) = (128, 64);
        let direction = |uv: Vec2| {
            let (theta, phi) = (uv.y * std::f32::consts::PI, uv.x * std::f32::consts::TAU);
            Vec3::new(
                libm::sinf(theta) * libm::cosf(phi),
                libm::sinf(theta) * libm::sinf(phi),
                libm::cosf(theta),
            )
        };
        let even = vec![1.0; across * down];
        let varied: Vec<f32> = (0..across * down).map(|i| (i % 7 + i % 5) as f32).collect();
        let mut rng = fastrand::Rng::with_seed(9);
        for (func, exact) in [(even, true), (varied, false)] {
            let tables = FacingTables::new(&func, across, down, direction);
            assert_eq!(tables.block, 2);
            for _ in 0..20_000 {
                let facing = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5);
                let u = Vec2::new(rng.f32(), rng.f32());
                let mut read = None;
                let Some((uv, _)) =
                    tables.sample(facing, u, |row, column| read = Some((row, column)))
                else {
                    continue;
                };
                let picked = (
                    (uv.y * down as f32) as usize,
                    (uv.x * across as f32) as usize,
                );
                let (row, column) = read.expect("a record was read");
                assert_eq!(
                    (row / 2, column / 2),
                    (picked.0 / 2, picked.1 / 2),
                    "{u} {facing}"
                );
                if exact {
                    assert_eq!((row, column), picked, "{u} {facing}");
                }
            }
        }
    }

    #[test]
    fn every_direction_falls_in_the_bin_whose_centre_is_near_it() {
        for bin in 0..FACING_BINS {
            assert_eq!(facing_bin(bin_centre(bin)), bin);
            assert_eq!(
                facing_bin(3.0 * bin_centre(bin)),
                bin,
                "length does not matter"
            );
        }
        let mut rng = fastrand::Rng::with_seed(5);
        let mut worst = 1.0f32;
        for _ in 0..100_000 {
            let d = Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, rng.f32() - 0.5).normalize();
            let bin = facing_bin(d);
            let cos = d.dot(bin_centre(bin));
            worst = worst.min(cos);
            // No other centre is much nearer (a face's cells are not quite equal in angle).
            let nearest = (0..FACING_BINS)
                .map(|b| d.dot(bin_centre(b)))
                .fold(-1.0, f32::max);
            assert!(
                cos >= nearest - 0.1,
                "{d}: bin {bin} at cos {cos}, nearest {nearest}"
            );
        }
        // Within 30 degrees of its bin's centre.
        assert!(worst > libm::cosf(30f32.to_radians()), "worst cos {worst}");
        // Hostile input lands in a bin.
        assert!(facing_bin(Vec3::ZERO) < FACING_BINS);
        assert!(facing_bin(Vec3::NAN) < FACING_BINS);
    }
}
