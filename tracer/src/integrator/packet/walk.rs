//! A packet's loop from vertex to vertex: its lanes' rays traced and their hits met one lane
//! at a time, their Lambert vertices shaded in lanes, every other vertex by [`Vertex`] for its
//! lane, and a lane that does what the packet cannot leaving it for the path loop.
//!
//! [`Vertex`]: crate::integrator::vertex::Vertex

use glam::Vec3;

use super::lambert::{LambertVertex, LightDraws};
use super::vectors::{lanes_set, mask_of, LaneVec3s};
use crate::geometry::SurfaceHit;
use crate::integrator::branch::walk_to_the_end;
use crate::integrator::glossy_split::splits_at;
use crate::integrator::light_draw::BsdfCounts;
use crate::integrator::mirror_images::mirror_after;
use crate::integrator::roulette::survives_in_lanes;
use crate::integrator::scene::PathScene;
use crate::integrator::state::{BeforeMirror, PathResult, PathState, PrevScatter};
use crate::integrator::vertex::{LightChoice, Vertex};
use crate::lanes::{Lanes, MAX_LANES};
use crate::material::{Bsdf, BsdfSample};
use crate::math::Ray;
use crate::medium::ShapeMedia;
use crate::sampler::{PacketSampler, VertexPacket, VertexSamples};
use crate::vec3_lanes::{dot, negate, offset_origin, plus, scale, select3, times, V3};

/// A packet whose live lanes are this few hands them to the path loop: shading in lanes costs
/// what it costs for all `L::N`, and below three live lanes one path at a time is the cheaper
/// (bench/RESULTS.md, "A packet's last lanes"). Paths live a few vertices, so most packets end
/// with few lanes.
pub(super) const FEW_LANES: usize = 2;

/// What a lane's last vertex leaves the next one beyond its point, density and side (which
/// the packet keeps in lanes): the rest of [`PrevScatter`].
#[derive(Clone, Copy)]
pub(super) struct LanePrevScatter {
    pub(super) specular: bool,
    pub(super) image_share: f32,
    pub(super) before_mirror: Option<BeforeMirror>,
    /// Whether the vertex gathered light broadly (from the packet's `prev_facing` side).
    pub(super) broad: bool,
}

impl LanePrevScatter {
    /// The camera counts as specular: emitters its rays see are taken at full weight.
    pub(super) const CAMERA: Self = Self {
        specular: true,
        image_share: 0.0,
        before_mirror: None,
        broad: false,
    };
    /// A Lambert vertex shaded in lanes, `image_share` of whose light samples went to lamp
    /// images.
    pub(super) const fn lambert(image_share: f32) -> Self {
        Self {
            specular: false,
            image_share,
            before_mirror: None,
            broad: true,
        }
    }
}

/// Camera paths in lanes between two vertices. Every lane still in the packet has scattered
/// at every vertex so far (null surfaces, volumes and splits make a lane leave), so all are at
/// the same depth; they branch together at their first vertex (where `branches` > 1 only
/// Lambert lanes stay) and may all still split or none.
pub(super) struct Packet<L: Lanes> {
    pub(super) live: [bool; MAX_LANES],
    pub(super) origin: V3<L>,
    pub(super) dir: V3<L>,
    pub(super) throughput: V3<L>,
    pub(super) radiance: V3<L>,
    pub(super) depth: u32,
    pub(super) branches: usize,
    /// Whether a glossy vertex may split the lanes' paths ([`PathState::may_split`]).
    pub(super) may_split: bool,
    pub(super) prev_p: V3<L>,
    pub(super) prev_pdf: L,
    /// After a broad vertex, the side it gathered light from.
    pub(super) prev_facing: V3<L>,
    pub(super) prev: [LanePrevScatter; MAX_LANES],
    /// The rays each lane traced in this packet.
    pub(super) rays: [u32; MAX_LANES],
}

impl<L: Lanes> Packet<L> {
    /// Where lane `i`'s last ray was sampled, as [`walk`] carries it.
    #[inline(always)]
    pub(super) fn prev_scatter(&self, i: usize, parts: &PacketByLane) -> PrevScatter {
        let prev = self.prev[i];
        PrevScatter {
            p: parts.prev_p.get(i),
            pdf: parts.prev_pdf[i],
            specular: prev.specular,
            image_share: prev.image_share,
            before_mirror: prev.before_mirror,
            lamps_counted: false,
            facing: prev.broad.then_some(parts.prev_facing.get(i)),
        }
    }

