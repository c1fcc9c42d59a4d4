//! The wide BVH's memory layout and the interface its SIMD kernels implement: the leaf module
//! that `wide_bvh` (build and traversal) and `simd` (the kernels) both read.
//!
//! A node holds the boxes of its eight children as structure-of-arrays floats, so one ray is
//! tested against all eight with one 8-lane slab test. A leaf is one packet of up to four
//! triangles, also structure-of-arrays, tested with one 4-lane Möller-Trumbore.
//!
//! Determinism: every kernel computes, lane by lane, exactly the scalar operations written in
//! [`slab_lane`] and [`triangle_lane`] (same operations, same order, no fused multiply-add), so
//! the scalar, SSE, AVX2 and AVX-512 paths return bit-identical results and workers on
//! different CPUs render the same image bytes.

use obvhs::aabb::Aabb;

/// Children per node.
pub const WIDTH: usize = 8;
/// Triangles per leaf packet (obvhs's CWBVH leaves hold at most 3 primitives; sibling leaves
/// are merged up to this).
pub const PACKET: usize = 4;

/// Child reference: bit 31 marks a leaf (the low bits index `packets`), otherwise the value
/// indexes `nodes`.
pub const LEAF: u32 = 1 << 31;
/// Set on a leaf whose packet has lanes that are not triangles (analytic shapes), which the
/// traversal hands to the caller's own test.
pub const LEAF_HAS_OTHER: u32 = 1 << 30;
/// The largest packet index a child reference can hold.
pub const MAX_PACKETS: u32 = LEAF_HAS_OTHER - 1;
/// An empty child slot (its box is empty, so it is never hit).
pub const EMPTY: u32 = u32::MAX;
/// A packet lane without a primitive.
pub const NO_SLOT: u32 = u32::MAX;

/// pbrt's robust slab test factor, 1 + 2 gamma(3): the far distance is scaled up so rounding
/// in the slab arithmetic never rejects a box the ray touches.
pub const SLAB_ROBUST: f32 =
    1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Order of the six bound rows in [`Node::bounds`].
pub const MIN_X: usize = 0;
pub const MAX_X: usize = 3;

/// Eight children's boxes (rows min x, min y, min z, max x, max y, max z; empty slots have
/// min = +inf, max = -inf) and references. Four cache lines (the last one partly padding).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Node {
    pub bounds: [[f32; WIDTH]; 6],
    pub child: [u32; WIDTH],
    /// Bit i set when child i is a leaf.
    pub leaves: u32,
}

impl Node {
    pub const EMPTY: Node = Node {
        bounds: [
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
            [f32::NEG_INFINITY; WIDTH],
        ],
        child: [EMPTY; WIDTH],
        leaves: 0,
    };

    /// Puts child reference `child` with box `b` in `slot`.
    pub fn set_child(&mut self, slot: usize, b: &Aabb, child: u32) {
        for axis in 0..3 {
            self.bounds[MIN_X + axis][slot] = b.min[axis];
            self.bounds[MAX_X + axis][slot] = b.max[axis];
        }
        self.child[slot] = child;
    }
}

/// Up to four triangles as (vertex 0, edge 1, edge 2) in structure-of-arrays order (rows x, y,
/// z), with the leaf-order primitive index of each lane. Lanes without a triangle hold NaN
/// coordinates, which fail every comparison of the test.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Packet {
    pub p0: [[f32; PACKET]; 3],
    pub e1: [[f32; PACKET]; 3],
    pub e2: [[f32; PACKET]; 3],
    pub slot: [u32; PACKET],
}

impl Packet {
    pub const EMPTY: Packet = Packet {
        p0: [[f32::NAN; PACKET]; 3],
        e1: [[f32::NAN; PACKET]; 3],
        e2: [[f32::NAN; PACKET]; 3],
        slot: [NO_SLOT; PACKET],
    };
}

/// A ray prepared for traversal: origin, direction, and the reciprocal direction used by the
/// slab test, with zero (and subnormal) components replaced by the smallest normal float of
/// the same sign so that no product is 0 x inf (NaN).
#[derive(Clone, Copy, Debug)]
pub struct TraversalRay {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub inv_dir: [f32; 3],
    /// Row of `Node::bounds` holding each axis's near plane (min for a positive direction).
    pub near_row: [usize; 3],
}

impl TraversalRay {
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Self {
        let inv = |d: f32| {
            let safe = if d.abs() < f32::MIN_POSITIVE {
                f32::MIN_POSITIVE.copysign(d)
            } else {
                d
            };
            1.0 / safe
        };
        let inv_dir = dir.map(inv);
        let near_row = [0, 1, 2].map(|a| {
            if inv_dir[a] >= 0.0 {
                MIN_X + a
            } else {
                MAX_X + a
            }
        });
        Self {
            origin,
            dir,
            inv_dir,
            near_row,
        }
    }
}

