//! A subpath's random walk: from the camera or from a light, surface to surface, recording a
//! vertex at every scattering surface with its forward density and its predecessor's reverse
//! one. Null surfaces and panes of architectural glass are crossed as the path tracer crosses
//! them (no vertex, the pane's straight transmittance carried; an emitter crossed is kept
//! aside for the strategy that ends there), and shadow rays cross them the same way, so every
//! strategy sees the same light behind them.

use glam::Vec3;

use super::scene::{BidirectionalScene, MAX_VERTICES};
use super::vertex::{shading_correction, Kind, LightVertex, PathVertex, SurfaceVertex};
use crate::geometry::SurfaceHit;
use crate::integrator::shadow::goes_straight_on;
use crate::integrator::state::MAX_PASS_THROUGH;
use crate::lights::Emitter;
use crate::material::Bsdf;
use crate::math::{luminance, offset_origin, Ray};
use crate::sampler::{PixelSampler, VertexSamples};

/// Which way a subpath carries light, which decides the BSDF's adjoint.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Carries {
    /// A camera subpath: radiance flows toward its start.
    Radiance,
    /// A light subpath: light flows from its start.
    Importance,
}

/// The rule of LuxRender's bidirectional roulette: a subpath goes on past a vertex with
/// probability `min(1, max(threshold, luminance of the BSDF sample's weight))` (the weight
/// `f |cos| / pdf`: the share of the light the vertex passes on). Not at the first vertex.
fn survival(threshold: f32, weight: Vec3) -> f32 {
    luminance(weight).max(threshold).min(1.0)
}

/// An emitter a camera subpath crossed (a lamp of null material, a glowing pane): the vertex
/// it would have been, after the subpath's first `at` vertices. The path goes on through it,
/// as the path tracer's does, and the strategy of the camera path ending there (`s = 0`) is
/// taken from this vertex.
pub(super) struct CrossedEmitter {
    pub(super) at: usize,
    pub(super) vertex: PathVertex,
}

/// Walks on from `path`'s last vertex along `ray` with throughput `beta`, adding vertices
/// until `max_vertices` or the path ends; `pdf_dir` is the solid-angle density of `ray`'s
/// direction (unused after the camera or a light, whose own densities give the first
/// vertex's). A camera subpath that escapes ends with a vertex at infinity; the emitters it
/// crosses go to `crossed`. Returns the rays traced.
#[allow(clippy::too_many_arguments)]
pub(super) fn walk<S: BidirectionalScene>(
    scene: &S,
    path: &mut Vec<PathVertex>,
    crossed: &mut Vec<CrossedEmitter>,
    mut ray: Ray,
    mut beta: Vec3,
    max_vertices: usize,
    carries: Carries,
    rr_threshold: f32,
    sampler: &mut PixelSampler,
) -> u32 {
    let mut rays = 0;
    let mut pdf_dir = 0.0;
    let mut pass_through = 0;
    let panes = scene.has_panes();
    while path.len() < max_vertices {
        rays += 1;
        let Some(hit) = scene.geometry().intersect(&ray, f32::INFINITY) else {
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
                };
                vertex.pdf_fwd = first_or_next(scene, path, prev, pdf_dir, &vertex);
                path.push(vertex);
            }
            break;
        };
        let wo = -ray.dir;
        let u = sampler.get_vertex();
        let bsdf = scene.bsdf_at(&hit, u.mix);
        let straight = goes_straight_on(scene, &hit, &bsdf, wo, u.lobe, panes, sampler);
        if let Some(transmittance) = straight {
            if carries == Carries::Radiance
                && path.len() < max_vertices
                && crossed.len() < MAX_VERTICES
                && scene.lights().emitted(&hit, wo) != Vec3::ZERO
            {
                let prev = path.last().expect("a walk starts from a vertex");
                let mut vertex = surface_vertex(hit, bsdf, wo, u, beta);
                vertex.pdf_fwd = first_or_next(scene, path, prev, pdf_dir, &vertex);
                let at = path.len();
                crossed.push(CrossedEmitter { at, vertex });
            }
            beta *= transmittance;
            pass_through += 1;
            if pass_through > MAX_PASS_THROUGH {
                break;
            }
            ray = Ray::new(offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
            continue;
        }
        pass_through = 0;
        let prev = *path.last().expect("a walk starts from a vertex");
        let mut vertex = surface_vertex(hit, bsdf, wo, u, beta);
        vertex.pdf_fwd = first_or_next(scene, path, &prev, pdf_dir, &vertex);
        path.push(vertex);
        if path.len() >= max_vertices {
            break;
        }
        let Some(bs) = bsdf.sample(wo, u.lobe, u.bsdf) else {
            break;
        };
        if bs.pdf <= 0.0 || bs.f == Vec3::ZERO {
            break;
        }
        let mut weight = bs.f * (bs.wi.dot(hit.ns).abs() / bs.pdf);
        let last = path.len() - 1;
        if carries == Carries::Importance {
            if let Kind::Surface(s) = &path[last].kind {
                weight *= shading_correction(s, wo, bs.wi);
            }
        }
        // The density of going back the same way, for the previous vertex.
        let (pdf_fwd, pdf_rev) = if bs.specular {
            path[last].delta = true;
            (0.0, 0.0)
        } else {
            (bs.pdf, bsdf.pdf(bs.wi, wo))
        };
        // No sample finds a delta light: a point, a spot, a distant light.
        let rev = if path[last - 1].is_delta_light() {
            0.0
        } else {
            path[last].area_density(pdf_rev, &path[last - 1])
        };
        path[last - 1].pdf_rev = rev;
        if path.len() > 2 {
            let q = survival(rr_threshold, weight);
            if q <= 0.0 || u.roulette >= q {
                break;
            }
            weight /= q;
        }
        beta *= weight;
        if beta == Vec3::ZERO || !beta.is_finite() {
            break;
        }
        pdf_dir = pdf_fwd;
        ray = Ray::new(offset_origin(hit.p, hit.ng, bs.wi), bs.wi);
    }
    rays
}

/// A surface vertex reached with throughput `beta`, its densities not yet known.
fn surface_vertex(
    hit: SurfaceHit,
    bsdf: Bsdf,
    wo: Vec3,
    u: VertexSamples,
    beta: Vec3,
) -> PathVertex {
    PathVertex {
        kind: Kind::Surface(SurfaceVertex {
            hit,
            bsdf,
            wo,
            sides: Default::default(),
            u,
        }),
        p: hit.p,
        ng: hit.ng,
        beta,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        delta: false,
    }
}

/// The forward density of `next`, reached from `prev` (`path`'s last vertex): the camera's or
/// the light's own density when `prev` is the subpath's start, else `prev`'s BSDF sample's
/// `pdf_dir` as an area density.
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