    /// Lane `i`'s path as [`walk`] carries it, with what its ray hits (`None`: not traced
    /// yet).
    #[inline(always)]
    pub(super) fn lane_state(
        &self,
        i: usize,
        parts: &PacketByLane,
        traced: Option<Option<SurfaceHit>>,
    ) -> PathState {
        PathState {
            ray: Ray::new(parts.origin.get(i), parts.dir.get(i)),
            traced,
            throughput: parts.throughput.get(i),
            radiance: parts.radiance.get(i),
            medium: None,
            depth: self.depth,
            pass_through: 0,
            may_split: self.may_split,
            branches: self.branches,
            prev: self.prev_scatter(i, parts),
            // A dispersive vertex is never shaded in lanes: a path takes its wavelength alone.
            wavelength: None,
        }
    }

    /// Lane `i` leaves the packet and its path goes on alone by [`walk`] from the packet's
    /// state (with what its ray hits, when traced already) and from `stream`'s place in the
    /// lane's own sample stream; its light and rays go to `out`.
    #[inline(always)]
    pub(super) fn go_on_alone<S: PathScene>(
        &mut self,
        scene: &S,
        i: usize,
        parts: &PacketByLane,
        traced: Option<Option<SurfaceHit>>,
        stream: &PacketSampler<L>,
        out: &mut PathResult,
    ) {
        self.live[i] = false;
        out.rays += self.rays[i];
        let state = self.lane_state(i, parts, traced);
        walk_to_the_end(scene, state, &mut stream.lane(i), (out, &mut ()));
    }

    /// Ends lane `i`: its light and rays go to `out`.
    #[inline(always)]
    pub(super) fn finish(&mut self, i: usize, radiance: Vec3, out: &mut PathResult) {
        self.live[i] = false;
        out.radiance += radiance;
        out.rays += self.rays[i];
    }

    /// Ends every live lane where `m` is not set.
    #[inline(always)]
    pub(super) fn keep(&mut self, m: L::M, out: &mut [PathResult; MAX_LANES]) {
        let kept = lanes_set::<L>(m);
        if (0..L::N).all(|i| kept[i] || !self.live[i]) {
            return;
        }
        let radiance = LaneVec3s::of(self.radiance);
        for i in 0..L::N {
            if self.live[i] && !kept[i] {
                self.finish(i, radiance.get(i), &mut out[i]);
            }
        }
    }

    /// Ends every live lane.
    #[inline(always)]
    pub(super) fn finish_all(&mut self, out: &mut [PathResult; MAX_LANES]) {
        self.keep(L::mask(false), out);
    }
}

/// A packet's state, lane by lane: what a lane leaving it takes along.
pub(super) struct PacketByLane {
    pub(super) origin: LaneVec3s,
    pub(super) dir: LaneVec3s,
    pub(super) throughput: LaneVec3s,
    pub(super) radiance: LaneVec3s,
    pub(super) prev_p: LaneVec3s,
    pub(super) prev_pdf: [f32; MAX_LANES],
    pub(super) prev_facing: LaneVec3s,
}

impl PacketByLane {
    #[inline(always)]
    pub(super) fn of<L: Lanes>(packet: &Packet<L>) -> Self {
        Self {
            origin: LaneVec3s::of(packet.origin),
            dir: LaneVec3s::of(packet.dir),
            throughput: LaneVec3s::of(packet.throughput),
            radiance: LaneVec3s::of(packet.radiance),
            prev_p: LaneVec3s::of(packet.prev_p),
            prev_pdf: packet.prev_pdf.values(),
            prev_facing: LaneVec3s::of(packet.prev_facing),
        }
    }
}

/// A vertex shaded for one lane by [`Vertex`], as [`walk`] shades it.
#[derive(Clone, Copy)]
pub(super) struct ShadedAlone {
    pub(super) image_share: f32,
    /// The BSDF sample and the throughput's weight; None ends the path.
    pub(super) sample: Option<(BsdfSample, Vec3)>,
    /// The side a broad vertex gathers light from.
    pub(super) broad: Option<Vec3>,
    pub(super) before_mirror: Option<BeforeMirror>,
}

/// Where a packet's paths branch ([`MAX_BRANCHES`]): the vertex its continuations start from.
pub(super) struct PacketBranchPoint<L: Lanes> {
    pub(super) vertex: LambertVertex<L>,
    pub(super) throughput: V3<L>,
    pub(super) roulette: L,
    /// The share of each lane's light samples that went to lamp images.
    pub(super) image_share: [f32; MAX_LANES],
    /// The packet's stream after the vertex's own dimensions.
    pub(super) sampler: PacketSampler<L>,
}

