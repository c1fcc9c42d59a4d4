//! Russian roulette: where a path may end, with what probability, and the weight a survivor
//! carries. Written once over lanes: a path alone is one lane, a packet's Lambert vertices all
//! of theirs, to the same bits.

use glam::Vec3;

use super::options::{IntegratorDesc, RussianRoulette};
use crate::lanes::Lanes;

/// Bounces before Russian roulette may end a path under the `probability` strategy (as in
/// LuxRender).
pub(super) const RR_MIN_DEPTH: u32 = 3;

/// Under the `efficiency` strategy a path survives a broad scattering vertex (a diffuse, velvet
/// or cloth lobe, under a coat or not, as [`Bsdf::gathers_from`] tells; a volume's phase
/// function) with this multiple of its throughput's largest channel as probability, capped at
/// 1, from the first vertex on; a glossy or specular vertex never ends it. A path into the
/// black squares of a checkerboard, or off a dark wall, mostly ends there instead of bouncing
/// on for little light; three times the throughput keeps the bright paths; and the light a
/// glossy vertex sends on is concentrated (caustics seen from a diffuse floor), which a
/// roulette there turns into fireflies. Measured against other rules: bench/RESULTS.md,
/// "Russian roulette".
///
/// [`Bsdf::gathers_from`]: crate::material::Bsdf::gathers_from
pub(super) const RR_THROUGHPUT_SCALE: f32 = 3.0;

/// The least survival probability of the `efficiency` strategy: a path it keeps is weighed by
/// at most 20 times.
pub(super) const RR_MIN_SURVIVAL: f32 = 0.05;

/// Russian roulette after a bounce at the `depth`th vertex, which scattered broadly or not (see
/// [`RR_THROUGHPUT_SCALE`]): false ends the path; else the throughput is divided by the
/// survival probability.
#[inline(always)]
pub(super) fn survives(
    integrator: &IntegratorDesc,
    depth: u32,
    broad: bool,
    u_rr: f32,
    throughput: &mut Vec3,
) -> bool {
    let mut lane = throughput.to_array();
    let kept = survives_in_lanes::<f32>(integrator, depth, broad, u_rr, &mut lane);
    *throughput = Vec3::from_array(lane);
    kept
}

/// [`survives`] in lanes, at vertices that scattered broadly where `broad` is set: the lanes
/// the roulette keeps, and the throughput divided by their survival probability.
#[inline(always)]
pub(super) fn survives_in_lanes<L: Lanes>(
    integrator: &IntegratorDesc,
    depth: u32,
    broad: L::M,
    u_rr: L,
    throughput: &mut [L; 3],
) -> L::M {
    let (continue_prob, rouletted) = match integrator.rr_strategy {
        RussianRoulette::Probability if depth >= RR_MIN_DEPTH => {
            (L::splat(integrator.rr_continue_prob), L::mask(true))
        }
        // The largest channel, not luminance: a path along a saturated red wall has a small
        // luminance but a large red throughput, and dividing that by a small survival
        // probability is what makes coloured fireflies.
        RussianRoulette::Efficiency => {
            let t = *throughput;
            let largest = t[0].max(t[1].max(t[2])) * L::splat(RR_THROUGHPUT_SCALE);
            // f32::clamp's order of tests.
            let low = L::select(
                largest.lt(L::splat(RR_MIN_SURVIVAL)),
                L::splat(RR_MIN_SURVIVAL),
                largest,
            );
            (L::select(L::splat(1.0).lt(low), L::splat(1.0), low), broad)
        }
        _ => return L::mask(true),
    };
    // What `u_rr >= continue_prob` ends (NaN included).
    let kept = !continue_prob.le(u_rr) | !rouletted;
    let t = *throughput;
    *throughput = [
        L::select(rouletted, t[0] / continue_prob, t[0]),
        L::select(rouletted, t[1] / continue_prob, t[1]),
        L::select(rouletted, t[2] / continue_prob, t[2]),
    ];
    kept
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::integrator::options::{RussianRoulette, DEFAULT_RR_CONTINUE_PROB};

    fn integrator(strategy: RussianRoulette) -> IntegratorDesc {
        IntegratorDesc {
            rr_strategy: strategy,
            ..IntegratorDesc::path_defaults("path")
        }
    }

    /// Survival as `survives` decides it, and the throughput it leaves.
    fn roulette(
        strategy: RussianRoulette,
        depth: u32,
        broad: bool,
        u: f32,
        t: Vec3,
    ) -> Option<Vec3> {
        let mut t = t;
        survives(&integrator(strategy), depth, broad, u, &mut t).then_some(t)
    }

    #[test]
    fn efficiency_roulette_ends_dark_paths_at_broad_vertices_from_the_first() {
        let dark = Vec3::new(0.02, 0.01, 0.0);
        // Survival 3 x 0.02 = 0.06, at the first vertex already.
        assert_eq!(
            roulette(RussianRoulette::Efficiency, 1, true, 0.06, dark),
            None
        );
        let kept = roulette(RussianRoulette::Efficiency, 1, true, 0.059, dark).unwrap();
        assert!((kept - dark / 0.06).abs().max_element() < 1e-6, "{kept}");
        // Never below the floor: a black path survives 1 in 20, weighed by 20.
        let black = roulette(RussianRoulette::Efficiency, 1, true, 0.049, Vec3::ZERO);
        assert_eq!(black, Some(Vec3::ZERO));
        assert_eq!(
            roulette(RussianRoulette::Efficiency, 1, true, 0.05, Vec3::ZERO),
            None
        );
        // A third of the throughput or more always goes on, unchanged.
        let bright = Vec3::new(0.34, 0.1, 0.1);
        assert_eq!(
            roulette(RussianRoulette::Efficiency, 9, true, 0.999, bright),
            Some(bright)
        );
    }

    #[test]
    fn efficiency_roulette_never_ends_paths_at_glossy_or_specular_vertices() {
        for depth in [1, 3, 10] {
            let t = Vec3::splat(0.001);
            assert_eq!(
                roulette(RussianRoulette::Efficiency, depth, false, 0.999, t),
                Some(t)
            );
        }
    }

    #[test]
    fn probability_roulette_keeps_luxrenders_rule() {
        let t = Vec3::splat(0.5);
        let p = DEFAULT_RR_CONTINUE_PROB;
        for broad in [true, false] {
            // Not before the third vertex, whatever the vertex.
            assert_eq!(
                roulette(RussianRoulette::Probability, 2, broad, 0.999, t),
                Some(t)
            );
            assert_eq!(roulette(RussianRoulette::Probability, 3, broad, p, t), None);
            let kept = roulette(RussianRoulette::Probability, 3, broad, p - 0.01, t).unwrap();
            assert!((kept - t / p).abs().max_element() < 1e-6, "{kept}");
        }
        assert_eq!(
            roulette(RussianRoulette::None, 9, true, 0.999, Vec3::ZERO),
            Some(Vec3::ZERO)
        );
    }
}
