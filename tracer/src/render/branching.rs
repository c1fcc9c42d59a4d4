//! How many continuations a scene's camera paths send on from their first broad vertex
//! ([`MAX_BRANCHES`]), measured on a pilot when the scene is built.
//!
//! A pixel's error is the error of what comes before that vertex (the pixel and lens
//! position, the first hit, its light sample), `v_first`, plus the error of what its
//! continuations bring, `v_next` with one continuation; a camera sample's cost is likewise
//! `c_first` plus `c_next`. With `k` continuations the error is `v_first + v_next / k` and the
//! cost `c_first + k c_next`, so the efficiency, 1 / (error x cost), is best at
//! `k = sqrt((v_next / c_next) / (v_first / c_first))` (the splitting factor of Rath et al.
//! 2022, "EARS", for the first vertex of the whole image).
//!
//! The pilot renders a set of pixels twice with independent samples, each time with two
//! continuations drawn independently of each other, each a whole path's continuation
//! ([`BranchDraw::Independent`](crate::integrator::path::BranchDraw::Independent)): per pixel,
//! four renders with one continuation, (a, b) and (a', b'), where a and b share everything
//! before the vertex. Their differences give the two parts with stratification included (the
//! continuations' variance measured per path, without it, came out up to ten times too large on
//! Captain Falcon, whose first bounce the samples stratify well): `v_next` is half the expected
//! (a - b)^2, `v_first` what a and b share, the expected (a - a') (b - b') / 2, a product of
//! independent differences (a continuation's rare bright sample, a caustic of Cornell's glass,
//! weighs in linearly, where the difference of two squared errors, the earlier pilot's, took it
//! squared). Each part is believed `CONFIDENCE` standard errors off its estimate, on the side
//! that favours one continuation: what Cornell's own rare bright pixels need (the lamp seen
//! through the glass, which a and b share; a pilot that misses them sees no `v_first`). Rays
//! count for the cost: those of the continuations, and the rest. The model leaves out that a
//! render's continuations are stratified together (Captain Falcon gains 1.14x with two, which
//! it does not see) and that each carries a `k`th of the throughput into the roulette (fewer
//! rays, more noise): its choices err towards one continuation.
//!
//! The pilot's camera samples are a fiftieth of the render's (`PILOT_SHARE`; at most
//! `MAX_PILOT_PIXELS` pixels), some 3% of its time, and half that where half its pixels
//! already rule more continuations out: a render too short to spare a pilot of
//! `MIN_PILOT_PIXELS` keeps one continuation; a 480x270 render of 16 spp is just long enough.
//! Measured there (one thread, 4 seeds, MSE x time against one continuation, the pilot's time
//! included): depth of field 1.23x (2 or 3 continuations, 1.25x and 1.30x alone); Cornell 0.95x
//! (1, and 2 in one seed), Mario 0.99x, Captain Falcon 0.99x (1, the pilot stopping half way).
//! In 8 seeds the pilot gave Cornell 1 continuation 7 times and 2 once (1.02x alone); in 6,
//! Mario and Falcon 1.
//!
//! Only the scene and the render settings decide it: every node that builds the scene takes
//! the same number, and the image is the same bytes wherever it is rendered.

use glam::DVec3;
use rayon::prelude::*;

use super::settings::RenderSettings;
use crate::integrator::path::{trace_pilot_path, PathScene, MAX_BRANCHES};
use crate::math::Ray;
use crate::sampler::{mix64, PixelSampler};

/// Samples per pilot pixel in each of its two renders: the render's, within these bounds
/// (the error's make-up changes with the samples: the camera's and the first vertex's few
/// dimensions are stratified better as they grow than a whole continuation is).
const MIN_PILOT_SPP: u32 = 4;
const MAX_PILOT_SPP: u32 = 16;

/// The most pixels the pilot renders.
const MAX_PILOT_PIXELS: u64 = 2304;

/// Fewer pixels than this choose badly (Cornell's caustics): one continuation.
const MIN_PILOT_PIXELS: u64 = 1024;

/// The share of the render's camera samples the pilot may take, as a divisor (each of its
/// samples costs some one and a half of the render's: it traces two continuations).
const PILOT_SHARE: u64 = 50;

/// How much cheaper a ray before the branching vertex is than one after it, in rays per
/// sample: the camera ray is coherent and the first light sample's shadow ray an any-hit ray,
/// where a continuation's rays are closest hits shaded in full. Fitted to the render times of
/// one and two continuations (16 spp, 480x270, one thread): depth of field 0.5, Mario 0.5,
/// Captain Falcon 0.7, Cornell 1.0.
const FIRST_RAYS_DISCOUNT: f64 = 0.6;

/// Splitting must promise at least this efficiency over one continuation: a scene near the
/// break-even point gains nothing either way.
const MIN_GAIN: f64 = 1.05;

/// Standard errors each part of the error is taken off its estimate, towards one continuation,
/// for the choice: at one, Cornell took 3 or 4 continuations in 3 of 16 seeds (0.94x, 0.85x),
/// at two in none of 12, and depth of field still 2 to 4.
const CONFIDENCE: f64 = 2.0;

