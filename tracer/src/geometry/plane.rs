//! The course's infinite plane. It has no finite bounding box, so it lives outside the BVH and
//! every ray tests the (few) planes directly.

use glam::{Affine3A, Mat3, Mat4, Vec2, Vec3, Vec3A};

use crate::math::Frame;

use super::hit::SurfaceHit;

pub(crate) struct InfinitePlane {
    pub shape: u32,
    point: Vec3A,
    /// Front-side unit normal in world space.
    n: Vec3A,
    world_to_object: Affine3A,
    object_to_world: Affine3A,
    /// In-plane object-space axes that define uv.
    axes: Frame,
}

impl InfinitePlane {
    /// None when the normal or the transform is degenerate.
    pub fn new(
        shape: u32,
        normal: Vec3,
        object_to_world: &Mat4,
        reverse_orientation: bool,
    ) -> Option<Self> {
        let normal = normal.try_normalize()?;
        let object_to_world = Affine3A::from_mat4(*object_to_world);
        let linear = Mat3::from(object_to_world.matrix3);
        let det = linear.determinant();
        (det != 0.0
            && det.is_finite()
            && object_to_world.is_finite()
            && super::world_range::within_world(object_to_world.translation.into()))
        .then_some(())?;
        let orientation = if reverse_orientation { -1.0 } else { 1.0 };
        let n = (linear.inverse().transpose() * normal).try_normalize()? * orientation;
        Some(Self {
            shape,
            point: object_to_world.translation,
            n: n.into(),
            world_to_object: crate::math::affine_inverse(&object_to_world),
            object_to_world,
            axes: Frame::from_normal(normal),
        })
    }

    #[inline]
    pub fn intersect(&self, origin: Vec3A, dir: Vec3A, tmax: f32) -> Option<f32> {
        let t = (self.point - origin).dot(self.n) / dir.dot(self.n);
        (t > 0.0 && t < tmax).then_some(t)
    }

    pub fn hit(&self, origin: Vec3A, dir: Vec3A, t: f32, prim: u32) -> SurfaceHit {
        let p = origin + t * dir;
        // Project onto the plane to undo the error of o + t d.
        let p = p - (p - self.point).dot(self.n) * self.n;
        let local = Vec3::from(self.world_to_object.transform_point3a(p));
        let n = Vec3::from(self.n);
        SurfaceHit {
            t,
            p: p.into(),
            ng: n,
            ns: n,
            uv: Vec2::new(local.dot(self.axes.s), local.dot(self.axes.t)),
            dpdu: self.object_to_world.transform_vector3(self.axes.s),
            dpdv: self.object_to_world.transform_vector3(self.axes.t),
            shape: self.shape,
            prim,
        }
    }
}
