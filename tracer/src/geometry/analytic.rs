//! The exactly intersected shapes placed in the world: each kind's object-space surface
//! ([`crate::shape::ExactSurface`]) under its transform. Rays are intersected in object space;
//! hits and samples are returned in world space.

use glam::{Affine3A, Mat3, Mat4, Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;

use crate::math::Frame;
use crate::shape::kind::area_scale;
use crate::shape::{AnalyticSurface, ExactSurface, SurfaceFrame};

use super::hit::{SurfaceHit, SurfaceSample};

/// An exact shape placed in the world.
#[derive(Clone, Debug)]
pub struct AnalyticShape {
    pub(crate) shape: u32,
    surface: AnalyticSurface,
    object_to_world: Affine3A,
    world_to_object: Affine3A,
    normal_to_world: Mat3,
    /// Transpose of the linear part, for the area-density change of the transform.
    linear_transpose: Mat3,
    abs_det: f32,
    /// -1 under ReverseOrientation. The object-space outward normal transformed by the inverse
    /// transpose stays outward whatever the handedness of the transform, which is what the
    /// LuxRender/pbrt rule (cross product of world-space tangents, flipped when the transform
    /// swaps handedness) amounts to.
    orientation: f32,
}

impl AnalyticShape {
    /// None for a singular or non-finite transform.
    pub(crate) fn new(
        shape: u32,
        surface: AnalyticSurface,
        object_to_world: &Mat4,
        reverse_orientation: bool,
    ) -> Option<Self> {
        let object_to_world = Affine3A::from_mat4(*object_to_world);
        let linear = Mat3::from(object_to_world.matrix3);
        let det = linear.determinant();
        (det != 0.0 && det.is_finite() && object_to_world.is_finite()).then_some(())?;
        Some(Self {
            shape,
            surface,
            object_to_world,
            world_to_object: crate::math::affine_inverse(&object_to_world),
            normal_to_world: linear.inverse().transpose(),
            linear_transpose: linear.transpose(),
            abs_det: det.abs(),
            orientation: if reverse_orientation { -1.0 } else { 1.0 },
        })
    }

    pub(crate) fn world_bounds(&self) -> Aabb {
        let (lo, hi) = self.surface.bounds();
        let mut bounds = Aabb::INVALID;
        for corner in 0..8 {
            let c = Vec3::select(
                glam::BVec3::new(corner & 1 != 0, corner & 2 != 0, corner & 4 != 0),
                hi,
                lo,
            );
            bounds.extend(self.object_to_world.transform_point3a(c.into()));
        }
        bounds
    }

    /// The first hit with t in (0, tmax) of the world-space ray.
    #[inline]
    pub(crate) fn intersect(&self, origin: Vec3A, dir: Vec3A, tmax: f32) -> Option<f32> {
        // The direction is not renormalised, so t is the same in both spaces.
        let o = self.world_to_object.transform_point3a(origin);
        let d = self.world_to_object.transform_vector3a(dir);
        self.surface.intersect(o, d, tmax)
    }

    /// The hit at `t`, a distance [`Self::intersect`] returned for this world-space ray: the
    /// shading data at the point its test accepted, without solving for the root again.
    pub(crate) fn hit(&self, origin: Vec3A, dir: Vec3A, t: f32, prim: u32) -> SurfaceHit {
        let o = self.world_to_object.transform_point3a(origin);
        let d = self.world_to_object.transform_vector3a(dir);
        let p = self.surface.surface_point(o, d, t);
        let SurfaceFrame { uv, dpdu, dpdv, n } = self.surface.shading(p);
        let ng = self.world_normal(n);
        let dpdu = Vec3::from(self.object_to_world.transform_vector3a(dpdu));
        let dpdv = Vec3::from(self.object_to_world.transform_vector3a(dpdv));
        let fallback = Frame::from_normal(ng);
        let usable = |d: Vec3| d.length_squared() > 0.0 && d.is_finite();
        SurfaceHit {
            t,
            p: self.object_to_world.transform_point3a(p).into(),
            ng,
            ns: ng,
            uv,
            dpdu: if usable(dpdu) { dpdu } else { fallback.s },
            // At a pole (or a disk's centre) the v tangent vanishes.
            dpdv: if usable(dpdv) { dpdv } else { fallback.t },
            shape: self.shape,
            prim,
        }
    }

    fn world_normal(&self, n_object: Vec3A) -> Vec3 {
        (self.normal_to_world * Vec3::from(n_object)).normalize() * self.orientation
    }

    /// World-space area: exact under similarity transforms, otherwise the object area scaled
    /// by |det|^(2/3) (used only to estimate a light's power).
    pub fn area(&self) -> f32 {
        self.surface.area() * area_scale(self.abs_det)
    }

    /// A point sampled uniformly by object-space area; `pdf_area` is the density in world
    /// space (it varies over the surface under a non-uniform scale).
    pub fn sample(&self, u: Vec2) -> SurfaceSample {
        let (p, n) = self.surface.sample(u);
        let n = self.world_normal(n);
        SurfaceSample {
            p: self.object_to_world.transform_point3a(p).into(),
            n,
            pdf_area: self.pdf_area(n),
        }
    }

    /// The density of [`Self::sample`] at a point with world normal `n`: the object-space
    /// density divided by the transform's area scale |det M| / |M^T n|.
    pub fn pdf_area(&self, n: Vec3) -> f32 {
        (self.linear_transpose * n).length() / (self.surface.area() * self.abs_det)
    }

    /// Centre and radius when this is a whole sphere under a similarity transform, where
    /// light sampling can pick directions in the cone the sphere subtends.
    pub fn whole_sphere(&self) -> Option<(Vec3, f32)> {
        let radius = self.surface.whole_sphere_radius()?;
        let m = self.linear_transpose;
        let gram = m * m.transpose();
        let s2 = gram.x_axis.x;
        let similar = (gram - Mat3::from_diagonal(Vec3::splat(s2)))
            .to_cols_array()
            .iter()
            .all(|e| e.abs() <= 1e-4 * s2);
        similar.then(|| (self.object_to_world.translation.into(), radius * s2.sqrt()))
    }

    /// +1 when the front side is the outside, -1 under ReverseOrientation.
    pub fn orientation(&self) -> f32 {
        self.orientation
    }
}
