//! A camera path's branching vertex: at its first broad vertex a path may go on as several
//! continuations, each a path of its own from there.

use glam::{Vec2, Vec3};

use super::groups::GroupSink;
use super::path::walk;
use super::roulette::survives;
use super::scene::PathScene;
use super::state::{BranchPoint, PathResult, PathState, PrevScatter};
use crate::math::{offset_origin, Ray};
use crate::sampler::PixelSampler;

/// The most continuations a camera path may branch into at its first broad scattering vertex
/// (a diffuse, velvet or cloth lobe, under a coat or not, [`Bsdf::gathers_from`], reached
/// through specular vertices only), each carrying its share of the throughput and its own
/// sample stream; the vertex's light sample is weighed against all of them. Where the light
/// that reaches a pixel through its first bounce holds most of the noise, and a path costs
/// more before that vertex than after (the camera ray, the film, the first light sample),
/// more continuations per camera sample are the cheaper way to less noise; how many a scene
/// takes is measured when it is built (`render::branching`; what each count gains on the seed
/// scenes: bench/RESULTS.md, "Branching camera paths").
///
/// [`Bsdf::gathers_from`]: crate::material::Bsdf::gathers_from
pub const MAX_BRANCHES: usize = 4;

/// Traces `state` to its end by [`walk`], and where it reaches its branching vertex, every
/// continuation from there; their light and rays go to `out`, each light term to its light
/// group in `groups` (a sink that keeps groups only comes with a state that does not branch).
#[inline(always)]
pub(super) fn walk_to_the_end<S: PathScene, G: GroupSink>(
    scene: &S,
    state: PathState,
    sampler: &mut PixelSampler,
    (out, groups): (&mut PathResult, &mut G),
) {
    if let Some(point) = walk(scene, state, sampler, (out, groups)) {
        branch(scene, &point, sampler, out);
        out.radiance += point.radiance;
        out.rays += point.rays;
    }
}

/// Traces the continuations of `point`, adding their light and rays to `out`. Their directions
/// are drawn as one split draw (stratified together, [`PixelSampler::get_split_draws`]); the
/// first goes on in the path's own stream, the others in [`PixelSampler::branch`]es of it. Each
/// carries 1 / `count` of the throughput and takes its roulette on the whole (a continuation is
/// one of `count` estimates of the same light, not a dimmer path); the light each finds
/// emitting is weighed against the vertex's light sample with all `count` BSDF samples
/// counted. Out of line: the paths of a scene that does not branch never come here, and the
/// loop they run stays small.
#[inline(never)]
fn branch<S: PathScene>(
    scene: &S,
    point: &BranchPoint,
    sampler: &mut PixelSampler,
    out: &mut PathResult,
) {
    let count = point.count;
    let (lobes, dirs) = sampler.get_split_draws::<MAX_BRANCHES>(count);
    for k in 0..count {
        let (mut stream, u_rr) = if k == 0 {
            (sampler.clone(), point.roulette)
        } else {
            let mut stream = sampler.branch(k as u32);
            let u_rr = stream.get_1d();
            (stream, u_rr)
        };
        if let Some(state) = continuation(scene, point, lobes[k], dirs[k], u_rr) {
            let branched = walk(scene, state, &mut stream, (out, &mut ()));
            debug_assert!(branched.is_none(), "a continuation branches once only");
        }
    }
}

/// The continuation of `point` along the BSDF sample (`u_lobe`, `u`); None where the sample
/// finds nothing or the roulette (`u_rr`) ends it.
fn continuation<S: PathScene>(
    scene: &S,
    point: &BranchPoint,
    u_lobe: f32,
    u: Vec2,
    u_rr: f32,
) -> Option<PathState> {
    let hit = &point.hit;
    let count = point.count;
    let bs = point
        .bsdf
        .sample(point.wo, u_lobe, u)
        .filter(|bs| bs.pdf > 0.0 && bs.f != Vec3::ZERO)?;
    let mut throughput = point.throughput * bs.f * (bs.wi.dot(hit.ns).abs() / bs.pdf);
    if !survives(scene.integrator(), point.depth, true, u_rr, &mut throughput) {
        return None;
    }
    Some(PathState {
        ray: Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi),
        traced: None,
        throughput: throughput / count as f32,
        radiance: Vec3::ZERO,
        medium: point.sides.toward(bs.wi, hit.ng),
        depth: point.depth,
        pass_through: 0,
        may_split: point.may_split,
        branches: 1,
        wavelength: point.wavelength,
        // Counted `count` times against the light sample (the split's way, with the share
        // already in the throughput). A broad BSDF's samples are not specular: no mirror
        // follows.
        prev: PrevScatter {
            p: hit.p,
            pdf: count as f32 * bs.pdf,
            specular: bs.specular,
            image_share: point.image_share,
            before_mirror: None,
            lamps_counted: false,
            facing: point.facing,
        },
    })
}
