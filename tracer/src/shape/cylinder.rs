//! `Shape "cylinder"`: pbrt's open cylinder about z, cut to a z range and a sweep in azimuth,
//! intersected exactly.
//!
//! | parameter | default |
//! |---|---|
//! | `radius` | 1 |
//! | `zmin`, `zmax` | -1, 1 (in either order) |
//! | `phimax` | 360 (degrees) |

use glam::{Mat4, Vec2, Vec3, Vec3A};

use super::kind::{mean_area_scale, ExactSurface, Placement, ShapeKind, SurfaceFrame};
use super::revolved::{
    beyond_phi, exact_sweep, phi_of, quadratic_roots, sweep, u_tangent, DEFAULT_PHIMAX,
    DEFAULT_RADIUS,
};
use crate::diag::SourcePos;
use crate::mesh::grid::grid_mesh;
use crate::mesh::TriangleMesh;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// The z range of a cylinder when the file does not say.
pub const DEFAULT_ZMIN: f32 = -1.0;
pub const DEFAULT_ZMAX: f32 = 1.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    pub radius: f32,
    pub zmin: f32,
    pub zmax: f32,
    /// Degrees.
    pub phimax: f32,
}

/// `Shape "cylinder"` with LuxRender's defaults.
pub fn read(
    _ctx: &mut dyn ParseContext,
    _ty: &str,
    params: &ParamList,
    _pos: &SourcePos,
) -> Result<Cylinder, ParseError> {
    Ok(Cylinder {
        radius: params.float("radius", DEFAULT_RADIUS)?,
        zmin: params.float("zmin", DEFAULT_ZMIN)?,
        zmax: params.float("zmax", DEFAULT_ZMAX)?,
        phimax: params.float("phimax", DEFAULT_PHIMAX)?,
    })
}

impl ShapeKind for Cylinder {
    type Surface = CylinderSurface;

    fn placement(&self) -> Placement<'_, CylinderSurface> {
        Placement::Exact(CylinderSurface::new(self))
    }

    fn world_area(&self, object_to_world: &Mat4) -> f32 {
        sweep(self.phimax)
            * self.radius.abs()
            * (self.zmax - self.zmin).abs()
            * mean_area_scale(object_to_world)
    }

    fn tessellate(&self, segments: u32) -> Option<TriangleMesh> {
        let Cylinder {
            radius,
            zmin,
            zmax,
            phimax,
        } = *self;
        let phimax = sweep(phimax);
        let point = move |u: f32, v: f32| {
            let phi = u * phimax;
            let n = Vec3::new(libm::cosf(phi), libm::sinf(phi), 0.0);
            (n * radius + Vec3::Z * (zmin + v * (zmax - zmin)), n)
        };
        Some(grid_mesh(segments.max(3), 1, &point))
    }
}

/// A cylinder ready to intersect.
#[derive(Clone, Copy, Debug)]
pub struct CylinderSurface {
    radius: f32,
    z_min: f32,
    z_max: f32,
    phi_max: f32,
}

impl CylinderSurface {
    /// None for a non-positive or non-finite radius, an empty or non-finite z range or an
    /// empty sweep.
    fn new(cylinder: &Cylinder) -> Option<Self> {
        let Cylinder {
            radius,
            zmin,
            zmax,
            phimax,
        } = *cylinder;
        let (z_min, z_max) = (zmin.min(zmax), zmin.max(zmax));
        let valid = radius > 0.0 && radius.is_finite() && z_min < z_max;
        (valid && z_min.is_finite() && z_max.is_finite()).then_some(())?;
        Some(Self {
            radius,
            z_min,
            z_max,
            phi_max: exact_sweep(phimax)?,
        })
    }
}

impl ExactSurface for CylinderSurface {
    fn bounds(&self) -> (Vec3, Vec3) {
        let r = self.radius;
        (Vec3::new(-r, -r, self.z_min), Vec3::new(r, r, self.z_max))
    }

    #[inline]
    fn intersect(&self, o: Vec3A, d: Vec3A, tmax: f32) -> Option<f32> {
        let a = d.x * d.x + d.y * d.y;
        if a == 0.0 {
            return None;
        }
        let b = 2.0 * (d.x * o.x + d.y * o.y);
        let c = o.x * o.x + o.y * o.y - self.radius * self.radius;
        let f = b / (2.0 * a);
        let closest = Vec2::new(o.x - f * d.x, o.y - f * d.y);
        let (t0, t1) = quadratic_roots(a, b, c, self.radius, closest.length())?;
        [t0, t1].into_iter().find(|&t| {
            if !(t > 0.0 && t < tmax) {
                return false;
            }
            let p = self.surface_point(o, d, t);
            p.z >= self.z_min && p.z <= self.z_max && !beyond_phi(p, self.phi_max)
        })
    }

    #[inline]
    fn surface_point(&self, o: Vec3A, d: Vec3A, t: f32) -> Vec3A {
        let mut p = o + t * d;
        let scale = self.radius / (p.x * p.x + p.y * p.y).sqrt();
        p.x *= scale;
        p.y *= scale;
        p
    }

    fn shading(&self, p: Vec3A) -> SurfaceFrame {
        let Self {
            radius,
            z_min,
            z_max,
            phi_max,
        } = *self;
        SurfaceFrame {
            uv: Vec2::new(phi_of(p) / phi_max, (p.z - z_min) / (z_max - z_min)),
            dpdu: u_tangent(p, phi_max),
            dpdv: Vec3A::new(0.0, 0.0, z_max - z_min),
            n: Vec3A::new(p.x / radius, p.y / radius, 0.0),
        }
    }

    fn area(&self) -> f32 {
        (self.z_max - self.z_min) * self.radius * self.phi_max
    }

    fn sample(&self, u: Vec2) -> (Vec3A, Vec3A) {
        let z = self.z_min + u.x * (self.z_max - self.z_min);
        let (sin, cos) = libm::sincosf(u.y * self.phi_max);
        (
            Vec3A::new(self.radius * cos, self.radius * sin, z),
            Vec3A::new(cos, sin, 0.0),
        )
    }
}
