//! Triangle meshes in world space: the ray/triangle test on the BVH's hot data, and the shading
//! data (vertex normals, uvs) read once per closest hit.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec3A};

use crate::math::Frame;
use crate::mesh::TriangleMesh;

use super::hit::{SurfaceHit, SurfaceSample};

/// The uvs of a triangle whose mesh has none (pbrt's rule).
const DEFAULT_UVS: [Vec2; 3] = [
    Vec2::new(0.0, 0.0),
    Vec2::new(1.0, 0.0),
    Vec2::new(1.0, 1.0),
];

/// What the ray/triangle test reads: one vertex and the two edges from it, in world space.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriangleEdges {
    p0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
}

impl TriangleEdges {
    pub fn new([p0, p1, p2]: [Vec3; 3]) -> Self {
        let p0 = Vec3A::from(p0);
        Self {
            p0,
            e1: Vec3A::from(p1) - p0,
            e2: Vec3A::from(p2) - p0,
        }
    }

    /// (vertex 0, edge 1, edge 2): what the wide BVH's leaf packets store.
    pub fn parts(&self) -> [Vec3A; 3] {
        [self.p0, self.e1, self.e2]
    }

    #[cfg(test)]
    pub fn vertices(&self) -> [Vec3A; 3] {
        [self.p0, self.p0 + self.e1, self.p0 + self.e2]
    }

    /// Möller-Trumbore. Returns (t, b1, b2) for a hit with t in (0, tmax); b1 and b2 are the
    /// barycentric weights of the second and third vertices. A zero determinant gives infinite
    /// or NaN values, which fail the comparisons. The wide BVH's kernels
    /// (`wide_node::triangle_lane`) compute exactly this arithmetic lane by lane; this glam form
    /// is the oracle the tests hold them to (and the form images were rendered with before).
    #[cfg(test)]
    pub fn intersect(&self, origin: Vec3A, dir: Vec3A, tmax: f32) -> Option<(f32, f32, f32)> {
        let pvec = dir.cross(self.e2);
        let inv_det = 1.0 / self.e1.dot(pvec);
        let tvec = origin - self.p0;
        let qvec = tvec.cross(self.e1);
        let b1 = tvec.dot(pvec) * inv_det;
        let b2 = dir.dot(qvec) * inv_det;
        let t = self.e2.dot(qvec) * inv_det;
        let inside = (b1 >= 0.0) & (b2 >= 0.0) & (b1 + b2 <= 1.0);
        (inside & (t > 0.0) & (t < tmax)).then_some((t, b1, b2))
    }
}

/// One mesh shape in world space.
pub(crate) struct WorldMesh {
    pub shape: u32,
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    /// Only the triangles that can be hit: indices in range, inside the world's range
    /// ([`super::world_range::MAX_WORLD_COORD`]), non-zero area.
    indices: Vec<[u32; 3]>,
    /// -1 when ReverseOrientation or a handedness-swapping transform (but not both) turns the
    /// front side against the winding order.
    orientation: f32,
}

/// Why some of a mesh's input was left out.
#[derive(Debug, Default, PartialEq, Eq)]
pub(crate) struct MeshIssues {
    pub bad_triangles: usize,
    pub dropped_normals: bool,
    pub dropped_uvs: bool,
}

impl WorldMesh {
    pub fn new(
        shape: u32,
        mesh: &TriangleMesh,
        object_to_world: &Mat4,
        reverse_orientation: bool,
    ) -> (Self, MeshIssues) {
        let mut issues = MeshIssues::default();
        let positions: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|&p| object_to_world.transform_point3(p))
            .collect();
        let linear = Mat3::from_mat4(*object_to_world);
        let det = linear.determinant();
        // Normals transform with the inverse transpose; a singular transform has none.
        let normal_matrix = (det != 0.0 && det.is_finite()).then(|| linear.inverse().transpose());
        let normals = match (&mesh.normals, normal_matrix) {
            (Some(n), Some(m)) if n.len() == mesh.positions.len() => {
                Some(n.iter().map(|&n| (m * n).normalize_or_zero()).collect())
            }
            (Some(_), _) => {
                issues.dropped_normals = true;
                None
            }
            (None, _) => None,
        };
        let uvs = match &mesh.uvs {
            Some(uv) if uv.len() == mesh.positions.len() => {
                Some(uv.iter().map(|&[u, v]| Vec2::new(u, v)).collect())
            }
            Some(_) => {
                issues.dropped_uvs = true;
                None
            }
            None => None,
        };
        let indices: Vec<[u32; 3]> = mesh
            .indices
            .iter()
            .copied()
            .filter(|tri| {
                let valid = tri.iter().all(|&i| (i as usize) < positions.len()) && {
                    let [p0, p1, p2] = tri.map(|i| positions[i as usize]);
                    [p0, p1, p2]
                        .iter()
                        .all(|p| super::world_range::within_world(*p))
                        && (p1 - p0).cross(p2 - p0).normalize_or_zero() != Vec3::ZERO
                };
                issues.bad_triangles += usize::from(!valid);
                valid
            })
            .collect();
        let orientation = if reverse_orientation ^ (det < 0.0) {
            -1.0
        } else {
            1.0
        };
        let mesh = Self {
            shape,
            positions,
            normals,
            uvs,
            indices,
            orientation,
        };
        (mesh, issues)
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    pub fn vertices(&self, tri: u32) -> [Vec3; 3] {
        self.indices[tri as usize].map(|i| self.positions[i as usize])
    }

