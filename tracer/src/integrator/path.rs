//! The path tracer: unidirectional path tracing with next-event estimation, multiple importance sampling of
//! light and BSDF samples (power heuristic), and Russian roulette; through participating
//! media (LuxRender's named volumes) with Beer-Lambert transmittance, free-flight sampling,
//! phase-function scattering and next-event estimation at scattering events.
//!
//! The volume a ray travels in follows LuxRender's rule: after a surface, the side of it the
//! ray leaves into (a shape's `Interior` or `Exterior`; a side with no volume is the ray's
//! own when the ray came from it, else no volume). A ray in no volume takes, for its segment,
//! the volume on the near side of the surface it hits. A scene without volumes takes none of
//! these steps and draws no extra random numbers, so it renders as it did before volumes.

use glam::{Vec2, Vec3};

use super::options::{IntegratorDesc, RussianRoulette};
use crate::geometry::{SceneGeometry, SurfaceHit};
use crate::lanes::Lanes;
use crate::lights::{follows_plane, ImageWeights, Lights, IMAGE_SHARE};
use crate::material::{Bsdf, BsdfSample};
use crate::math::{offset_origin, Ray};
use crate::medium::{Flight, MediumId, Phase, ShapeMedia, Volumes};
use crate::sampler::{PixelSampler, VertexSamples};

/// What the path tracer needs from the scene. The renderer's built scene implements it, so the
/// integrator does not depend on how the scene is built.
pub trait PathScene {
    /// The scene's SurfaceIntegrator settings.
    fn integrator(&self) -> &IntegratorDesc;
    /// Bounces per path (the settings' max depth, which the command line may override).
    fn max_depth(&self) -> u32;
    fn geometry(&self) -> &SceneGeometry;
    fn lights(&self) -> &Lights;
    /// The BSDF at a hit; `u_mix` resolves mix materials.
    fn bsdf_at(&self, hit: &SurfaceHit, u_mix: f32) -> Bsdf;
    /// The scene's volumes and the camera's.
    fn volumes(&self) -> &Volumes;
    /// The volumes on the two sides of shape `shape`.
    fn shape_media(&self, shape: u32) -> ShapeMedia;
    /// Whether shape `shape` is `null` (shadow rays cross it, as paths do: the geometry's
    /// occlusion test looks through it).
    fn is_pass_through(&self, shape: u32) -> bool;
    /// Whether paths split at glossy vertices ([`GLOSSY_SPLIT`]): the integrator allows it, the
    /// scene has lamps and metals, and no volumes or material that lets rays through at some
    /// hits only (a split sample crosses a surface only where [`Self::is_pass_through`] says so).
    fn glossy_split(&self) -> bool;
    /// The continuations a camera path's first broad scattering vertex sends on (see
    /// [`MAX_BRANCHES`]; 1: the path goes on alone).
    fn first_vertex_branches(&self) -> usize;
}

/// The most continuations a camera path may branch into at its first broad scattering vertex
/// (a diffuse, velvet or cloth lobe, under a coat or not, [`Bsdf::gathers_from`], reached
/// through specular vertices only), each carrying its share of the throughput and its own
/// sample stream; the vertex's light sample is weighed against all of them. Where the light
/// that reaches a pixel through its first bounce holds most of the noise, and a path costs
/// more before that vertex than after (the camera ray, the film, the first light sample),
/// more continuations per camera sample are the cheaper way to less noise; how many a scene
/// takes is measured when it is built (`render::branching`). Measured with 1 to 4 branches at
/// 16 spp (480x270, one thread, 4 seeds, MSE x time against 1 branch): depth of field 1.25x,
/// 1.30x, 1.26x (the room's indirect light is most of its noise); Captain Falcon 1.14x, 1.04x,
/// 1.02x; Cornell 1.02x, 0.94x (long paths in a closed box: a branch costs nearly as much as a
/// sample); Mario 0.98x, 0.91x (its noise is the caustics its glossy vertices already split
/// for).
pub const MAX_BRANCHES: usize = 4;

/// Null surfaces crossed in a row before a path gives up (guards against stacked coplanar
/// null faces).
const MAX_PASS_THROUGH: u32 = 64;

/// BSDF samples a path's first glossy vertex that may see a lamp takes for the lamps it sees
/// directly (the path goes on with a sample of its own, which finds the environment). A lamp
/// in a narrow lobe is a bright patch that one sample finds or misses: Mario's metal figure
/// held some 60% of its image's error at 16 spp in those highlights, and the floor's speckles
/// are the same highlights seen from the floor. Measured on Mario (480x270, 16 spp, instructions by callgrind; when the path
/// went on with one of the split's samples): 4 samples cut the error to 0.55 for 1.08 times the
/// work, 8 to 0.46 for 1.17, 16 to 0.44 for 1.35.
pub const GLOSSY_SPLIT: usize = 8;

/// Bounces before Russian roulette may end a path under the `probability` strategy (as in
/// LuxRender).
pub(super) const RR_MIN_DEPTH: u32 = 3;

/// Under the `efficiency` strategy a path survives a broad scattering vertex (a diffuse, velvet
/// or cloth lobe, under a coat or not, as [`Bsdf::gathers_from`] tells; a volume's phase
/// function) with this multiple of its throughput's largest channel as probability, capped at
/// 1, from the first vertex on; a glossy or specular vertex never ends it. Measured against the
/// rule it replaced (the throughput itself, from the third vertex on, at every vertex), MSE x
/// CPU time at 16 spp, one thread: depth of field 0.81, Cornell 0.91, Mario 0.96, Captain
/// Falcon 0.74, our volumes scene 0.87; our daylight scene 1.02-1.08 (MSE +4%: under an open sky
/// a path's continuation is one cheap ray, little to save). A path into the black squares of a
/// checkerboard, or off a dark wall, mostly ends there instead of bouncing on for little light;
/// three times the throughput keeps the bright paths that the old rule ended; and the light a
/// glossy vertex sends on is concentrated (the caustics of Mario's metal seen from the floor),
/// which the roulette turned into fireflies.
pub(super) const RR_THROUGHPUT_SCALE: f32 = 3.0;

