//! A subpath's random walk: from the camera or from a light, recording a vertex at every
//! scattering surface and at every scattering event in a volume, with its forward density and
//! its predecessor's reverse one. Null surfaces and panes of architectural glass are crossed
//! as the path tracer crosses them (no vertex, the pane's straight transmittance carried; an
//! emitter crossed is kept aside for the strategy that ends there), and shadow rays cross them
//! the same way, so every strategy sees the same light behind them.
//! Volumes are walked through as the path tracer walks through them ([`super::super::media`]'s
//! rules, free flights and phase function): each segment in a volume draws its free flight,
//! the subpath carrying the flight's weight, and a scattering event is a vertex that counts
//! against the subpath's depth as a surface's does.

use glam::Vec3;

use super::scene::{BidirectionalScene, MAX_VERTICES};
use super::vertex::{Carries, Kind, LightVertex, MediumVertex, PathVertex, SurfaceVertex};
use crate::geometry::SurfaceHit;
use crate::integrator::media::{free_flight, meet_surface};
use crate::integrator::shadow::goes_straight_on;
use crate::integrator::state::MAX_PASS_THROUGH;
use crate::lights::Emitter;
use crate::material::Bsdf;
use crate::math::{luminance, offset_origin, Ray};
use crate::medium::{Flight, MediumId, ShapeMedia};
use crate::sampler::{PixelSampler, VertexSamples};
use crate::wavelength::Wavelength;

/// The rule of LuxRender's bidirectional roulette: a subpath goes on past a vertex with
/// probability `min(1, max(threshold, luminance of the BSDF sample's weight))` (the weight
/// `f |cos| / pdf`: the share of the light the vertex passes on; the phase function's over
/// its density in a volume). Not at the first vertex.
fn survival(threshold: f32, weight: Vec3) -> f32 {
    luminance(weight).max(threshold).min(1.0)
}

/// A sample's wavelength, shared by its camera and light subpaths: drawn from `number` (the
/// camera stream's [`PixelSampler::wavelength_number`]) at the first dispersive vertex either
/// subpath meets, so that a path joined from both has one wavelength. Unlike the path tracer's
/// paths, subpaths do not carry its weight in their throughput (a path joined from two that
/// both met dispersion would take it twice): the strategies' contributions take it once,
/// where a vertex they join at is [`PathVertex::dispersed`].
pub(super) struct SampleWavelength {
    pub(super) number: f32,
    pub(super) drawn: Option<Wavelength>,
}

impl SampleWavelength {
    /// `contribution` of a path that met dispersion (`dispersed`) or not.
    pub(super) fn weigh(&self, dispersed: bool, contribution: Vec3) -> Vec3 {
        match self.drawn {
            Some(w) if dispersed => contribution * w.weight,
            _ => contribution,
        }
    }
}

/// An emitter a camera subpath crossed (a lamp of null material, a glowing pane): the vertex
/// it would have been, after the subpath's first `at` vertices. The path goes on through it,
/// as the path tracer's does, and the strategy of the camera path ending there (`s = 0`) is
/// taken from this vertex.
pub(super) struct CrossedEmitter {
    pub(super) at: usize,
    pub(super) vertex: PathVertex,
}