    /// The unit normal on the front side.
    pub fn geometric_normal(&self, tri: u32) -> Vec3 {
        let [p0, p1, p2] = self.vertices(tri);
        (p1 - p0).cross(p2 - p0).normalize() * self.orientation
    }

    pub fn surface(&self, tri: u32) -> TriangleSurface {
        TriangleSurface {
            vertices: self.vertices(tri),
            n: self.geometric_normal(tri),
            uvs: match &self.uvs {
                Some(uvs) => self.indices[tri as usize].map(|i| uvs[i as usize]),
                None => DEFAULT_UVS,
            },
        }
    }

    /// The hit on triangle `tri` whose hot data is `edges`. Position and normal come from
    /// `edges` (already in cache); the vertex indices, a likely cache miss, are read only for
    /// meshes with normals or uvs.
    pub fn hit(
        &self,
        tri: u32,
        edges: &TriangleEdges,
        t: f32,
        b1: f32,
        b2: f32,
        prim: u32,
    ) -> SurfaceHit {
        let b0 = 1.0 - b1 - b2;
        let (p0, e1, e2) = (
            Vec3::from(edges.p0),
            Vec3::from(edges.e1),
            Vec3::from(edges.e2),
        );
        let ng = e1.cross(e2).normalize() * self.orientation;
        let idx =
            (self.normals.is_some() || self.uvs.is_some()).then(|| self.indices[tri as usize]);
        let [uv0, uv1, uv2] = match (&self.uvs, idx) {
            (Some(uvs), Some(idx)) => idx.map(|i| uvs[i as usize]),
            _ => DEFAULT_UVS,
        };
        let ns = match (&self.normals, idx) {
            (Some(n), Some(idx)) => {
                let ns =
                    (b0 * n[idx[0] as usize] + b1 * n[idx[1] as usize] + b2 * n[idx[2] as usize])
                        .normalize_or_zero();
                match ns.dot(ng) {
                    d if d < 0.0 => -ns,
                    d if d > 0.0 => ns,
                    _ => ng,
                }
            }
            _ => ng,
        };
        let (dpdu, dpdv) = uv_tangents([p0, p0 + e1, p0 + e2], [uv0, uv1, uv2], ng);
        SurfaceHit {
            t,
            p: p0 + b1 * e1 + b2 * e2,
            ng,
            ns,
            uv: b0 * uv0 + b1 * uv1 + b2 * uv2,
            dpdu,
            dpdv,
            shape: self.shape,
            prim,
        }
    }
}

/// pbrt's partial derivatives of position along u and v, from the uv differences over the
/// triangle; any orthonormal tangents when the uvs are degenerate.
fn uv_tangents([p0, p1, p2]: [Vec3; 3], [uv0, uv1, uv2]: [Vec2; 3], ng: Vec3) -> (Vec3, Vec3) {
    let (duv02, duv12) = (uv0 - uv2, uv1 - uv2);
    let (dp02, dp12) = (p0 - p2, p1 - p2);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    let dpdu = (duv12.y * dp02 - duv02.y * dp12) / det;
    let dpdv = (duv02.x * dp12 - duv12.x * dp02) / det;
    let usable = |d: Vec3| d.is_finite() && d != Vec3::ZERO;
    if det.abs() > 1e-12 && usable(dpdu) && usable(dpdv) {
        (dpdu, dpdv)
    } else {
        let frame = Frame::from_normal(ng);
        (frame.s, frame.t)
    }
}

/// A world-space triangle with its front-side normal, for sampling points on emitters.
#[derive(Clone, Copy, Debug)]
pub struct TriangleSurface {
    pub vertices: [Vec3; 3],
    pub n: Vec3,
    /// The vertices' uvs, as a ray hit interpolates them (a textured emitter's colour).
    pub uvs: [Vec2; 3],
}

impl TriangleSurface {
    pub fn area(&self) -> f32 {
        let [p0, p1, p2] = self.vertices;
        0.5 * (p1 - p0).cross(p2 - p0).length()
    }

    /// A point uniformly distributed by area.
    pub fn sample(&self, u: Vec2) -> SurfaceSample {
        let su0 = u.x.sqrt();
        let (b0, b1) = (1.0 - su0, u.y * su0);
        let [p0, p1, p2] = self.vertices;
        SurfaceSample {
            p: b0 * p0 + b1 * p1 + (1.0 - b0 - b1) * p2,
            n: self.n,
            pdf_area: 1.0 / self.area(),
        }
    }

    /// The uv at `p`, a point of the triangle, interpolated as a ray's hit on it is.
    pub fn uv_at(&self, p: Vec3) -> Vec2 {
        let [p0, p1, p2] = self.vertices;
        let n = (p1 - p0).cross(p2 - p0);
        let inv = 1.0 / n.length_squared();
        let b1 = (p - p0).cross(p2 - p0).dot(n) * inv;
        let b2 = (p1 - p0).cross(p - p0).dot(n) * inv;
        let [uv0, uv1, uv2] = self.uvs;
        (1.0 - b1 - b2) * uv0 + b1 * uv1 + b2 * uv2
    }
}