/// The least survival probability of the `efficiency` strategy: a path it keeps is weighed by
/// at most 20 times.
pub(super) const RR_MIN_SURVIVAL: f32 = 0.05;

/// Radiance along a camera ray, and the number of rays traced for it.
#[derive(Clone, Copy, Debug, Default)]
pub struct PathResult {
    pub radiance: Vec3,
    pub rays: u32,
}

/// The power heuristic's weight of a sample drawn with density `pdf_a` against one of
/// `pdf_b`, in lanes (one lane for a path alone; the packets' weights are the same bits).
#[inline(always)]
pub(super) fn power_heuristic<L: Lanes>(pdf_a: L, pdf_b: L) -> L {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    let zero = L::splat(0.0);
    L::select(zero.lt(a + b), a / (a + b), zero)
}

/// Where the ray that reached the current vertex was sampled, for MIS on emitters it hits.
pub(super) struct PrevScatter {
    pub(super) p: Vec3,
    pub(super) pdf: f32,
    pub(super) specular: bool,
    /// The share of the light samples at `p` that went to lamp images (0 where it sees none):
    /// the lights' own share is what is left.
    pub(super) image_share: f32,
    /// Set when the ray just reflected in a flat mirror straight after a non-specular vertex:
    /// a lamp it reaches is one a lamp-image sample at that vertex could have found.
    pub(super) before_mirror: Option<BeforeMirror>,
    /// Set when `p` split ([`GLOSSY_SPLIT`]): its own BSDF samples took the light of the lamps
    /// it sees directly, so a lamp this ray finds (through null surfaces too) is not counted.
    /// An environment map it escapes to is, as after any vertex.
    pub(super) lamps_counted: bool,
    /// The side `p`'s light sample sampled environment maps for ([`Bsdf::gathers_from`]):
    /// the density an escaping ray is weighed by.
    pub(super) facing: Option<Vec3>,
}

impl PrevScatter {
    /// A vertex that sampled no lamp images.
    pub(super) fn plain(p: Vec3, pdf: f32, specular: bool) -> Self {
        Self {
            p,
            pdf,
            specular,
            image_share: 0.0,
            before_mirror: None,
            lamps_counted: false,
            facing: None,
        }
    }
}

/// The non-specular vertex before a flat mirror (one that sampled lamp images, with
/// [`IMAGE_SHARE`] of its light samples), and the mirror's plane.
#[derive(Clone, Copy)]
pub(super) struct BeforeMirror {
    p: Vec3,
    pdf: f32,
    plane: u16,
}

/// Where a vertex's light sample goes ([`Vertex::choose_light`]).
pub(super) enum LightChoice {
    /// To a lamp image: the light it brings, weighed.
    Image(Vec3),
    /// To the lights, with this draw.
    Lights(LightDraw),
}

/// A light sample's random numbers, the share of a vertex's light samples its kind (lights,
/// or lamp images) gets, and the BSDF samples its MIS weight counts against it.
#[derive(Clone, Copy)]
pub(super) struct LightDraw {
    pub(super) share: f32,
    pub(super) u_select: f32,
    u: Vec2,
    /// The BSDF samples the vertex weighs its light sample against.
    bsdf_counts: BsdfCounts,
}

/// The BSDF samples a vertex's light sample is weighed against: 1, the continuations' count at
/// a branching vertex; at a split vertex [`GLOSSY_SPLIT`] for lamps and 1 for environment maps
/// (the split's samples take only the lamps' light; the path's own sample goes on to find the
/// environment's).
#[derive(Clone, Copy, Debug)]
pub(super) struct BsdfCounts {
    lamps: f32,
    environment: f32,
}

impl BsdfCounts {
    pub(super) const ONE: Self = Self::all(1.0);
    const SPLIT: Self = Self {
        lamps: GLOSSY_SPLIT as f32,
        environment: 1.0,
    };

    pub(super) const fn all(count: f32) -> Self {
        Self {
            lamps: count,
            environment: count,
        }
    }

    /// The count for a light sample from a lamp, or from the environment (`at_infinity`: an
    /// environment map, a sky or its sun disc).
    fn for_light(&self, at_infinity: bool) -> f32 {
        if at_infinity {
            self.environment
        } else {
            self.lamps
        }
    }
}

impl LightDraw {
    fn new(share: f32, u_select: f32, u: Vec2) -> Self {
        Self {
            share,
            u_select,
            u,
            bsdf_counts: BsdfCounts::ONE,
        }
    }

    /// A vertex's light sample, all of it for the lights.
    fn lights_only(u: &VertexSamples) -> Self {
        Self::new(1.0, u.light_select, u.light)
    }
}