/// Standard errors each part is taken off its estimate, away from one continuation, for the
/// early stop: the pilot ends on half its pixels where even so one continuation is best.
const STOP_CONFIDENCE: f64 = 1.0;

/// The pilot's samples are their own (the render's seed, keyed apart): one key for each of its
/// two renders.
const PILOT_KEYS: [u64; 2] = [0x7069_6c6f_745f_6b31, 0x7069_6c6f_745f_6b32];

/// The pilot's estimates: errors of a pixel's mean at the pilot's samples (summed over the
/// colour channels), costs in rays per camera sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BranchFigures {
    pub v_first: f64,
    pub v_next: f64,
    pub c_first: f64,
    pub c_next: f64,
}

impl BranchFigures {
    /// Relative efficiency of `k` continuations (1 / (error x cost), any unit).
    pub fn efficiency(&self, k: usize) -> f64 {
        let k = k as f64;
        1.0 / ((self.v_first + self.v_next / k) * (self.c_first + k * self.c_next))
    }

    /// The continuations with the best efficiency: 1 unless more beat it by `MIN_GAIN`.
    pub fn best(&self) -> usize {
        let one = self.efficiency(1);
        if !(one.is_finite() && one > 0.0) {
            return 1;
        }
        let (k, eff) = (2..=MAX_BRANCHES)
            .map(|k| (k, self.efficiency(k)))
            .fold((1, one), |best, kv| if kv.1 > best.1 { kv } else { best });
        if eff >= one * MIN_GAIN {
            k
        } else {
            1
        }
    }
}

/// What the pilot renders: a scene's paths, with its render's settings and camera.
pub trait PilotScene: PathScene + Sync {
    fn settings(&self) -> &RenderSettings;
    /// The camera ray of the pixel sample `sampler` draws, at pixel (`x`, `y`).
    fn camera_ray(&self, x: u32, y: u32, sampler: &mut PixelSampler) -> Option<Ray>;
}

/// Measures the scene on its pilot; None when the render is too short to spare one.
pub fn measure(scene: &impl PilotScene) -> Option<BranchFigures> {
    let settings = scene.settings();
    let samples = u64::from(settings.width) * u64::from(settings.height) * u64::from(settings.spp);
    let spp = settings.spp.clamp(MIN_PILOT_SPP, MAX_PILOT_SPP);
    let pixels = (samples / (PILOT_SHARE * 2 * u64::from(spp))).min(MAX_PILOT_PIXELS);
    if pixels < MIN_PILOT_PIXELS {
        return None;
    }
    let keys = PILOT_KEYS.map(|key| mix64(mix64(settings.seed) ^ key));
    let render = |half: u64| -> Vec<[PixelMean; 2]> {
        (0..(pixels - half).div_ceil(2))
            .into_par_iter()
            .map(|j| {
                let (x, y) = pilot_pixel(2 * j + half, pixels, settings.width, settings.height);
                keys.map(|key| pixel_mean(scene, x, y, spp, key))
            })
            .collect()
    };
    // Half the pixels first (every other one: all over the image); where even figures believed
    // on the side that favours more continuations keep one, the rest would not change that
    // (Mario and Captain Falcon stop there).
    let mut renders = render(0);
    if figures(&renders, spp, -STOP_CONFIDENCE).best() == 1 {
        return Some(figures(&renders, spp, CONFIDENCE));
    }
    renders.extend(render(1));
    Some(figures(&renders, spp, CONFIDENCE))
}

