//! How many continuations a scene's camera paths send on from their first broad vertex
//! ([`MAX_BRANCHES`]), measured on a pilot when the scene is built.
//!
//! A pixel's error is the error of what comes before that vertex (the pixel and lens
//! position, the first hit, its light sample) plus the error of what its continuations bring,
//! which more continuations divide; a camera sample's cost is likewise `c_first` plus `c_next`
//! per continuation. With `k` continuations the error is `v_first + v_next / k` for the cost
//! `c_first + k c_next`, and the efficiency, 1 / (error x cost), is best at
//! `k = sqrt((v_next / c_next) / (v_first / c_first))` (the splitting factor of Rath et al.
//! 2022, "EARS", for the first vertex of the whole image).
//!
//! The pilot renders a set of pixels as the render would, with one continuation and with two,
//! each twice with samples of its own (two keys; a key's two renders share everything before
//! the vertex). Half the squared difference of a pixel's two renders estimates the error of its
//! mean, so the errors of one and of two continuations are measured, not modelled from the
//! continuations' own: a render's two continuations are one split draw, stratified together,
//! and do better than two independent ones (modelled as independent, they would be judged too
//! dear where they pay: bench/RESULTS.md, "Branching camera paths"). For three and four, the
//! model through the two measured errors.
//!
//! Each count is taken over one fewer only where it beats it by `MIN_GAIN` with standard
//! errors to spare (`CONFIDENCE` for two, `MODEL_CONFIDENCE` for more): a test on the mean over
//! pixels of the difference of the two (error x cost), paired, so that a pixel's own luck (a
//! rare bright first hit, Cornell's lamp seen through its glass, which both counts' renders of
//! a key share) weighs on both sides. Rays count for the cost.
//!
//! The pilot's camera samples are a twenty-fifth of the render's (`PILOT_SHARE`; at most
//! `MAX_PILOT_PIXELS` pixels), half that where half its pixels already rule two continuations
//! out: a render too short to spare a pilot of `MIN_PILOT_PIXELS` keeps one continuation; a
//! 480x270 render of 16 spp is just long enough (what the pilot gains there: bench/RESULTS.md,
//! "Branching camera paths").
//!
//! Only the scene and the render settings decide it: every node that builds the scene takes
//! the same number, and the image is the same bytes wherever it is rendered.

use glam::DVec3;
use rayon::prelude::*;

use super::settings::RenderSettings;
use crate::integrator::{trace_branching_path, PathScene, MAX_BRANCHES};
use crate::math::Ray;
use crate::sampler::{mix64, PixelSampler};

/// Samples per pilot pixel in each of its renders: the render's, within these bounds (the
/// error's make-up changes with the samples: the camera's and the first vertex's few
/// dimensions are stratified better as they grow than a whole continuation is).
const MIN_PILOT_SPP: u32 = 4;
const MAX_PILOT_SPP: u32 = 16;

/// The most pixels the pilot renders (and no more than the image has: a pixel rendered twice
/// counts as two that agree). Some 1.3 M camera samples: a second on two cores for
/// Captain Falcon, to choose within a few percent for a render of hours.
const MAX_PILOT_PIXELS: u64 = 16384;

/// Fewer pixels than this choose badly (Cornell's caustics): one continuation.
const MIN_PILOT_PIXELS: u64 = 1024;

/// The share of the render's camera samples the pilot's four renders may take together, as a
/// divisor (a sample with two continuations costs about one and a half of one with one: the
/// pilot's four renders cost some 6% of the render, half that where it stops half way).
const PILOT_SHARE: u64 = 25;

/// How much cheaper a ray before the branching vertex is than one after it, in rays per
/// sample: the camera ray is coherent and the first light sample's shadow ray an any-hit ray,
/// where a continuation's rays are closest hits shaded in full. Fitted to the render times of
/// one and two continuations against their rays per sample on the seed scenes
/// (bench/RESULTS.md, "Branching camera paths").
const FIRST_RAYS_DISCOUNT: f64 = 0.4;

/// Splitting must promise at least this efficiency over one continuation: a scene near the
/// break-even point gains nothing either way.
const MIN_GAIN: f64 = 1.05;

/// Standard errors by which two continuations must beat one (by `MIN_GAIN`) to be taken: half
/// of one, as a wrong choice costs little and the pilot's figures scatter between seeds
/// (bench/RESULTS.md, "Branching camera paths").
const CONFIDENCE: f64 = 0.5;

/// Standard errors by which more than two continuations must beat one fewer (by `MIN_GAIN`),
/// by the model: three or four where two barely pay cost more (bench/RESULTS.md, "Branching
/// camera paths").
const MODEL_CONFIDENCE: f64 = 1.0;

/// Standard errors by which two continuations may fall short of one (by `MIN_GAIN`) on half
/// the pilot's pixels before it stops there with one.
const STOP_CONFIDENCE: f64 = 1.0;