/// The largest f32 below 1: a rescaled sample stays in [0, 1).
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// Russian roulette after a bounce at the `depth`th vertex, which scattered broadly or not (see
/// [`RR_THROUGHPUT_SCALE`]): false ends the path; else the throughput is divided by the
/// survival probability.
pub(super) fn survives(
    integrator: &IntegratorDesc,
    depth: u32,
    broad: bool,
    u_rr: f32,
    throughput: &mut Vec3,
) -> bool {
    let continue_prob = match integrator.rr_strategy {
        RussianRoulette::Probability if depth >= RR_MIN_DEPTH => integrator.rr_continue_prob,
        // The largest channel, not luminance: a path along a saturated red wall has a small
        // luminance but a large red throughput, and dividing that by a small survival
        // probability is what makes coloured fireflies.
        RussianRoulette::Efficiency if broad => {
            (throughput.max_element() * RR_THROUGHPUT_SCALE).clamp(RR_MIN_SURVIVAL, 1.0)
        }
        _ => return true,
    };
    if u_rr >= continue_prob {
        return false;
    }
    *throughput /= continue_prob;
    true
}

// Inlined into the unit loop: without it this loop stays a call away and the scenes without
// mirrors run 0.5% more instructions (callgrind, depth of field 160x90 32 spp).
#[inline(always)]
pub fn trace_path<S: PathScene>(scene: &S, ray: Ray, sampler: &mut PixelSampler) -> PathResult {
    trace_branching_path(scene, ray, sampler, scene.first_vertex_branches())
}

/// [`trace_path`] with `branches` continuations at the first broad vertex (clamped to 1 ..=
/// [`MAX_BRANCHES`]) whatever the scene's own number: what `render::branching` measures with.
#[inline(always)]
pub fn trace_branching_path<S: PathScene>(
    scene: &S,
    ray: Ray,
    sampler: &mut PixelSampler,
    branches: usize,
) -> PathResult {
    let mut out = PathResult::default();
    let state = PathState::camera(scene, ray, branches.clamp(1, MAX_BRANCHES));
    walk(scene, state, sampler, &mut out);
    out
}

/// A path between two vertices: the ray to the next one and what the path carries.
pub(super) struct PathState {
    pub(super) ray: Ray,
    /// What `ray` hits (`Some(None)`: nothing), when the caller has traced it already: a path
    /// leaving a packet at a vertex the packet does not shade is not traced twice.
    pub(super) traced: Option<Option<SurfaceHit>>,
    pub(super) throughput: Vec3,
    /// The light the path has gathered so far (a path traced in lanes up to here goes on one
    /// at a time with its sum, which it adds to in the same order).
    pub(super) radiance: Vec3,
    pub(super) medium: Option<MediumId>,
    pub(super) depth: u32,
    /// Null surfaces crossed since the last vertex.
    pub(super) pass_through: u32,
    /// Whether the path may still split at a glossy vertex (once, at its first that may see a
    /// lamp).
    pub(super) may_split: bool,
    /// The continuations its next broad vertex sends on, while every vertex so far was
    /// specular (1 after that).
    pub(super) branches: usize,
    pub(super) prev: PrevScatter,
}

impl PathState {
    fn camera<S: PathScene>(scene: &S, ray: Ray, branches: usize) -> Self {
        Self {
            ray,
            traced: None,
            throughput: Vec3::ONE,
            radiance: Vec3::ZERO,
            medium: scene.volumes().camera,
            depth: 0,
            pass_through: 0,
            may_split: scene.glossy_split(),
            branches,
            // The camera ray counts as specular: emitters it sees are taken at full weight.
            prev: PrevScatter::plain(ray.origin, 0.0, true),
        }
    }
}

