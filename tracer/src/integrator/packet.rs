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

use glam::{Vec2, Vec3};

use super::options::RussianRoulette;
use super::path::{
    power_heuristic, walk, BeforeMirror, BsdfCounts, LightChoice, PathResult, PathScene, PathState,
    PrevScatter, Vertex, MAX_BRANCHES, RR_MIN_DEPTH, RR_MIN_SURVIVAL, RR_THROUGHPUT_SCALE,
};
use crate::bxdf::local::cosine_hemisphere;
use crate::geometry::SurfaceHit;
use crate::lanes::{Lanes, MAX_LANES};
use crate::lights::LightSamples;
use crate::material::{Bsdf, BsdfSample};
use crate::math::Ray;
use crate::medium::ShapeMedia;
use crate::sampler::{PacketSampler, VertexPacket, VertexSamples};

/// Whether `scene`'s camera paths may be traced in packets: no volumes (a packet's lanes all
/// travel in none). Any material, light or camera: lanes that meet what a packet does not
/// follow leave it.
pub fn covers<S: PathScene>(scene: &S) -> bool {
    scene.volumes().media.is_empty() && scene.volumes().camera.is_none()
}

/// A packet whose live lanes are this few hands them to [`walk`]: shading in lanes costs
/// what it costs for all `L::N`, and below three live lanes one path at a time is the
/// cheaper (depth of field, Cornell and Captain Falcon 2-3% sooner than with no such bound,
/// Mario even; bench/RESULTS.md, session 28). Paths live a few vertices, so most packets end
/// with few lanes.
const FEW_LANES: usize = 2;

/// Three coordinates in lanes.
type V3<L> = [L; 3];

#[inline(always)]
fn dot<L: Lanes>(a: V3<L>, b: V3<L>) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn scale<L: Lanes>(a: V3<L>, k: L) -> V3<L> {
    [a[0] * k, a[1] * k, a[2] * k]
}

#[inline(always)]
fn times<L: Lanes>(a: V3<L>, b: V3<L>) -> V3<L> {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

#[inline(always)]
fn plus<L: Lanes>(a: V3<L>, b: V3<L>) -> V3<L> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `-a`, exactly (the sign of a zero too).
#[inline(always)]
fn negate<L: Lanes>(a: V3<L>) -> V3<L> {
    scale(a, L::splat(-1.0))
}

#[inline(always)]
fn select3<L: Lanes>(m: L::M, a: V3<L>, b: V3<L>) -> V3<L> {
    [
        L::select(m, a[0], b[0]),
        L::select(m, a[1], b[1]),
        L::select(m, a[2], b[2]),
    ]
}

/// Per-lane vectors as lanes hold them: a row of x, one of y, one of z, filled and read lane
/// by lane (lanes past `L::N` are not read).
#[derive(Clone, Copy)]
struct Rows([[f32; MAX_LANES]; 3]);

impl Rows {
    const fn splat(v: Vec3) -> Self {
        Self([[v.x; MAX_LANES], [v.y; MAX_LANES], [v.z; MAX_LANES]])
    }

    #[inline(always)]
    fn set(&mut self, i: usize, v: Vec3) {
        (self.0[0][i], self.0[1][i], self.0[2][i]) = (v.x, v.y, v.z);
    }

    #[inline(always)]
    fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.0[0][i], self.0[1][i], self.0[2][i])
    }

    #[inline(always)]
    fn load<L: Lanes>(&self) -> V3<L> {
        [
            L::load(&self.0[0]),
            L::load(&self.0[1]),
            L::load(&self.0[2]),
        ]
    }

    #[inline(always)]
    fn of<L: Lanes>(v: V3<L>) -> Self {
        let mut rows = [[0.0; MAX_LANES]; 3];
        for (lanes, row) in v.iter().zip(&mut rows) {
            lanes.store(row);
        }
        Self(rows)
    }
}

/// `x == 0` (either zero).
#[inline(always)]
fn is_zero<L: Lanes>(x: L) -> L::M {
    let zero = L::splat(0.0);
    x.le(zero) & zero.le(x)
}

