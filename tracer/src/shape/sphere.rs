//! `Shape "sphere"`: pbrt's sphere about the object-space origin, cut to a z range and a sweep
//! in azimuth, intersected exactly.
//!
//! | parameter | default |
//! |---|---|
//! | `radius` | 1 |
//! | `zmin`, `zmax` | -radius, radius (clamped to the sphere, in either order) |
//! | `phimax` | 360 (degrees) |

use std::f32::consts::TAU;

use glam::{Mat4, Vec2, Vec3, Vec3A};

use super::kind::{mean_area_scale, ExactSurface, Placement, ShapeKind, SurfaceFrame};
use super::revolved::{
    beyond_phi, cut_in_phi, exact_sweep, phi_of, quadratic_roots, sweep, u_tangent, DEFAULT_PHIMAX,
    DEFAULT_RADIUS,
};
use crate::diag::SourcePos;
use crate::mesh::grid::grid_mesh;
use crate::mesh::TriangleMesh;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub radius: f32,
    pub zmin: f32,
    pub zmax: f32,
    /// Degrees.
    pub phimax: f32,
}

/// `Shape "sphere"` with LuxRender's defaults.
pub fn read(
    _ctx: &mut dyn ParseContext,
    _ty: &str,
    params: &ParamList,
    _pos: &SourcePos,
) -> Result<Sphere, ParseError> {
    let radius = params.float("radius", DEFAULT_RADIUS)?;
    Ok(Sphere {
        radius,
        zmin: params.float("zmin", -radius)?,
        zmax: params.float("zmax", radius)?,
        phimax: params.float("phimax", DEFAULT_PHIMAX)?,
    })
}

impl Sphere {
    /// zmin and zmax in order, clamped to [-|radius|, |radius|]: the range the renderer, the
    /// area of an emitting sphere and the tessellation all use.
    pub fn z_range(&self) -> (f32, f32) {
        let r = self.radius.abs();
        let (zmin, zmax) = (self.zmin, self.zmax);
        (zmin.min(zmax).clamp(-r, r), zmin.max(zmax).clamp(-r, r))
    }
}

impl ShapeKind for Sphere {
    type Surface = SphereSurface;

    fn placement(&self) -> Placement<'_, SphereSurface> {
        Placement::Exact(SphereSurface::new(self))
    }

    fn world_area(&self, object_to_world: &Mat4) -> f32 {
        let (z0, z1) = self.z_range();
        sweep(self.phimax) * self.radius.abs() * (z1 - z0) * mean_area_scale(object_to_world)
    }

    fn tessellate(&self, segments: u32) -> Option<TriangleMesh> {
        let n_phi = segments.max(3);
        let radius = self.radius;
        let (z0, z1) = self.z_range();
        let (th0, th1) = (libm::acosf(z0 / radius), libm::acosf(z1 / radius));
        let phimax = sweep(self.phimax);
        let point = move |u: f32, v: f32| {
            let (phi, theta) = (u * phimax, th0 + v * (th1 - th0));
            let n = Vec3::new(
                libm::sinf(theta) * libm::cosf(phi),
                libm::sinf(theta) * libm::sinf(phi),
                libm::cosf(theta),
            );
            (n * radius, n)
        };
        Some(grid_mesh(n_phi, (n_phi / 2).max(2), &point))
    }
}

/// A sphere ready to intersect. `theta_z_min` > `theta_z_max`: theta is measured from +z, so
/// the lower z limit has the larger angle (pbrt's convention, which makes v grow from bottom to
/// top).
#[derive(Clone, Copy, Debug)]
pub struct SphereSurface {
    radius: f32,
    z_min: f32,
    z_max: f32,
    theta_z_min: f32,
    theta_z_max: f32,
    phi_max: f32,
}

impl SphereSurface {
    /// None for a non-positive or non-finite radius, an empty z range or an empty sweep.
    fn new(sphere: &Sphere) -> Option<Self> {
        let radius = sphere.radius;
        (radius > 0.0 && radius.is_finite()).then_some(())?;
        let (z_min, z_max) = sphere.z_range();
        (z_min < z_max).then_some(())?;
        Some(Self {
            radius,
            z_min,
            z_max,
            theta_z_min: libm::acosf((z_min / radius).clamp(-1.0, 1.0)),
            theta_z_max: libm::acosf((z_max / radius).clamp(-1.0, 1.0)),
            phi_max: exact_sweep(sphere.phimax)?,
        })
    }
}

impl ExactSurface for SphereSurface {
    fn bounds(&self) -> (Vec3, Vec3) {
        let r = self.radius;
        (Vec3::new(-r, -r, self.z_min), Vec3::new(r, r, self.z_max))
    }