/// The pilot's samples are their own (the render's seed, keyed apart): one key for each of the
/// two renders of a count.
const PILOT_KEYS: [u64; 2] = [0x7069_6c6f_745f_6b31, 0x7069_6c6f_745f_6b32];

/// The pilot's measures, with one continuation and with two: the error of a pixel's mean at
/// the pilot's samples (summed over the colour channels), and rays per camera sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BranchFigures {
    pub error: [f64; 2],
    pub rays: [f64; 2],
    /// Standard errors by which `k` continuations beat `k - 1` by `MIN_GAIN`, from `k` = 2 on
    /// (negative where they fall short): the mean over pixels of (error x cost) with `k - 1`
    /// less `MIN_GAIN` times that with `k`, over its standard error.
    pub pays_by: [f64; MAX_BRANCHES - 1],
}

/// The error of `k` continuations from `error`, that of one and of two (a pixel's, or the mean
/// over pixels): as measured for one and two; for more, `v_first + v_next / k` through those
/// two.
fn error_of(k: usize, error: [f64; 2]) -> f64 {
    match k {
        1 => error[0],
        k => {
            let v_next = 2.0 * (error[0] - error[1]);
            error[0] - v_next + v_next / k as f64
        }
    }
}

impl BranchFigures {
    /// The cost of a camera sample with `k` continuations, `c_first + k c_next`, in rays (those
    /// before the vertex less `FIRST_RAYS_DISCOUNT`).
    pub fn cost(&self, k: usize) -> f64 {
        let c_next = self.rays[1] - self.rays[0];
        (self.rays[0] - FIRST_RAYS_DISCOUNT + (k as f64 - 1.0) * c_next).max(0.0)
    }

    /// The continuations to take: one more while it beats one fewer by `MIN_GAIN`, with
    /// `CONFIDENCE` standard errors to spare for two and `MODEL_CONFIDENCE` for more.
    pub fn best(&self) -> usize {
        (2..=MAX_BRANCHES)
            .take_while(|&k| {
                let confidence = if k == 2 { CONFIDENCE } else { MODEL_CONFIDENCE };
                self.pays_by[k - 2] >= confidence
            })
            .last()
            .unwrap_or(1)
    }
}

/// What the pilot renders: a scene's paths, with its render's settings and camera.
pub trait PilotScene: PathScene + Sync {
    fn settings(&self) -> &RenderSettings;
    /// The camera ray of the pixel sample `sampler` draws, at pixel (`x`, `y`).
    fn camera_ray(&self, x: u32, y: u32, sampler: &mut PixelSampler) -> Option<Ray>;
}

/// A pilot pixel's four renders: by key, with one continuation and with two.
type PilotPixel = [[PixelMean; 2]; 2];

/// Measures the scene on its pilot; None when the render is too short to spare one.
pub fn measure(scene: &impl PilotScene) -> Option<BranchFigures> {
    let settings = scene.settings();
    let image = u64::from(settings.width) * u64::from(settings.height);
    let samples = image * u64::from(settings.spp);
    let spp = settings.spp.clamp(MIN_PILOT_SPP, MAX_PILOT_SPP);
    let pixels = (samples / (PILOT_SHARE * 4 * u64::from(spp)))
        .min(MAX_PILOT_PIXELS)
        .min(image);
    if pixels < MIN_PILOT_PIXELS {
        return None;
    }
    let keys = PILOT_KEYS.map(|key| mix64(mix64(settings.seed) ^ key));
    let render = |half: u64| -> Vec<PilotPixel> {
        (0..(pixels - half).div_ceil(2))
            .into_par_iter()
            .map(|j| {
                let (x, y) = pilot_pixel(2 * j + half, pixels, settings.width, settings.height);
                keys.map(|key| [1, 2].map(|branches| pixel_mean(scene, x, y, spp, key, branches)))
            })
            .collect()
    };
    // Half the pixels first (every other one: all over the image); where two continuations
    // fall short of one even so, the rest would not change that.
    let mut renders = render(0);
    let half = figures(&renders, spp);
    if half.pays_by[0] < -STOP_CONFIDENCE {
        return Some(half);
    }
    renders.extend(render(1));
    Some(figures(&renders, spp))
}

