//! A path's segments through participating media (LuxRender's named volumes): Beer-Lambert
//! transmittance, free-flight sampling, and at a scattering event the light sample and the
//! phase function's sample.
//!
//! The volume a ray travels in follows LuxRender's rule: after a surface, the side of it the
//! ray leaves into (a shape's `Interior` or `Exterior`; a side with no volume is the ray's
//! own when the ray came from it, else no volume). A ray in no volume takes, for its segment,
//! the volume on the near side of the surface it hits. A scene without volumes takes none of
//! these steps and draws no random numbers for them.

use glam::{Vec2, Vec3};

use super::groups::{credit, GroupSink, LightTerm, LitBy};
use super::mis::power_heuristic;
use super::roulette::survives;
use super::scene::PathScene;
use super::shadow::{shadow_tmax, shadow_transmittance};
use super::state::PrevScatter;
use crate::geometry::SurfaceHit;
use crate::math::Ray;
use crate::medium::{Flight, MediumDesc, MediumId, Phase, ShapeMedia};
use crate::sampler::PixelSampler;

/// The sides of the surface `hit` (if any) as a ray along `dir` in volume `medium` meets
/// them, and the ray's volume for the segment up to it: a ray in no volume crosses the one on
/// the near side of what it hits. No volumes in the scene (`has_media` false): no sides, and
/// `medium` unchanged. The path tracer's and the bidirectional walks' one rule.
#[inline(always)]
pub(super) fn meet_surface<S: PathScene>(
    scene: &S,
    hit: Option<&SurfaceHit>,
    dir: Vec3,
    medium: &mut Option<MediumId>,
    has_media: bool,
) -> ShapeMedia {
    match hit {
        Some(hit) if has_media => {
            let sides = scene.shape_media(hit.shape).met_by(dir, hit.ng, *medium);
            if medium.is_none() {
                *medium = sides.toward(-dir, hit.ng);
            }
            sides
        }
        _ => ShapeMedia::default(),
    }
}

/// The fate of a ray crossing `length` of `volume`: one random number drawn, only when the
/// volume scatters.
#[inline(always)]
pub(super) fn free_flight(volume: &MediumDesc, length: f32, sampler: &mut PixelSampler) -> Flight {
    let u = if volume.scatters() {
        sampler.get_1d()
    } else {
        0.0
    };
    volume.flight(length, u)
}

/// A direction drawn from the phase function at a scattering event reached along `-wo`.
pub(super) struct PhaseSample {
    pub(super) wi: Vec3,
    /// The solid-angle density of `wi`.
    pub(super) pdf: f32,
    /// The phase function over the density: what the path's throughput is multiplied by.
    pub(super) weight: Vec3,
}

/// Draws the direction a path leaves a scattering event with (`u` its two numbers); None when
/// the density is not positive.
#[inline(always)]
pub(super) fn sample_phase(phase: &Phase, wo: Vec3, u: Vec2) -> Option<PhaseSample> {
    let wi = phase.sample(wo, u);
    let pdf = phase.pdf(wo, wi);
    if pdf.is_nan() || pdf <= 0.0 {
        return None;
    }
    Some(PhaseSample {
        wi,
        pdf,
        weight: phase.eval(wo, wi) / pdf,
    })
}

/// A path's segment through a volume: the ray, up to `length` (infinite where it hits nothing).
pub(super) struct Segment<'a> {
    pub(super) volume: &'a MediumDesc,
    pub(super) id: Option<MediumId>,
    pub(super) ray: Ray,
    pub(super) length: f32,
    /// The path's last segment (direct lighting's, after its first non-specular vertex): it
    /// only looks for light beyond, and ends where it would scatter.
    pub(super) last: bool,
}

/// What a path does along a [`Segment`].
pub(super) enum Travel {
    /// Through to its end, carrying this throughput.
    Crossed(Vec3),
    /// Scattered inside: the throughput the path goes on with, its next ray and what it leaves
    /// the next vertex.
    Scattered {
        throughput: Vec3,
        ray: Ray,
        prev: PrevScatter,
    },
    /// The path ends (absorbed, out of depth, or ended by the roulette).
    Ended,
}

/// The path's segment `segment`, reached with `throughput` after `depth` vertices: the light
/// of a scattering vertex is added to `radiance`, the rays traced counted in `rays`. A path on
/// its [`Segment::last`] ends where it would scatter.
#[inline(always)]
pub(super) fn travel<S: PathScene, G: GroupSink>(
    scene: &S,
    segment: &Segment,
    depth: u32,
    mut throughput: Vec3,
    (radiance, groups): (&mut Vec3, &mut G),
    sampler: &mut PixelSampler,
    rays: &mut u32,
) -> Travel {
    let m = segment.volume;
    match free_flight(m, segment.length, sampler) {
        Flight::Pass { weight } => {
            throughput *= weight;
            if throughput == Vec3::ZERO {
                Travel::Ended
            } else {
                Travel::Crossed(throughput)
            }
        }
        Flight::Scatter { distance, weight } => {
            throughput *= weight;
            if depth >= scene.max_depth() || segment.last {
                return Travel::Ended;
            }
            let depth = depth + 1;
            let ray = segment.ray;
            let p = ray.at(distance);
            let wo = -ray.dir;
            let phase = m.phase();
            let term = direct_light_in_medium(scene, p, wo, &phase, segment.id, sampler, rays);
            let light = throughput * term.light;
            *radiance += light;
            credit(groups, scene.lights(), term.from, light);
            let Some(PhaseSample { wi, pdf, weight }) = sample_phase(&phase, wo, sampler.get_2d())
            else {
                return Travel::Ended;
            };
            throughput *= weight;
            if !survives(
                scene.integrator(),
                depth,
                true,
                sampler.get_1d(),
                &mut throughput,
            ) {
                return Travel::Ended;
            }
            Travel::Scattered {
                throughput,
                ray: Ray::new(p, wi),
                prev: PrevScatter::plain(p, pdf, false),
            }
        }
    }
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
) -> LightTerm {
    let u_select = sampler.get_1d();
    let u_light = sampler.get_2d();
    let Some(ls) = scene.lights().sample(p, None, u_select, u_light) else {
        return LightTerm::NONE;
    };
    if ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let tr = shadow_transmittance(scene, p, ls.wi, shadow_tmax(p, p, ls.dist), medium, rays);
    if tr == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let weight = if ls.delta {
        1.0
    } else {
        power_heuristic(ls.pdf, phase.pdf(wo, ls.wi))
    };
    LightTerm {
        light: tr * phase.eval(wo, ls.wi) * ls.li * (weight / ls.pdf),
        from: Some(LitBy::Choice {
            u_select,
            wi: ls.wi,
        }),
    }
}
