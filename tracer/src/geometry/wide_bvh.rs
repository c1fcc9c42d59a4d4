//! YAT's own traversal of obvhs's BVH: the CWBVH8 that obvhs builds is converted into wide
//! nodes with exact float child boxes and leaf packets of triangles (layout in `wide_node`),
//! and traced with 8-lane slab tests and 4-lane triangle tests (kernels in `simd`, chosen at
//! run time).
//!
//! The closest hit is the smallest t, ties going to the lowest leaf-order primitive index, so
//! the answer does not depend on the order in which children are visited. All kernels also
//! visit in the same order (children sorted by entry distance, equal distances by slot), so
//! every code path returns the same hit, bit for bit.

use std::mem::MaybeUninit;

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;

use super::hit::PrimHit;
#[cfg(target_arch = "x86_64")]
use super::simd::{Avx2, Avx512, Sse};
use super::simd::{Isa, Scalar};
use super::triangle::TriangleEdges;
use super::wide_node::{
    Kernel, Node, Packet, PacketHits, TraversalRay, LEAF, LEAF_HAS_OTHER, MAX_PACKETS, PACKET,
    WIDTH,
};

/// Stack entries a traversal keeps on the thread's stack; a deeper BVH (degenerate input)
/// gets a heap stack instead.
const INLINE_STACK: usize = 256;

/// A traversal stack entry: a child reference and its entry distance. Left uninitialised
/// until pushed (zeroing 2 KB per ray cost more than a node visit); entries below the stack
/// size have always been written.
type Entry = MaybeUninit<(u32, f32)>;

#[derive(Default)]
pub struct WideBvh {
    nodes: Vec<Node>,
    packets: Vec<Packet>,
    /// Per packet: the lanes holding primitives that are not triangles (bit per lane).
    other_lanes: Vec<u8>,
    /// Per packet: the lanes whose triangles end an any-hit query (all but those
    /// [`Self::cross_in_any_hit`] names).
    blocking_lanes: Vec<u8>,
    /// Stack entries a traversal can need: 7 per level below the root, plus 8.
    stack_size: usize,
    isa: Option<Isa>,
}

impl WideBvh {
    /// The wide form of `bvh`, whose primitive `slot` (leaf order) has box `boxes[slot]` and,
    /// when it is a triangle, `triangles[slot]`.
    pub fn new(bvh: &CwBvh, boxes: &[Aabb], triangles: &[Option<TriangleEdges>]) -> Self {
        let count = bvh.nodes.len();
        // Exact boxes bottom up (obvhs's are quantised outwards): children follow parents.
        let mut node_box = vec![Aabb::INVALID; count];
        let leaf_box = |start: u32, n: u32| {
            (start..start + n).fold(Aabb::INVALID, |b, s| b.union(&boxes[s as usize]))
        };
        for n in (0..count).rev() {
            let cw = &bvh.nodes[n];
            node_box[n] = (0..WIDTH)
                .filter(|&i| !cw.is_child_empty(i))
                .map(|i| {
                    if cw.is_leaf(i) {
                        let (start, n) = cw.child_primitives(i);
                        leaf_box(start, n)
                    } else {
                        node_box[cw.child_node_index(i) as usize]
                    }
                })
                .fold(Aabb::INVALID, |b, c| b.union(&c));
        }

        let mut wide = WideBvh {
            nodes: Vec::with_capacity(count),
            packets: Vec::new(),
            other_lanes: Vec::new(),
            blocking_lanes: Vec::new(),
            stack_size: 0,
            isa: Some(Isa::best()),
        };
        let mut depth = vec![0usize; count];
        let mut max_depth = 0;
        for (n, cw) in bvh.nodes.iter().enumerate() {
            let mut node = Node::EMPTY;
            let mut slots = 0..WIDTH;
            let mut leaves = Vec::new();
            for i in (0..WIDTH).filter(|&i| !cw.is_child_empty(i)) {
                if cw.is_leaf(i) {
                    let (start, n) = cw.child_primitives(i);
                    leaves.push((leaf_box(start, n), (start..start + n).collect()));
                } else {
                    let c = cw.child_node_index(i) as usize;
                    depth[c] = depth[n] + 1;
                    max_depth = max_depth.max(depth[c]);
                    let slot = slots.next().expect("a CWBVH node has at most 8 children");
                    node.set_child(slot, &node_box[c], c as u32);
                }
            }
            for (b, prims) in merge_leaves(leaves) {
                let slot = slots.next().expect("merging never adds leaves");
                node.leaves |= 1 << slot;
                node.set_child(slot, &b, wide.push_packet(&prims, triangles));
            }
            wide.nodes.push(node);
        }
        wide.stack_size = (WIDTH - 1) * max_depth + WIDTH;
        wide
    }