/// Where a packet's lanes scatter at a vertex: the BSDF samples' directions, densities and
/// throughput weights, where they are valid, which vertices scattered broadly (and to which
/// side).
pub(super) struct ScatterLanes<L: Lanes> {
    pub(super) weight: V3<L>,
    pub(super) wi: V3<L>,
    pub(super) pdf: L,
    pub(super) valid: L::M,
    pub(super) broad: L::M,
    pub(super) facing: V3<L>,
}

/// A lane at a vertex: which, the packet's state lane by lane, and the BSDF samples its light
/// sample is weighed against.
pub(super) struct LaneVertex<'a> {
    pub(super) lane: usize,
    pub(super) parts: &'a PacketByLane,
    pub(super) bsdf_count: f32,
}

/// What a packet's lanes meet at their next vertex, lane by lane.
pub(super) struct LaneHits {
    pub(super) p: LaneVec3s,
    pub(super) ng: LaneVec3s,
    pub(super) ns: LaneVec3s,
    pub(super) frame: [LaneVec3s; 3],
    pub(super) f: LaneVec3s,
    /// The lanes at a bare Lambert surface, shaded in lanes (but a light sample that goes to a
    /// lamp image).
    pub(super) lambert: [bool; MAX_LANES],
    /// The vertices shaded one lane at a time: any other surface.
    pub(super) alone: [Option<ShadedAlone>; MAX_LANES],
    /// The light that lanes shaded one at a time bring (alone, or through lamp images).
    pub(super) lit_alone: [Option<Vec3>; MAX_LANES],
    pub(super) image_share: [f32; MAX_LANES],
    pub(super) draws: LightDraws,
    /// The vertex's numbers lane by lane, once a lane is shaded alone.
    pub(super) by_lane: Option<[VertexSamples; MAX_LANES]>,
}

impl LaneHits {
    #[inline(always)]
    pub(super) fn new() -> Self {
        Self {
            p: LaneVec3s::splat(Vec3::ZERO),
            ng: LaneVec3s::splat(Vec3::ZERO),
            ns: LaneVec3s::splat(Vec3::ZERO),
            frame: [LaneVec3s::splat(Vec3::ZERO); 3],
            f: LaneVec3s::splat(Vec3::ZERO),
            lambert: [false; MAX_LANES],
            alone: [None; MAX_LANES],
            lit_alone: [None; MAX_LANES],
            image_share: [0.0; MAX_LANES],
            draws: LightDraws {
                u_select: [0.0; MAX_LANES],
                share: [1.0; MAX_LANES],
            },
            by_lane: None,
        }
    }

    /// Ready for the next vertex, whose numbers are `u`. The lanes' points, normals and
    /// values are left as they were: a lane's are read only where this vertex sets them.
    #[inline(always)]
    pub(super) fn reset<L: Lanes>(&mut self, u: &VertexPacket<L>) {
        self.lambert = [false; MAX_LANES];
        self.alone = [None; MAX_LANES];
        self.lit_alone = [None; MAX_LANES];
        self.image_share = [0.0; MAX_LANES];
        self.draws = LightDraws {
            u_select: u.light_select.values(),
            share: [1.0; MAX_LANES],
        };
        self.by_lane = None;
    }

