//! A packet's branching vertex: its continuations, one packet each, traced in order as the
//! path loop's are.

use super::vectors::lanes_set;
use super::walk::{walk_packet, LanePrevScatter, Packet, PacketBranchPoint};
use crate::integrator::branch::MAX_BRANCHES;
use crate::integrator::roulette::survives_in_lanes;
use crate::integrator::scene::PathScene;
use crate::integrator::state::PathResult;
use crate::lanes::{Lanes, MAX_LANES};
use crate::vec3_lanes::{dot, offset_origin, scale, times};

/// The continuations of a packet's paths at their branching vertex, one packet each, traced
/// in order (as [`super::path`]'s `BranchVertex::branch` traces a path's).
#[inline(always)]
pub(super) fn branch_packet<S: PathScene, L: Lanes>(
    scene: &S,
    parent: &Packet<L>,
    mut branch: PacketBranchPoint<L>,
    out: &mut [PathResult; MAX_LANES],
) {
    let count = parent.branches;
    let (_, dirs) = branch.sampler.get_split_draws::<MAX_BRANCHES>(count);
    let v = &branch.vertex;
    let facing = v.facing();
    let count_f = L::splat(count as f32);
    for (k, &dir) in dirs.iter().enumerate().take(count) {
        let (mut stream, u_rr) = if k == 0 {
            (branch.sampler.clone(), branch.roulette)
        } else {
            let mut stream = branch.sampler.branch(k as u32);
            let u_rr = stream.get_1d();
            (stream, u_rr)
        };
        let bs = v.sample(dir);
        let cos = dot(bs.wi, v.ns).abs();
        let mut throughput = scale(times(branch.throughput, v.f), cos / bs.pdf);
        let broad = L::mask(true);
        let kept = bs.valid
            & survives_in_lanes(
                scene.integrator(),
                parent.depth,
                broad,
                u_rr,
                &mut throughput,
            );
        let kept = lanes_set::<L>(kept);
        let mut live = [false; MAX_LANES];
        for i in 0..L::N {
            live[i] = parent.live[i] && kept[i];
        }
        let zero = L::splat(0.0);
        let prev = branch.image_share.map(LanePrevScatter::lambert);
        let mut continuation = Packet {
            live,
            origin: offset_origin(v.p, v.ng, bs.wi),
            dir: bs.wi,
            throughput: [
                throughput[0] / count_f,
                throughput[1] / count_f,
                throughput[2] / count_f,
            ],
            radiance: [zero; 3],
            depth: parent.depth,
            branches: 1,
            may_split: parent.may_split,
            prev_p: v.p,
            prev_pdf: count_f * bs.pdf,
            prev_facing: facing,
            prev,
            rays: [0; MAX_LANES],
        };
        let branched = walk_packet(scene, &mut continuation, &mut stream, out);
        debug_assert!(branched.is_none(), "a continuation branches once only");
    }
}