    /// Packs primitives `prims` (leaf order, at most [`PACKET`]) into one packet; returns the
    /// child reference.
    fn push_packet(&mut self, prims: &[u32], triangles: &[Option<TriangleEdges>]) -> u32 {
        debug_assert!(prims.len() <= PACKET);
        let mut packet = Packet::EMPTY;
        let mut other = 0u8;
        for (lane, &slot) in prims.iter().enumerate() {
            packet.slot[lane] = slot;
            match triangles[slot as usize] {
                Some(edges) => {
                    let [p0, e1, e2] = edges.parts();
                    for axis in 0..3 {
                        packet.p0[axis][lane] = p0[axis];
                        packet.e1[axis][lane] = e1[axis];
                        packet.e2[axis][lane] = e2[axis];
                    }
                }
                None => other |= 1 << lane,
            }
        }
        let index = self.packets.len() as u32;
        debug_assert!(index <= MAX_PACKETS);
        self.packets.push(packet);
        self.other_lanes.push(other);
        self.blocking_lanes.push(u8::MAX);
        LEAF | index | if other != 0 { LEAF_HAS_OTHER } else { 0 }
    }

    /// Triangles whose primitive slot `crossed` names no longer end an any-hit query: shadow
    /// rays cross them (`null` surfaces). Closest hits still find them.
    pub fn cross_in_any_hit(&mut self, crossed: impl Fn(u32) -> bool) {
        for (packet, lanes) in self.packets.iter().zip(&mut self.blocking_lanes) {
            for (lane, &slot) in packet.slot.iter().enumerate() {
                if *lanes & (1 << lane) != 0 && crossed(slot) {
                    *lanes &= !(1 << lane);
                }
            }
        }
    }

    /// The node a child reference (without the leaf bit) names.
    #[inline(always)]
    fn node(&self, child: u32) -> &Node {
        debug_assert!((child as usize) < self.nodes.len());
        // SAFETY: child references are made by `new`, each the index of a node it pushed, and
        // the traversals start at node 0 only when there are nodes.
        unsafe { self.nodes.get_unchecked(child as usize) }
    }

    /// The packet a leaf reference's index names.
    #[inline(always)]
    fn packet(&self, index: usize) -> &Packet {
        debug_assert!(index < self.packets.len());
        // SAFETY: leaf references are made by `push_packet`, each the index of the packet it
        // pushed.
        unsafe { self.packets.get_unchecked(index) }
    }

    /// Runs the traversal on `isa` from now on; false (and no change) when this CPU lacks it.
    pub fn set_isa(&mut self, isa: Isa) -> bool {
        let ok = Isa::available().contains(&isa);
        if ok {
            self.isa = Some(isa);
        }
        ok
    }