/// The mask of the lanes `set` names.
#[inline(always)]
fn mask_of<L: Lanes>(set: &[bool; MAX_LANES]) -> L::M {
    let mut ones = [0.0; MAX_LANES];
    for (one, &set) in ones.iter_mut().zip(set) {
        *one = if set { 1.0 } else { 0.0 };
    }
    L::splat(0.0).lt(L::load(&ones))
}

/// Which lanes a mask sets.
#[inline(always)]
fn lanes_set<L: Lanes>(m: L::M) -> [bool; MAX_LANES] {
    let ones = L::select(m, L::splat(1.0), L::splat(0.0)).values();
    let mut set = [false; MAX_LANES];
    for (set, one) in set.iter_mut().zip(ones) {
        *set = one > 0.0;
    }
    set
}

/// [`crate::math::offset_origin`] in lanes.
#[inline(always)]
fn offset_origin<L: Lanes>(p: V3<L>, ng: V3<L>, dir: V3<L>) -> V3<L> {
    let a = [p[0].abs(), p[1].abs(), p[2].abs()];
    let largest = a[0].max(a[1].max(a[2]));
    let eps = L::splat(1e-4) * (L::splat(1.0) + largest);
    let step = scale(ng, eps);
    let ahead = L::splat(0.0).le(dot(dir, ng));
    select3(
        ahead,
        plus(p, step),
        [p[0] - step[0], p[1] - step[1], p[2] - step[2]],
    )
}

/// The Lambert vertices of a packet's live lanes: what [`Bsdf`] holds of a bare Lambert one.
struct LambertVertex<L: Lanes> {
    p: V3<L>,
    ng: V3<L>,
    ns: V3<L>,
    frame: [V3<L>; 3],
    f: V3<L>,
    /// `-ray.dir`, the direction the path arrived from.
    wo: V3<L>,
    /// `wo` in the shading frame.
    wo_local: V3<L>,
}

/// A BSDF sample of a packet's Lambert vertices.
struct LambertSample<L: Lanes> {
    wi: V3<L>,
    pdf: L,
    /// Where the sample is a direction the path may take (else the scalar code finds none).
    valid: L::M,
}

impl<L: Lanes> LambertVertex<L> {
    /// The shading normal on `wo`'s side ([`Bsdf::gathers_from`]).
    #[inline(always)]
    fn facing(&self) -> V3<L> {
        let n = self.frame[2];
        select3(self.wo_local[2].lt(L::splat(0.0)), negate(n), n)
    }

    /// [`Bsdf::sample`] of a Lambert lobe, with [`DiffuseReflection::sample`]'s checks.
    ///
    /// [`DiffuseReflection::sample`]: crate::bxdf::diffuse::DiffuseReflection::sample
    #[inline(always)]
    fn sample(&self, u: [L; 2]) -> LambertSample<L> {
        let zero = L::splat(0.0);
        let wo_z = self.wo_local[2];
        let mirrored = wo_z.lt(zero);
        // The lobe mirrors a query from below to the upper hemisphere and back.
        let [x, y, z] = cosine_hemisphere(u);
        let wo_up = L::select(mirrored, L::splat(-1.0) * wo_z, wo_z);
        let same_hemisphere = zero.lt(wo_up * z);
        let pdf = L::select(
            same_hemisphere,
            z.abs() * L::splat(std::f32::consts::FRAC_1_PI),
            zero,
        );
        let z = L::select(mirrored, L::splat(-1.0) * z, z);
        let [s, t, n] = self.frame;
        let world = [
            s[0] * x + t[0] * y + n[0] * z,
            s[1] * x + t[1] * y + n[1] * z,
            s[2] * x + t[2] * y + n[2] * z,
        ];
        let wi = scale(world, L::splat(1.0) / dot(world, world).sqrt());
        // The geometric and shading normals agree on the sides of wo and wi.
        let geometric = dot(self.wo, self.ng) * dot(wi, self.ng);
        let shading = wo_z * z;
        let agree =
            (zero.lt(geometric) & zero.lt(shading)) | (geometric.lt(zero) & shading.lt(zero));
        LambertSample {
            wi,
            pdf,
            valid: agree & same_hemisphere & zero.lt(pdf),
        }
    }
}

