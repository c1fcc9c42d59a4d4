//! The x86-64 kernels: the triangle test on 4 SSE lanes (SSE2 is part of x86-64), the slab
//! test on 8 AVX2 lanes (its comparison into a mask register with AVX-512) or on two halves of
//! 4 SSE lanes. Each lane performs exactly the
//! operations of `wide_node::slab_lane` and `wide_node::triangle_lane`, in the same order and
//! without fused multiply-add; `minps`/`maxps` return their second operand on ties, as the
//! scalar code's comparisons do.
//!
//! The kernels are `#[inline(always)]` without `#[target_feature]`: the traversal instantiates
//! them inside a function compiled with AVX2 (or AVX-512) enabled (`wide_bvh`), chosen only
//! after run-time detection, so every intrinsic below inlines into that code.

use std::arch::x86_64::*;

use crate::geometry::wide_node::{
    far_row_of, Kernel, Node, Packet, PacketHits, TraversalRay, SLAB_ROBUST, WIDTH,
};

/// The ray broadcast to SSE lanes, for the triangle test.
#[derive(Clone, Copy)]
pub struct Ray4 {
    origin: [__m128; 3],
    dir: [__m128; 3],
}

impl Ray4 {
    #[inline(always)]
    fn new(ray: &TraversalRay) -> Self {
        // SAFETY: SSE2 is part of x86-64.
        unsafe {
            Self {
                origin: ray.origin.map(|v| _mm_set1_ps(v)),
                dir: ray.dir.map(|v| _mm_set1_ps(v)),
            }
        }
    }
}

/// Möller-Trumbore on four lanes; see `wide_node::triangle_lane` for the scalar original.
#[inline(always)]
fn triangles4(packet: &Packet, ray: &Ray4, tmax: f32, hits: &mut PacketHits) -> u32 {
    // SAFETY: SSE2 is part of x86-64; the loads read the packet's 16-byte rows and the stores
    // write `hits`' 4-float rows (unaligned forms, so alignment is not assumed).
    unsafe {
        let load = |row: &[f32; 4]| _mm_loadu_ps(row.as_ptr());
        let [ox, oy, oz] = ray.origin;
        let [dx, dy, dz] = ray.dir;
        let (p0x, p0y, p0z) = (
            load(&packet.p0[0]),
            load(&packet.p0[1]),
            load(&packet.p0[2]),
        );
        let (e1x, e1y, e1z) = (
            load(&packet.e1[0]),
            load(&packet.e1[1]),
            load(&packet.e1[2]),
        );
        let (e2x, e2y, e2z) = (
            load(&packet.e2[0]),
            load(&packet.e2[1]),
            load(&packet.e2[2]),
        );
        let mul = |a, b| _mm_mul_ps(a, b);
        let sub = |a, b| _mm_sub_ps(a, b);
        let add = |a, b| _mm_add_ps(a, b);
        let px = sub(mul(dy, e2z), mul(e2y, dz));
        let py = sub(mul(dz, e2x), mul(e2z, dx));
        let pz = sub(mul(dx, e2y), mul(e2x, dy));
        let det = add(add(mul(e1x, px), mul(e1y, py)), mul(e1z, pz));
        let inv_det = _mm_div_ps(_mm_set1_ps(1.0), det);
        let (tx, ty, tz) = (sub(ox, p0x), sub(oy, p0y), sub(oz, p0z));
        let qx = sub(mul(ty, e1z), mul(e1y, tz));
        let qy = sub(mul(tz, e1x), mul(e1z, tx));
        let qz = sub(mul(tx, e1y), mul(e1x, ty));
        let b1 = mul(add(add(mul(tx, px), mul(ty, py)), mul(tz, pz)), inv_det);
        let b2 = mul(add(add(mul(dx, qx), mul(dy, qy)), mul(dz, qz)), inv_det);
        let t = mul(add(add(mul(e2x, qx), mul(e2y, qy)), mul(e2z, qz)), inv_det);
        let zero = _mm_setzero_ps();
        let inside = _mm_and_ps(
            _mm_and_ps(_mm_cmpge_ps(b1, zero), _mm_cmpge_ps(b2, zero)),
            _mm_cmple_ps(add(b1, b2), _mm_set1_ps(1.0)),
        );
        let in_range = _mm_and_ps(_mm_cmpgt_ps(t, zero), _mm_cmple_ps(t, _mm_set1_ps(tmax)));
        _mm_storeu_ps(hits.t.as_mut_ptr(), t);
        _mm_storeu_ps(hits.b1.as_mut_ptr(), b1);
        _mm_storeu_ps(hits.b2.as_mut_ptr(), b2);
        _mm_movemask_ps(_mm_and_ps(inside, in_range)) as u32
    }
}

