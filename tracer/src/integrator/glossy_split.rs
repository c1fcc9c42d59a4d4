//! The glossy split: a path's first glossy vertex that may see a lamp takes several BSDF
//! samples for the lamps it sees directly.

use glam::Vec3;

use super::mis::power_heuristic;
use super::scene::{Crossing, PathScene};
use super::shadow::pane_transmittance;
use super::state::MAX_PASS_THROUGH;
use crate::geometry::SurfaceHit;
use crate::lights::Lights;
use crate::material::Bsdf;
use crate::math::{offset_origin, Ray};
use crate::sampler::PixelSampler;

/// BSDF samples a path's first glossy vertex that may see a lamp takes for the lamps it sees
/// directly (the path goes on with a sample of its own, which finds the environment). A lamp
/// in a narrow lobe is a bright patch that one sample finds or misses: a metal figure's
/// highlights, and the speckles they make on a floor that sees the figure. Why 8:
/// bench/RESULTS.md, "Glossy split".
pub const GLOSSY_SPLIT: usize = 8;

/// Whether a path that may still split splits at the vertex at `hit` (reached from `wo`, its
/// BSDF `bsdf`): its first glossy vertex that may see a lamp splits; elsewhere more samples
/// would find the dimmer surroundings and cost what they save. Whether it splits depends on
/// the path so far only, not on this vertex's own samples, so either way its estimate is
/// unbiased.
#[inline(always)]
pub(super) fn splits_at(lights: &Lights, hit: &SurfaceHit, wo: Vec3, bsdf: &Bsdf) -> bool {
    bsdf.glossy_cone(wo)
        .is_some_and(|cone| lights.lamp_may_be_in(hit.p, &cone))
}

/// What a split vertex's BSDF samples see of the lights.
pub(super) struct SplitLight {
    pub(super) radiance: Vec3,
    pub(super) rays: u32,
}

/// The lamps a split vertex ([`GLOSSY_SPLIT`]) sees directly along its BSDF samples: each
/// weighed against the light sample by the power heuristic with the samples' count, and
/// divided by it. The samples are one split draw, stratified together; the path goes on with
/// the vertex's own `lobe` and `bsdf` numbers and does not count a lamp it finds next
/// ([`PrevScatter::lamps_counted`]). Environment maps are left to that path, weighed against
/// the light sample as one BSDF sample ([`BsdfCounts`]): a sample that cannot reach a lamp's
/// bounding sphere is then not traced at all (taking the environment too costs rays for no
/// less error). The path does not go on with one of the split's samples: sample `j` of every
/// camera sample's split draw lies in the same `1 / GLOSSY_SPLIT` of its first number, so a
/// pixel's paths would all go on through one strip of the lobe. Null surfaces are crossed as the path crosses them (a scene splits only when no
/// material lets rays through at some hits only, see [`PathScene::glossy_split`]). A lamp
/// behind a flat mirror is the path's to find, one sample as without the split, which is what
/// the vertex's lamp-image sample weighs against. Out of line: most vertices do not split.
#[inline(never)]
pub(super) fn split_bsdf_light<S: PathScene>(
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
        let mut scale = bs.f * (bs.wi.dot(hit.ns).abs() / (bs.pdf * count));
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
            match scene.crossing(next.shape) {
                Crossing::Blocks => break,
                Crossing::Null => {}
                Crossing::Pane => scale *= pane_transmittance(scene, &next, bs.wi),
            }
            ray = Ray::new(offset_origin(next.p, next.ng, bs.wi), bs.wi);
        }
    }
    seen
}