impl<L: Lanes> LambertVertex<L> {
    /// [`direct_light`] at the vertices of the lanes `lanes` sets, with `draw`'s light choice
    /// numbers and share: in lanes, but the shadow rays (counted in `rays`) and, unless the
    /// lights are a few plain triangle lamps ([`TriangleLamps`]), the light's choice and point.
    ///
    /// [`TriangleLamps`]: crate::lights::TriangleLamps
    #[inline(always)]
    fn direct_light<S: PathScene>(
        &self,
        scene: &S,
        lanes: &[bool; MAX_LANES],
        rays: &mut [u32; MAX_LANES],
        draw: &LightDraws,
        u: [L; 2],
        bsdf_count: f32,
    ) -> V3<L> {
        let zero = L::splat(0.0);
        let light = match scene.lights().triangle_lamps() {
            Some(lamps) => {
                let s = lamps.sample(self.p, L::load(&draw.u_select), u);
                let pdf = L::select(mask_of::<L>(lanes), s.pdf, zero);
                LightSamples { pdf, ..s }
            }
            None => self.light_one_lane_at_a_time(scene, lanes, draw, u),
        };
        let LightSamples {
            wi,
            li,
            pdf,
            dist,
            delta,
        } = light;
        let pdf = pdf * L::load(&draw.share);
        let dark: L::M = is_zero(li[0]) & is_zero(li[1]) & is_zero(li[2]);
        let lit = !pdf.le(zero) & !dark;
        // The BSDF's value: Lambert's where the normals agree and wo and wi share a side.
        let wi_z = dot(wi, self.frame[2]);
        let geometric = dot(self.wo, self.ng) * dot(wi, self.ng);
        let shading = self.wo_local[2] * wi_z;
        let agree =
            (zero.lt(geometric) & zero.lt(shading)) | (geometric.lt(zero) & shading.lt(zero));
        let reflects = agree & zero.lt(shading);
        let origin = offset_origin(self.p, self.ng, wi);
        let to_origin = [
            origin[0] - self.p[0],
            origin[1] - self.p[1],
            origin[2] - self.p[2],
        ];
        // `shadow_tmax`: its multiply-add by -1 is this subtraction, exactly.
        let short = (dist - dot(to_origin, to_origin).sqrt()) * L::splat(1.0 - 1e-3);
        let finite = dist.abs().lt(L::splat(f32::INFINITY));
        let tmax = L::select(finite, short, L::splat(f32::INFINITY)).values();
        let tested = lanes_set::<L>(lit & reflects);
        let (origin, dir) = (Rows::of(origin), Rows::of(wi));
        let mut visible = [0.0; MAX_LANES];
        for i in 0..L::N {
            if lanes[i] && tested[i] {
                rays[i] += 1;
                let blocked = scene
                    .geometry()
                    .occluded(&Ray::new(origin.get(i), dir.get(i)), tmax[i]);
                visible[i] = if blocked { 0.0 } else { 1.0 };
            }
        }
        let bsdf_pdf = L::select(
            zero.lt(shading),
            wi_z.abs() * L::splat(std::f32::consts::FRAC_1_PI),
            zero,
        );
        let heuristic = power_heuristic(pdf, L::splat(bsdf_count) * bsdf_pdf);
        let weight = L::select(zero.lt(delta), L::splat(1.0), heuristic);
        let k = dot(wi, self.ns).abs() * weight / pdf;
        let light = scale(times(self.f, li), k);
        let shown = zero.lt(L::load(&visible));
        [
            L::select(shown, light[0], zero),
            L::select(shown, light[1], zero),
            L::select(shown, light[2], zero),
        ]
    }

