//! The range of world space geometry may occupy.

use glam::Vec3;

/// World coordinates beyond this are left out of the scene: the BVH quantises child boxes
/// relative to their parent's extent, and boxes of extent 2 x 3e38 overflow to infinity and NaN
/// (obvhs then builds a broken tree, or panics in its checks). 1e15 is far beyond any scene's
/// scale (32-bit floats resolve 0.1 m only up to 1e6 m), and a box of this extent still has a
/// finite surface area summed over 2^26 primitives.
pub const MAX_WORLD_COORD: f32 = 1.0e15;

/// Whether a world-space point is inside the range geometry may occupy (NaN is not).
pub(crate) fn within_world(p: Vec3) -> bool {
    p.abs().cmple(Vec3::splat(MAX_WORLD_COORD)).all()
}
