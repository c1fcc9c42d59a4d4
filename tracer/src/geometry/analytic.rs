//! Analytic quadrics: pbrt's sphere, disk and cylinder with their z and phi limits. Rays are
//! intersected in object space; hits and samples are returned in world space.

use std::f32::consts::TAU;

use glam::{Affine3A, Mat3, Mat4, Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;

use crate::math::{atan2, Frame};
use crate::shape::Geometry;

use super::hit::{SurfaceHit, SurfaceSample};

#[derive(Clone, Copy, Debug)]
enum Quadric {
    /// `theta_z_min` > `theta_z_max`: theta is measured from +z, so the lower z limit has the
    /// larger angle (pbrt's convention, which makes v grow from bottom to top).
    Sphere {
        radius: f32,
        z_min: f32,
        z_max: f32,
        theta_z_min: f32,
        theta_z_max: f32,
        phi_max: f32,
    },
    Disk {
        height: f32,
        radius: f32,
        inner_radius: f32,
        phi_max: f32,
    },
    Cylinder {
        radius: f32,
        z_min: f32,
        z_max: f32,
        phi_max: f32,
    },
}

/// Where a ray meets a quadric, in object space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct QuadricHit {
    pub t: f32,
    p: Vec3A,
    phi: f32,
}

/// A sphere, disk or cylinder placed in the world.
#[derive(Clone, Debug)]
pub struct AnalyticShape {
    pub(crate) shape: u32,
    quadric: Quadric,
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
    /// None for a degenerate shape (non-positive radius, empty z or phi range, singular or
    /// non-finite transform) or a geometry that is not a quadric.
    pub(crate) fn new(
        shape: u32,
        geometry: &Geometry,
        object_to_world: &Mat4,
        reverse_orientation: bool,
    ) -> Option<Self> {
        let phi_range = |degrees: f32| {
            let phi = degrees.clamp(0.0, 360.0).to_radians();
            (phi > 0.0).then_some(phi)
        };
        let quadric = match *geometry {
            Geometry::Sphere { radius, phimax, .. } => {
                (radius > 0.0 && radius.is_finite()).then_some(())?;
                let (z_min, z_max) = geometry.sphere_z_range()?;
                (z_min < z_max).then_some(())?;
                Quadric::Sphere {
                    radius,
                    z_min,
                    z_max,
                    theta_z_min: libm::acosf((z_min / radius).clamp(-1.0, 1.0)),
                    theta_z_max: libm::acosf((z_max / radius).clamp(-1.0, 1.0)),
                    phi_max: phi_range(phimax)?,
                }
            }
            Geometry::Disk {
                height,
                radius,
                inner_radius,
                phimax,
            } => {
                let valid = radius > 0.0
                    && radius.is_finite()
                    && height.is_finite()
                    && (0.0..radius).contains(&inner_radius);
                valid.then_some(())?;
                Quadric::Disk {
                    height,
                    radius,
                    inner_radius,
                    phi_max: phi_range(phimax)?,
                }
            }
            Geometry::Cylinder {
                radius,
                zmin,
                zmax,
                phimax,
            } => {
                let (z_min, z_max) = (zmin.min(zmax), zmin.max(zmax));
                let valid = radius > 0.0 && radius.is_finite() && z_min < z_max;
                (valid && z_min.is_finite() && z_max.is_finite()).then_some(())?;
                Quadric::Cylinder {
                    radius,
                    z_min,
                    z_max,
                    phi_max: phi_range(phimax)?,
                }
            }
            Geometry::Mesh(_) | Geometry::Plane { .. } => return None,
        };
        let object_to_world = Affine3A::from_mat4(*object_to_world);
        let linear = Mat3::from(object_to_world.matrix3);
        let det = linear.determinant();
        (det != 0.0 && det.is_finite() && object_to_world.is_finite()).then_some(())?;
        Some(Self {
            shape,
            quadric,
            object_to_world,
            world_to_object: crate::math::affine_inverse(&object_to_world),
            normal_to_world: linear.inverse().transpose(),
            linear_transpose: linear.transpose(),
            abs_det: det.abs(),
            orientation: if reverse_orientation { -1.0 } else { 1.0 },
        })
    }