    /// The closest primitive hit with t in (0, tmax). Triangles are tested here; every other
    /// primitive through `other(slot, bound)`, which returns its nearest t below `bound`.
    pub fn closest(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        tmax: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<PrimHit> {
        if self.nodes.is_empty() || tmax.is_nan() || tmax <= 0.0 {
            return None;
        }
        let ray = TraversalRay::new(origin.into(), dir.into());
        match self.isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `isa` is only ever set to an instruction set the CPU was detected to run.
            Some(Isa::Avx512) => unsafe { self.closest_avx512(&ray, tmax, other) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Some(Isa::Avx2) => unsafe { self.closest_avx2(&ray, tmax, other) },
            #[cfg(target_arch = "x86_64")]
            Some(Isa::Sse) => self.closest_with::<Sse>(&ray, tmax, other),
            _ => self.closest_with::<Scalar>(&ray, tmax, other),
        }
    }

    /// Whether any primitive is hit with t in (0, tmax); `other(slot, tmax)` as for
    /// [`Self::closest`].
    pub fn any(
        &self,
        origin: Vec3A,
        dir: Vec3A,
        tmax: f32,
        other: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() || tmax.is_nan() || tmax <= 0.0 {
            return false;
        }
        let ray = TraversalRay::new(origin.into(), dir.into());
        match self.isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as in `closest`.
            Some(Isa::Avx512) => unsafe { self.any_avx512(&ray, tmax, other) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Some(Isa::Avx2) => unsafe { self.any_avx2(&ray, tmax, other) },
            #[cfg(target_arch = "x86_64")]
            Some(Isa::Sse) => self.any_with::<Sse>(&ray, tmax, other),
            _ => self.any_with::<Scalar>(&ray, tmax, other),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn closest_avx2(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<PrimHit> {
        self.closest_with::<Avx2>(ray, tmax, other)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn any_avx2(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        other: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        self.any_with::<Avx2>(ray, tmax, other)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    unsafe fn closest_avx512(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<PrimHit> {
        self.closest_with::<Avx512>(ray, tmax, other)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    unsafe fn any_avx512(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        other: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        self.any_with::<Avx512>(ray, tmax, other)
    }

    #[inline(always)]
    fn closest_with<K: Kernel>(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        other: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<PrimHit> {
        if self.stack_size <= INLINE_STACK {
            let mut stack = [Entry::uninit(); INLINE_STACK];
            self.closest_on::<K>(ray, tmax, other, &mut stack)
        } else {
            let mut stack = vec![Entry::uninit(); self.stack_size];
            self.closest_on::<K>(ray, tmax, other, &mut stack)
        }
    }

    #[inline(always)]
    fn closest_on<K: Kernel>(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        mut other: impl FnMut(u32, f32) -> Option<f32>,
        stack: &mut [Entry],
    ) -> Option<PrimHit> {
        let kray = K::prepare(ray);
        // Slot 0 with t = tmax: the tie rule (equal t, lower slot) never accepts t = tmax.
        let mut best = PrimHit {
            prim: 0,
            t: tmax,
            b1: 0.0,
            b2: 0.0,
        };
        let mut tnear = [0f32; WIDTH];
        let mut hits = PacketHits::default();
        let mut sp = 0;
        let mut node = 0u32;
        'nodes: loop {
            let n = self.node(node);
            let mask = K::slabs(n, &kray, best.t, &mut tnear);
            // One internal child hit (common for coherent rays): descend without the stack.
            if mask != 0 && mask & (mask - 1) == 0 {
                let child = n.child[mask.trailing_zeros() as usize];
                if child & LEAF == 0 {
                    node = child;
                    continue;
                }
            }
            sp = push_nearest_last(stack, sp, n, mask, &tnear);
            while sp > 0 {
                sp -= 1;
                // SAFETY: entries below the stack size were pushed.
                let (child, near) = unsafe { stack.get_unchecked(sp).assume_init() };
                if near > best.t {
                    continue;
                }
                if child & LEAF == 0 {
                    node = child;
                    continue 'nodes;
                }
                let index = (child & MAX_PACKETS) as usize;
                let packet = self.packet(index);
                let mut lanes = K::triangles(packet, &kray, best.t, &mut hits);
                while lanes != 0 {
                    let lane = lanes.trailing_zeros() as usize;
                    lanes &= lanes - 1;
                    let (slot, t) = (packet.slot[lane], hits.t[lane]);
                    if t < best.t || (t == best.t && slot < best.prim) {
                        best = PrimHit {
                            prim: slot,
                            t,
                            b1: hits.b1[lane],
                            b2: hits.b2[lane],
                        };
                    }
                }
                if child & LEAF_HAS_OTHER != 0 {
                    let mut lanes = self.other_lanes[index];
                    while lanes != 0 {
                        let lane = lanes.trailing_zeros() as usize;
                        lanes &= lanes - 1;
                        let slot = packet.slot[lane];
                        // The bound just above best.t lets an equal t reach the tie rule.
                        if let Some(t) = other(slot, best.t.next_up()) {
                            if t < best.t || (t == best.t && slot < best.prim) {
                                best = PrimHit {
                                    prim: slot,
                                    t,
                                    b1: 0.0,
                                    b2: 0.0,
                                };
                            }
                        }
                    }
                }
            }
            break;
        }
        (best.t < tmax).then_some(best)
    }

    #[inline(always)]
    fn any_with<K: Kernel>(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        other: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        if self.stack_size <= INLINE_STACK {
            let mut stack = [MaybeUninit::uninit(); INLINE_STACK];
            self.any_on::<K>(ray, tmax, other, &mut stack)
        } else {
            let mut stack = vec![MaybeUninit::uninit(); self.stack_size];
            self.any_on::<K>(ray, tmax, other, &mut stack)
        }
    }

    /// Tests a node's leaf children as soon as the node is hit, before descending (large
    /// triangles high in the tree end most shadow rays early); internal children are visited
    /// in slot order, unsorted: any hit will do.
    #[inline(always)]
    fn any_on<K: Kernel>(
        &self,
        ray: &TraversalRay,
        tmax: f32,
        mut other: impl FnMut(u32, f32) -> bool,
        stack: &mut [MaybeUninit<u32>],
    ) -> bool {
        let kray = K::prepare(ray);
        // The kernels accept t <= bound; the query wants t < tmax.
        let bound = tmax.next_down();
        let mut tnear = [0f32; WIDTH];
        let mut hits = PacketHits::default();
        stack[0] = MaybeUninit::new(0);
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            // SAFETY: entries below the stack size were pushed.
            let n = self.node(unsafe { stack.get_unchecked(sp).assume_init() });
            let mask = K::slabs(n, &kray, bound, &mut tnear);
            let mut leaves = mask & n.leaves;
            while leaves != 0 {
                let i = leaves.trailing_zeros() as usize;
                leaves &= leaves - 1;
                let child = n.child[i];
                let index = (child & MAX_PACKETS) as usize;
                let packet = self.packet(index);
                let blocking = u32::from(self.blocking_lanes[index]);
                if K::triangles(packet, &kray, bound, &mut hits) & blocking != 0 {
                    return true;
                }
                if child & LEAF_HAS_OTHER != 0 {
                    let lanes = self.other_lanes[index];
                    if (0..PACKET)
                        .filter(|lane| lanes & (1 << lane) != 0)
                        .any(|lane| other(packet.slot[lane], tmax))
                    {
                        return true;
                    }
                }
            }
            let mut inner = mask & !n.leaves;
            while inner != 0 {
                let i = inner.trailing_zeros() as usize;
                inner &= inner - 1;
                debug_assert!(sp < stack.len());
                // SAFETY: `stack` holds `stack_size` entries, at least what a traversal of
                // this BVH's depth pushes (see `push_nearest_last`).
                unsafe { *stack.get_unchecked_mut(sp) = MaybeUninit::new(n.child[i]) };
                sp += 1;
            }
        }
        false
    }
}

/// A node's leaves, merged pairwise into packets of up to [`PACKET`] primitives while that
/// lowers the surface-area cost. obvhs's CWBVH leaves hold at most 3 primitives, so a 4-lane
/// packet per leaf runs partly empty; one packet holding two leaves is tested whenever their
/// union box is hit, the two leaves whenever either box is, so a pair merges when the union's
/// area is below the sum of theirs (the best such pair first). Which primitives a ray can hit
/// does not change, nor the hit returned (see the tie rule).
fn merge_leaves(mut leaves: Vec<(Aabb, Vec<u32>)>) -> Vec<(Aabb, Vec<u32>)> {
    loop {
        let mut best: Option<(f32, usize, usize)> = None;
        for a in 0..leaves.len() {
            for b in a + 1..leaves.len() {
                if leaves[a].1.len() + leaves[b].1.len() > PACKET {
                    continue;
                }
                let union = leaves[a].0.union(&leaves[b].0);
                let saving = leaves[a].0.half_area() + leaves[b].0.half_area() - union.half_area();
                if saving > 0.0 && best.is_none_or(|(s, _, _)| saving > s) {
                    best = Some((saving, a, b));
                }
            }
        }
        let Some((_, a, b)) = best else {
            return leaves;
        };
        // b > a, so removing b leaves a in place.
        let (merged_box, prims) = leaves.remove(b);
        leaves[a].0 = leaves[a].0.union(&merged_box);
        leaves[a].1.extend(prims);
    }
}

/// Pushes the children of `node` set in `mask` onto `stack[sp..]` with their entry distances,
/// the nearest last (on top; equal distances keep slot order): an insertion sort, as most
/// nodes have one to three hits. Returns the new stack size.
#[inline(always)]
fn push_nearest_last(
    stack: &mut [Entry],
    mut sp: usize,
    node: &Node,
    mut mask: u32,
    tnear: &[f32; WIDTH],
) -> usize {
    let base = sp;
    while mask != 0 {
        let i = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        let entry = (node.child[i], tnear[i]);
        let mut j = sp;
        debug_assert!(sp < stack.len());
        // SAFETY: entries base..sp were pushed, and j <= sp < stack.len(): a node at depth d
        // is visited with at most 7 entries per level above it on the stack (its ancestors'
        // other children) and pushes at most 8, and `WideBvh::stack_size` (the stack's
        // length) is 7 x the BVH's depth + 8.
        unsafe {
            while j > base && stack.get_unchecked(j - 1).assume_init().1 < entry.1 {
                *stack.get_unchecked_mut(j) = *stack.get_unchecked(j - 1);
                j -= 1;
            }
            *stack.get_unchecked_mut(j) = Entry::new(entry);
        }
        sp += 1;
    }
    sp
}