/// The per-lane results of a packet test.
#[derive(Clone, Copy, Debug, Default)]
pub struct PacketHits {
    pub t: [f32; PACKET],
    pub b1: [f32; PACKET],
    pub b2: [f32; PACKET],
}

/// A SIMD implementation of the two hot tests. Implementations must compute, lane by lane,
/// exactly what [`slab_lane`] and [`triangle_lane`] compute.
pub trait Kernel {
    /// The ray in the kernel's registers.
    type Ray: Copy;
    fn prepare(ray: &TraversalRay) -> Self::Ray;
    /// The slab test of the ray against the node's eight boxes, clipped to [0, tmax]: bit i of
    /// the result is set when child i is hit, and `tnear[i]` is its entry distance.
    fn slabs(node: &Node, ray: &Self::Ray, tmax: f32, tnear: &mut [f32; WIDTH]) -> u32;
    /// Möller-Trumbore on the packet's lanes: bit i is set when lane i is hit with t in
    /// (0, tmax] (inclusive, so equal distances reach the tie rule).
    fn triangles(packet: &Packet, ray: &Self::Ray, tmax: f32, hits: &mut PacketHits) -> u32;
}

/// One lane of the slab test: (hit, tnear). Min and max are written as comparisons so that
/// they mean what the x86 `minps`/`maxps` instructions do; no operand is ever NaN here (see
/// [`TraversalRay`]), so the choice only documents the contract.
#[inline(always)]
pub fn slab_lane(node: &Node, ray: &TraversalRay, lane: usize, tmax: f32) -> (bool, f32) {
    let min = |a: f32, b: f32| if a < b { a } else { b };
    let max = |a: f32, b: f32| if a > b { a } else { b };
    let plane =
        |row: usize, axis: usize| (node.bounds[row][lane] - ray.origin[axis]) * ray.inv_dir[axis];
    let near = [0, 1, 2].map(|a| plane(ray.near_row[a], a));
    let far = [0, 1, 2].map(|a| plane(far_row_of(ray.near_row[a]), a));
    let tnear = max(max(near[0], near[1]), max(near[2], 0.0));
    let tfar = min(min(far[0], far[1]), far[2]) * SLAB_ROBUST;
    let tfar = min(tfar, tmax);
    (tnear <= tfar, tnear)
}

/// The far row of an axis given its near row (min x <-> max x and so on).
#[inline(always)]
pub fn far_row_of(near_row: usize) -> usize {
    if near_row >= MAX_X {
        near_row - MAX_X
    } else {
        near_row + MAX_X
    }
}

/// One lane of the triangle test: Möller-Trumbore with exactly the arithmetic of
/// `TriangleEdges::intersect` (glam's cross and dot: products, then (x + y) + z), returning
/// (hit with t in (0, tmax], t, b1, b2).
#[inline(always)]
pub fn triangle_lane(
    packet: &Packet,
    ray: &TraversalRay,
    lane: usize,
    tmax: f32,
) -> (bool, f32, f32, f32) {
    let [ox, oy, oz] = ray.origin;
    let [dx, dy, dz] = ray.dir;
    let (p0x, p0y, p0z) = (packet.p0[0][lane], packet.p0[1][lane], packet.p0[2][lane]);
    let (e1x, e1y, e1z) = (packet.e1[0][lane], packet.e1[1][lane], packet.e1[2][lane]);
    let (e2x, e2y, e2z) = (packet.e2[0][lane], packet.e2[1][lane], packet.e2[2][lane]);
    // pvec = dir x e2
    let px = dy * e2z - e2y * dz;
    let py = dz * e2x - e2z * dx;
    let pz = dx * e2y - e2x * dy;
    let inv_det = 1.0 / ((e1x * px + e1y * py) + e1z * pz);
    let (tx, ty, tz) = (ox - p0x, oy - p0y, oz - p0z);
    // qvec = tvec x e1
    let qx = ty * e1z - e1y * tz;
    let qy = tz * e1x - e1z * tx;
    let qz = tx * e1y - e1x * ty;
    let b1 = ((tx * px + ty * py) + tz * pz) * inv_det;
    let b2 = ((dx * qx + dy * qy) + dz * qz) * inv_det;
    let t = ((e2x * qx + e2y * qy) + e2z * qz) * inv_det;
    let inside = (b1 >= 0.0) & (b2 >= 0.0) & (b1 + b2 <= 1.0);
    (inside & (t > 0.0) & (t <= tmax), t, b1, b2)
}