    pub(crate) fn world_bounds(&self) -> Aabb {
        let (lo, hi) = match self.quadric {
            Quadric::Sphere {
                radius,
                z_min,
                z_max,
                ..
            }
            | Quadric::Cylinder {
                radius,
                z_min,
                z_max,
                ..
            } => (
                Vec3::new(-radius, -radius, z_min),
                Vec3::new(radius, radius, z_max),
            ),
            Quadric::Disk { height, radius, .. } => (
                Vec3::new(-radius, -radius, height),
                Vec3::new(radius, radius, height),
            ),
        };
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
        match self.quadric {
            Quadric::Sphere {
                radius,
                z_min,
                z_max,
                phi_max,
                ..
            } => {
                let a = d.length_squared();
                let b = 2.0 * d.dot(o);
                let c = o.length_squared() - radius * radius;
                let closest = o - (b / (2.0 * a)) * d;
                let (t0, t1) = quadratic_roots(a, b, c, radius, closest.length())?;
                // A whole sphere clips nothing: the traversal needs no point on it.
                let (cut_low, cut_high) = (z_min > -radius, z_max < radius);
                let whole = !cut_low && !cut_high && !cut_in_phi(phi_max);
                [t0, t1].into_iter().find(|&t| {
                    if !(t > 0.0 && t < tmax) {
                        return false;
                    }
                    if whole {
                        return true;
                    }
                    let p = self.surface_point(o, d, t);
                    let clipped = (cut_low && p.z < z_min)
                        || (cut_high && p.z > z_max)
                        || beyond_phi(p, phi_max);
                    !clipped
                })
            }
            Quadric::Disk {
                height,
                radius,
                inner_radius,
                phi_max,
            } => {
                if d.z == 0.0 {
                    return None;
                }
                let t = (height - o.z) / d.z;
                if !(t > 0.0 && t < tmax) {
                    return None;
                }
                let p = self.surface_point(o, d, t);
                let dist2 = p.x * p.x + p.y * p.y;
                if dist2 > radius * radius || dist2 < inner_radius * inner_radius {
                    return None;
                }
                (!beyond_phi(p, phi_max)).then_some(t)
            }
            Quadric::Cylinder {
                radius,
                z_min,
                z_max,
                phi_max,
            } => {
                let a = d.x * d.x + d.y * d.y;
                if a == 0.0 {
                    return None;
                }
                let b = 2.0 * (d.x * o.x + d.y * o.y);
                let c = o.x * o.x + o.y * o.y - radius * radius;
                let f = b / (2.0 * a);
                let closest = glam::Vec2::new(o.x - f * d.x, o.y - f * d.y);
                let (t0, t1) = quadratic_roots(a, b, c, radius, closest.length())?;
                [t0, t1].into_iter().find(|&t| {
                    if !(t > 0.0 && t < tmax) {
                        return false;
                    }
                    let p = self.surface_point(o, d, t);
                    p.z >= z_min && p.z <= z_max && !beyond_phi(p, phi_max)
                })
            }
        }
    }

    /// The point at distance `t` along the object-space ray (`o`, `d`), moved onto the surface:
    /// the point [`Self::intersect`] tests a root's clipping at.
    fn surface_point(&self, o: Vec3A, d: Vec3A, t: f32) -> Vec3A {
        let mut p = o + t * d;
        match self.quadric {
            Quadric::Sphere { radius, .. } => {
                // Reproject onto the surface to undo the error of o + t d.
                p *= radius / p.length();
                if p.x == 0.0 && p.y == 0.0 {
                    p.x = 1e-5 * radius;
                }
            }
            Quadric::Disk { height, .. } => p.z = height,
            Quadric::Cylinder { radius, .. } => {
                let scale = radius / (p.x * p.x + p.y * p.y).sqrt();
                p.x *= scale;
                p.y *= scale;
            }
        }
        p
    }

    /// The quadric hit at `t`, a distance [`Self::intersect`] returned for this world-space
    /// ray: the shading data without solving for the root again.
    pub(crate) fn hit_at(&self, origin: Vec3A, dir: Vec3A, t: f32) -> QuadricHit {
        let o = self.world_to_object.transform_point3a(origin);
        let d = self.world_to_object.transform_vector3a(dir);
        let p = self.surface_point(o, d, t);
        QuadricHit {
            t,
            p,
            phi: phi_of(p),
        }
    }

