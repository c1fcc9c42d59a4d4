//! Triangle meshes: the data every mesh-like shape becomes, reading them from inline shape
//! parameters ([`inline`]) and from PLY files ([`ply`]), Loop subdivision and displacement
//! ([`subdiv`]), heightfields ([`heightfield`]), the swept quadrics ([`quadric`]), on the
//! parametric grid ([`grid`]) the tessellated shapes share.

pub mod grid;
pub mod heightfield;
pub mod inline;
pub mod ply;
pub mod quadric;
pub mod subdiv;

use glam::Vec3;

/// Triangle mesh data in object space. Quads are already split into triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Bytes a vertex takes: its position, and its normal and uv where the mesh has them.
    pub fn bytes_per_vertex(&self) -> u64 {
        let size = |present: bool, bytes: usize| if present { bytes as u64 } else { 0 };
        size(true, std::mem::size_of::<Vec3>())
            + size(self.normals.is_some(), std::mem::size_of::<Vec3>())
            + size(self.uvs.is_some(), std::mem::size_of::<[f32; 2]>())
    }

    /// Bytes the mesh's arrays hold.
    pub fn heap_bytes(&self) -> u64 {
        self.positions.len() as u64 * self.bytes_per_vertex()
            + self.indices.len() as u64 * std::mem::size_of::<[u32; 3]>() as u64
    }
}
