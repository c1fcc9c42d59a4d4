//! The quadrics of pbrt-v1 and LuxRender that YAT renders as triangle meshes: `cone`,
//! `paraboloid` and `hyperboloid`, each a curve swept around the z axis, tessellated into
//! [`COLUMNS`] x [`ROWS`] quads with smooth normals and LuxRender's (u, v) (u along the sweep,
//! v along the curve).
//!
//! ```text
//! Shape "cone" "float radius" [1] "float height" [2]
//! Shape "paraboloid" "float radius" [1] "float zmin" [0] "float zmax" [1]
//! Shape "hyperboloid" "point p1" [1 0 0] "point p2" [0 1 1]
//! ```
//!
//! | type | parameter | default | meaning |
//! |---|---|---|---|
//! | all | `phimax` | 360 | sweep in degrees, clamped to [0, 360] |
//! | `cone` | `radius` | 1 | radius of the base, at z = 0 |
//! | `cone` | `radius2` | 0 | radius of the top; above 0 the cone is a frustum of height `height` |
//! | `cone` | `height` | 1 | height of the apex (or of the frustum's top) |
//! | `paraboloid` | `radius` | 1 | radius at `zmax`: x^2 + y^2 = radius^2 z / zmax |
//! | `paraboloid` | `zmin`, `zmax` | 0, 1 | the z range |
//! | `hyperboloid` | `p1`, `p2` | (0 0 0), (1 1 1) | the segment swept around z |
//!
//! The front is the side cross(dP/du, dP/dv) points to, as in LuxRender: outward for the cone
//! and the paraboloid.

use glam::{Mat3, Vec3};

use crate::mesh::grid::grid_mesh;
use crate::mesh::TriangleMesh;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// Sweep in degrees when the file does not say.
pub const DEFAULT_PHIMAX: f32 = 360.0;
/// A cone's base radius, top radius and height when the file does not say.
pub const DEFAULT_CONE_RADIUS: f32 = 1.0;
pub const DEFAULT_CONE_RADIUS2: f32 = 0.0;
pub const DEFAULT_CONE_HEIGHT: f32 = 1.0;
/// A paraboloid's radius and z range when the file does not say.
pub const DEFAULT_PARABOLOID_RADIUS: f32 = 1.0;
pub const DEFAULT_PARABOLOID_ZMIN: f32 = 0.0;
pub const DEFAULT_PARABOLOID_ZMAX: f32 = 1.0;
/// A hyperboloid's segment when the file does not say.
pub const DEFAULT_HYPERBOLOID_P1: Vec3 = Vec3::ZERO;
pub const DEFAULT_HYPERBOLOID_P2: Vec3 = Vec3::ONE;
/// Quads around the axis: the polygon's area is within 0.2% of the circle's.
pub const COLUMNS: u32 = 64;
/// Quads along the swept curve.
pub const ROWS: u32 = 32;

/// A swept quadric's parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum Quadric {
    /// From radius `radius` at z = 0 to `radius2` at z = `height`.
    Cone {
        radius: f32,
        radius2: f32,
        height: f32,
        phimax: f32,
    },
    Paraboloid {
        radius: f32,
        zmin: f32,
        zmax: f32,
        phimax: f32,
    },
    Hyperboloid {
        p1: Vec3,
        p2: Vec3,
        phimax: f32,
    },
}

impl Quadric {
    /// The quadric of `Shape "ty"`, or `None` when `ty` is not one.
    pub fn read(ty: &str, params: &ParamList) -> Result<Option<Self>, ParseError> {
        let phimax = params.float("phimax", DEFAULT_PHIMAX)?;
        let q = match ty {
            "cone" => Quadric::Cone {
                radius: params.float("radius", DEFAULT_CONE_RADIUS)?,
                radius2: params.float("radius2", DEFAULT_CONE_RADIUS2)?,
                height: params.float("height", DEFAULT_CONE_HEIGHT)?,
                phimax,
            },
            "paraboloid" => Quadric::Paraboloid {
                radius: params.float("radius", DEFAULT_PARABOLOID_RADIUS)?,
                zmin: params.float("zmin", DEFAULT_PARABOLOID_ZMIN)?,
                zmax: params.float("zmax", DEFAULT_PARABOLOID_ZMAX)?,
                phimax,
            },
            "hyperboloid" => Quadric::Hyperboloid {
                p1: params.vec3("p1", DEFAULT_HYPERBOLOID_P1)?,
                p2: params.vec3("p2", DEFAULT_HYPERBOLOID_P2)?,
                phimax,
            },
            _ => return Ok(None),
        };
        if let Quadric::Paraboloid { zmax, .. } = q {
            if zmax <= 0.0 {
                let p = params
                    .find("zmax")
                    .expect("only a given zmax is not positive");
                return Err(params.error(p, "a paraboloid's zmax must be above 0"));
            }
        }
        Ok(Some(q))
    }

