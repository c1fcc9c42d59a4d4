//! Lamp images in flat mirrors: a vertex's light samples of them, and the mirror a path's
//! BSDF sample reflects in after such a vertex (for the MIS weight of the lamp it finds).

use glam::{Vec2, Vec3};

use super::groups::{LightTerm, LitBy};
use super::light_draw::LightDraw;
use super::mis::power_heuristic;
use super::scene::PathScene;
use super::shadow::{shadow_tmax, shadow_transmittance};
use super::state::{BeforeMirror, PrevScatter};
use crate::geometry::SurfaceHit;
use crate::lights::{follows_plane, ImageWeights, Lights, IMAGE_SHARE};
use crate::material::{Bsdf, BsdfSample};
use crate::math::{offset_origin, Ray};
use crate::sampler::VertexSamples;

/// The largest f32 below 1: a rescaled sample stays in [0, 1).
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// A vertex's light sample in a scene with lamp images: where the vertex sees one, the first
/// [`IMAGE_SHARE`] of the choice dimension (rescaled) samples an image (returned with the
/// images' weights), the rest the lights. Out of line: the path loop of a scene without
/// mirrors stays small.
#[inline(never)]
pub(super) fn split_light_sample(
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
pub(super) fn direct_light_via_mirror<S: PathScene>(
    scene: &S,
    hit: &SurfaceHit,
    wo: Vec3,
    bsdf: &Bsdf,
    images: &ImageWeights,
    draw: LightDraw,
    rays: &mut u32,
) -> LightTerm {
    let lights = scene.lights();
    let Some(s) = lights.sample_image(images, draw.u_select, draw.u) else {
        return LightTerm::NONE;
    };
    if s.pdf.is_nan() || s.pdf <= 0.0 || s.li == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let f = bsdf.eval(wo, s.wi);
    if f == Vec3::ZERO {
        return LightTerm::NONE;
    }
    *rays += 1;
    let origin = offset_origin(hit.p, hit.ng, s.wi);
    let ray = Ray::new(origin, s.wi);
    let Some(mirror) = scene.geometry().intersect(&ray, s.to_mirror * MIRROR_REACH) else {
        return LightTerm::NONE;
    };
    if lights.mirror_plane(&mirror) != Some(s.plane) {
        return LightTerm::NONE;
    }
    // A plain mirror: nothing to choose, and its reflection draws no random number.
    let Some(r) = scene.bsdf_at(&mirror, 0.0).sample(-s.wi, 0.0, Vec2::ZERO) else {
        return LightTerm::NONE;
    };
    if !r.specular || r.pdf.is_nan() || r.pdf <= 0.0 || !follows_plane(r.wi, s.reflected) {
        return LightTerm::NONE;
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
        return LightTerm::NONE;
    }
    let pdf = draw.share * s.pdf;
    let weight = power_heuristic(pdf, draw.bsdf_counts.lamps * bsdf.pdf(wo, s.wi));
    LightTerm {
        light: tr * f * reflectance * s.li * (s.wi.dot(hit.ns).abs() * weight / pdf),
        from: Some(LitBy::Light(s.lamp)),
    }
}

/// The flat mirror the vertex at `hit` (reached from `wo`) is, when the path's sample `bs`
/// reflects in it straight after a vertex that sampled lamp images (`prev`; nothing `crossed`
/// between, neither a null surface nor a pane: an image's light sample needs the mirror to be
/// the first surface it meets).
#[inline(always)]
pub(super) fn mirror_after(
    lights: &Lights,
    hit: &SurfaceHit,
    wo: Vec3,
    prev: &PrevScatter,
    bs: &BsdfSample,
    crossed: bool,
) -> Option<BeforeMirror> {
    let after_images = !prev.specular && prev.image_share > 0.0;
    if !bs.specular || !after_images || crossed {
        return None;
    }
    lights
        .mirror_plane(hit)
        .filter(|&plane| follows_plane(bs.wi, lights.reflect_in_plane(plane, -wo)))
        .map(|plane| BeforeMirror {
            p: prev.p,
            pdf: prev.pdf,
            plane,
        })
}