    /// The lights' samples ([`super::path::PathScene::lights`]' `sample`) of the lanes `lanes`
    /// sets, one lane at a time (a density of 0 where there is none).
    #[inline(always)]
    fn light_one_lane_at_a_time<S: PathScene>(
        &self,
        scene: &S,
        lanes: &[bool; MAX_LANES],
        draw: &LightDraws,
        u: [L; 2],
    ) -> LightSamples<L> {
        let (p, facing) = (Rows::of(self.p), Rows::of(self.facing()));
        let (select, ux, uy) = (draw.u_select, u[0].values(), u[1].values());
        let mut wi = Rows::splat(Vec3::Z);
        let mut li = Rows::splat(Vec3::ZERO);
        let (mut pdf, mut dist, mut delta) = ([0.0; MAX_LANES], [0.0; MAX_LANES], [0.0; MAX_LANES]);
        for i in 0..L::N {
            if !lanes[i] {
                continue;
            }
            let u = Vec2::new(ux[i], uy[i]);
            // No sample: a density of 0, which ends the lane's light sample as `direct_light`.
            let (at, side) = (p.get(i), Some(facing.get(i)));
            if let Some(ls) = scene.lights().sample(at, side, select[i], u) {
                (pdf[i], dist[i]) = (ls.pdf, ls.dist);
                wi.set(i, ls.wi);
                li.set(i, ls.li);
                delta[i] = if ls.delta { 1.0 } else { 0.0 };
            }
        }
        LightSamples {
            wi: wi.load::<L>(),
            li: li.load::<L>(),
            pdf: L::load(&pdf),
            dist: L::load(&dist),
            delta: L::load(&delta),
        }
    }
}

/// The light choice numbers and shares of a packet's lane light samples
/// ([`super::path::LightDraw`]'s).
struct LightDraws {
    u_select: [f32; MAX_LANES],
    share: [f32; MAX_LANES],
}

/// [`super::path::survives`] in lanes, at vertices that scattered broadly where `broad` is
/// set: the lanes the roulette keeps, and the throughput divided by their survival
/// probability.
#[inline(always)]
fn survives<S: PathScene, L: Lanes>(
    scene: &S,
    depth: u32,
    broad: L::M,
    u_rr: L,
    throughput: &mut V3<L>,
) -> L::M {
    let integrator = scene.integrator();
    let (continue_prob, rouletted) = match integrator.rr_strategy {
        RussianRoulette::Probability if depth >= RR_MIN_DEPTH => {
            (L::splat(integrator.rr_continue_prob), L::mask(true))
        }
        RussianRoulette::Efficiency => {
            let t = *throughput;
            let largest = t[0].max(t[1].max(t[2])) * L::splat(RR_THROUGHPUT_SCALE);
            // f32::clamp's order of tests.
            let low = L::select(
                largest.lt(L::splat(RR_MIN_SURVIVAL)),
                L::splat(RR_MIN_SURVIVAL),
                largest,
            );
            (L::select(L::splat(1.0).lt(low), L::splat(1.0), low), broad)
        }
        _ => return L::mask(true),
    };
    // What `u_rr >= continue_prob` ends (NaN included).
    let kept = !continue_prob.le(u_rr) | !rouletted;
    let t = *throughput;
    *throughput = [
        L::select(rouletted, t[0] / continue_prob, t[0]),
        L::select(rouletted, t[1] / continue_prob, t[1]),
        L::select(rouletted, t[2] / continue_prob, t[2]),
    ];
    kept
}

/// What a lane's last vertex leaves the next one beyond its point, density and side (which
/// the packet keeps in lanes): the rest of [`PrevScatter`].
#[derive(Clone, Copy)]
struct PrevLane {
    specular: bool,
    image_share: f32,
    before_mirror: Option<BeforeMirror>,
    /// Whether the vertex gathered light broadly (from the packet's `prev_facing` side).
    broad: bool,
}

