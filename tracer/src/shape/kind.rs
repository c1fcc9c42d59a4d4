//! What every shape kind says of itself, for the dispatch [`super`]'s kind list generates: how
//! the scene geometry places it, its world-space area and its triangles for consumers that take
//! only triangles; and, for the kinds intersected exactly, their object-space surface. A leaf of
//! the shape family, so the shape files never import `shape/mod.rs`.

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec2, Vec3, Vec3A};

use crate::mesh::TriangleMesh;

pub trait ShapeKind {
    /// The object-space surface [`crate::geometry`] intersects exactly ([`NotExact`] for the
    /// kinds that are triangles or unbounded).
    type Surface: ExactSurface;

    /// How the scene geometry places the shape.
    fn placement(&self) -> Placement<'_, Self::Surface>;

    /// The world-space area under `object_to_world` (infinite for an unbounded shape), for
    /// area-light normalisation.
    fn world_area(&self, object_to_world: &Mat4) -> f32;

    /// Object-space triangles wound so the outward side is the front, with YAT's uv
    /// parameterisation, `segments` around: for consumers that take only triangles (the
    /// LuxCore exporter). None for the kinds that are triangles already or unbounded.
    fn tessellate(&self, _segments: u32) -> Option<TriangleMesh> {
        None
    }
}

/// How a shape enters the scene geometry.
#[derive(Clone, Debug)]
pub enum Placement<'a, S> {
    /// Triangles, flattened into world space, one BVH primitive each.
    Triangles(&'a Arc<TriangleMesh>),
    /// One BVH primitive intersected exactly; None for a degenerate shape, which is skipped.
    Exact(Option<S>),
    /// An infinite plane through the object-space origin with this unit normal, outside the
    /// BVH.
    Unbounded(Vec3),
}

impl<'a, S> Placement<'a, S> {
    /// The same placement with the exact surface turned into `T`.
    pub fn map<T>(self, f: impl FnOnce(S) -> T) -> Placement<'a, T> {
        match self {
            Placement::Triangles(mesh) => Placement::Triangles(mesh),
            Placement::Exact(surface) => Placement::Exact(surface.map(f)),
            Placement::Unbounded(normal) => Placement::Unbounded(normal),
        }
    }
}

/// A surface intersected exactly, in object space. Rays are not renormalised by the transform,
/// so a distance `t` is the same in object and world space.
pub trait ExactSurface: Copy {
    /// Object-space bounds (low and high corners).
    fn bounds(&self) -> (Vec3, Vec3);

    /// The first t in (0, tmax) where the object-space ray `o + t d` meets the surface.
    fn intersect(&self, o: Vec3A, d: Vec3A, tmax: f32) -> Option<f32>;

    /// The point at distance `t` along the object-space ray, moved onto the surface: the point
    /// [`ExactSurface::intersect`] tests a root's clipping at.
    fn surface_point(&self, o: Vec3A, d: Vec3A, t: f32) -> Vec3A;

    /// At a surface point: uv, the object-space tangents along u and v, and the outward unit
    /// normal.
    fn shading(&self, p: Vec3A) -> SurfaceFrame;

    /// Object-space area.
    fn area(&self) -> f32;

    /// A point (and its outward unit normal) uniformly distributed over the object-space area.
    fn sample(&self, u: Vec2) -> (Vec3A, Vec3A);

    /// The radius when this is a whole sphere about the origin (light sampling then picks
    /// directions in the cone it subtends).
    fn whole_sphere_radius(&self) -> Option<f32> {
        None
    }
}

/// What [`ExactSurface::shading`] tells of a surface point, in object space.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceFrame {
    pub uv: Vec2,
    pub dpdu: Vec3A,
    pub dpdv: Vec3A,
    pub n: Vec3A,
}

/// The exact surface of the kinds that have none: no value exists, so nothing is called.
#[derive(Clone, Copy, Debug)]
pub enum NotExact {}

impl ExactSurface for NotExact {
    fn bounds(&self) -> (Vec3, Vec3) {
        match *self {}
    }
    fn intersect(&self, _: Vec3A, _: Vec3A, _: f32) -> Option<f32> {
        match *self {}
    }
    fn surface_point(&self, _: Vec3A, _: Vec3A, _: f32) -> Vec3A {
        match *self {}
    }
    fn shading(&self, _: Vec3A) -> SurfaceFrame {
        match *self {}
    }
    fn area(&self) -> f32 {
        match *self {}
    }
    fn sample(&self, _: Vec2) -> (Vec3A, Vec3A) {
        match *self {}
    }
}

/// The mean area scale of a transform, |det|^(2/3): exact under similarity transforms, what
/// the area of an exact shape under a non-uniform scale is estimated with.
pub fn mean_area_scale(object_to_world: &Mat4) -> f32 {
    area_scale(Mat3::from_mat4(*object_to_world).determinant().abs())
}

/// [`mean_area_scale`] of a transform whose determinant has magnitude `abs_det`.
pub fn area_scale(abs_det: f32) -> f32 {
    libm::powf(abs_det, 2.0 / 3.0)
}
