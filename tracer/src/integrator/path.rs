//! The path tracer's loop: unidirectional path tracing with next-event estimation, multiple
//! importance sampling of light and BSDF samples (power heuristic) and Russian roulette,
//! through participating media ([`super::media`]), with the glossy split
//! ([`super::glossy_split`]), lamp images in flat mirrors ([`super::mirror_images`]) and the
//! branching vertex ([`super::branch`]); LuxRender's direct lighting is this walk ended after
//! the first non-specular vertex ([`PathScene::direct_lighting`]). What a vertex does is
//! [`super::vertex`]'s, shared with the packets of [`super::packet`]; this file is the loop
//! that strings vertices together.

use glam::Vec3;

use super::glossy_split::{split_bsdf_light, splits_at};
use super::groups::{credit, GroupSink, LitBy};
use super::light_draw::BsdfCounts;
use super::media::{meet_surface, travel, Segment, Travel};
use super::mirror_images::mirror_after;
use super::mis::power_heuristic;
use super::roulette::survives;
use super::scene::PathScene;
use super::shadow::goes_straight_on;
use super::state::{BranchPoint, PathResult, PathState, PrevScatter, MAX_PASS_THROUGH};
use super::vertex::Vertex;
use crate::lights::IMAGE_SHARE;
use crate::math::{offset_origin, Ray};
use crate::sampler::PixelSampler;

/// Traces `state` on, adding its light and rays to `out` (and each light term to its light
/// group's sum in `groups`: a sink that keeps groups is only handed in by a render whose paths
/// neither split nor branch), to its end or to the vertex where it branches (returned, with
/// its light and rays so far not yet added: see [`super::branch::walk_to_the_end`]).
// Inlined into the unit loop, as `trace_path` is.
#[inline(always)]
pub(super) fn walk<S: PathScene, G: GroupSink>(
    scene: &S,
    state: PathState,
    sampler: &mut PixelSampler,
    (out, groups): (&mut PathResult, &mut G),
) -> Option<BranchPoint> {
    let integrator = scene.integrator();
    let max_depth = scene.max_depth();
    let lights = scene.lights();
    let volumes = scene.volumes();
    let has_media = !volumes.media.is_empty();
    let panes = scene.has_panes();
    let direct_lighting = scene.direct_lighting();
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
        mut wavelength,
    } = state;
    let mut rays = 0u32;

    loop {
        rays += 1;
        // Direct lighting's path ends where the ray from its first non-specular vertex ends.
        let last_segment = direct_lighting && !prev.specular;
        let hit = match traced.take() {
            Some(hit) => hit,
            None => scene.geometry().intersect(&ray, f32::INFINITY),
        };
        // The sides of the surface hit as this ray meets them (no volumes: nothing to do).
        let sides = meet_surface(scene, hit.as_ref(), ray.dir, &mut medium, has_media);
        if let Some(volume) = medium.and_then(|m| volumes.get(m)) {
            let segment = Segment {
                volume,
                id: medium,
                ray,
                length: hit.as_ref().map_or(f32::INFINITY, |h| h.t),
                last: last_segment,
            };
            match travel(
                scene,
                &segment,
                depth,
                throughput,
                (&mut radiance, groups),
                sampler,
                &mut rays,
            ) {
                Travel::Crossed(carried) => throughput = carried,
                Travel::Scattered {
                    throughput: carried,
                    ray: next,
                    prev: from,
                } => {
                    throughput = carried;
                    depth += 1;
                    prev = from;
                    branches = 1;
                    ray = next;
                    continue;
                }
                Travel::Ended => break,
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
                let light = throughput * le * weight;
                radiance += light;
                credit(groups, lights, Some(LitBy::Environment(ray.dir)), light);
            }
            out.escaped |= depth == 0;
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
            let light = throughput * le * weight;
            radiance += light;
            credit(groups, lights, Some(LitBy::Shape(hit.shape)), light);
        }

        // Every dimension a scattering vertex uses, drawn at once. A specular vertex draws the
        // light sample's too (and does not use them): the dimension layout of a vertex stays
        // fixed whatever the material.
        let u = sampler.get_vertex();
        let mut bsdf = scene.bsdf_at(&hit, u.mix);
        if let Some(weight) = bsdf.disperse(&mut wavelength, || sampler.wavelength_number()) {
            throughput *= weight;
        }
        let straight = goes_straight_on(scene, &hit, &bsdf, wo, u.lobe, panes, sampler);
        if let Some(transmittance) = straight {
            throughput *= transmittance;
            pass_through += 1;
            if pass_through > MAX_PASS_THROUGH {
                out.escaped |= depth == 0;
                break;
            }
            medium = sides.toward(ray.dir, hit.ng);
            ray = Ray::new(offset_origin(hit.p, hit.ng, ray.dir), ray.dir);
            continue;
        }
        let crossed = pass_through > 0;
        pass_through = 0;
        if depth >= max_depth || last_segment {
            break;
        }
        depth += 1;

        let split = may_split && splits_at(lights, &hit, wo, &bsdf);
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
            depth,
            bsdf_counts,
        };
        let (term, image_share) = vertex.light_term(scene, &u, &mut rays);
        if let Some(term) = term {
            let light = throughput * term.light;
            radiance += light;
            credit(groups, lights, term.from, light);
        }
        if split {
            may_split = false;
            let seen = split_bsdf_light(scene, &hit, wo, &bsdf, image_share, sampler);
            radiance += throughput * seen.radiance;
            rays += seen.rays;
        } else if branching {
            // Each continuation is a path of its own from here; this one ends.
            return Some(BranchPoint {
                hit,
                wo,
                bsdf,
                facing: broad,
                sides,
                image_share,
                throughput,
                depth,
                may_split,
                roulette: u.roulette,
                count: branches,
                radiance,
                rays,
                wavelength,
            });
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

        let before_mirror = mirror_after(lights, &hit, wo, &prev, &bs, crossed);
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
    None
}
