//! Bilinear lookups into a decoded image with LuxRender's wrap modes.
//!
//! Row convention (checked in LuxRender 1.x's source): its image reader stores rows top to
//! bottom (it reads FreeImage's bottom-up scanlines in reverse) and its MIPMap looks up texel
//! row t x height, so t = 0 is the top row of the file. Blender's exporter writes vscale -1 and
//! vdelta 1, i.e. t = 1 - v, and Blender's v = 0 is the bottom of the image, so the texture
//! comes out upright.

use glam::{Vec2, Vec3};

use crate::desc::Wrap;
use crate::image_io::{Edge, RgbImage};

/// Bilinear interpolation of the texels around (s, t) under `wrap`, texels times `gain`. The
/// black and white borders are not scaled by the gain (as in LuxRender).
pub fn lookup(image: &RgbImage, st: Vec2, wrap: Wrap, gain: f32) -> Vec3 {
    let (edge, border) = match wrap {
        Wrap::Repeat => (Edge::Repeat, Vec3::ZERO),
        Wrap::Clamp => (Edge::Clamp, Vec3::ZERO),
        Wrap::Black => (Edge::Outside, Vec3::ZERO),
        Wrap::White => (Edge::Outside, Vec3::ONE),
    };
    let (inside, outside_weight) = image.bilinear(st, edge, edge);
    inside * gain + border * outside_weight
}