/// The figures of the pilot's `renders` of `spp` samples.
fn figures(renders: &[PilotPixel], spp: u32) -> BranchFigures {
    let n = renders.len() as f64;
    let rays = [0, 1].map(|count| {
        renders
            .iter()
            .map(|[one, other]| one[count].rays + other[count].rays)
            .sum::<u64>() as f64
            / (2.0 * n * f64::from(spp))
    });
    // Per pixel, the error of its mean with one continuation and with two: half the squared
    // difference of its two keys' renders.
    let errors: Vec<[f64; 2]> = renders
        .iter()
        .map(|[one, other]| {
            [0, 1].map(|count| (one[count].radiance - other[count].radiance).length_squared() / 2.0)
        })
        .collect();
    let mean = |count: usize| errors.iter().map(|e| e[count]).sum::<f64>() / n;
    let mut figures = BranchFigures {
        error: [mean(0), mean(1)],
        rays,
        pays_by: [0.0; MAX_BRANCHES - 1],
    };
    // Per pixel, (error x cost) with k - 1 less MIN_GAIN times that with k: paired, so that a
    // pixel's own luck weighs on both sides.
    for k in 2..=MAX_BRANCHES {
        let (fewer, more) = (figures.cost(k - 1), MIN_GAIN * figures.cost(k));
        let pays: Vec<f64> = errors
            .iter()
            .map(|&e| error_of(k - 1, e) * fewer - error_of(k, e) * more)
            .collect();
        let pay = pays.iter().sum::<f64>() / n;
        let spread = pays.iter().map(|p| (p - pay).powi(2)).sum::<f64>() / (n - 1.0);
        figures.pays_by[k - 2] = pay / (spread / n).sqrt();
    }
    figures
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

/// A pilot pixel's render: the mean of its samples' radiance and the rays they took.
struct PixelMean {
    radiance: DVec3,
    rays: u64,
}

/// `spp` samples of pixel (`x`, `y`) with `branches` continuations and `seed`.
fn pixel_mean(
    scene: &impl PilotScene,
    x: u32,
    y: u32,
    spp: u32,
    seed: u64,
    branches: usize,
) -> PixelMean {
    let mut mean = PixelMean {
        radiance: DVec3::ZERO,
        rays: 0,
    };
    for index in 0..spp {
        let mut sampler = PixelSampler::new(x, y, index, spp, seed);
        if let Some(ray) = scene.camera_ray(x, y, &mut sampler) {
            let path = trace_branching_path(scene, ray, &mut sampler, branches);
            mean.rays += u64::from(path.rays);
            if path.radiance.is_finite() {
                mean.radiance += path.radiance.as_dvec3();
            }
        }
    }
    mean.radiance /= f64::from(spp);
    mean
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_model_goes_through_one_and_two() {
        // v_first 1, v_next 8.
        let error = [9.0, 5.0];
        for k in 1..=MAX_BRANCHES {
            let model = 1.0 + 8.0 / k as f64;
            assert!((error_of(k, error) - model).abs() < 1e-12, "{k}");
        }
    }

    #[test]
    fn each_more_continuation_must_pay_with_confidence() {
        let f = |pays_by| BranchFigures {
            error: [9.0, 5.0],
            rays: [3.0, 4.0],
            pays_by,
        };
        assert_eq!(f([CONFIDENCE, MODEL_CONFIDENCE, 0.0]).best(), 3);
        assert_eq!(f([CONFIDENCE, 0.99 * MODEL_CONFIDENCE, 10.0]).best(), 2);
        assert_eq!(f([0.99 * CONFIDENCE, 10.0, 10.0]).best(), 1);
        assert_eq!(f([f64::NAN, 10.0, 10.0]).best(), 1);
        assert_eq!(f([10.0; 3]).best(), MAX_BRANCHES);
    }

    /// Pilot renders of `n` pixels whose two keys differ by `d1` with one continuation and `d2`
    /// with two, from pixel to pixel a little more or less, and take `rays` per sample.
    fn renders(n: usize, d1: f64, d2: f64, rays: [u64; 2]) -> Vec<PilotPixel> {
        (0..n)
            .map(|i| {
                let scale = 1.0 + 0.1 * ((i % 5) as f64 - 2.0);
                let mean = |d: f64, count: usize| PixelMean {
                    radiance: DVec3::splat(d * scale),
                    rays: rays[count],
                };
                [[mean(0.0, 0), mean(0.0, 1)], [mean(d1, 0), mean(d2, 1)]]
            })
            .collect()
    }

    #[test]
    fn the_figures_say_where_two_continuations_pay() {
        // 2 samples a pixel: 4.5 rays a sample with one continuation, 6.5 with two (costs 3.9
        // and 5.9).
        let rays = [9, 13];
        // Two halve the error for 1.5 times the cost.
        let pays = figures(&renders(100, 2.0, 2f64.sqrt(), rays), 2);
        assert!(
            (pays.error[1] / pays.error[0] - 0.5).abs() < 1e-9,
            "{pays:?}"
        );
        assert!(pays.pays_by[0] > 10.0, "{pays:?}");
        // Two bring the same error at more cost.
        let not = figures(&renders(100, 2.0, 2.0, rays), 2);
        assert!(not.pays_by[0] < -10.0, "{not:?}");
        assert_eq!((pays.best() > 1, not.best()), (true, 1));
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