/// Traces `state` on, adding its light and rays to `out`.
// Inlined into the unit loop, as `trace_path` is.
#[inline(always)]
pub(super) fn walk<S: PathScene>(
    scene: &S,
    state: PathState,
    sampler: &mut PixelSampler,
    out: &mut PathResult,
) {
    let integrator = scene.integrator();
    let max_depth = scene.max_depth();
    let lights = scene.lights();
    let volumes = scene.volumes();
    let has_media = !volumes.media.is_empty();
    let PathState {
        mut ray,
        mut traced,
        mut throughput,
        mut radiance,
        mut medium,
        mut depth,
        mut pass_through,
        mut may_split,
        mut branches,
        mut prev,
    } = state;
    let mut rays = 0u32;

    loop {
        rays += 1;
        let hit = match traced.take() {
            Some(hit) => hit,
            None => scene.geometry().intersect(&ray, f32::INFINITY),
        };
        // The sides of the surface hit as this ray meets them (no volumes: nothing to do).
        let sides = match &hit {
            Some(hit) if has_media => {
                let sides = scene.shape_media(hit.shape).met_by(ray.dir, hit.ng, medium);
                // A ray in no volume crosses the one on the near side of what it hits.
                if medium.is_none() {
                    medium = sides.toward(-ray.dir, hit.ng);
                }
                sides
            }
            _ => ShapeMedia::default(),
        };
        if let Some(m) = medium.and_then(|m| volumes.get(m)) {
            let length = hit.as_ref().map_or(f32::INFINITY, |h| h.t);
            let u = if m.scatters() { sampler.get_1d() } else { 0.0 };
            match m.flight(length, u) {
                Flight::Pass { weight } => throughput *= weight,
                Flight::Scatter { distance, weight } => {
                    throughput *= weight;
                    if depth >= max_depth {
                        break;
                    }
                    depth += 1;
                    let p = ray.at(distance);
                    let wo = -ray.dir;
                    let phase = m.phase();
                    radiance += throughput
                        * direct_light_in_medium(scene, p, wo, &phase, medium, sampler, &mut rays);
                    let wi = phase.sample(wo, sampler.get_2d());
                    let pdf = phase.pdf(wo, wi);
                    if pdf.is_nan() || pdf <= 0.0 {
                        break;
                    }
                    throughput *= phase.eval(wo, wi) / pdf;
                    if !survives(integrator, depth, true, sampler.get_1d(), &mut throughput) {
                        break;
                    }
                    prev = PrevScatter::plain(p, pdf, false);
                    branches = 1;
                    ray = Ray::new(p, wi);
                    continue;
                }
            }
            if throughput == Vec3::ZERO {
                break;
            }
        }

        let Some(hit) = hit else {
            if depth > 0 || integrator.include_environment {
                let (le, weight) = if prev.specular {
                    (lights.environment(ray.dir), 1.0)
                } else {
                    let (le, pdf) = lights.environment_and_pdf(ray.dir, prev.facing);
                    let pdf_light = (1.0 - prev.image_share) * pdf;
                    (le, power_heuristic(prev.pdf, pdf_light))
                };
                radiance += throughput * le * weight;
            }
            break;
        };
        let wo = -ray.dir;

        let le = lights.emitted(&hit, wo);
        if le != Vec3::ZERO && !prev.lamps_counted {
            let weight = if !prev.specular {
                let pdf_light = (1.0 - prev.image_share) * lights.pdf_hit(prev.p, &hit);
                power_heuristic(prev.pdf, pdf_light)
            } else if let Some(b) = prev.before_mirror {
                power_heuristic(b.pdf, IMAGE_SHARE * lights.image_pdf(b.p, b.plane, &hit))
            } else {
                1.0
            };
            radiance += throughput * le * weight;
        }

        // Every dimension a scattering vertex uses, drawn at once. A specular vertex draws the
        // light sample's too (and does not use them): the dimension layout of a vertex stays
        // fixed whatever the material.
        let u = sampler.get_vertex();
        let bsdf = scene.bsdf_at(&hit, u.mix);
        if bsdf.is_pass_through() {
            // Only the mix choice is used: the next vertex's dimensions follow it.
            sampler.unread_after_mix();
            pass_through += 1;
            if pass_through > MAX_PASS_THROUGH {
                break;
            }
            medium = sides.toward(ray.dir, hit.ng);
            ray = Ray::new(offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
            continue;
        }
        let crossed_null = pass_through > 0;
        pass_through = 0;
        if depth >= max_depth {
            break;
        }
        depth += 1;

        // The first glossy vertex that may see a lamp splits (see [`GLOSSY_SPLIT`]); elsewhere
        // more samples would find the dimmer surroundings and cost what they save. Whether it
        // splits depends on the path so far only, not on this vertex's own samples, so either
        // way its estimate is unbiased.
        let split = may_split
            && (bsdf.glossy_cone(wo)).is_some_and(|cone| lights.lamp_may_be_in(hit.p, &cone));
        let broad = bsdf.gathers_from(wo);
        let branching = !split && branches > 1 && broad.is_some();
        let bsdf_counts = if split {
            BsdfCounts::SPLIT
        } else if branching {
            BsdfCounts::all(branches as f32)
        } else {
            BsdfCounts::ONE
        };
        let vertex = Vertex {
            hit: &hit,
            wo,
            bsdf: &bsdf,
            sides,
        };
        let (light, image_share) = vertex.light(scene, &u, depth, bsdf_counts, &mut rays);
        if let Some(light) = light {
            radiance += throughput * light;
        }
        if split {
            may_split = false;
            let seen = split_bsdf_light(scene, &hit, wo, &bsdf, image_share, sampler);
            radiance += throughput * seen.radiance;
            rays += seen.rays;
        } else if branching {
            // Each continuation is a path of its own from here; this one ends.
            let vertex = BranchVertex {
                hit: &hit,
                wo,
                bsdf: &bsdf,
                facing: broad,
                sides,
                image_share,
                throughput,
                depth,
                may_split,
                roulette: u.roulette,
            };
            vertex.branch(scene, branches, sampler, out);
            break;
        }
        if !bsdf.is_specular() {
            branches = 1;
        }

        let Some((bs, weight)) = vertex.sample(&u) else {
            break;
        };
        throughput *= weight;

        if !survives(
            integrator,
            depth,
            broad.is_some(),
            u.roulette,
            &mut throughput,
        ) {
            break;
        }

        let before_mirror = vertex.mirror_after(lights, &prev, &bs, crossed_null);
        prev = PrevScatter {
            p: hit.p,
            pdf: bs.pdf,
            specular: bs.specular,
            image_share,
            before_mirror,
            lamps_counted: split,
            facing: broad,
        };
        medium = sides.toward(bs.wi, hit.ng);
        ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
    }
    out.radiance += radiance;
    out.rays += rays;
}

/// A surface vertex a path scatters at: what [`walk`] does there, and what a packet's lane
/// that meets a material the packet does not shade in lanes has done for it
/// ([`super::packet`]), the same operations either way.
pub(super) struct Vertex<'a> {
    pub(super) hit: &'a SurfaceHit,
    /// The direction the path arrived from.
    pub(super) wo: Vec3,
    pub(super) bsdf: &'a Bsdf,
    pub(super) sides: ShapeMedia,
}

