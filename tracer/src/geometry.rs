//! World-space geometry and ray queries: every shape of the scene (triangles and analytic
//! shapes) in one obvhs BVH.
//!
//! OWNER: geometry helper. Interface used by the integrator and lights; keep the signatures.

use glam::{Vec2, Vec3};

use crate::desc::SceneDesc;
use crate::math::Ray;

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
    /// Index into `SceneDesc::shapes` (material, area light).
    pub shape: u32,
    /// Primitive within the scene's geometry (for light sampling pdfs).
    pub prim: u32,
}

/// A point sampled on a primitive's surface.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceSample {
    pub p: Vec3,
    pub n: Vec3,
    /// Density with respect to area.
    pub pdf_area: f32,
}

pub struct SceneGeometry {}

impl SceneGeometry {
    pub fn build(_desc: &SceneDesc) -> Self {
        todo!("geometry helper")
    }

    pub fn triangle_count(&self) -> usize {
        todo!("geometry helper")
    }

    /// Closest hit with t in (0, tmax).
    pub fn intersect(&self, _ray: &Ray, _tmax: f32) -> Option<SurfaceHit> {
        todo!("geometry helper")
    }

    /// Whether anything blocks the ray within (0, tmax).
    pub fn occluded(&self, _ray: &Ray, _tmax: f32) -> bool {
        todo!("geometry helper")
    }
}