/// SSE only: triangles on 4 lanes, the eight slabs as two halves of 4 lanes.
pub struct Sse;

#[derive(Clone, Copy)]
pub struct SseRay {
    tri: Ray4,
    origin: [__m128; 3],
    inv_dir: [__m128; 3],
    near_row: [usize; 3],
    far_row: [usize; 3],
}

impl Kernel for Sse {
    type Ray = SseRay;

    #[inline(always)]
    fn prepare(ray: &TraversalRay) -> SseRay {
        // SAFETY: SSE2 is part of x86-64.
        unsafe {
            SseRay {
                tri: Ray4::new(ray),
                origin: ray.origin.map(|v| _mm_set1_ps(v)),
                inv_dir: ray.inv_dir.map(|v| _mm_set1_ps(v)),
                near_row: ray.near_row,
                far_row: ray.near_row.map(far_row_of),
            }
        }
    }

    #[inline(always)]
    fn slabs(node: &Node, ray: &SseRay, tmax: f32, tnear: &mut [f32; WIDTH]) -> u32 {
        // SAFETY: SSE2 is part of x86-64; each load reads 4 floats inside a bound row of 8 and
        // each store writes 4 floats inside `tnear`.
        unsafe {
            let mut mask = 0;
            for half in 0..2 {
                let at = half * 4;
                let plane = |row: usize, axis: usize| {
                    let b = _mm_loadu_ps(node.bounds[row].as_ptr().add(at));
                    _mm_mul_ps(_mm_sub_ps(b, ray.origin[axis]), ray.inv_dir[axis])
                };
                let n = [0, 1, 2].map(|a| plane(ray.near_row[a], a));
                let f = [0, 1, 2].map(|a| plane(ray.far_row[a], a));
                let near = _mm_max_ps(_mm_max_ps(n[0], n[1]), _mm_max_ps(n[2], _mm_setzero_ps()));
                let far = _mm_mul_ps(
                    _mm_min_ps(_mm_min_ps(f[0], f[1]), f[2]),
                    _mm_set1_ps(SLAB_ROBUST),
                );
                let far = _mm_min_ps(far, _mm_set1_ps(tmax));
                _mm_storeu_ps(tnear.as_mut_ptr().add(at), near);
                mask |= (_mm_movemask_ps(_mm_cmple_ps(near, far)) as u32) << at;
            }
            mask
        }
    }

    #[inline(always)]
    fn triangles(packet: &Packet, ray: &SseRay, tmax: f32, hits: &mut PacketHits) -> u32 {
        triangles4(packet, &ray.tri, tmax, hits)
    }
}

/// AVX2: the eight slabs on one 8-lane register; triangles on 4 SSE lanes. Only run inside a
/// function with AVX2 enabled, after detection.
pub struct Avx2;

#[derive(Clone, Copy)]
pub struct Avx2Ray {
    tri: Ray4,
    origin: [__m256; 3],
    inv_dir: [__m256; 3],
    near_row: [usize; 3],
    far_row: [usize; 3],
}

impl Kernel for Avx2 {
    type Ray = Avx2Ray;