    pub(crate) fn hit(&self, hit: QuadricHit, prim: u32) -> SurfaceHit {
        let QuadricHit { t, p, phi } = hit;
        let (uv, dpdu, dpdv, n) = match self.quadric {
            Quadric::Sphere {
                radius,
                theta_z_min,
                theta_z_max,
                phi_max,
                ..
            } => {
                let theta = libm::acosf((p.z / radius).clamp(-1.0, 1.0));
                let v = (theta - theta_z_min) / (theta_z_max - theta_z_min);
                // dp/dtheta = (z cos phi, z sin phi, -r sin theta), with r sin theta = rho,
                // cos phi = x / rho, sin phi = y / rho (no trigonometry on the hot path; at a
                // pole it is not finite and the fallback below takes over).
                let rho = (p.x * p.x + p.y * p.y).sqrt();
                let dpdtheta = Vec3A::new(p.z * p.x / rho, p.z * p.y / rho, -rho);
                (
                    Vec2::new(phi / phi_max, v),
                    u_tangent(p, phi_max),
                    (theta_z_max - theta_z_min) * dpdtheta,
                    p / radius,
                )
            }
            Quadric::Disk {
                radius,
                inner_radius,
                phi_max,
                ..
            } => {
                let r_hit = (p.x * p.x + p.y * p.y).sqrt();
                let v = (radius - r_hit) / (radius - inner_radius);
                let dpdv = Vec3A::new(p.x, p.y, 0.0) * ((inner_radius - radius) / r_hit);
                (
                    Vec2::new(phi / phi_max, v),
                    u_tangent(p, phi_max),
                    dpdv,
                    Vec3A::Z,
                )
            }
            Quadric::Cylinder {
                radius,
                z_min,
                z_max,
                phi_max,
            } => {
                let v = (p.z - z_min) / (z_max - z_min);
                let n = Vec3A::new(p.x / radius, p.y / radius, 0.0);
                let dpdv = Vec3A::new(0.0, 0.0, z_max - z_min);
                (Vec2::new(phi / phi_max, v), u_tangent(p, phi_max), dpdv, n)
            }
        };
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

    fn object_area(&self) -> f32 {
        match self.quadric {
            Quadric::Sphere {
                radius,
                z_min,
                z_max,
                phi_max,
                ..
            } => phi_max * radius * (z_max - z_min),
            Quadric::Disk {
                radius,
                inner_radius,
                phi_max,
                ..
            } => phi_max * 0.5 * (radius * radius - inner_radius * inner_radius),
            Quadric::Cylinder {
                radius,
                z_min,
                z_max,
                phi_max,
            } => (z_max - z_min) * radius * phi_max,
        }
    }

    /// World-space area: exact under similarity transforms, otherwise the object area scaled
    /// by |det|^(2/3) (used only to estimate a light's power).
    pub fn area(&self) -> f32 {
        self.object_area() * libm::powf(self.abs_det, 2.0 / 3.0)
    }

    /// A point sampled uniformly by object-space area; `pdf_area` is the density in world
    /// space (it varies over the surface under a non-uniform scale).
    pub fn sample(&self, u: Vec2) -> SurfaceSample {
        let (p, n) = match self.quadric {
            Quadric::Sphere {
                radius,
                z_min,
                z_max,
                phi_max,
                ..
            } => {
                // Archimedes: z uniform gives uniform area on a sphere zone.
                let z = z_min + u.x * (z_max - z_min);
                let rho = (radius * radius - z * z).max(0.0).sqrt();
                let (sin, cos) = libm::sincosf(u.y * phi_max);
                let p = Vec3A::new(rho * cos, rho * sin, z);
                (p, p / radius)
            }
            Quadric::Disk {
                height,
                radius,
                inner_radius,
                phi_max,
            } => {
                let r2 = inner_radius * inner_radius;
                let rho = (r2 + u.x * (radius * radius - r2)).sqrt();
                let (sin, cos) = libm::sincosf(u.y * phi_max);
                (Vec3A::new(rho * cos, rho * sin, height), Vec3A::Z)
            }
            Quadric::Cylinder {
                radius,
                z_min,
                z_max,
                phi_max,
            } => {
                let z = z_min + u.x * (z_max - z_min);
                let (sin, cos) = libm::sincosf(u.y * phi_max);
                (
                    Vec3A::new(radius * cos, radius * sin, z),
                    Vec3A::new(cos, sin, 0.0),
                )
            }
        };
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
        (self.linear_transpose * n).length() / (self.object_area() * self.abs_det)
    }

    /// Centre and radius when this is a whole sphere under a similarity transform, where
    /// light sampling can pick directions in the cone the sphere subtends.
    pub fn whole_sphere(&self) -> Option<(Vec3, f32)> {
        let Quadric::Sphere {
            radius,
            z_min,
            z_max,
            phi_max,
            ..
        } = self.quadric
        else {
            return None;
        };
        let whole = z_min <= -radius && z_max >= radius && phi_max >= TAU;
        let m = self.linear_transpose;
        let gram = m * m.transpose();
        let s2 = gram.x_axis.x;
        let similar = (gram - Mat3::from_diagonal(Vec3::splat(s2)))
            .to_cols_array()
            .iter()
            .all(|e| e.abs() <= 1e-4 * s2);
        (whole && similar).then(|| (self.object_to_world.translation.into(), radius * s2.sqrt()))
    }

    /// +1 when the front side is the outside, -1 under ReverseOrientation.
    pub fn orientation(&self) -> f32 {
        self.orientation
    }
}

/// Roots of a t^2 + b t + c with the discriminant computed as pbrt-v4 does,
/// 4a (r + l)(r - l) with l the distance from the centre to the closest point on the ray,
/// which loses far less precision than b^2 - 4ac for distant or grazing rays.
fn quadratic_roots(a: f32, b: f32, c: f32, radius: f32, closest: f32) -> Option<(f32, f32)> {
    let discrim = 4.0 * a * (radius + closest) * (radius - closest);
    if discrim < 0.0 || a == 0.0 {
        return None;
    }
    let root = discrim.sqrt();
    let q = if b < 0.0 {
        -0.5 * (b - root)
    } else {
        -0.5 * (b + root)
    };
    let (t0, t1) = (q / a, c / q);
    Some(if t0 > t1 { (t1, t0) } else { (t0, t1) })
}

/// Whether a quadric swept through `phi_max` is cut by it: a full turn clips nothing, as
/// [`phi_of`] is at most TAU (the intersection tests skip the azimuth then).
fn cut_in_phi(phi_max: f32) -> bool {
    phi_max < TAU
}

/// Whether `p` lies past `phi_max` in azimuth, on a quadric cut short of a full turn (without
/// an atan2 on a whole one).
fn beyond_phi(p: Vec3A, phi_max: f32) -> bool {
    cut_in_phi(phi_max) && phi_of(p) > phi_max
}

/// The azimuth of `p` about z, in [0, TAU].
fn phi_of(p: Vec3A) -> f32 {
    let phi = atan2(p.y, p.x);
    if phi < 0.0 {
        phi + TAU
    } else {
        phi
    }
}

/// d p / d u for a surface swept around z with u = phi / phi_max.
fn u_tangent(p: Vec3A, phi_max: f32) -> Vec3A {
    Vec3A::new(-phi_max * p.y, phi_max * p.x, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The intersection tests skip the azimuth of a shape swept through a full turn: that
    /// must clip nothing, so no azimuth may exceed a full turn as the scene gives it (360
    /// degrees), even just below the +x axis where it wraps.
    #[test]
    fn a_full_turn_clips_no_azimuth() {
        let full_turn = 360.0f32.to_radians();
        assert!(!cut_in_phi(full_turn));
        assert!(cut_in_phi(359.99f32.to_radians()));
        for k in 0u32..255 {
            let below_x = -f32::from_bits(1 + k * 0x0040_0000).min(1e-3);
            for p in [
                Vec3A::new(1.0, below_x, 0.0),
                Vec3A::new(-1.0, below_x, 0.0),
            ] {
                assert!(phi_of(p) <= full_turn, "{p}: {}", phi_of(p));
            }
        }
    }
}