impl Vertex<'_> {
    /// The vertex's light sample (None at a specular vertex), weighed against `bsdf_counts`
    /// BSDF samples, and the share of its light samples that went to lamp images. `depth`
    /// counts this vertex.
    #[inline(always)]
    pub(super) fn light<S: PathScene>(
        &self,
        scene: &S,
        u: &VertexSamples,
        depth: u32,
        bsdf_counts: BsdfCounts,
        rays: &mut u32,
    ) -> (Option<Vec3>, f32) {
        if self.bsdf.is_specular() {
            return (None, 0.0);
        }
        let (choice, image_share) = self.choose_light(scene, u, depth, bsdf_counts, rays);
        let light = match choice {
            LightChoice::Image(light) => light,
            LightChoice::Lights(draw) => {
                direct_light(scene, self.hit, self.wo, self.bsdf, self.sides, draw, rays)
            }
        };
        (Some(light), image_share)
    }

    /// Where the light sample of this vertex (not a specular one) goes, and the share of its
    /// light samples that went to lamp images: see [`Self::light`].
    #[inline(always)]
    pub(super) fn choose_light<S: PathScene>(
        &self,
        scene: &S,
        u: &VertexSamples,
        depth: u32,
        bsdf_counts: BsdfCounts,
        rays: &mut u32,
    ) -> (LightChoice, f32) {
        let lights = scene.lights();
        let (hit, wo, bsdf) = (self.hit, self.wo, self.bsdf);
        // A path through a mirror needs one more vertex: none past the last.
        let (draw, image) = if lights.has_mirror_images() && depth < scene.max_depth() {
            split_light_sample(lights, hit.p, u)
        } else {
            (LightDraw::lights_only(u), None)
        };
        let draw = LightDraw {
            bsdf_counts,
            ..draw
        };
        match image {
            Some(images) => {
                let light = direct_light_via_mirror(scene, hit, wo, bsdf, &images, draw, rays);
                (LightChoice::Image(light), draw.share)
            }
            // What the lights leave (nothing where no image is seen).
            None => (LightChoice::Lights(draw), 1.0 - draw.share),
        }
    }

    /// The path's BSDF sample here and what its throughput is multiplied by; None where the
    /// path ends (no sample, or one that carries nothing).
    #[inline(always)]
    pub(super) fn sample(&self, u: &VertexSamples) -> Option<(BsdfSample, Vec3)> {
        let bs = self.bsdf.sample(self.wo, u.lobe, u.bsdf)?;
        if bs.pdf <= 0.0 || bs.f == Vec3::ZERO {
            return None;
        }
        let cos = bs.wi.dot(self.hit.ns).abs();
        let weight = bs.f * (cos / bs.pdf);
        Some((bs, weight))
    }

    /// The flat mirror this vertex is, when the path's sample `bs` reflects in it straight
    /// after a vertex that sampled lamp images (`prev`; no null surface between).
    #[inline(always)]
    pub(super) fn mirror_after(
        &self,
        lights: &Lights,
        prev: &PrevScatter,
        bs: &BsdfSample,
        crossed_null: bool,
    ) -> Option<BeforeMirror> {
        let after_images = !prev.specular && prev.image_share > 0.0;
        if !bs.specular || !after_images || crossed_null {
            return None;
        }
        lights
            .mirror_plane(self.hit)
            .filter(|&plane| follows_plane(bs.wi, lights.reflect_in_plane(plane, -self.wo)))
            .map(|plane| BeforeMirror {
                p: prev.p,
                pdf: prev.pdf,
                plane,
            })
    }
}

/// A camera path's first broad vertex where it branches ([`MAX_BRANCHES`]): what its
/// continuations start from.
struct BranchVertex<'a> {
    hit: &'a SurfaceHit,
    wo: Vec3,
    bsdf: &'a Bsdf,
    /// The side the BSDF gathers light from ([`Bsdf::gathers_from`]).
    facing: Option<Vec3>,
    sides: ShapeMedia,
    image_share: f32,
    throughput: Vec3,
    depth: u32,
    may_split: bool,
    /// The vertex's own roulette number: the first continuation's.
    roulette: f32,
}

impl BranchVertex<'_> {
    /// Traces the vertex's `count` continuations, adding their light and rays to `out`. Their
    /// directions are drawn as one split draw (stratified together,
    /// [`PixelSampler::get_split_draws`]); the first goes on in the path's own stream, the
    /// others in [`PixelSampler::branch`]es of it. Each carries 1 / `count` of the throughput and
    /// takes its roulette on the whole (a continuation is one of `count` estimates of the same
    /// light, not a dimmer path); the light each finds emitting is weighed against the vertex's
    /// light sample with all `count` BSDF samples counted. Out of line, as the paths of a scene
    /// that does not branch never come here: the loop they run stays as small as it was
    /// (inlined, it made depth of field 5% slower).
    #[inline(never)]
    fn branch<S: PathScene>(
        &self,
        scene: &S,
        count: usize,
        sampler: &mut PixelSampler,
        out: &mut PathResult,
    ) {
        let (lobes, dirs) = sampler.get_split_draws::<MAX_BRANCHES>(count);
        for k in 0..count {
            let (mut stream, u_rr) = if k == 0 {
                (sampler.clone(), self.roulette)
            } else {
                let mut stream = sampler.branch(k as u32);
                let u_rr = stream.get_1d();
                (stream, u_rr)
            };
            if let Some(state) = self.continuation(scene, count, lobes[k], dirs[k], u_rr) {
                walk(scene, state, &mut stream, out);
            }
        }
    }

    /// The continuation along the BSDF sample (`u_lobe`, `u`), one of `count`; None where the
    /// sample finds nothing or the roulette (`u_rr`) ends it.
    fn continuation<S: PathScene>(
        &self,
        scene: &S,
        count: usize,
        u_lobe: f32,
        u: Vec2,
        u_rr: f32,
    ) -> Option<PathState> {
        let hit = self.hit;
        let bs = self
            .bsdf
            .sample(self.wo, u_lobe, u)
            .filter(|bs| bs.pdf > 0.0 && bs.f != Vec3::ZERO)?;
        let mut throughput = self.throughput * bs.f * (bs.wi.dot(hit.ns).abs() / bs.pdf);
        if !survives(scene.integrator(), self.depth, true, u_rr, &mut throughput) {
            return None;
        }
        Some(PathState {
            ray: Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi),
            traced: None,
            throughput: throughput / count as f32,
            radiance: Vec3::ZERO,
            medium: self.sides.toward(bs.wi, hit.ng),
            depth: self.depth,
            pass_through: 0,
            may_split: self.may_split,
            branches: 1,
            // Counted `count` times against the light sample (the split's way, with the share
            // already in the throughput). A broad BSDF's samples are not specular: no mirror
            // follows.
            prev: PrevScatter {
                p: hit.p,
                pdf: count as f32 * bs.pdf,
                specular: bs.specular,
                image_share: self.image_share,
                before_mirror: None,
                lamps_counted: false,
                facing: self.facing,
            },
        })
    }
}