impl PrevLane {
    /// The camera counts as specular: emitters its rays see are taken at full weight.
    const CAMERA: Self = Self {
        specular: true,
        image_share: 0.0,
        before_mirror: None,
        broad: false,
    };
    /// A Lambert vertex shaded in lanes, `image_share` of whose light samples went to lamp
    /// images.
    const fn lambert(image_share: f32) -> Self {
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
struct Packet<L: Lanes> {
    live: [bool; MAX_LANES],
    origin: V3<L>,
    dir: V3<L>,
    throughput: V3<L>,
    radiance: V3<L>,
    depth: u32,
    branches: usize,
    /// Whether a glossy vertex may split the lanes' paths ([`PathState::may_split`]).
    may_split: bool,
    prev_p: V3<L>,
    prev_pdf: L,
    /// After a broad vertex, the side it gathered light from.
    prev_facing: V3<L>,
    prev: [PrevLane; MAX_LANES],
    /// The rays each lane traced in this packet.
    rays: [u32; MAX_LANES],
}

impl<L: Lanes> Packet<L> {
    /// Where lane `i`'s last ray was sampled, as [`walk`] carries it.
    #[inline(always)]
    fn prev_scatter(&self, i: usize, parts: &PacketParts) -> PrevScatter {
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
    fn lane_state(
        &self,
        i: usize,
        parts: &PacketParts,
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
        }
    }

    /// Lane `i` leaves the packet and its path goes on alone by [`walk`] from the packet's
    /// state (with what its ray hits, when traced already) and from `stream`'s place in the
    /// lane's own sample stream; its light and rays go to `out`.
    #[inline(always)]
    fn go_on_alone<S: PathScene>(
        &mut self,
        scene: &S,
        i: usize,
        parts: &PacketParts,
        traced: Option<Option<SurfaceHit>>,
        stream: &PacketSampler<L>,
        out: &mut PathResult,
    ) {
        self.live[i] = false;
        out.rays += self.rays[i];
        let state = self.lane_state(i, parts, traced);
        walk(scene, state, &mut stream.lane(i), out);
    }

    /// Ends lane `i`: its light and rays go to `out`.
    #[inline(always)]
    fn finish(&mut self, i: usize, radiance: Vec3, out: &mut PathResult) {
        self.live[i] = false;
        out.radiance += radiance;
        out.rays += self.rays[i];
    }

    /// Ends every live lane where `m` is not set.
    #[inline(always)]
    fn keep(&mut self, m: L::M, out: &mut [PathResult; MAX_LANES]) {
        let kept = lanes_set::<L>(m);
        if (0..L::N).all(|i| kept[i] || !self.live[i]) {
            return;
        }
        let radiance = Rows::of(self.radiance);
        for i in 0..L::N {
            if self.live[i] && !kept[i] {
                self.finish(i, radiance.get(i), &mut out[i]);
            }
        }
    }

    /// Ends every live lane.
    #[inline(always)]
    fn finish_all(&mut self, out: &mut [PathResult; MAX_LANES]) {
        self.keep(L::mask(false), out);
    }
}

/// A packet's state, lane by lane: what a lane leaving it takes along.
struct PacketParts {
    origin: Rows,
    dir: Rows,
    throughput: Rows,
    radiance: Rows,
    prev_p: Rows,
    prev_pdf: [f32; MAX_LANES],
    prev_facing: Rows,
}

impl PacketParts {
    #[inline(always)]
    fn of<L: Lanes>(packet: &Packet<L>) -> Self {
        Self {
            origin: Rows::of(packet.origin),
            dir: Rows::of(packet.dir),
            throughput: Rows::of(packet.throughput),
            radiance: Rows::of(packet.radiance),
            prev_p: Rows::of(packet.prev_p),
            prev_pdf: packet.prev_pdf.values(),
            prev_facing: Rows::of(packet.prev_facing),
        }
    }
}

/// A vertex shaded for one lane by [`Vertex`], as [`walk`] shades it.
#[derive(Clone, Copy)]
struct AloneStep {
    image_share: f32,
    /// The BSDF sample and the throughput's weight; None ends the path.
    sample: Option<(BsdfSample, Vec3)>,
    /// The side a broad vertex gathers light from.
    broad: Option<Vec3>,
    before_mirror: Option<BeforeMirror>,
}

/// Where a packet's paths branch ([`MAX_BRANCHES`]): the vertex its continuations start from.
struct BranchPoint<L: Lanes> {
    vertex: LambertVertex<L>,
    throughput: V3<L>,
    roulette: L,
    /// The share of each lane's light samples that went to lamp images.
    image_share: [f32; MAX_LANES],
    /// The packet's stream after the vertex's own dimensions.
    sampler: PacketSampler<L>,
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
    let mut origin = Rows::splat(Vec3::ZERO);
    let mut dir = Rows::splat(Vec3::Z);
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
        prev: [PrevLane::CAMERA; MAX_LANES],
        rays: [0; MAX_LANES],
    };
    if let Some(branch) = walk_packet(scene, &mut packet, sampler, &mut out) {
        branch_packet(scene, &packet, branch, &mut out);
        packet.finish_all(&mut out);
    }
    out
}

/// The continuations of a packet's paths at their branching vertex, one packet each, traced
/// in order (as [`super::path`]'s `BranchVertex::branch` traces a path's).
#[inline(always)]
fn branch_packet<S: PathScene, L: Lanes>(
    scene: &S,
    parent: &Packet<L>,
    mut branch: BranchPoint<L>,
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
        let kept = bs.valid & survives(scene, parent.depth, broad, u_rr, &mut throughput);
        let kept = lanes_set::<L>(kept);
        let mut live = [false; MAX_LANES];
        for i in 0..L::N {
            live[i] = parent.live[i] && kept[i];
        }
        let zero = L::splat(0.0);
        let prev = branch.image_share.map(PrevLane::lambert);
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

/// Where a packet's lanes scatter at a vertex: the BSDF samples' directions, densities and
/// throughput weights, where they are valid, which vertices scattered broadly (and to which
/// side).
struct ScatterLanes<L: Lanes> {
    weight: V3<L>,
    wi: V3<L>,
    pdf: L,
    valid: L::M,
    broad: L::M,
    facing: V3<L>,
}

/// A lane at a vertex: which, the packet's state lane by lane, and the BSDF samples its light
/// sample is weighed against.
struct LaneAt<'a> {
    lane: usize,
    parts: &'a PacketParts,
    bsdf_count: f32,
}

/// What a packet's lanes meet at their next vertex, lane by lane.
struct LaneHits {
    p: Rows,
    ng: Rows,
    ns: Rows,
    frame: [Rows; 3],
    f: Rows,
    /// The lanes at a bare Lambert surface, shaded in lanes (but a light sample that goes to a
    /// lamp image).
    lambert: [bool; MAX_LANES],
    /// The vertices shaded one lane at a time: any other surface.
    alone: [Option<AloneStep>; MAX_LANES],
    /// The light that lanes shaded one at a time bring (alone, or through lamp images).
    lit_alone: [Option<Vec3>; MAX_LANES],
    image_share: [f32; MAX_LANES],
    draws: LightDraws,
    /// The vertex's numbers lane by lane, once a lane is shaded alone.
    by_lane: Option<[VertexSamples; MAX_LANES]>,
}

impl LaneHits {
    #[inline(always)]
    fn new() -> Self {
        Self {
            p: Rows::splat(Vec3::ZERO),
            ng: Rows::splat(Vec3::ZERO),
            ns: Rows::splat(Vec3::ZERO),
            frame: [Rows::splat(Vec3::ZERO); 3],
            f: Rows::splat(Vec3::ZERO),
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
    fn reset<L: Lanes>(&mut self, u: &VertexPacket<L>) {
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
    fn meet<S: PathScene, L: Lanes>(
        &mut self,
        scene: &S,
        packet: &mut Packet<L>,
        at: &LaneAt,
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
            let splits = packet.may_split
                && bsdf
                    .glossy_cone(wo)
                    .is_some_and(|cone| lights.lamp_may_be_in(hit.p, &cone));
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
        let vertex = Vertex {
            hit,
            wo,
            bsdf,
            sides: ShapeMedia::default(),
        };
        let depth = packet.depth + 1;
        let mut rays = 0;
        if lambert_here {
            let (choice, image_share) = vertex.choose_light(
                scene,
                &us[i],
                depth,
                BsdfCounts::all(at.bsdf_count),
                &mut rays,
            );
            self.image_share[i] = image_share;
            match choice {
                LightChoice::Image(light) => self.lit_alone[i] = Some(light),
                LightChoice::Lights(draw) => {
                    (self.draws.u_select[i], self.draws.share[i]) = (draw.u_select, draw.share);
                }
            }
        } else {
            let (light, image_share) =
                vertex.light(scene, &us[i], depth, BsdfCounts::ONE, &mut rays);
            let sample = vertex.sample(&us[i]);
            let before_mirror = match &sample {
                Some((bs, _)) => {
                    let prev = packet.prev_scatter(i, at.parts);
                    vertex.mirror_after(lights, &prev, bs, false)
                }
                None => None,
            };
            self.lit_alone[i] = light;
            self.alone[i] = Some(AloneStep {
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
    fn with_alone_lanes<L: Lanes>(
        &self,
        lambert: ScatterLanes<L>,
        prev: &mut [PrevLane; MAX_LANES],
    ) -> ScatterLanes<L> {
        let in_lanes = mask_of::<L>(&self.lambert);
        let mut wi = Rows::splat(Vec3::Z);
        let mut weight = Rows::splat(Vec3::ONE);
        let mut pdf = [0.0; MAX_LANES];
        let mut valid = [false; MAX_LANES];
        let mut broad = self.lambert;
        let mut facing = Rows::splat(Vec3::ZERO);
        for i in 0..L::N {
            let Some(step) = self.alone[i] else {
                prev[i] = PrevLane::lambert(self.image_share[i]);
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
            prev[i] = PrevLane {
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
fn walk_packet<S: PathScene, L: Lanes>(
    scene: &S,
    packet: &mut Packet<L>,
    sampler: &mut PacketSampler<L>,
    out: &mut [PathResult; MAX_LANES],
) -> Option<BranchPoint<L>> {
    let geometry = scene.geometry();
    let lights = scene.lights();
    let max_depth = scene.max_depth();
    let mut hits = LaneHits::new();
    loop {
        if packet.live[..L::N].iter().filter(|&&live| live).count() <= FEW_LANES {
            let parts = PacketParts::of(packet);
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
        let parts = PacketParts::of(packet);
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
                    let at = LaneAt {
                        lane: i,
                        parts: &parts,
                        bsdf_count,
                    };
                    !bsdf.is_pass_through() && hits.meet(scene, packet, &at, hit, &bsdf, &u)
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
            let mut light_alone = Rows::splat(Vec3::ZERO);
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
            return Some(BranchPoint {
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
            packet.prev = hits.image_share.map(PrevLane::lambert);
            lambert
        };
        packet.throughput = times(packet.throughput, weight);
        let kept = valid
            & survives(
                scene,
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

#[cfg(test)]
mod tests {
    use crate::integrator::path::PathScene;
    use std::sync::atomic::AtomicBool;

    use crate::assets::MemorySource;
    use crate::film::SampleBuffer;
    use crate::lanes::tests::on_every_lane_type;
    use crate::lanes::Lanes;
    use crate::lanes::OnLanes;
    use crate::parse::parse_scene;
    use crate::render::{plan_units, RenderScene, RenderSettings, WorkUnit};

    /// A depth-of-field scene of our own: a thin lens, a checkered Lambert floor, a red
    /// Lambert sphere; what packets shade one lane at a time: a glass sphere, a rough
    /// (Oren-Nayar) wall, a flat mirror with the lamp's image, a gold sphere (whose glossy
    /// vertices split paths, which leave the packet); and what lanes leave packets for: a null
    /// lamp seen directly, the open sky.
    const SCENE: &str = r#"LookAt 0 -4 1.2  0 0 0.6  0 0 1
Camera "perspective" "float fov" [50] "float lensradius" [0.1] "float focaldistance" [3.5]
Film "fleximage" "integer xresolution" [24] "integer yresolution" [16]
PixelFilter "gaussian"
SurfaceIntegrator "path" "integer maxdepth" [6]
WorldBegin
Texture "checks" "color" "checkerboard" "float uscale" [6] "float vscale" [6] "color tex1" [0.8 0.8 0.8] "color tex2" [0.1 0.1 0.1]
AttributeBegin
Material "matte" "texture Kd" ["checks"]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-3 -3 0 3 -3 0 3 3 0 -3 3 0] "float uv" [0 0 1 0 1 1 0 1]
AttributeEnd
AttributeBegin
Material "matte" "color Kd" [0.5 0.5 0.5] "float sigma" [30]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-3 2 0 3 2 0 3 2 3 -3 2 3]
AttributeEnd
AttributeBegin
Material "matte" "color Kd" [0.7 0.2 0.2]
Translate -0.6 0 0.5
Shape "sphere" "float radius" [0.5]
AttributeEnd
AttributeBegin
Material "glass"
Translate 0.7 -0.4 0.4
Shape "sphere" "float radius" [0.4]
AttributeEnd
AttributeBegin
Material "mirror"
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-2.5 -2 0 -2.5 2 0 -2.5 2 2.5 -2.5 -2 2.5]
AttributeEnd
AttributeBegin
Material "metal" "string name" ["gold"] "float uroughness" [0.05] "float vroughness" [0.05]
Translate 0.3 0.9 0.35
Shape "sphere" "float radius" [0.35]
AttributeEnd
AttributeBegin
Material "null"
AreaLightSource "area" "color L" [6 6 6] "float power" [0]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [-0.5 -0.5 2 -0.5 0.5 2 0.5 0.5 2 0.5 -0.5 2]
AttributeEnd
"#;

    /// A light that makes the lamp's tables go (the light's choice and point one lane at a
    /// time).
    const POINT: &str = r#"LightSource "point" "point from" [1 -1 2.5] "color L" [0.5 0.5 0.5]"#;

    /// The scene with `light` beside the lamp (its tables are sampled in lanes when there is
    /// none).
    fn scene(spp: u32, branches: usize, light: &str) -> (RenderScene, RenderSettings) {
        let mut source = MemorySource::new();
        let text = format!("{SCENE}{light}\nWorldEnd\n");
        source.insert("main.lxs", text.as_bytes().into());
        let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
        assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
        let settings = RenderSettings {
            width: 24,
            height: 16,
            spp,
            max_depth: desc.integrator.max_depth,
            seed: 3,
            latlong: Default::default(),
        };
        let scene = RenderScene::build(&desc, &source, &settings).expect("scene builds");
        assert!(super::covers(&scene), "packets cover the scene");
        assert!(scene.glossy_split(), "the gold sphere splits paths");
        assert!(
            scene.lights().has_mirror_images(),
            "the mirror shows the lamp"
        );
        assert_eq!(
            scene.lights().triangle_lamps().is_some(),
            light.is_empty(),
            "lamp tables with {light:?}"
        );
        (scene.with_first_vertex_branches(branches), settings)
    }

    /// Every unit of a uniform render (72 samples a pixel, 9 a unit: a packet and a sample
    /// left over) and of an adaptive round (nested samples 16 to 48 in blocks of the floor,
    /// the spheres and the wall) renders to the same buffer bytes and counts in packets of
    /// every lane type as one sample at a time, with one continuation per camera path and with
    /// three, with the lamp sampled from its tables in lanes and (beside a point light) one
    /// lane at a time.
    fn packets_render_the_scalar_bytes<L: Lanes>() {
        let never = AtomicBool::new(false);
        for (branches, light) in [(1, ""), (3, ""), (1, POINT), (3, POINT)] {
            let (scene, settings) = scene(72, branches, light);
            let adaptive = WorkUnit {
                index: 0,
                x0: 0,
                y0: 0,
                x1: 16,
                y1: 16,
                sample_start: 16,
                sample_end: 48,
                // Blocks (1, 0), and (1, 2), (2, 2), (1, 3), (2, 3) on the floor and spheres.
                mask: Some(0x0606_0002),
            };
            let mut rays = 0;
            for unit in plan_units(&settings).iter().chain([&adaptive]) {
                let (one, one_stats) = scene.render_unit_in::<f32>(unit, &never).unwrap();
                let (lanes, lane_stats) = scene.render_unit_in::<L>(unit, &never).unwrap();
                let at = format!(
                    "unit {unit:?}, {branches} continuations, light {light:?}, {} lanes",
                    L::N
                );
                assert_eq!(lane_stats, one_stats, "{at}");
                assert_eq!(
                    bits(lanes.rgb.as_flattened()),
                    bits(one.rgb.as_flattened()),
                    "{at}"
                );
                assert_eq!(bits(&lanes.weight), bits(&one.weight), "{at}");
                let half = |b: &SampleBuffer| bits(b.half_rgb.as_flattened());
                assert_eq!(half(&lanes), half(&one), "{at}");
                rays += one_stats.rays;
            }
            assert!(rays > 0);
        }
    }

    fn bits(values: &[f32]) -> Vec<u32> {
        values.iter().map(|v| v.to_bits()).collect()
    }

    #[test]
    fn packets_render_what_one_path_at_a_time_renders() {
        struct Renders;
        impl OnLanes for Renders {
            type Output = ();
            fn run<L: Lanes>(&self) {
                packets_render_the_scalar_bytes::<L>();
            }
        }
        on_every_lane_type(&Renders);
    }
}