    /// The sweep in radians.
    pub fn phimax(&self) -> f32 {
        let (Quadric::Cone { phimax, .. }
        | Quadric::Paraboloid { phimax, .. }
        | Quadric::Hyperboloid { phimax, .. }) = *self;
        phimax.clamp(0.0, 360.0).to_radians()
    }

    /// The swept curve at v in [0, 1], in the plane phi = 0 (the hyperboloid's segment
    /// wherever it is).
    pub fn curve(&self, v: f32) -> Vec3 {
        match *self {
            Quadric::Cone {
                radius,
                radius2,
                height,
                ..
            } => Vec3::new(radius + v * (radius2 - radius), 0.0, v * height),
            Quadric::Paraboloid {
                radius, zmin, zmax, ..
            } => {
                let z = zmin + v * (zmax - zmin);
                Vec3::new(radius * (z / zmax).max(0.0).sqrt(), 0.0, z)
            }
            Quadric::Hyperboloid { p1, p2, .. } => p1.lerp(p2, v),
        }
    }

    /// The surface at (u, v): the curve at v turned by u x phimax about z.
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        Mat3::from_rotation_z(u * self.phimax()) * self.curve(v)
    }

    /// The front-facing unit normal cross(dP/du, dP/dv) at (u, v), by central differences;
    /// where it vanishes (an apex on the axis) the normal of the nearest row inside.
    fn normal(&self, u: f32, v: f32) -> Vec3 {
        const STEP: f32 = 1.0e-3;
        for v in [v, v.clamp(STEP, 1.0 - STEP)] {
            let dpdu = self.point(u + STEP, v) - self.point(u - STEP, v);
            let dpdv = self.point(u, (v + STEP).min(1.0)) - self.point(u, (v - STEP).max(0.0));
            let n = dpdu.cross(dpdv);
            if n.length_squared() > 1.0e-20 {
                return n.normalize();
            }
        }
        Vec3::ZERO
    }

    /// The triangles, [`COLUMNS`] x [`ROWS`] quads.
    pub fn tessellate(&self) -> TriangleMesh {
        let surface = |u: f32, v: f32| (self.point(u, v), self.normal(u, v));
        let mut mesh = grid_mesh(COLUMNS, ROWS, &surface);
        if mesh
            .normals
            .as_ref()
            .is_some_and(|n| n.contains(&Vec3::ZERO))
        {
            // A sweep of 0 degrees or a curve on the axis: nothing to smooth.
            mesh.normals = None;
        }
        mesh
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    fn mesh_area(m: &TriangleMesh) -> f64 {
        m.indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// The area of a surface of revolution, phimax x the integral of rho |C'| over the
    /// curve (Simpson's rule, 20000 intervals, in f64), for curves whose distance to the axis
    /// is |C_xy(v)|.
    fn swept_area(q: &Quadric) -> f64 {
        let n = 20_000;
        let h = 1.0 / n as f64;
        let c = |v: f64| q.curve(v as f32).as_dvec3();
        let integrand = |v: f64| {
            let p = c(v);
            let rho = (p.x * p.x + p.y * p.y).sqrt();
            // The meridian: (rho, z) as functions of v, differentiated numerically.
            let e = 1e-6;
            let (a, b) = (c((v - e).max(0.0)), c((v + e).min(1.0)));
            let rho_of = |p: glam::DVec3| (p.x * p.x + p.y * p.y).sqrt();
            let span = (v + e).min(1.0) - (v - e).max(0.0);
            let drho = (rho_of(b) - rho_of(a)) / span;
            let dz = (b.z - a.z) / span;
            rho * (drho * drho + dz * dz).sqrt()
        };
        let mut s = integrand(0.0) + integrand(1.0);
        for i in 1..n {
            s += integrand(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        q.phimax() as f64 * s * h / 3.0
    }

    #[test]
    fn cone_area_matches_the_closed_form() {
        let cone = Quadric::Cone {
            radius: 1.5,
            radius2: 0.0,
            height: 2.0,
            phimax: 360.0,
        };
        // pi r s, s the slant height.
        let exact = PI * 1.5 * (1.5f64 * 1.5 + 2.0 * 2.0).sqrt();
        let a = mesh_area(&cone.tessellate());
        assert!((a / exact - 1.0).abs() < 0.01, "cone area {a} vs {exact}");
        assert!(
            (a / exact - 1.0).abs() > 1e-4,
            "a polygonal cone is a bit smaller"
        );
        let frustum = Quadric::Cone {
            radius: 2.0,
            radius2: 1.0,
            height: 1.0,
            phimax: 180.0,
        };
        // Half of pi (r1 + r2) s.
        let exact = 0.5 * PI * 3.0 * 2f64.sqrt();
        let a = mesh_area(&frustum.tessellate());
        assert!(
            (a / exact - 1.0).abs() < 0.01,
            "frustum area {a} vs {exact}"
        );
    }

    #[test]
    fn paraboloid_area_matches_the_closed_form() {
        let (r, zmin, zmax) = (1.0f64, 0.25f64, 2.0f64);
        let p = Quadric::Paraboloid {
            radius: r as f32,
            zmin: zmin as f32,
            zmax: zmax as f32,
            phimax: 360.0,
        };
        // x^2 + y^2 = k z with k = r^2 / zmax: area = (pi k^(1/2) / 6)((k + 4z)^(3/2) ...),
        // written as 2 pi integral of sqrt(k z) sqrt(1 + k / (4 z)) dz = pi/6 sqrt(k)
        // [(4z + k)^(3/2)] from zmin to zmax.
        let k = r * r / zmax;
        let f = |z: f64| libm::pow(4.0 * z + k, 1.5);
        let exact = PI / 6.0 * k.sqrt() * (f(zmax) - f(zmin));
        let a = mesh_area(&p.tessellate());
        assert!(
            (a / exact - 1.0).abs() < 0.01,
            "paraboloid area {a} vs {exact}"
        );
        let numeric = swept_area(&p);
        assert!((numeric / exact - 1.0).abs() < 1e-3, "{numeric} vs {exact}");
    }

    #[test]
    fn hyperboloid_area_matches_the_swept_integral() {
        let h = Quadric::Hyperboloid {
            p1: Vec3::new(1.0, 0.0, -1.0),
            p2: Vec3::new(0.0, 1.0, 1.0),
            phimax: 360.0,
        };
        let exact = swept_area(&h);
        let a = mesh_area(&h.tessellate());
        assert!(
            (a / exact - 1.0).abs() < 0.01,
            "hyperboloid area {a} vs {exact}"
        );
        // Its waist: the segment passes the axis at distance sqrt(1/2) at v = 1/2.
        let m = h.tessellate();
        let waist = m
            .positions
            .iter()
            .map(|p| p.truncate().length())
            .fold(f32::INFINITY, f32::min);
        assert!((waist - 0.5f32.sqrt()).abs() < 1e-3, "waist {waist}");
    }

    #[test]
    fn cone_and_paraboloid_face_outwards() {
        for q in [
            Quadric::Cone {
                radius: 1.0,
                radius2: 0.0,
                height: 1.0,
                phimax: 360.0,
            },
            Quadric::Paraboloid {
                radius: 1.0,
                zmin: 0.0,
                zmax: 1.0,
                phimax: 360.0,
            },
        ] {
            let m = q.tessellate();
            assert!(!m.indices.is_empty());
            for t in &m.indices {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                let centre = (a + b + c) / 3.0;
                let n = (b - a).cross(c - a);
                // Outward: away from the axis.
                assert!(n.dot(centre.truncate().extend(0.0)) > 0.0, "{q:?} {t:?}");
            }
            let normals = m.normals.as_ref().unwrap();
            assert!(normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        }
    }
}