    #[inline]
    fn intersect(&self, o: Vec3A, d: Vec3A, tmax: f32) -> Option<f32> {
        let Self {
            radius,
            z_min,
            z_max,
            phi_max,
            ..
        } = *self;
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
            let clipped =
                (cut_low && p.z < z_min) || (cut_high && p.z > z_max) || beyond_phi(p, phi_max);
            !clipped
        })
    }

    #[inline]
    fn surface_point(&self, o: Vec3A, d: Vec3A, t: f32) -> Vec3A {
        let mut p = o + t * d;
        // Reproject onto the surface to undo the error of o + t d.
        p *= self.radius / p.length();
        if p.x == 0.0 && p.y == 0.0 {
            p.x = 1e-5 * self.radius;
        }
        p
    }

    fn shading(&self, p: Vec3A) -> SurfaceFrame {
        let Self {
            radius,
            theta_z_min,
            theta_z_max,
            phi_max,
            ..
        } = *self;
        let theta = libm::acosf((p.z / radius).clamp(-1.0, 1.0));
        let v = (theta - theta_z_min) / (theta_z_max - theta_z_min);
        // dp/dtheta = (z cos phi, z sin phi, -r sin theta), with r sin theta = rho,
        // cos phi = x / rho, sin phi = y / rho (no trigonometry on the hot path; at a
        // pole it is not finite and the geometry's fallback takes over).
        let rho = (p.x * p.x + p.y * p.y).sqrt();
        let dpdtheta = Vec3A::new(p.z * p.x / rho, p.z * p.y / rho, -rho);
        SurfaceFrame {
            uv: Vec2::new(phi_of(p) / phi_max, v),
            dpdu: u_tangent(p, phi_max),
            dpdv: (theta_z_max - theta_z_min) * dpdtheta,
            n: p / radius,
        }
    }

    fn area(&self) -> f32 {
        self.phi_max * self.radius * (self.z_max - self.z_min)
    }

    fn sample(&self, u: Vec2) -> (Vec3A, Vec3A) {
        let Self {
            radius,
            z_min,
            z_max,
            phi_max,
            ..
        } = *self;
        // Archimedes: z uniform gives uniform area on a sphere zone.
        let z = z_min + u.x * (z_max - z_min);
        let rho = (radius * radius - z * z).max(0.0).sqrt();
        let (sin, cos) = libm::sincosf(u.y * phi_max);
        let p = Vec3A::new(rho * cos, rho * sin, z);
        (p, p / radius)
    }

    fn whole_sphere_radius(&self) -> Option<f32> {
        let whole = self.z_min <= -self.radius && self.z_max >= self.radius && self.phi_max >= TAU;
        whole.then_some(self.radius)
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::*;

    #[test]
    fn tessellated_sphere_is_round_outward_and_has_the_right_area() {
        let sphere = Sphere {
            radius: 2.0,
            zmin: -2.0,
            zmax: 2.0,
            phimax: 360.0,
        };
        let mesh = sphere.tessellate(128).unwrap();
        assert!(mesh
            .positions
            .iter()
            .all(|p| (p.length() - 2.0).abs() < 1e-5));
        let mut area = 0.0;
        for tri in &mesh.indices {
            let [a, b, c] = tri.map(|i| mesh.positions[i as usize]);
            let cross = (b - a).cross(c - a);
            assert!(cross.dot(a + b + c) > 0.0, "triangle {tri:?} faces inwards");
            area += 0.5 * cross.length();
        }
        let exact = 4.0 * PI * 4.0;
        assert!((area / exact - 1.0).abs() < 1e-3, "area {area} vs {exact}");
    }

    /// The poles' collapsed triangles are left out: moved to where a small lamp hangs, every
    /// triangle left still has an area (a zero-area one stops LuxCore sampling the light).
    #[test]
    fn tessellated_small_sphere_has_no_degenerate_triangle_in_world_space() {
        let sphere = Sphere {
            radius: 0.04,
            zmin: -0.04,
            zmax: 0.04,
            phimax: 360.0,
        };
        let mesh = sphere.tessellate(256).unwrap();
        let at = Vec3::new(0.4, -0.3, 1.9);
        let mut area = 0.0;
        for tri in &mesh.indices {
            let [a, b, c] = tri.map(|i| mesh.positions[i as usize] + at);
            let cross = (b - a).cross(c - a);
            assert!(cross.length() > 0.0, "triangle {tri:?} has no area");
            area += 0.5 * cross.length();
        }
        let exact = 4.0 * PI * 0.04 * 0.04;
        assert!((area / exact - 1.0).abs() < 1e-3, "area {area} vs {exact}");
    }
}