    #[inline(always)]
    fn prepare(ray: &TraversalRay) -> Avx2Ray {
        // SAFETY: only called from traversal functions compiled with AVX2 after detection.
        // (No closures around AVX intrinsics here: a closure is its own function without the
        // caller's target features, so the intrinsics in it would not inline.)
        unsafe {
            let [ox, oy, oz] = ray.origin;
            let [ix, iy, iz] = ray.inv_dir;
            Avx2Ray {
                tri: Ray4::new(ray),
                origin: [_mm256_set1_ps(ox), _mm256_set1_ps(oy), _mm256_set1_ps(oz)],
                inv_dir: [_mm256_set1_ps(ix), _mm256_set1_ps(iy), _mm256_set1_ps(iz)],
                near_row: ray.near_row,
                far_row: ray.near_row.map(far_row_of),
            }
        }
    }

    #[inline(always)]
    fn slabs(node: &Node, ray: &Avx2Ray, tmax: f32, tnear: &mut [f32; WIDTH]) -> u32 {
        let (near, far) = slab_near_far(node, ray, tmax);
        // SAFETY: AVX2 as above; the store writes `tnear`'s 8 floats.
        unsafe {
            _mm256_storeu_ps(tnear.as_mut_ptr(), near);
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
        }
    }

    #[inline(always)]
    fn triangles(packet: &Packet, ray: &Avx2Ray, tmax: f32, hits: &mut PacketHits) -> u32 {
        triangles4(packet, &ray.tri, tmax, hits)
    }
}

/// The eight slabs' entry and exit distances on one 8-lane register (exit clipped to tmax), for
/// the AVX2 and AVX-512 kernels.
#[inline(always)]
fn slab_near_far(node: &Node, ray: &Avx2Ray, tmax: f32) -> (__m256, __m256) {
    // SAFETY: only inlined into functions compiled with AVX2 after detection (see the module's
    // doc); each load reads one bound row of 8 floats.
    unsafe {
        macro_rules! plane {
            ($row:expr, $axis:expr) => {
                _mm256_mul_ps(
                    _mm256_sub_ps(
                        _mm256_loadu_ps(node.bounds[$row].as_ptr()),
                        ray.origin[$axis],
                    ),
                    ray.inv_dir[$axis],
                )
            };
        }
        let (n0, n1, n2) = (
            plane!(ray.near_row[0], 0),
            plane!(ray.near_row[1], 1),
            plane!(ray.near_row[2], 2),
        );
        let (f0, f1, f2) = (
            plane!(ray.far_row[0], 0),
            plane!(ray.far_row[1], 1),
            plane!(ray.far_row[2], 2),
        );
        let near = _mm256_max_ps(
            _mm256_max_ps(n0, n1),
            _mm256_max_ps(n2, _mm256_setzero_ps()),
        );
        let far = _mm256_mul_ps(
            _mm256_min_ps(_mm256_min_ps(f0, f1), f2),
            _mm256_set1_ps(SLAB_ROBUST),
        );
        (near, _mm256_min_ps(far, _mm256_set1_ps(tmax)))
    }
}

/// AVX-512 (F and VL): the AVX2 kernel's arithmetic with its comparisons made straight into
/// mask registers, run inside traversal functions compiled for AVX-512, where the ray and the
/// node's planes have 32 vector registers instead of 16. Only run there, after detection.
pub struct Avx512;

impl Kernel for Avx512 {
    type Ray = Avx2Ray;

    #[inline(always)]
    fn prepare(ray: &TraversalRay) -> Avx2Ray {
        Avx2::prepare(ray)
    }

    #[inline(always)]
    fn slabs(node: &Node, ray: &Avx2Ray, tmax: f32, tnear: &mut [f32; WIDTH]) -> u32 {
        let (near, far) = slab_near_far(node, ray, tmax);
        // SAFETY: AVX-512 F and VL, detected by the caller; the store writes `tnear`'s 8
        // floats.
        unsafe {
            _mm256_storeu_ps(tnear.as_mut_ptr(), near);
            u32::from(_mm256_cmp_ps_mask::<_CMP_LE_OQ>(near, far))
        }
    }

    #[inline(always)]
    fn triangles(packet: &Packet, ray: &Avx2Ray, tmax: f32, hits: &mut PacketHits) -> u32 {
        triangles4(packet, &ray.tri, tmax, hits)
    }
}
