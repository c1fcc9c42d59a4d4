//! What a ray query returns and what light sampling draws on a surface: the leaf the shape
//! files and the scene geometry share.

use glam::{Vec2, Vec3};

/// A ray's closest hit, with everything shading needs.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    pub t: f32,
    pub p: Vec3,
    /// Geometric normal, unit, on the shape's front side (ReverseOrientation applied).
    pub ng: Vec3,
    /// Shading normal (interpolated vertex normals, or `ng`), unit, flipped to ng's side.
    pub ns: Vec3,
    pub uv: Vec2,
    /// Surface tangent along u (world space, not normalised; any tangent when uv is absent).
    pub dpdu: Vec3,
    /// Surface tangent along v (world space, not normalised; `ng x dpdu` when uv is absent):
    /// with `dpdu`, what a bump map's height derivatives are taken along.
    pub dpdv: Vec3,
    /// Index into `SceneDesc::shapes` (material, area light).
    pub shape: u32,
    /// Primitive within the scene's geometry (for light sampling pdfs).
    pub prim: u32,
}

/// A ray's closest primitive as the traversal finds it, before any shading data is read
/// ([`super::SceneGeometry::surface`] turns it into a [`SurfaceHit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimHit {
    /// As [`SurfaceHit::prim`].
    pub prim: u32,
    pub t: f32,
    /// Barycentric weights of a triangle's second and third vertices (0 for other shapes).
    pub(crate) b1: f32,
    pub(crate) b2: f32,
}

/// A point sampled on a primitive's surface.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceSample {
    pub p: Vec3,
    pub n: Vec3,
    /// Density with respect to area.
    pub pdf_area: f32,
}