    /// Takes in lane `at.lane`'s hit, with its BSDF (not a null one), where the lane may stay
    /// in the packet: false where it leaves (where the paths may branch, anything but Lambert;
    /// a glossy vertex that splits). Counts the lane's rays.
    #[inline(always)]
    pub(super) fn meet<S: PathScene, L: Lanes>(
        &mut self,
        scene: &S,
        packet: &mut Packet<L>,
        at: &LaneVertex,
        hit: &SurfaceHit,
        bsdf: &Bsdf,
        u: &VertexPacket<L>,
    ) -> bool {
        let i = at.lane;
        let wo = -at.parts.dir.get(i);
        if packet.depth >= scene.max_depth() {
            // The path ends here.
            packet.rays[i] += 1;
            return true;
        }
        let lights = scene.lights();
        let lambert = bsdf.as_lambert();
        if lambert.is_none() {
            // A path branches at its first broad vertex, or keeps its branches past a specular
            // one: only Lambert lanes branch together.
            let splits = packet.may_split && splits_at(lights, hit, wo, bsdf);
            if packet.branches > 1 || splits {
                return false;
            }
        }
        packet.rays[i] += 1;
        self.p.set(i, hit.p);
        self.ng.set(i, hit.ng);
        self.ns.set(i, hit.ns);
        let lambert_here = lambert.is_some();
        if let Some((frame, ng, f)) = lambert {
            self.lambert[i] = true;
            self.ng.set(i, ng);
            self.f.set(i, f);
            self.frame[0].set(i, frame.s);
            self.frame[1].set(i, frame.t);
            self.frame[2].set(i, frame.n);
            if !lights.has_mirror_images() {
                return true;
            }
        }
        let us = match &self.by_lane {
            Some(us) => us,
            None => self.by_lane.insert(u.by_lane()),
        };
        // Only Lambert lanes stay where paths branch: any other's count is 1.
        let vertex = Vertex {
            hit,
            wo,
            bsdf,
            sides: ShapeMedia::default(),
            depth: packet.depth + 1,
            bsdf_counts: BsdfCounts::all(at.bsdf_count),
        };
        let mut rays = 0;
        if lambert_here {
            let (choice, image_share) = vertex.choose_light(scene, &us[i], &mut rays);
            self.image_share[i] = image_share;
            match choice {
                LightChoice::Image(term) => self.lit_alone[i] = Some(term.light),
                LightChoice::Lights(draw) => {
                    (self.draws.u_select[i], self.draws.share[i]) = (draw.u_select, draw.share);
                }
            }
        } else {
            let (light, image_share) = vertex.light(scene, &us[i], &mut rays);
            let sample = vertex.sample(&us[i]);
            let before_mirror = match &sample {
                Some((bs, _)) => {
                    let prev = packet.prev_scatter(i, at.parts);
                    mirror_after(lights, hit, wo, &prev, bs, false)
                }
                None => None,
            };
            self.lit_alone[i] = light;
            self.alone[i] = Some(ShadedAlone {
                image_share,
                sample,
                broad: bsdf.gathers_from(wo),
                before_mirror,
            });
        }
        packet.rays[i] += rays;
        true
    }

    /// `lambert`'s lanes where the vertex was Lambert, the lone lanes' own samples elsewhere;
    /// each lane's `prev` set for the next vertex.
    #[inline(always)]
    pub(super) fn with_alone_lanes<L: Lanes>(
        &self,
        lambert: ScatterLanes<L>,
        prev: &mut [LanePrevScatter; MAX_LANES],
    ) -> ScatterLanes<L> {
        let in_lanes = mask_of::<L>(&self.lambert);
        let mut wi = LaneVec3s::splat(Vec3::Z);
        let mut weight = LaneVec3s::splat(Vec3::ONE);
        let mut pdf = [0.0; MAX_LANES];
        let mut valid = [false; MAX_LANES];
        let mut broad = self.lambert;
        let mut facing = LaneVec3s::splat(Vec3::ZERO);
        for i in 0..L::N {
            let Some(step) = self.alone[i] else {
                prev[i] = LanePrevScatter::lambert(self.image_share[i]);
                continue;
            };
            let mut specular = false;
            if let Some((s, w)) = step.sample {
                wi.set(i, s.wi);
                weight.set(i, w);
                (pdf[i], valid[i]) = (s.pdf, true);
                specular = s.specular;
            }
            if let Some(side) = step.broad {
                broad[i] = true;
                facing.set(i, side);
            }
            prev[i] = LanePrevScatter {
                specular,
                image_share: step.image_share,
                before_mirror: step.before_mirror,
                broad: step.broad.is_some(),
            };
        }
        ScatterLanes {
            weight: select3(in_lanes, lambert.weight, weight.load::<L>()),
            wi: select3(in_lanes, lambert.wi, wi.load::<L>()),
            pdf: L::select(in_lanes, lambert.pdf, L::load(&pdf)),
            valid: (in_lanes & lambert.valid) | mask_of::<L>(&valid),
            broad: mask_of::<L>(&broad),
            facing: select3(in_lanes, lambert.facing, facing.load::<L>()),
        }
    }
}

