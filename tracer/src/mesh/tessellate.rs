//! Triangle meshes for the analytic shapes: spheres, disks and cylinders become grids of
//! triangles ([`tessellate`]), an infinite plane a large square ([`plane_quad`]). For consumers
//! that only take triangles (the LuxCore exporter); the renderer intersects the shapes exactly.
//! (Cones, paraboloids and hyperboloids are meshes from the start: [`super::quadric`].)

use glam::Vec3;

use crate::mesh::grid::{grid_mesh, SurfacePoint};
use crate::mesh::TriangleMesh;
use crate::shape::Geometry;

/// Object-space triangles of an analytic shape, wound so the outward side is the front, with
/// YAT's uv parameterisation: `segments` around (at least 3), half as many from pole to pole
/// on a sphere. `None` for meshes and planes.
pub fn tessellate(geometry: &Geometry, segments: u32) -> Option<TriangleMesh> {
    let n_phi = segments.max(3);
    let (rows, grid): (u32, Box<SurfacePoint>) = match *geometry {
        Geometry::Sphere { radius, phimax, .. } => {
            let (z0, z1) = geometry.sphere_z_range()?;
            let (th0, th1) = (libm::acosf(z0 / radius), libm::acosf(z1 / radius));
            let phimax = phimax.clamp(0.0, 360.0).to_radians();
            let f = move |u: f32, v: f32| {
                let (phi, theta) = (u * phimax, th0 + v * (th1 - th0));
                let n = Vec3::new(
                    libm::sinf(theta) * libm::cosf(phi),
                    libm::sinf(theta) * libm::sinf(phi),
                    libm::cosf(theta),
                );
                (n * radius, n)
            };
            ((n_phi / 2).max(2), Box::new(f))
        }
        Geometry::Disk {
            height,
            radius,
            inner_radius,
            phimax,
        } => {
            let phimax = phimax.clamp(0.0, 360.0).to_radians();
            let f = move |u: f32, v: f32| {
                let (phi, r) = (u * phimax, radius - v * (radius - inner_radius));
                (
                    Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), height),
                    Vec3::Z,
                )
            };
            (1, Box::new(f))
        }
        Geometry::Cylinder {
            radius,
            zmin,
            zmax,
            phimax,
        } => {
            let phimax = phimax.clamp(0.0, 360.0).to_radians();
            let f = move |u: f32, v: f32| {
                let phi = u * phimax;
                let n = Vec3::new(libm::cosf(phi), libm::sinf(phi), 0.0);
                (n * radius + Vec3::Z * (zmin + v * (zmax - zmin)), n)
            };
            (1, Box::new(f))
        }
        Geometry::Mesh(_) | Geometry::Plane { .. } => return None,
    };
    Some(grid_mesh(n_phi, rows, &*grid))
}

/// A square of side 2 x `half_size` through the object-space origin, front towards `normal`;
/// uvs are the in-plane object coordinates (YAT's plane uv).
pub fn plane_quad(normal: Vec3, half_size: f32) -> TriangleMesh {
    let n = normal.normalize_or_zero();
    let s = n.any_orthonormal_vector();
    let t = n.cross(s);
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| (s * a + t * b) * half_size);
    TriangleMesh {
        positions: corners.to_vec(),
        normals: None,
        uvs: Some(corners.map(|p| [p.dot(s), p.dot(t)]).to_vec()),
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::*;

    #[test]
    fn tessellated_sphere_is_round_outward_and_has_the_right_area() {
        let sphere = Geometry::Sphere {
            radius: 2.0,
            zmin: -2.0,
            zmax: 2.0,
            phimax: 360.0,
        };
        let mesh = tessellate(&sphere, 128).unwrap();
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
}