/// Walks on from `path`'s last vertex along `ray`, in volume `medium`, with throughput `beta`,
/// adding vertices until `max_vertices` or the path ends. A camera subpath that escapes ends
/// with a vertex at infinity; the emitters it crosses go to `crossed`. `from_infinity`: `ray` is light from a light at infinity, which
/// crossed all of its first segment's volume from there (that volume's transmittance over an
/// infinite distance, as a shadow ray toward the light finds it; no event in it). Returns the
/// rays traced.
#[allow(clippy::too_many_arguments)]
pub(super) fn walk<S: BidirectionalScene>(
    scene: &S,
    path: &mut Vec<PathVertex>,
    crossed: &mut Vec<CrossedEmitter>,
    mut ray: Ray,
    mut medium: Option<MediumId>,
    mut from_infinity: bool,
    mut beta: Vec3,
    max_vertices: usize,
    carries: Carries,
    rr_threshold: f32,
    wavelength: &mut SampleWavelength,
    sampler: &mut PixelSampler,
) -> u32 {
    let mut rays = 0;
    let mut dispersed = path.last().is_some_and(|v| v.dispersed);
    // The solid-angle density of `ray`'s direction (unused after the camera or a light, whose
    // own densities give the first vertex's).
    let mut pdf_dir = 0.0;
    let mut pass_through = 0;
    let panes = scene.has_panes();
    let volumes = scene.volumes();
    let has_media = !volumes.media.is_empty();
    while path.len() < max_vertices {
        rays += 1;
        let hit = scene.geometry().intersect(&ray, f32::INFINITY);
        let sides = meet_surface(scene, hit.as_ref(), ray.dir, &mut medium, has_media);
        if let Some(volume) = medium.and_then(|m| volumes.get(m)) {
            let flight = if from_infinity {
                Flight::Pass {
                    weight: volume.transmittance(f32::INFINITY),
                }
            } else {
                free_flight(volume, hit.as_ref().map_or(f32::INFINITY, |h| h.t), sampler)
            };
            match flight {
                Flight::Pass { weight } => {
                    beta *= weight;
                    if beta == Vec3::ZERO {
                        break;
                    }
                }
                Flight::Scatter { distance, weight } => {
                    beta *= weight;
                    pass_through = 0;
                    let prev = *path.last().expect("a walk starts from a vertex");
                    let mut vertex = PathVertex {
                        kind: Kind::Medium(MediumVertex {
                            phase: volume.phase(),
                            wo: -ray.dir,
                            medium,
                            u: sampler.get_vertex(),
                        }),
                        p: ray.at(distance),
                        ng: Vec3::ZERO,
                        beta,
                        pdf_fwd: 0.0,
                        pdf_rev: 0.0,
                        delta: false,
                        dispersed,
                    };
                    vertex.pdf_fwd = first_or_next(scene, path, &prev, pdf_dir, &vertex);
                    path.push(vertex);
                    let Some(next) =
                        scatter_on(path, max_vertices, carries, rr_threshold, &mut beta)
                    else {
                        break;
                    };
                    pdf_dir = next.0;
                    ray = Ray::new(vertex.p, next.1);
                    continue;
                }
            }
        }
        from_infinity = false;
        let Some(hit) = hit else {
            if carries == Carries::Radiance && !scene.lights().is_empty() {
                let prev = path.last().expect("a walk starts from a vertex");
                let mut vertex = PathVertex {
                    kind: Kind::Light(LightVertex {
                        emitter: Emitter::Environment,
                        toward: Some(ray.dir),
                        delta_position: false,
                        delta_direction: false,
                    }),
                    p: ray.origin,
                    ng: Vec3::ZERO,
                    beta,
                    pdf_fwd: 0.0,
                    pdf_rev: 0.0,
                    delta: false,
                    dispersed,
                };
                vertex.pdf_fwd = first_or_next(scene, path, prev, pdf_dir, &vertex);
                path.push(vertex);
            }
            break;
        };
        let wo = -ray.dir;
        let u = sampler.get_vertex();
        let mut bsdf = scene.bsdf_at(&hit, u.mix);
        dispersed |= bsdf.is_dispersive();
        bsdf.disperse(&mut wavelength.drawn, || wavelength.number);
        let straight = goes_straight_on(scene, &hit, &bsdf, wo, u.lobe, panes, sampler);
        if let Some(transmittance) = straight {
            if carries == Carries::Radiance
                && path.len() < max_vertices
                && crossed.len() < MAX_VERTICES
                && scene.lights().emitted(&hit, wo) != Vec3::ZERO
            {
                let prev = path.last().expect("a walk starts from a vertex");
                let mut vertex = surface_vertex(hit, bsdf, wo, sides, u, beta, dispersed);
                vertex.pdf_fwd = first_or_next(scene, path, prev, pdf_dir, &vertex);
                let at = path.len();
                crossed.push(CrossedEmitter { at, vertex });
            }
            beta *= transmittance;
            pass_through += 1;
            if pass_through > MAX_PASS_THROUGH {
                break;
            }
            medium = sides.toward(ray.dir, hit.ng);
            ray = Ray::new(offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
            continue;
        }
        pass_through = 0;
        let prev = *path.last().expect("a walk starts from a vertex");
        let mut vertex = surface_vertex(hit, bsdf, wo, sides, u, beta, dispersed);
        vertex.pdf_fwd = first_or_next(scene, path, &prev, pdf_dir, &vertex);
        path.push(vertex);
        let Some((pdf, wi)) = scatter_on(path, max_vertices, carries, rr_threshold, &mut beta)
        else {
            break;
        };
        pdf_dir = pdf;
        medium = sides.toward(wi, hit.ng);
        ray = Ray::new(offset_origin(hit.p, hit.ng, wi), wi);
    }
    rays
}

/// A surface vertex reached with throughput `beta`, its densities not yet known.
fn surface_vertex(
    hit: SurfaceHit,
    bsdf: Bsdf,
    wo: Vec3,
    sides: ShapeMedia,
    u: VertexSamples,
    beta: Vec3,
    dispersed: bool,
) -> PathVertex {
    PathVertex {
        kind: Kind::Surface(SurfaceVertex {
            hit,
            bsdf,
            wo,
            sides,
            u,
        }),
        p: hit.p,
        ng: hit.ng,
        beta,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        delta: false,
        dispersed,
    }
}

/// The subpath on from its last vertex, just added (a scattering one): unless the subpath is
/// full, the direction its own numbers draw, the reverse density that gives its previous
/// vertex, LuxRender's roulette (from the second scattering vertex on) and the throughput
/// `beta` carried on. Returns the direction's solid-angle density (0 for a specular one) and
/// the direction; None where the subpath ends.
fn scatter_on(
    path: &mut [PathVertex],
    max_vertices: usize,
    carries: Carries,
    rr_threshold: f32,
    beta: &mut Vec3,
) -> Option<(f32, Vec3)> {
    if path.len() >= max_vertices {
        return None;
    }
    let last = path.len() - 1;
    let next = path[last].sample_on(carries)?;
    let mut weight = next.weight;
    if next.specular {
        path[last].delta = true;
    }
    // The density of going back the same way, for the previous vertex. No sample finds a
    // delta light: a point, a spot, a distant light.
    let rev = if path[last - 1].is_delta_light() {
        0.0
    } else {
        path[last].area_density(next.pdf_rev, &path[last - 1])
    };
    path[last - 1].pdf_rev = rev;
    if path.len() > 2 {
        let roulette = path[last].samples().map_or(0.0, |u| u.roulette);
        let q = survival(rr_threshold, weight);
        if q <= 0.0 || roulette >= q {
            return None;
        }
        weight /= q;
    }
    *beta *= weight;
    if *beta == Vec3::ZERO || !beta.is_finite() {
        return None;
    }
    Some((next.pdf, next.wi))
}

/// The forward density of `next`, reached from `prev` (`path`'s last vertex): the camera's or
/// the light's own density when `prev` is the subpath's start, else `prev`'s BSDF or phase
/// function sample's `pdf_dir` as an area density.
fn first_or_next<S: BidirectionalScene>(
    scene: &S,
    path: &[PathVertex],
    prev: &PathVertex,
    pdf_dir: f32,
    next: &PathVertex,
) -> f32 {
    if path.len() == 1 {
        prev.pdf_toward(scene, None, next)
    } else {
        prev.area_density(pdf_dir, next)
    }
}
