//! What placing a shape costs the build at its peak: the figure the build budget's memory
//! estimate charges for every shape placed, every instance counted. Geometry is flattened into
//! world space, so an instance costs as much as a copy: its world-space vertices and indices,
//! its BVH primitives and their share of the BVH, the build's temporaries alive at the same
//! time, and the records the description and the built scene keep per shape. The per-primitive
//! figures are measured at the peak of builds of a few sizes and rounded up (docs/security.md,
//! "build budget").

use crate::shape::{Geometry, Placement};

/// Bytes per triangle placed besides its vertices: its world-space indices, its BVH primitive
/// before and after leaf ordering, its box (the same twice), the edges the wide BVH's packets
/// are filled from, its share of obvhs's build and of the wide nodes and leaf packets, and what
/// the allocator keeps of the parser's freed records (a PLY file's elements).
pub const BYTES_PER_TRIANGLE: u64 = 464;
/// Bytes per exact shape (sphere, disk, cylinder) placed: its world-space record, and its BVH primitive,
/// box and share of the BVH as a triangle's.
pub const BYTES_PER_ANALYTIC: u64 = 640;
/// Bytes per shape placed, whatever it is: its record in the description and in the built
/// scene's copy, its inverse transform, its world-space record and the allocator's headers
/// of its arrays.
pub const BYTES_PER_SHAPE: u64 = 384;

/// What placing one instance of `geometry` adds to the build's peak.
pub fn placed_bytes(geometry: &Geometry) -> u64 {
    let primitives = match geometry.placement() {
        Placement::Triangles(mesh) => {
            let vertices = mesh.positions.len() as u64 * mesh.bytes_per_vertex();
            let triangles = mesh.indices.len() as u64;
            vertices.saturating_add(triangles.saturating_mul(BYTES_PER_TRIANGLE))
        }
        Placement::Unbounded(_) => 0,
        Placement::Exact(_) => BYTES_PER_ANALYTIC,
    };
    BYTES_PER_SHAPE.saturating_add(primitives)
}
