//! Triangle meshes: the data every mesh-like shape becomes, reading them from inline shape
//! parameters ([`inline`]) and from PLY files ([`ply`]), Loop subdivision and displacement
//! ([`subdiv`]), heightfields ([`heightfield`]), the swept quadrics ([`quadric`]), and
//! making them from the analytic shapes ([`tessellate`]) on the shared parametric grid
//! ([`grid`]).

pub mod grid;
pub mod heightfield;
pub mod inline;
pub mod ply;
pub mod quadric;
pub mod subdiv;
pub mod tessellate;

use glam::Vec3;

/// Triangle mesh data in object space. Quads are already split into triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<[u32; 3]>,
}
