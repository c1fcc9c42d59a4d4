//! The strategies: a camera subpath's first `t` vertices joined to a light subpath's first
//! `s`, each weighed by [`mis_weight`]. `s = 0`: the camera path's last vertex is on a light;
//! `s = 1`: its last vertex takes a light sample (the path tracer's next-event estimation);
//! `t = 1`: a light subpath vertex is seen by the camera (light tracing: a splat anywhere on
//! the film); otherwise a shadow ray joins two scattering vertices. A scattering vertex is a
//! surface's or an event in a volume: the phase function takes the BSDF's place there, and no
//! cosine is taken there (in the geometry term nor in the densities). Every connection
//! carries the shadow ray's transmittance, through the volumes it crosses from the volume its
//! start is in ([`PathVertex::leaving`]).

use glam::Vec3;

use super::scene::{BidirectionalScene, LightSplat, MAX_VERTICES};
use super::vertex::{Carries, Kind, LightVertex, PathVertex};
use super::weight::{mis_weight, Densities, Limits};
use crate::integrator::groups::LightTerm;
use crate::integrator::shadow::{shadow_tmax, shadow_transmittance};

/// What reaches the point `dist` along unit `dir` from `from` (a scattering vertex, or the
/// lens): the shadow ray's transmittance through null surfaces, panes and volumes, from the
/// volume `from` is in.
fn transmittance<S: BidirectionalScene>(
    scene: &S,
    from: &PathVertex,
    dir: Vec3,
    dist: f32,
    rays: &mut u32,
) -> Vec3 {
    let (origin, medium) = from.leaving(dir, scene.volumes().camera);
    let tmax = shadow_tmax(from.p, origin, dist);
    shadow_transmittance(scene, origin, dir, tmax, medium, rays)
}

/// [`transmittance`] from `from` to the point `to`.
fn transmittance_to<S: BidirectionalScene>(
    scene: &S,
    from: &PathVertex,
    to: Vec3,
    rays: &mut u32,
) -> Vec3 {
    let d = to - from.p;
    let dist = d.length();
    if dist <= 0.0 {
        return Vec3::ZERO;
    }
    transmittance(scene, from, d / dist, dist, rays)
}

/// Copies a subpath's densities for a strategy to change at its connection.
fn densities(path: &[PathVertex]) -> ([Densities; MAX_VERTICES], usize) {
    let mut out = [Densities::default(); MAX_VERTICES];
    for (o, v) in out.iter_mut().zip(path) {
        *o = v.into();
    }
    (out, path.len())
}

/// `s = 0`: the camera subpath `before` (its first vertices) ends at `pt`, on an area light
/// or at infinity: `pt` is the subpath's next vertex, or an emitter it crossed there.
pub(super) fn camera_hits_light<S: BidirectionalScene>(
    scene: &S,
    before: &[PathVertex],
    pt: &PathVertex,
    limits: Limits,
) -> Vec3 {
    let t = before.len() + 1;
    let le = pt.emitted(scene);
    if le == Vec3::ZERO {
        return Vec3::ZERO;
    }
    if t == 2 && pt.at_infinity() && !scene.integrator().include_environment {
        return Vec3::ZERO;
    }
    let prev = &before[t - 2];
    let (mut cam, n) = densities(before);
    cam[n] = pt.into();
    let n = n + 1;
    cam[t - 1].rev = pt.pdf_light_origin(scene, prev);
    cam[t - 1].delta = false;
    cam[t - 2].rev = pt.pdf_light(scene, prev);
    pt.beta * le * mis_weight(&[], &cam[..n], false, limits)
}

/// `s = 1`: the camera subpath's `t`th vertex samples a light (and which it reached).
pub(super) fn camera_samples_light<S: BidirectionalScene>(
    scene: &S,
    camera: &[PathVertex],
    t: usize,
    limits: Limits,
    rays: &mut u32,
) -> LightTerm {
    let pt = &camera[t - 1];
    let Some(u) = pt.samples() else {
        return LightTerm::NONE;
    };
    if pt.delta {
        return LightTerm::NONE;
    }
    let Some((ls, point)) = scene
        .lights()
        .sample_light_point(pt.p, u.light_select, u.light)
    else {
        return LightTerm::NONE;
    };
    if ls.pdf <= 0.0 || ls.li == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let f = pt.scatters_toward(ls.wi, Carries::Radiance);
    if f == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let tr = transmittance(scene, pt, ls.wi, ls.dist, rays);
    if tr == Vec3::ZERO {
        return LightTerm::NONE;
    }
    let unweighted = pt.beta * f * ls.li * tr * (pt.cos_toward(ls.wi) / ls.pdf);
    let light_vertex = PathVertex {
        kind: Kind::Light(LightVertex {
            emitter: point.emitter,
            toward: point.at_infinity.then_some(ls.wi),
            delta_position: point.delta_position,
            delta_direction: point.delta_direction,
        }),
        p: point.p,
        ng: point.normal.unwrap_or(Vec3::ZERO),
        beta: Vec3::ZERO,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        delta: false,
        dispersed: false,
    };
    let prev = &camera[t - 2];
    let light = [Densities {
        fwd: light_vertex.pdf_light_origin(scene, pt),
        rev: pt.pdf_toward(scene, Some(prev), &light_vertex),
        delta: false,
    }];
    let (mut cam, n) = densities(&camera[..t]);
    cam[t - 1].rev = light_vertex.pdf_light(scene, pt);
    cam[t - 2].rev = pt.pdf_toward(scene, Some(&light_vertex), prev);
    LightTerm {
        light: unweighted * mis_weight(&light, &cam[..n], light_vertex.is_delta_light(), limits),
        from: light_vertex.lit_by(),
    }
}

