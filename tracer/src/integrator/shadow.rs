//! Shadow rays: what reaches a light sample's point, through null surfaces, panes of
//! architectural glass and volumes.

use glam::Vec3;

use super::scene::{Crossing, PathScene};
use super::state::MAX_PASS_THROUGH;
use crate::geometry::SurfaceHit;
use crate::lanes::Lanes;
use crate::material::Bsdf;
use crate::math::{offset_origin, Ray};
use crate::medium::MediumId;
use crate::sampler::PixelSampler;
use crate::vec3_lanes::{dot, V3};

/// What reaches `origin + t dir` from `origin`, for t up to `tmax`, in volume `medium`: 0 when
/// a surface blocks the way, else the volumes' and panes' transmittance. `null` surfaces let
/// the ray through (into the volume behind them), as LuxRender's shadow rays cross them and as
/// paths do, so light sampling sees what BSDF sampling sees: the sky behind a `null` lamp, or a
/// light inside a null-bounded volume. (A shadow ray stopped there would lose the light samples
/// of what BSDF samples find behind it, while MIS weighs each as if the other could: dark.)
/// Panes of architectural glass let it through with their transmittance, as LuxRender's
/// shadow rays cross them: the sun through a window is light-sampled.
pub(super) fn shadow_transmittance<S: PathScene>(
    scene: &S,
    origin: Vec3,
    dir: Vec3,
    tmax: f32,
    medium: Option<MediumId>,
    rays: &mut u32,
) -> Vec3 {
    if scene.volumes().media.is_empty() && !scene.has_panes() {
        *rays += 1;
        let blocked = scene.geometry().occluded(&Ray::new(origin, dir), tmax);
        return if blocked { Vec3::ZERO } else { Vec3::ONE };
    }
    shadow_walk(scene, origin, dir, tmax, medium, rays)
}

/// [`shadow_transmittance`] in a scene with volumes or panes: surface by surface. Out of line:
/// the path loop of a scene without them stays small.
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
        match scene.crossing(h.shape) {
            Crossing::Blocks => return Vec3::ZERO,
            Crossing::Null => {}
            Crossing::Pane => tr *= pane_transmittance(scene, &h, dir),
        }
        if tr == Vec3::ZERO {
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

/// Whether a path that reached `hit` along `-wo` goes straight on through it, and what it
/// carries on if so: a `null` surface always (its mix number alone read, so the next vertex's
/// dimensions follow), a pane of architectural glass when its lobe choice `u_lobe` is the
/// straight transmission (`panes`: the scene has some). Paths cross as shadow rays cross, so
/// the light behind is weighed against the previous vertex's light sample. The path tracer's
/// and the bidirectional walks' one rule.
#[inline(always)]
pub(super) fn goes_straight_on<S: PathScene>(
    scene: &S,
    hit: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    u_lobe: f32,
    panes: bool,
    sampler: &mut PixelSampler,
) -> Option<Vec3> {
    if bsdf.is_pass_through() {
        sampler.unread_after_mix();
        Some(Vec3::ONE)
    } else if panes && scene.crossing(hit.shape) == Crossing::Pane {
        bsdf.sample_straight(wo, u_lobe)
    } else {
        None
    }
}

/// What the pane at `hit` lets straight through along `dir`: its material evaluated there
/// (a pane's material is a glass, never a mix: nothing to choose).
pub(super) fn pane_transmittance<S: PathScene>(scene: &S, hit: &SurfaceHit, dir: Vec3) -> Vec3 {
    scene
        .bsdf_at(hit, 0.0)
        .straight_transmittance(dir)
        .unwrap_or(Vec3::ZERO)
}

/// The distance a shadow ray from `origin` travels to a light sampled at `dist` from `p`:
/// stopped short of the light's own surface.
#[inline(always)]
pub(super) fn shadow_tmax(p: Vec3, origin: Vec3, dist: f32) -> f32 {
    shadow_tmax_in_lanes::<f32>(p.to_array(), origin.to_array(), dist)
}

/// [`shadow_tmax`] in lanes (infinite for a light at infinity).
#[inline(always)]
pub(super) fn shadow_tmax_in_lanes<L: Lanes>(p: V3<L>, origin: V3<L>, dist: L) -> L {
    let to_origin = [origin[0] - p[0], origin[1] - p[1], origin[2] - p[2]];
    let short = (dist - dot(to_origin, to_origin).sqrt()) * L::splat(1.0 - 1e-3);
    let finite = dist.abs().lt(L::splat(f32::INFINITY));
    L::select(finite, short, L::splat(f32::INFINITY))
}
