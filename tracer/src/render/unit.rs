//! What a unit of work is and what rendering it reports: the types the film, the unit plan and
//! every node share. It imports only the leaf [`Layers`].

use super::layers::Layers;

/// Side in pixels of the square blocks an adaptive unit's mask switches on and off: blocks
/// start at multiples of it from the unit's corner. (Why 4, not 8: bench/RESULTS.md, "Session
/// 10: 4x4-pixel blocks".)
pub const BLOCK_SIZE: u32 = 4;

/// Blocks per side of a mask: 8 x 8 blocks, one bit each in a u64.
const MASK_SIDE_BLOCKS: u32 = 8;

/// The widest or tallest unit with a block mask.
pub const MAX_MASKED_SIDE: u32 = MASK_SIDE_BLOCKS * BLOCK_SIZE;

/// A tile of pixels x a range of sample indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WorkUnit {
    /// Position in the plan (of its round, when adaptive); results are keyed by it.
    pub index: u32,
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    pub sample_start: u32,
    pub sample_end: u32,
    /// None: every pixel of the tile, and no half sums (a uniform render). Some(mask): an
    /// adaptive unit, at most [`MAX_MASKED_SIDE`] a side, rendering only the blocks of
    /// [`BLOCK_SIZE`] pixels whose bit is set (bit `by * 8 + bx` for the block `bx` blocks
    /// right of and `by` below the corner) and reporting the sums of its odd-index samples too.
    pub mask: Option<u64>,
}

impl WorkUnit {
    /// The tile's pixels (without the filter's border: [`FilmFrame::region`]).
    pub fn tile(&self) -> PixelRect {
        PixelRect {
            x0: self.x0,
            y0: self.y0,
            x1: self.x1,
            y1: self.y1,
        }
    }

    /// Pixels of the tile (its sample buffer covers the tile and the filter's border around
    /// it: [`FilmFrame::region`]).
    pub fn pixel_count(&self) -> usize {
        ((self.x1 - self.x0) * (self.y1 - self.y0)) as usize
    }

    /// Whether the unit renders the pixel (x, y) of its tile.
    pub fn renders(&self, x: u32, y: u32) -> bool {
        self.mask.is_none_or(|mask| {
            let bit = (y - self.y0) / BLOCK_SIZE * MASK_SIDE_BLOCKS + (x - self.x0) / BLOCK_SIZE;
            bit < 64 && mask >> bit & 1 == 1
        })
    }

    /// The blocks of the tile, row by row: each one's top-left pixel and its bit in a mask (the
    /// one owner of the mask's layout; blocks in the last column and row may be cut short by
    /// the tile's edge).
    pub fn tile_blocks(&self) -> impl Iterator<Item = (u32, u32, u64)> + '_ {
        (self.y0..self.y1)
            .step_by(BLOCK_SIZE as usize)
            .flat_map(move |y| {
                (self.x0..self.x1)
                    .step_by(BLOCK_SIZE as usize)
                    .map(move |x| (x, y))
            })
            .map(|(x, y)| {
                let bit =
                    (y - self.y0) / BLOCK_SIZE * MASK_SIDE_BLOCKS + (x - self.x0) / BLOCK_SIZE;
                (x, y, 1u64.checked_shl(bit).unwrap_or(0))
            })
    }

    /// Pixels the unit renders: the tile's, or those of its active blocks.
    pub fn active_pixel_count(&self) -> usize {
        match self.mask {
            None => self.pixel_count(),
            Some(mask) => self
                .tile_blocks()
                .filter(|&(_, _, bit)| mask & bit != 0)
                .map(|(x, y, _)| {
                    ((self.x1 - x).min(BLOCK_SIZE) * (self.y1 - y).min(BLOCK_SIZE)) as usize
                })
                .sum(),
        }
    }

    /// Camera samples the unit takes.
    pub fn sample_count(&self) -> u64 {
        self.active_pixel_count() as u64 * u64::from(self.sample_end - self.sample_start)
    }
}

/// A rectangle of film pixels, [x0, x1) x [y0, y1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl PixelRect {
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    pub fn pixel_count(&self) -> usize {
        (self.x1 - self.x0) as usize * (self.y1 - self.y0) as usize
    }
}

/// What decides which pixels a unit's samples reach: the film's size, how many pixels the
/// pixel filter reaches beyond the pixel a sample lies in, per axis (`filter.rs`), and whether
/// units carry light splats besides. Every node derives it from the settings and the scene
/// alike (`RenderSettings::film_frame`), so a unit's buffer has the same extent everywhere and
/// a peer's buffer is checked exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FilmFrame {
    pub width: u32,
    pub height: u32,
    /// Pixels a sample's filter reaches to the left and right (`border[0]`), above and below
    /// (`border[1]`) of its own pixel.
    pub border: [u32; 2],
    /// Whether the render's units carry light splats (`film::LightSplats`): contributions of
    /// light subpaths connected to the camera, which land anywhere on the film rather than in
    /// the unit's region. Only a bidirectional integrator makes them; a film of such a frame
    /// keeps their sums (and takes no adaptive render: `Film::adaptive`). False for every
    /// render until that integrator derives it from the scene in `RenderSettings::film_frame`,
    /// the one place every node's frame comes from.
    pub light_splats: bool,
    /// The layers the units carry besides radiance and weight ([`Layers`]): alpha when a file
    /// the scene's Film writes has an alpha channel.
    pub layers: Layers,
}