/// `t = 1`: the light subpath's `s`th vertex (a scattering one, `s >= 2`) seen by the camera
/// through the lens point its own lens numbers choose: a splat at its film position.
pub(super) fn camera_sees_light_vertex<S: BidirectionalScene>(
    scene: &S,
    light: &[PathVertex],
    s: usize,
    limits: Limits,
    rays: &mut u32,
) -> Option<LightSplat> {
    let qs = &light[s - 1];
    let u = qs.samples()?;
    if qs.delta {
        return None;
    }
    let camera = scene.camera();
    let view = camera.view(qs.p, u.light)?;
    let to_lens = view.lens_point - qs.p;
    let wi = to_lens.normalize_or_zero();
    let f = qs.scatters_toward(wi, Carries::Importance);
    if f == Vec3::ZERO {
        return None;
    }
    let tr = transmittance_to(scene, qs, view.lens_point, rays);
    if tr == Vec3::ZERO {
        return None;
    }
    let unweighted = qs.beta * f * tr * (qs.cos_toward(wi) * view.density);
    let lens = PathVertex {
        kind: Kind::Camera,
        p: view.lens_point,
        ng: Vec3::ZERO,
        beta: Vec3::ONE,
        pdf_fwd: 0.0,
        pdf_rev: 0.0,
        delta: false,
        dispersed: false,
    };
    let prev = &light[s - 2];
    let (mut lig, n) = densities(&light[..s]);
    lig[s - 1].rev = lens.pdf_toward(scene, None, qs);
    lig[s - 2].rev = qs.pdf_toward(scene, Some(&lens), prev);
    let cam = [Densities::default()];
    let radiance = unweighted * mis_weight(&lig[..n], &cam, light[0].is_delta_light(), limits);
    Some(LightSplat {
        raster: view.raster,
        radiance,
        group: None,
    })
}

/// `s, t >= 2`: a shadow ray joins the light subpath's `s`th vertex and the camera subpath's
/// `t`th.
pub(super) fn join<S: BidirectionalScene>(
    scene: &S,
    light: &[PathVertex],
    s: usize,
    camera: &[PathVertex],
    t: usize,
    limits: Limits,
    rays: &mut u32,
) -> Vec3 {
    let (qs, pt) = (&light[s - 1], &camera[t - 1]);
    if qs.samples().is_none() || pt.samples().is_none() {
        return Vec3::ZERO;
    }
    if qs.delta || pt.delta {
        return Vec3::ZERO;
    }
    let d = qs.p - pt.p;
    let dist2 = d.length_squared();
    if dist2 <= 0.0 {
        return Vec3::ZERO;
    }
    let dir = d / dist2.sqrt();
    let f_camera = pt.scatters_toward(dir, Carries::Radiance);
    if f_camera == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let f_light = qs.scatters_toward(-dir, Carries::Importance);
    if f_light == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let g = pt.cos_toward(dir) * qs.cos_toward(dir) / dist2;
    let unweighted = pt.beta * f_camera * f_light * qs.beta * g;
    if unweighted == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let tr = transmittance_to(scene, pt, qs.p, rays);
    if tr == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let (mut cam, nc) = densities(&camera[..t]);
    let (mut lig, nl) = densities(&light[..s]);
    let (pt_prev, qs_prev) = (&camera[t - 2], &light[s - 2]);
    cam[t - 1].rev = qs.pdf_toward(scene, Some(qs_prev), pt);
    cam[t - 2].rev = pt.pdf_toward(scene, Some(qs), pt_prev);
    lig[s - 1].rev = pt.pdf_toward(scene, Some(pt_prev), qs);
    lig[s - 2].rev = qs.pdf_toward(scene, Some(pt), qs_prev);
    let w = mis_weight(&lig[..nl], &cam[..nc], light[0].is_delta_light(), limits);
    unweighted * tr * w
}