/// The figures of the pilot's `renders` of `spp` samples, each part of the error believed
/// `standard_errors` off its estimate: positive towards one continuation, negative away from it.
fn figures(renders: &[[PixelMean; 2]], spp: u32, standard_errors: f64) -> BranchFigures {
    let n = renders.len() as f64;
    // Per pixel, from the continuations' renders (a, b) and (a', b'): the continuations' error,
    // half the expected (a - b)^2, and the rest, the covariance of a and b (what they share),
    // the expected (a - a') (b - b') / 2 (a product of independent differences, so that a
    // continuation's rare bright sample weighs in linearly, not squared).
    let parts: Vec<[f64; 2]> = renders
        .iter()
        .map(|[one, other]| {
            let (a, b) = one.continuations();
            let (a2, b2) = other.continuations();
            let next = ((a - b).length_squared() + (a2 - b2).length_squared()) / 4.0;
            let first = ((a - a2).dot(b - b2) + (a - b2).dot(b - a2)) / 4.0;
            [next, first]
        })
        .collect();
    // `towards_one`: +1 where a larger part favours one continuation (v_first), -1 where a
    // smaller one does (v_next).
    let believed = |part: usize, towards_one: f64| {
        let mean = parts.iter().map(|e| e[part]).sum::<f64>() / n;
        let spread = parts.iter().map(|e| (e[part] - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean + towards_one * standard_errors * (spread / n).sqrt()).max(0.0)
    };
    // Rays per camera sample, before the branching vertex and in each continuation.
    let per_sample = 2.0 * n * f64::from(spp);
    let rays = renders.iter().flatten().map(|p| p.rays).sum::<u64>() as f64 / per_sample;
    let c_next =
        renders.iter().flatten().map(|p| p.branch_rays).sum::<u64>() as f64 / per_sample / 2.0;
    BranchFigures {
        v_first: believed(1, 1.0),
        v_next: believed(0, -1.0),
        c_first: (rays - 2.0 * c_next - FIRST_RAYS_DISCOUNT).max(0.0),
        c_next,
    }
}

/// The continuations the scene's camera paths take.
pub fn choose(scene: &impl PilotScene) -> usize {
    let figures = measure(scene);
    let branches = figures.map_or(1, |f| f.best());
    tracing::debug!(?figures, branches, "first-vertex continuations");
    branches
}

/// Pilot pixel `i` of `count`: rows evenly down the image, columns by the golden ratio (a
/// rank-1 lattice, spread evenly over any image shape).
fn pilot_pixel(i: u64, count: u64, width: u32, height: u32) -> (u32, u32) {
    const GOLDEN: f64 = 0.618_033_988_749_895;
    let column = ((i as f64 * GOLDEN).fract() * f64::from(width)) as u32;
    let row = ((2 * i + 1) * u64::from(height) / (2 * count)) as u32;
    (column.min(width - 1), row.min(height - 1))
}

/// A pilot pixel's render with two continuations: the means of its samples' radiance and of
/// their [`crate::integrator::PathResult::branch_difference`]s, and the rays they took, all and
/// in the continuations.
struct PixelMean {
    radiance: DVec3,
    difference: DVec3,
    rays: u64,
    branch_rays: u64,
}

impl PixelMean {
    /// The pixel as each continuation alone renders it.
    fn continuations(&self) -> (DVec3, DVec3) {
        let half = self.difference / 2.0;
        (self.radiance + half, self.radiance - half)
    }
}

/// `spp` samples of pixel (`x`, `y`) with two continuations drawn independently
/// ([`BranchDraw::Independent`](crate::integrator::path::BranchDraw::Independent)) and `seed`.
fn pixel_mean(scene: &impl PilotScene, x: u32, y: u32, spp: u32, seed: u64) -> PixelMean {
    let mut mean = PixelMean {
        radiance: DVec3::ZERO,
        difference: DVec3::ZERO,
        rays: 0,
        branch_rays: 0,
    };
    for index in 0..spp {
        let mut sampler = PixelSampler::new(x, y, index, spp, seed);
        if let Some(ray) = scene.camera_ray(x, y, &mut sampler) {
            let path = trace_pilot_path(scene, ray, &mut sampler);
            mean.rays += u64::from(path.rays);
            mean.branch_rays += u64::from(path.branch_rays);
            if path.radiance.is_finite() && path.branch_difference.is_finite() {
                mean.radiance += path.radiance.as_dvec3();
                mean.difference += path.branch_difference.as_dvec3();
            }
        }
    }
    mean.radiance /= f64::from(spp);
    mean.difference /= f64::from(spp);
    mean
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figures(v_first: f64, v_next: f64, c_first: f64, c_next: f64) -> BranchFigures {
        BranchFigures {
            v_first,
            v_next,
            c_first,
            c_next,
        }
    }

    #[test]
    fn the_best_count_follows_the_splitting_factor() {
        // sqrt((v_next / c_next) / (v_first / c_first)): here sqrt(9) = 3.
        assert_eq!(figures(1.0, 9.0, 1.0, 1.0).best(), 3);
        // sqrt(4 x 2) = 2.8: three (error 2.33, cost 5) beats two (3, 4) and four (2, 6).
        assert_eq!(figures(1.0, 4.0, 2.0, 1.0).best(), 3);
        // More than four is never taken.
        assert_eq!(figures(1.0, 100.0, 1.0, 1.0).best(), MAX_BRANCHES);
        // The first part's error dominates: one.
        assert_eq!(figures(4.0, 1.0, 1.0, 1.0).best(), 1);
    }

    #[test]
    fn a_small_gain_keeps_one_continuation() {
        // Two continuations: error 2 for cost 3.125, against 3 for cost 2.125: 1.02x.
        let f = figures(1.0, 2.0, 1.125, 1.0);
        assert!(f.efficiency(2) > f.efficiency(1));
        assert!(f.efficiency(2) < MIN_GAIN * f.efficiency(1));
        assert_eq!(f.best(), 1);
    }

    #[test]
    fn degenerate_figures_keep_one_continuation() {
        assert_eq!(figures(0.0, 0.0, 1.0, 1.0).best(), 1);
        assert_eq!(figures(f64::NAN, 1.0, 1.0, 1.0).best(), 1);
        assert_eq!(figures(1.0, 1.0, 0.0, 0.0).best(), 1);
    }

    #[test]
    fn pilot_pixels_lie_in_the_image_and_spread_over_it() {
        let (width, height, count) = (7, 5, 2304);
        let mut seen = [false; 35];
        for i in 0..count {
            let (x, y) = pilot_pixel(i, count, width, height);
            assert!(x < width && y < height, "{x} {y}");
            seen[(y * width + x) as usize] = true;
        }
        assert!(
            seen.iter().all(|&s| s),
            "every pixel of a small image is visited"
        );
    }
}
