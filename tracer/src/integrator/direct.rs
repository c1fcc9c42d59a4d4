//! A surface vertex's light sample (next-event estimation), weighed against its BSDF samples.

use glam::Vec3;

use super::groups::{LightTerm, LitBy};
use super::light_draw::LightDraw;
use super::mis::power_heuristic;
use super::scene::PathScene;
use super::shadow::{shadow_tmax, shadow_transmittance};
use crate::geometry::SurfaceHit;
use crate::material::Bsdf;
use crate::math::offset_origin;
use crate::medium::ShapeMedia;

/// One light sample, weighted against BSDF sampling by the power heuristic, and the light it
/// came from. `sides` are the
/// volumes around the surface (the shadow ray starts in the one on the light's side).
// Inlined into the path loop: left to itself the compiler keeps it a call away, at a cost
// (bench/RESULTS.md, "The integrator's inlining").
#[inline(always)]
pub(super) fn direct_light<S: PathScene>(
    scene: &S,
    hit: &SurfaceHit,
    wo: Vec3,
    bsdf: &Bsdf,
    sides: ShapeMedia,
    draw: LightDraw,
    rays: &mut u32,
) -> LightTerm {
    let facing = bsdf.gathers_from(wo);
    let Some(mut ls) = scene.lights().sample(hit.p, facing, draw.u_select, draw.u) else {
        return LightTerm::NONE;
    };
    ls.pdf *= draw.share;
    if ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let f = bsdf.eval(wo, ls.wi);
    if f == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let origin = offset_origin(hit.p, hit.ng, ls.wi);
    let tmax = shadow_tmax(hit.p, origin, ls.dist);
    let medium = sides.toward(ls.wi, hit.ng);
    let tr = shadow_transmittance(scene, origin, ls.wi, tmax, medium, rays);
    if tr == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let weight = if ls.delta {
        1.0
    } else {
        let count = draw.bsdf_counts.for_light(ls.dist.is_infinite());
        power_heuristic(ls.pdf, count * bsdf.pdf(wo, ls.wi))
    };
    LightTerm {
        light: tr * f * ls.li * (ls.wi.dot(hit.ns).abs() * weight / ls.pdf),
        from: Some(LitBy::Choice {
            u_select: draw.u_select,
            wi: ls.wi,
        }),
    }
}
