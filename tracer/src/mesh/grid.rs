//! A parametric surface sampled on a grid of triangles: what every tessellated analytic shape
//! (sphere, disk, cylinder, cone, paraboloid, hyperboloid) is made of.

use glam::Vec3;

use crate::mesh::TriangleMesh;

/// Position and outward normal at parameters (u, v) in [0, 1]^2.
pub type SurfacePoint = dyn Fn(f32, f32) -> (Vec3, Vec3);

/// `columns` x `rows` quads (at least 1 each) over the (u, v) square, two triangles each,
/// wound so that the front faces the surface's normal; uvs are the parameters. Triangles
/// that collapse (at a pole or an apex) are left out.
pub fn grid_mesh(
    columns: u32,
    rows: u32,
    surface: &(dyn Fn(f32, f32) -> (Vec3, Vec3) + '_),
) -> TriangleMesh {
    let (columns, rows) = (columns.max(1), rows.max(1));
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=rows {
        for i in 0..=columns {
            let (u, v) = (i as f32 / columns as f32, j as f32 / rows as f32);
            let (p, n) = surface(u, v);
            positions.push(p);
            normals.push(n);
            uvs.push([u, v]);
        }
    }
    let at = |i: u32, j: u32| j * (columns + 1) + i;
    let mut indices = Vec::new();
    for j in 0..rows {
        for i in 0..columns {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            for tri in [[a, b, c], [a, c, d]] {
                let [p0, p1, p2] = tri.map(|k| positions[k as usize]);
                let cross = (p1 - p0).cross(p2 - p0);
                // A collapsed triangle's corners are one point only up to the rounding of the
                // surface's formula (sin(acos(-1)) is not 0 in f32): its area, against its
                // longest edge squared, is that rounding's size, some 1e-6, where the thinnest
                // real triangle of a grid is 1e-2 or more. Kept, it is degenerate once moved to
                // world space, and a renderer that samples lights by triangle (LuxCore) stops
                // sampling the whole light.
                let longest = [p1 - p0, p2 - p1, p0 - p2].map(Vec3::length_squared);
                if cross.length() <= 1e-4 * longest.into_iter().fold(0.0, f32::max) {
                    continue;
                }
                let outward: Vec3 = tri.iter().map(|&k| normals[k as usize]).sum();
                indices.push(if cross.dot(outward) >= 0.0 {
                    tri
                } else {
                    [tri[0], tri[2], tri[1]]
                });
            }
        }
    }
    TriangleMesh {
        positions,
        normals: Some(normals),
        uvs: Some(uvs),
        indices,
    }
}