/// Traces the packet on from its rays, adding each lane's light and rays to its `out`, until
/// every lane has ended or left, or the packet reaches the vertex where its paths branch
/// (returned, its lanes still live: the caller traces the continuations, then ends them).
#[inline(always)]
pub(super) fn walk_packet<S: PathScene, L: Lanes>(
    scene: &S,
    packet: &mut Packet<L>,
    sampler: &mut PacketSampler<L>,
    out: &mut [PathResult; MAX_LANES],
) -> Option<PacketBranchPoint<L>> {
    let geometry = scene.geometry();
    let lights = scene.lights();
    let max_depth = scene.max_depth();
    let mut hits = LaneHits::new();
    loop {
        if packet.live[..L::N].iter().filter(|&&live| live).count() <= FEW_LANES {
            let parts = PacketByLane::of(packet);
            for (i, out) in out.iter_mut().enumerate().take(L::N) {
                if packet.live[i] {
                    packet.go_on_alone(scene, i, &parts, None, sampler, out);
                }
            }
            return None;
        }
        let before = sampler.clone();
        let u = sampler.get_vertex();
        let mix = u.mix.values();
        let parts = PacketByLane::of(packet);
        let branching = packet.branches > 1;
        let bsdf_count = if branching {
            packet.branches as f32
        } else {
            1.0
        };
        hits.reset(&u);
        for i in 0..L::N {
            if !packet.live[i] {
                continue;
            }
            let ray = Ray::new(parts.origin.get(i), parts.dir.get(i));
            let wo = -ray.dir;
            let traced = geometry.intersect(&ray, f32::INFINITY);
            let stays = match &traced {
                Some(hit) if lights.emitted(hit, wo) == Vec3::ZERO => {
                    let bsdf = scene.bsdf_at(hit, mix[i]);
                    let at = LaneVertex {
                        lane: i,
                        parts: &parts,
                        bsdf_count,
                    };
                    !bsdf.is_pass_through()
                        && !bsdf.is_dispersive()
                        && hits.meet(scene, packet, &at, hit, &bsdf, &u)
                }
                _ => false,
            };
            if !stays {
                // From this ray and its hit.
                packet.go_on_alone(scene, i, &parts, Some(traced), &before, &mut out[i]);
            }
        }
        if !packet.live[..L::N].contains(&true) {
            return None;
        }
        if packet.depth >= max_depth {
            packet.finish_all(out);
            return None;
        }
        packet.depth += 1;

        let wo = negate(packet.dir);
        let frame = [
            hits.frame[0].load::<L>(),
            hits.frame[1].load::<L>(),
            hits.frame[2].load::<L>(),
        ];
        let vertex = LambertVertex {
            p: hits.p.load::<L>(),
            ng: hits.ng.load::<L>(),
            ns: hits.ns.load::<L>(),
            f: hits.f.load::<L>(),
            wo,
            wo_local: [dot(wo, frame[0]), dot(wo, frame[1]), dot(wo, frame[2])],
            frame,
        };
        // The lanes whose light sample goes to the lights, in lanes.
        let mut to_lights = hits.lambert;
        let mut any_alone = false;
        for ((to_lights, lit), alone) in to_lights.iter_mut().zip(&hits.lit_alone).zip(&hits.alone)
        {
            *to_lights &= lit.is_none();
            any_alone |= alone.is_some();
        }
        let light = vertex.direct_light(
            scene,
            &to_lights,
            &mut packet.rays,
            &hits.draws,
            u.light,
            bsdf_count,
        );
        if hits.by_lane.is_some() {
            let mut light_alone = LaneVec3s::splat(Vec3::ZERO);
            let mut lit = hits.lambert;
            for (i, (lit, alone)) in lit.iter_mut().zip(&hits.lit_alone).enumerate() {
                if let Some(l) = *alone {
                    light_alone.set(i, l);
                    *lit = true;
                }
            }
            let light = select3(mask_of::<L>(&to_lights), light, light_alone.load::<L>());
            let radiance = plus(packet.radiance, times(packet.throughput, light));
            packet.radiance = select3(mask_of::<L>(&lit), radiance, packet.radiance);
        } else {
            packet.radiance = plus(packet.radiance, times(packet.throughput, light));
        }
        if branching {
            return Some(PacketBranchPoint {
                vertex,
                throughput: packet.throughput,
                roulette: u.roulette,
                image_share: hits.image_share,
                sampler: sampler.clone(),
            });
        }

        let bs = vertex.sample(u.bsdf);
        let cos = dot(bs.wi, vertex.ns).abs();
        let lambert = ScatterLanes {
            weight: scale(vertex.f, cos / bs.pdf),
            wi: bs.wi,
            pdf: bs.pdf,
            valid: bs.valid,
            broad: L::mask(true),
            facing: vertex.facing(),
        };
        let ScatterLanes {
            weight,
            wi,
            pdf,
            valid,
            broad,
            facing,
        } = if any_alone {
            hits.with_alone_lanes(lambert, &mut packet.prev)
        } else {
            packet.prev = hits.image_share.map(LanePrevScatter::lambert);
            lambert
        };
        packet.throughput = times(packet.throughput, weight);
        let kept = valid
            & survives_in_lanes(
                scene.integrator(),
                packet.depth,
                broad,
                u.roulette,
                &mut packet.throughput,
            );
        packet.keep(kept, out);
        packet.prev_p = vertex.p;
        packet.prev_pdf = pdf;
        packet.prev_facing = facing;
        packet.origin = offset_origin(vertex.p, vertex.ng, wi);
        packet.dir = wi;
    }
}