impl FilmFrame {
    /// A frame whose filter reaches no neighbour (a box of half-width 0.5, or a synthetic
    /// film in tests), without light splats or layers.
    pub fn unbordered(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            border: [0, 0],
            light_splats: false,
            layers: Layers::NONE,
        }
    }

    /// Blocks per axis between two blocks of the same source plane of an adaptive film: the
    /// most blocks a pixel's samples come from along an axis, those within `border` of it,
    /// `ceil(2 border / BLOCK_SIZE) + 1` (2 for the common filters, which reach at most half a
    /// block: a pixel then gets samples from its own block and one neighbour per axis, of the
    /// other parity; 5 for the widest, `filter::MAX_BORDER`).
    pub fn plane_period(&self) -> u32 {
        (2 * self.border[0].max(self.border[1])).div_ceil(BLOCK_SIZE) + 1
    }

    /// Source planes of an adaptive film: a sample's sums go to the plane of the block it was
    /// taken in, so no pixel mixes two blocks' samples in one sum (see `Film::pixel`).
    pub fn source_planes(&self) -> usize {
        (self.plane_period() * self.plane_period()) as usize
    }

    /// The source plane of the block holding pixel (x, y).
    pub fn source_plane(&self, x: u32, y: u32) -> usize {
        let k = self.plane_period();
        (x / BLOCK_SIZE % k + k * (y / BLOCK_SIZE % k)) as usize
    }

    /// The entries of the film's light splat sums: none without light splats; else a plane of
    /// the film's pixels for the total and one for each light group kept apart, indexed
    /// `plane * width * height + y * width + x` (plane 0 the total, `1 + g` group `g`'s).
    pub fn splat_entries(&self) -> u64 {
        if self.light_splats {
            u64::from(self.width)
                * u64::from(self.height)
                * (1 + u64::from(self.layers.light_groups))
        } else {
            0
        }
    }

    /// The pixels `unit`'s samples reach: its tile grown by the border, clipped to the film;
    /// its sample buffer covers exactly these.
    pub fn region(&self, unit: &WorkUnit) -> PixelRect {
        let [bx, by] = self.border;
        PixelRect {
            x0: unit.x0.saturating_sub(bx),
            y0: unit.y0.saturating_sub(by),
            x1: unit.x1.saturating_add(bx).min(self.width),
            y1: unit.y1.saturating_add(by).min(self.height),
        }
    }
}

/// Counters a unit's render reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UnitStats {
    pub samples: u64,
    pub rays: u64,
    /// NaN or infinite samples dropped instead of entering the film.
    pub dropped: u64,
}

impl std::ops::AddAssign for UnitStats {
    fn add_assign(&mut self, o: Self) {
        self.samples += o.samples;
        self.rays += o.rays;
        self.dropped += o.dropped;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No pixel gets samples from two blocks of one source plane, for every border a filter
    /// can have, and the planes are as few as that allows along an axis.
    #[test]
    fn a_pixel_gets_at_most_one_block_per_source_plane() {
        for border in 0..=8u32 {
            let frame = FilmFrame {
                border: [border, border.saturating_sub(1)],
                ..FilmFrame::unbordered(64, 64)
            };
            let k = frame.plane_period();
            for y in 0..64u32 {
                for x in 0..64u32 {
                    let mut seen = vec![None; frame.source_planes()];
                    let near = |v: u32, b: u32| v.saturating_sub(b)..=(v + b).min(63);
                    for sy in near(y, frame.border[1]) {
                        for sx in near(x, frame.border[0]) {
                            let block = (sx / BLOCK_SIZE, sy / BLOCK_SIZE);
                            let plane = frame.source_plane(sx, sy);
                            assert!(
                                seen[plane].is_none_or(|b| b == block),
                                "border {border}: pixel ({x}, {y}) gets blocks {:?} and \
                                 {block:?} in plane {plane}",
                                seen[plane]
                            );
                            seen[plane] = Some(block);
                        }
                    }
                }
            }
            // Along an axis a pixel's samples come from k blocks in a row for some pixel.
            let blocks_reached = (0..64u32)
                .map(|x| {
                    let lo = x.saturating_sub(border) / BLOCK_SIZE;
                    let hi = (x + border).min(63) / BLOCK_SIZE;
                    hi - lo + 1
                })
                .max()
                .unwrap();
            assert_eq!(k, blocks_reached, "border {border}");
        }
        let planes = |border| {
            FilmFrame {
                border: [border, 0],
                ..FilmFrame::unbordered(1, 1)
            }
            .source_planes()
        };
        // The seed scenes' blackmanharris of half-width 2, the default one of 4, the widest.
        assert_eq!((planes(2), planes(4), planes(8)), (4, 9, 25));
    }
}
