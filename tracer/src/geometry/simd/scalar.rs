//! The kernels as plain scalar code: the reference every SIMD kernel matches bit for bit, and
//! the path on CPUs without one (aarch64).

use crate::geometry::wide_node::{
    slab_lane, triangle_lane, Kernel, Node, Packet, PacketHits, TraversalRay, PACKET, WIDTH,
};

pub struct Scalar;

impl Kernel for Scalar {
    type Ray = TraversalRay;

    #[inline(always)]
    fn prepare(ray: &TraversalRay) -> TraversalRay {
        *ray
    }

    #[inline(always)]
    fn slabs(node: &Node, ray: &TraversalRay, tmax: f32, tnear: &mut [f32; WIDTH]) -> u32 {
        let mut mask = 0;
        for (lane, near) in tnear.iter_mut().enumerate() {
            let (hit, t) = slab_lane(node, ray, lane, tmax);
            *near = t;
            mask |= u32::from(hit) << lane;
        }
        mask
    }

    #[inline(always)]
    fn triangles(packet: &Packet, ray: &TraversalRay, tmax: f32, hits: &mut PacketHits) -> u32 {
        let mut mask = 0;
        for lane in 0..PACKET {
            let (hit, t, b1, b2) = triangle_lane(packet, ray, lane, tmax);
            hits.t[lane] = t;
            hits.b1[lane] = b1;
            hits.b2[lane] = b2;
            mask |= u32::from(hit) << lane;
        }
        mask
    }
}