/// What reaches `origin + t dir` from `origin`, for t up to `tmax`, in volume `medium`: 0 when
/// a surface blocks the way, else the volumes' transmittance. `null` surfaces let the ray
/// through (into the volume behind them), as LuxRender's shadow rays cross them and as paths
/// do, so light sampling sees what BSDF sampling sees: the sky behind a `null` lamp, or a light
/// inside a null-bounded volume. When shadow rays stopped there, the light samples of the sky
/// behind Captain Falcon's null lamp were lost while the BSDF samples that crossed it found
/// the sky, and MIS weighed each as if the other could: its direct light came out 0.1% dark
/// (0.4% with the map sampled for the side a surface faces, which weighs light samples more).
fn shadow_transmittance<S: PathScene>(
    scene: &S,
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
    medium: Option<MediumId>,
    rays: &mut u32,
) -> Vec3 {
    if scene.volumes().media.is_empty() {
        *rays += 1;
        let blocked = scene.geometry().occluded(&Ray::new(origin, dir), tmax);
        return if blocked { Vec3::ZERO } else { Vec3::ONE };
    }
    shadow_walk(scene, origin, dir, tmax, medium, rays)
}

/// [`shadow_transmittance`] in a scene with volumes: surface by surface. Kept out of line so
/// that the path loop of a scene without volumes stays as small as it was.
#[inline(never)]
fn shadow_walk<S: PathScene>(
    scene: &S,
    mut origin: Vec3,
    dir: Vec3,
    mut tmax: f32,
    mut medium: Option<MediumId>,
    rays: &mut u32,
) -> Vec3 {
    let volumes = scene.volumes();
    let mut tr = Vec3::ONE;
    for _ in 0..=MAX_PASS_THROUGH {
        *rays += 1;
        let ray = Ray::new(origin, dir);
        let hit = scene.geometry().intersect(&ray, tmax);
        let sides = hit
            .as_ref()
            .map(|h| scene.shape_media(h.shape).met_by(dir, h.ng, medium));
        if let (Some(h), Some(sides), None) = (&hit, sides, medium) {
            medium = sides.toward(-dir, h.ng);
        }
        let length = hit.as_ref().map_or(tmax, |h| h.t);
        if let Some(m) = medium.and_then(|m| volumes.get(m)) {
            tr *= m.transmittance(length);
        }
        let (Some(h), Some(sides)) = (hit, sides) else {
            return tr;
        };
        if !scene.is_pass_through(h.shape) || tr == Vec3::ZERO {
            return Vec3::ZERO;
        }
        medium = sides.toward(dir, h.ng);
        let next = offset_origin(h.p, h.ng, dir);
        tmax -= (next - origin).length();
        origin = next;
        if tmax <= 0.0 {
            return tr;
        }
    }
    Vec3::ZERO
}

/// The distance a shadow ray from `origin` travels to a light sampled at `dist` from `p`:
/// stopped short of the light's own surface.
fn shadow_tmax(p: Vec3, origin: Vec3, dist: f32) -> f32 {
    if dist.is_finite() {
        (origin - p).length().mul_add(-1.0, dist) * (1.0 - 1e-3)
    } else {
        f32::INFINITY
    }
}

