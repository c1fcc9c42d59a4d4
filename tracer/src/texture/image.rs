//! Bilinear lookups into a decoded image with LuxRender's wrap modes.
//!
//! Row convention (checked in LuxRender 1.x's source): its image reader stores rows top to
//! bottom (it reads FreeImage's bottom-up scanlines in reverse) and its MIPMap looks up texel
//! row t x height, so t = 0 is the top row of the file. Blender's exporter writes vscale -1 and
//! vdelta 1, i.e. t = 1 - v, and Blender's v = 0 is the bottom of the image, so the texture
//! comes out upright.

use glam::{Vec2, Vec3};

use crate::desc::Wrap;
use crate::image_io::RgbImage;

/// Texel coordinates beyond this are clamped before conversion to integers (far outside any
/// image, and small enough that neighbours never overflow).
const MAX_COORD: f32 = 1.0e9;

/// The value of texel (x, y) (possibly outside the image) under `wrap`, times `gain`. The
/// black and white borders are not scaled by the gain (as in LuxRender).
fn texel(image: &RgbImage, x: i64, y: i64, wrap: Wrap, gain: f32) -> Vec3 {
    let (w, h) = (i64::from(image.width), i64::from(image.height));
    let inside = (0..w).contains(&x) && (0..h).contains(&y);
    let (x, y) = match wrap {
        Wrap::Repeat => (x.rem_euclid(w), y.rem_euclid(h)),
        Wrap::Clamp => (x.clamp(0, w - 1), y.clamp(0, h - 1)),
        Wrap::Black if !inside => return Vec3::ZERO,
        Wrap::White if !inside => return Vec3::ONE,
        Wrap::Black | Wrap::White => (x, y),
    };
    image.texel((y * w + x) as usize) * gain
}

/// Bilinear interpolation of the four texels around (s, t), with texel centres at half
/// integers.
pub fn lookup(image: &RgbImage, st: Vec2, wrap: Wrap, gain: f32) -> Vec3 {
    let texels = image.width as usize * image.height as usize;
    if texels == 0 || image.len() < texels || !st.is_finite() {
        return Vec3::ZERO;
    }
    let x = (st.x * image.width as f32 - 0.5).clamp(-MAX_COORD, MAX_COORD);
    let y = (st.y * image.height as f32 - 0.5).clamp(-MAX_COORD, MAX_COORD);
    let (x0, y0) = (x.floor(), y.floor());
    let (dx, dy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let at = |i: i64, j: i64| texel(image, x0 + i, y0 + j, wrap, gain);
    let top = at(0, 0) * (1.0 - dx) + at(1, 0) * dx;
    let bottom = at(0, 1) * (1.0 - dx) + at(1, 1) * dx;
    top * (1.0 - dy) + bottom * dy
}
