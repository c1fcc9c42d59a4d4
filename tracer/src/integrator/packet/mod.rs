//! Camera paths traced in lanes ([`crate::lanes`]): `L::N` consecutive samples of one pixel
//! step together from vertex to vertex, their random numbers drawn at once
//! ([`PacketSampler`]), their Lambert vertices sampled, weighed and rouletted in lanes. Rays are
//! traced, materials and lights looked up one lane at a time, as [`walk`] does; a light sample
//! that goes to a lamp image, and a vertex of any other material (mirror, glass, metal, a rough
//! or coated surface), are shaded one lane at a time by [`walk`]'s own [`Vertex`], and the lane
//! stays in the packet.
//!
//! Every lane computes what [`walk`] computes for its sample, operation for operation, so a
//! pixel's samples are the same bits whether traced here or one at a time: the choice between
//! the two (the CPU's lane types, a scene's coverage) never shows in an image. A lane whose
//! path does what the packet's lanes cannot do together (meets a miss, an emitter or a null
//! surface; splits at a glossy vertex; meets anything but Lambert where the paths branch)
//! leaves the packet and goes on one at a time from the same state and the same place in its
//! sample stream, by [`walk`] itself; so do the last lanes of a packet down to [`FEW_LANES`].

mod branch;
mod lambert;
#[cfg(test)]
mod tests;
mod vectors;
mod walk;

use glam::Vec3;

use crate::integrator::branch::MAX_BRANCHES;
use crate::integrator::scene::PathScene;
use crate::integrator::state::PathResult;
use crate::lanes::{Lanes, MAX_LANES};
use crate::math::Ray;
use crate::sampler::PacketSampler;
use branch::branch_packet;
use vectors::LaneVec3s;
use walk::{walk_packet, LanePrevScatter, Packet};

/// Whether `scene`'s camera paths may be traced in packets: no volumes (a packet's lanes all
/// travel in none) and no panes of architectural glass (a lane's shadow ray is blocked or not,
/// never dimmed), and path tracing's walk (direct lighting's paths end early: one at a time,
/// they are short). Any material, light or camera: lanes that meet what a packet does not
/// follow leave it.
pub fn covers<S: PathScene>(scene: &S) -> bool {
    scene.volumes().media.is_empty()
        && scene.volumes().camera.is_none()
        && !scene.has_panes()
        && !scene.direct_lighting()
}

/// Traces the packet's camera rays (`None`: no ray, black) to the end, one [`PathResult`] per
/// lane; the same bits as [`super::path::trace_path`] on each lane's ray and stream.
#[inline(always)]
pub fn trace_packet<S: PathScene, L: Lanes>(
    scene: &S,
    rays: &[Option<Ray>; MAX_LANES],
    sampler: &mut PacketSampler<L>,
) -> [PathResult; MAX_LANES] {
    let mut out = [PathResult::default(); MAX_LANES];
    let mut origin = LaneVec3s::splat(Vec3::ZERO);
    let mut dir = LaneVec3s::splat(Vec3::Z);
    let mut live = [false; MAX_LANES];
    for i in 0..L::N {
        if let Some(ray) = rays[i] {
            origin.set(i, ray.origin);
            dir.set(i, ray.dir);
            live[i] = true;
        }
    }
    let origin = origin.load::<L>();
    let zero = L::splat(0.0);
    let mut packet = Packet {
        live,
        origin,
        dir: dir.load::<L>(),
        throughput: [L::splat(1.0); 3],
        radiance: [zero; 3],
        depth: 0,
        branches: scene.first_vertex_branches().clamp(1, MAX_BRANCHES),
        may_split: scene.glossy_split(),
        prev_p: origin,
        prev_pdf: zero,
        prev_facing: [zero; 3],
        prev: [LanePrevScatter::CAMERA; MAX_LANES],
        rays: [0; MAX_LANES],
    };
    if let Some(branch) = walk_packet(scene, &mut packet, sampler, &mut out) {
        branch_packet(scene, &packet, branch, &mut out);
        packet.finish_all(&mut out);
    }
    out
}
