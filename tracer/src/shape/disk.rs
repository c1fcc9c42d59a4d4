//! `Shape "disk"`: pbrt's disk (or annulus) at a height on z, facing +z, cut to a sweep in
//! azimuth, intersected exactly.
//!
//! | parameter | default |
//! |---|---|
//! | `height` | 0 |
//! | `radius` | 1 |
//! | `innerradius` | 0 |
//! | `phimax` | 360 (degrees) |

use glam::{Mat4, Vec2, Vec3, Vec3A};

use super::kind::{mean_area_scale, ExactSurface, Placement, ShapeKind, SurfaceFrame};
use super::revolved::{
    beyond_phi, exact_sweep, phi_of, sweep, u_tangent, DEFAULT_PHIMAX, DEFAULT_RADIUS,
};
use crate::diag::SourcePos;
use crate::mesh::grid::grid_mesh;
use crate::mesh::TriangleMesh;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// Height of a disk above the object-space origin when the file does not say.
pub const DEFAULT_HEIGHT: f32 = 0.0;
/// Inner radius of a disk when the file does not say.
pub const DEFAULT_INNER_RADIUS: f32 = 0.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disk {
    pub height: f32,
    pub radius: f32,
    pub inner_radius: f32,
    /// Degrees.
    pub phimax: f32,
}

/// `Shape "disk"` with LuxRender's defaults.
pub fn read(
    _ctx: &mut dyn ParseContext,
    _ty: &str,
    params: &ParamList,
    _pos: &SourcePos,
) -> Result<Disk, ParseError> {
    Ok(Disk {
        height: params.float("height", DEFAULT_HEIGHT)?,
        radius: params.float("radius", DEFAULT_RADIUS)?,
        inner_radius: params.float("innerradius", DEFAULT_INNER_RADIUS)?,
        phimax: params.float("phimax", DEFAULT_PHIMAX)?,
    })
}

impl ShapeKind for Disk {
    type Surface = DiskSurface;

    fn placement(&self) -> Placement<'_, DiskSurface> {
        Placement::Exact(DiskSurface::new(self))
    }

    fn world_area(&self, object_to_world: &Mat4) -> f32 {
        let (r, r_in) = (self.radius, self.inner_radius);
        0.5 * sweep(self.phimax) * (r * r - r_in * r_in).abs() * mean_area_scale(object_to_world)
    }

    fn tessellate(&self, segments: u32) -> Option<TriangleMesh> {
        let Disk {
            height,
            radius,
            inner_radius,
            phimax,
        } = *self;
        let phimax = sweep(phimax);
        let point = move |u: f32, v: f32| {
            let (phi, r) = (u * phimax, radius - v * (radius - inner_radius));
            (
                Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), height),
                Vec3::Z,
            )
        };
        Some(grid_mesh(segments.max(3), 1, &point))
    }
}

/// A disk ready to intersect.
#[derive(Clone, Copy, Debug)]
pub struct DiskSurface {
    height: f32,
    radius: f32,
    inner_radius: f32,
    phi_max: f32,
}

impl DiskSurface {
    /// None for a non-positive or non-finite radius, an inner radius outside [0, radius), a
    /// non-finite height or an empty sweep.
    fn new(disk: &Disk) -> Option<Self> {
        let Disk {
            height,
            radius,
            inner_radius,
            phimax,
        } = *disk;
        let valid = radius > 0.0
            && radius.is_finite()
            && height.is_finite()
            && (0.0..radius).contains(&inner_radius);
        valid.then_some(())?;
        Some(Self {
            height,
            radius,
            inner_radius,
            phi_max: exact_sweep(phimax)?,
        })
    }
}

impl ExactSurface for DiskSurface {
    fn bounds(&self) -> (Vec3, Vec3) {
        let (r, h) = (self.radius, self.height);
        (Vec3::new(-r, -r, h), Vec3::new(r, r, h))
    }

    #[inline]
    fn intersect(&self, o: Vec3A, d: Vec3A, tmax: f32) -> Option<f32> {
        if d.z == 0.0 {
            return None;
        }
        let t = (self.height - o.z) / d.z;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        let p = self.surface_point(o, d, t);
        let dist2 = p.x * p.x + p.y * p.y;
        if dist2 > self.radius * self.radius || dist2 < self.inner_radius * self.inner_radius {
            return None;
        }
        (!beyond_phi(p, self.phi_max)).then_some(t)
    }

    #[inline]
    fn surface_point(&self, o: Vec3A, d: Vec3A, t: f32) -> Vec3A {
        let mut p = o + t * d;
        p.z = self.height;
        p
    }

    fn shading(&self, p: Vec3A) -> SurfaceFrame {
        let Self {
            radius,
            inner_radius,
            phi_max,
            ..
        } = *self;
        let r_hit = (p.x * p.x + p.y * p.y).sqrt();
        let v = (radius - r_hit) / (radius - inner_radius);
        SurfaceFrame {
            uv: Vec2::new(phi_of(p) / phi_max, v),
            dpdu: u_tangent(p, phi_max),
            dpdv: Vec3A::new(p.x, p.y, 0.0) * ((inner_radius - radius) / r_hit),
            n: Vec3A::Z,
        }
    }

    fn area(&self) -> f32 {
        let (r, r_in) = (self.radius, self.inner_radius);
        self.phi_max * 0.5 * (r * r - r_in * r_in)
    }

    fn sample(&self, u: Vec2) -> (Vec3A, Vec3A) {
        let r2 = self.inner_radius * self.inner_radius;
        let rho = (r2 + u.x * (self.radius * self.radius - r2)).sqrt();
        let (sin, cos) = libm::sincosf(u.y * self.phi_max);
        (Vec3A::new(rho * cos, rho * sin, self.height), Vec3A::Z)
    }
}