/// One light sample, weighted against BSDF sampling by the power heuristic. `sides` are the
/// volumes around the surface (the shadow ray starts in the one on the light's side).
// Inlined into the path loop, as it was before paths could branch (left to itself the compiler
// then kept it a call away: depth of field 4% slower, fuzz-profile builds).
#[inline(always)]
fn direct_light<S: PathScene>(
    scene: &S,
    hit: &SurfaceHit,
    wo: Vec3,
    bsdf: &Bsdf,
    sides: ShapeMedia,
    draw: LightDraw,
    rays: &mut u32,
) -> Vec3 {
    let facing = bsdf.gathers_from(wo);
    let Some(mut ls) = scene.lights().sample(hit.p, facing, draw.u_select, draw.u) else {
        return Vec3::ZERO;
    };
    ls.pdf *= draw.share;
    if ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let f = bsdf.eval(wo, ls.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let origin = offset_origin(hit.p, hit.ng, ls.wi);
    let tmax = shadow_tmax(hit.p, origin, ls.dist);
    let medium = sides.toward(ls.wi, hit.ng);
    let tr = shadow_transmittance(scene, origin, ls.wi, tmax, medium, rays);
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let weight = if ls.delta {
        1.0
    } else {
        let count = draw.bsdf_counts.for_light(ls.dist.is_infinite());
        power_heuristic(ls.pdf, count * bsdf.pdf(wo, ls.wi))
    };
    tr * f * ls.li * (ls.wi.dot(hit.ns).abs() * weight / ls.pdf)
}

/// What a split vertex's BSDF samples see of the lights.
struct SplitLight {
    radiance: Vec3,
    rays: u32,
}

/// The lamps a split vertex ([`GLOSSY_SPLIT`]) sees directly along its BSDF samples: each
/// weighed against the light sample by the power heuristic with the samples' count, and
/// divided by it. The samples are one split draw, stratified together; the path goes on with
/// the vertex's own `lobe` and `bsdf` numbers and does not count a lamp it finds next
/// ([`PrevScatter::lamps_counted`]). Environment maps are left to that path, weighed against
/// the light sample as one BSDF sample ([`BsdfCounts`]): a sample that cannot reach a lamp's
/// bounding sphere is then not traced at all. When the split's samples took the environment
/// too, Mario's error was the same (4 seeds, 16 spp: 0.000631 against 0.000627 now) for 15%
/// more rays and 17% more time. It once went on with the split's first sample instead,
/// saving a ray: but sample `j` of every camera sample's split draw lies in the same
/// `1 / GLOSSY_SPLIT` of its first number, so a pixel's paths all went on through one strip
/// of the lobe, and Mario's hat (which sees the lamp in its own crown) kept its noise from 16
/// to 64 spp. Null surfaces are crossed as the path crosses them (a scene splits only when no
/// material lets rays through at some hits only, see [`PathScene::glossy_split`]). A lamp
/// behind a flat mirror is the path's to find, one sample as without the split, which is what
/// the vertex's lamp-image sample weighs against. Out of line: most vertices do not split.
#[inline(never)]
fn split_bsdf_light<S: PathScene>(
    scene: &S,
    hit: &SurfaceHit,
    wo: Vec3,
    bsdf: &Bsdf,
    image_share: f32,
    sampler: &mut PixelSampler,
) -> SplitLight {
    let (lobes, dirs) = sampler.get_split_draws::<GLOSSY_SPLIT>(GLOSSY_SPLIT);
    let lights = scene.lights();
    let count = GLOSSY_SPLIT as f32;
    let mut seen = SplitLight {
        radiance: Vec3::ZERO,
        rays: 0,
    };
    for (&u_lobe, &u) in lobes.iter().zip(&dirs) {
        let Some(bs) = bsdf.sample(wo, u_lobe, u) else {
            continue;
        };
        if bs.pdf.is_nan() || bs.pdf <= 0.0 || bs.f == Vec3::ZERO {
            continue;
        }
        if !lights.lamp_may_be_along(hit.p, bs.wi) {
            continue;
        }
        let weight_of = |pdf_light: f32| {
            if bs.specular {
                1.0
            } else {
                power_heuristic(count * bs.pdf, (1.0 - image_share) * pdf_light)
            }
        };
        let scale = bs.f * (bs.wi.dot(hit.ns).abs() / (bs.pdf * count));
        let mut ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
        for _ in 0..=MAX_PASS_THROUGH {
            seen.rays += 1;
            let Some(next) = scene.geometry().intersect(&ray, f32::INFINITY) else {
                break;
            };
            let le = lights.emitted(&next, -bs.wi);
            if le != Vec3::ZERO {
                seen.radiance += scale * le * weight_of(lights.pdf_hit(hit.p, &next));
            }
            if !scene.is_pass_through(next.shape) {
                break;
            }
            ray = Ray::new(offset_origin(next.p, next.ng, bs.wi), bs.wi);
        }
    }
    seen
}

/// A vertex's light sample in a scene with lamp images: where the vertex sees one, the first
/// [`IMAGE_SHARE`] of the choice dimension (rescaled) samples an image (returned with the
/// images' weights), the rest the lights. Kept out of line: the path loop of a scene without
/// mirrors stays as small as it was.
#[inline(never)]
fn split_light_sample(
    lights: &Lights,
    p: Vec3,
    u: &VertexSamples,
) -> (LightDraw, Option<ImageWeights>) {
    let Some(images) = lights.image_weights(p) else {
        return (LightDraw::lights_only(u), None);
    };
    let share = IMAGE_SHARE;
    if u.light_select < share {
        let draw = LightDraw::new(share, u.light_select / share, u.light);
        (draw, Some(images))
    } else {
        let u_select = ((u.light_select - share) / (1.0 - share)).min(ONE_BELOW);
        (LightDraw::new(1.0 - share, u_select, u.light), None)
    }
}

/// How far past the mirror plane the ray to a lamp image's mirror point may find the mirror
/// (relative): the hit is checked to lie in the plane anyway.
const MIRROR_REACH: f32 = 1.0 + 1e-3;

/// One light sample through a flat mirror (a lamp image, [`crate::lights::ImageSample`]),
/// weighted against BSDF sampling by the power heuristic: the mirror must be the first surface
/// towards its sampled point, its reflection must follow the plane (as a BSDF sample's must for
/// the same path to count as found by an image), and the lamp must be in view of it. Scenes
/// with volumes have no lamp images. Out of line, as [`split_light_sample`].
#[inline(never)]
fn direct_light_via_mirror<S: PathScene>(
    scene: &S,
    hit: &SurfaceHit,
    wo: Vec3,
    bsdf: &Bsdf,
    images: &ImageWeights,
    draw: LightDraw,
    rays: &mut u32,
) -> Vec3 {
    let lights = scene.lights();
    let Some(s) = lights.sample_image(images, draw.u_select, draw.u) else {
        return Vec3::ZERO;
    };
    if s.pdf.is_nan() || s.pdf <= 0.0 || s.li == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let f = bsdf.eval(wo, s.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    *rays += 1;
    let origin = offset_origin(hit.p, hit.ng, s.wi);
    let ray = Ray::new(origin, s.wi);
    let Some(mirror) = scene.geometry().intersect(&ray, s.to_mirror * MIRROR_REACH) else {
        return Vec3::ZERO;
    };
    if lights.mirror_plane(&mirror) != Some(s.plane) {
        return Vec3::ZERO;
    }
    // A plain mirror: nothing to choose, and its reflection draws no random number.
    let Some(r) = scene.bsdf_at(&mirror, 0.0).sample(-s.wi, 0.0, Vec2::ZERO) else {
        return Vec3::ZERO;
    };
    if !r.specular || r.pdf.is_nan() || r.pdf <= 0.0 || !follows_plane(r.wi, s.reflected) {
        return Vec3::ZERO;
    }
    let reflectance = r.f * (r.wi.dot(mirror.ns).abs() / r.pdf);
    let to_light = s.light_point - mirror.p;
    let dist = to_light.length();
    let dir = to_light / dist;
    let origin = offset_origin(mirror.p, mirror.ng, dir);
    let tr = shadow_transmittance(
        scene,
        origin,
        dir,
        shadow_tmax(mirror.p, origin, dist),
        None,
        rays,
    );
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let pdf = draw.share * s.pdf;
    let weight = power_heuristic(pdf, draw.bsdf_counts.lamps * bsdf.pdf(wo, s.wi));
    tr * f * reflectance * s.li * (s.wi.dot(hit.ns).abs() * weight / pdf)
}

/// One light sample at a scattering event inside a volume, weighted against phase-function
/// sampling by the power heuristic.
#[inline(never)]
fn direct_light_in_medium<S: PathScene>(
    scene: &S,
    p: Vec3,
    wo: Vec3,
    phase: &Phase,
    medium: Option<MediumId>,
    sampler: &mut PixelSampler,
    rays: &mut u32,
) -> Vec3 {
    let u_select = sampler.get_1d();
    let u_light = sampler.get_2d();
    let Some(ls) = scene.lights().sample(p, None, u_select, u_light) else {
        return Vec3::ZERO;
    };
    if ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let tr = shadow_transmittance(scene, p, ls.wi, shadow_tmax(p, p, ls.dist), medium, rays);
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let weight = if ls.delta {
        1.0
    } else {
        power_heuristic(ls.pdf, phase.pdf(wo, ls.wi))
    };
    tr * phase.eval(wo, ls.wi) * ls.li * (weight / ls.pdf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::options::DEFAULT_RR_CONTINUE_PROB;

    fn integrator(strategy: RussianRoulette) -> IntegratorDesc {
        IntegratorDesc {
            rr_strategy: strategy,
            ..IntegratorDesc::path_defaults("path")
        }
    }

    /// Survival as `survives` decides it, and the throughput it leaves.
    fn roulette(
        strategy: RussianRoulette,
        depth: u32,
        broad: bool,
        u: f32,
        t: Vec3,
    ) -> Option<Vec3> {
        let mut t = t;
        survives(&integrator(strategy), depth, broad, u, &mut t).then_some(t)
    }

    #[test]
    fn efficiency_roulette_ends_dark_paths_at_broad_vertices_from_the_first() {
        let dark = Vec3::new(0.02, 0.01, 0.0);
        // Survival 3 x 0.02 = 0.06, at the first vertex already.
        assert_eq!(
            roulette(RussianRoulette::Efficiency, 1, true, 0.06, dark),
            None
        );
        let kept = roulette(RussianRoulette::Efficiency, 1, true, 0.059, dark).unwrap();
        assert!((kept - dark / 0.06).abs().max_element() < 1e-6, "{kept}");
        // Never below the floor: a black path survives 1 in 20, weighed by 20.
        let black = roulette(RussianRoulette::Efficiency, 1, true, 0.049, Vec3::ZERO);
        assert_eq!(black, Some(Vec3::ZERO));
        assert_eq!(
            roulette(RussianRoulette::Efficiency, 1, true, 0.05, Vec3::ZERO),
            None
        );
        // A third of the throughput or more always goes on, unchanged.
        let bright = Vec3::new(0.34, 0.1, 0.1);
        assert_eq!(
            roulette(RussianRoulette::Efficiency, 9, true, 0.999, bright),
            Some(bright)
        );
    }

    #[test]
    fn efficiency_roulette_never_ends_paths_at_glossy_or_specular_vertices() {
        for depth in [1, 3, 10] {
            let t = Vec3::splat(0.001);
            assert_eq!(
                roulette(RussianRoulette::Efficiency, depth, false, 0.999, t),
                Some(t)
            );
        }
    }

    #[test]
    fn probability_roulette_keeps_luxrenders_rule() {
        let t = Vec3::splat(0.5);
        let p = DEFAULT_RR_CONTINUE_PROB;
        for broad in [true, false] {
            // Not before the third vertex, whatever the vertex.
            assert_eq!(
                roulette(RussianRoulette::Probability, 2, broad, 0.999, t),
                Some(t)
            );
            assert_eq!(roulette(RussianRoulette::Probability, 3, broad, p, t), None);
            let kept = roulette(RussianRoulette::Probability, 3, broad, p - 0.01, t).unwrap();
            assert!((kept - t / p).abs().max_element() < 1e-6, "{kept}");
        }
        assert_eq!(
            roulette(RussianRoulette::None, 9, true, 0.999, Vec3::ZERO),
            Some(Vec3::ZERO)
        );
    }
}
