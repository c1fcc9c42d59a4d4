//! Checks of the cloth presets' measured constants (LuxRender's specular normalisation and the
//! bound of the highlight's directional albedo that caps glints), and of the cloth lobe's
//! energy, sampling and reciprocity at many points of every weave (the suite in `tests.rs`
//! looks at one point).

use glam::{Vec2, Vec3};

use super::cloth::{Preset, DEFAULT_REPEAT, PRESETS};
use crate::bxdf::cloth::{Cloth as ClothLobe, ALBEDO_STEPS};
use crate::bxdf::local::sample_cosine_hemisphere;
use crate::bxdf::Lobe;
use crate::sampler::PixelSampler;

fn repeat() -> Vec2 {
    Vec2::splat(DEFAULT_REPEAT)
}

/// 1 / the mean of the highlight (with glints) over cosine-distributed direction pairs and
/// uniform points: what LuxRender computes when it creates the material.
fn measured_normalization(preset: &'static Preset, n: u32) -> f64 {
    let mut sum = 0.0f64;
    for i in 0..n {
        let mut s = PixelSampler::new(0, 0, i, n, 3);
        let wi = sample_cosine_hemisphere(s.get_2d());
        let wo = sample_cosine_hemisphere(s.get_2d());
        let h = preset.highlight(s.get_2d(), repeat());
        sum += f64::from(h.integrand(wo, wi) * h.glint);
    }
    f64::from(n) / sum
}

/// The direction at cos(theta) = `cos`, azimuth `phi`.
fn direction(cos: f32, phi: f32) -> Vec3 {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    Vec3::new(sin * libm::cosf(phi), sin * libm::sinf(phi), cos)
}

/// The largest directional albedo of the normalised highlight (no glint) over `points` points
/// of the weave and 8 azimuths, at each step of cos(theta_o), by `n` cosine samples each.
fn measured_albedo(preset: &'static Preset, points: u32, n: u32) -> [f64; ALBEDO_STEPS] {
    let mut max = [0.0f64; ALBEDO_STEPS];
    for k in 0..points {
        let h = preset.highlight(PixelSampler::new(1, 0, k, points, 5).get_2d(), repeat());
        for (step, m) in max.iter_mut().enumerate() {
            // The last step is grazing; a direction exactly in the plane reflects nothing.
            let cos = (1.0 - step as f32 / (ALBEDO_STEPS - 1) as f32).max(0.002);
            for j in 0..8 {
                let wo = direction(cos, j as f32 * std::f32::consts::FRAC_PI_4 + 0.1);
                let sum: f64 = (0..n)
                    .map(|i| {
                        let u = PixelSampler::new(2, k, i, n, 7).get_2d();
                        f64::from(h.integrand(wo, sample_cosine_hemisphere(u)))
                    })
                    .sum();
                *m = m.max(sum / f64::from(n) * f64::from(preset.normalization));
            }
        }
    }
    max
}

#[test]
fn preset_normalisations_and_albedo_bounds_match_their_measurement() {
    let mut failures = Vec::new();
    for p in &PRESETS {
        let norm = measured_normalization(p, 1 << 18);
        let albedo = measured_albedo(p, 128, 512);
        println!(
            "{:>24}: normalization {norm:.1} (constant {}), normalised albedo max by cos theta_o \
             1..0: {:.2?} (bound {:?})",
            p.name, p.normalization, albedo, p.albedo_bound
        );
        if (f64::from(p.normalization) / norm - 1.0).abs() >= 0.03 {
            failures.push(format!("{}: normalization off", p.name));
        }
        if p.albedo_bound
            .iter()
            .zip(albedo)
            .any(|(b, m)| f64::from(*b) < m)
        {
            failures.push(format!("{}: an albedo bound below its measurement", p.name));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// Directional albedo by `n` samples of the lobe's own sampling (mean of f cos / pdf).
fn sampled_albedo(lobe: &ClothLobe, wo: Vec3, seed: u64, n: u32) -> Vec3 {
    let sum: Vec3 = (0..n)
        .filter_map(|i| lobe.sample(wo, 0.0, PixelSampler::new(3, 0, i, n, seed).get_2d()))
        .map(|s| s.f * s.wi.z / s.pdf)
        .sum();
    sum / n as f32
}

/// The same by uniform directions over the hemisphere and `f` alone.
fn uniform_albedo(lobe: &ClothLobe, wo: Vec3, seed: u64, n: u32) -> Vec3 {
    let sum: Vec3 = (0..n)
        .map(|i| {
            let u = PixelSampler::new(4, 0, i, n, seed).get_2d();
            let wi = direction(u.x, u.y * std::f32::consts::TAU);
            lobe.f(wo, wi) * wi.z
        })
        .sum();
    sum * (std::f32::consts::TAU / n as f32)
}

/// Outgoing directions from the normal to grazing.
fn outgoing() -> Vec<Vec3> {
    [1.0f32, 0.87, 0.5, 0.17, 0.03]
        .iter()
        .enumerate()
        .map(|(j, &c)| direction(c, 0.7 + j as f32))
        .collect()
}

#[test]
fn no_point_of_any_weave_reflects_more_than_it_receives() {
    let mut largest = 0.0f32;
    for (pi, p) in PRESETS.iter().enumerate() {
        for k in 0..24u32 {
            let uv = PixelSampler::new(5, pi as u32, k, 24, 9).get_2d();
            let h = p.highlight(uv, repeat());
            for (kd, ks) in [(0.0, 1.0), (0.3, 1.0), (0.6, 0.2)] {
                let lobe = ClothLobe::new(Vec3::splat(kd), Vec3::new(ks, ks * 0.5, ks), h);
                for wo in outgoing() {
                    let a = sampled_albedo(&lobe, wo, u64::from(k), 1 << 12).max_element();
                    largest = largest.max(a);
                    assert!(
                        a <= 1.01,
                        "{} at uv {uv} (glint {}), kd {kd} ks {ks}, wo {wo}: albedo {a}",
                        p.name,
                        h.glint
                    );
                }
            }
        }
    }
    println!("largest cloth albedo {largest:.3}");
    // The cap binds: some points reach what energy allows.
    assert!(largest > 0.9, "largest albedo {largest}");
}

#[test]
fn cloth_sampling_agrees_with_its_evaluation() {
    let mut worst = 0.0f32;
    for (pi, p) in PRESETS.iter().enumerate() {
        for k in 0..4u32 {
            let uv = PixelSampler::new(6, pi as u32, k, 4, 9).get_2d();
            let lobe = ClothLobe::new(Vec3::splat(0.2), Vec3::ONE, p.highlight(uv, repeat()));
            for wo in outgoing().into_iter().take(4) {
                let by_sampling = sampled_albedo(&lobe, wo, 1, 1 << 15);
                let by_uniform = uniform_albedo(&lobe, wo, 2, 1 << 17);
                let err = (by_sampling - by_uniform).abs().max_element();
                worst = worst.max(err);
                assert!(
                    err < 0.01 + 0.03 * by_uniform.max_element(),
                    "{} at uv {uv}, wo {wo}: sampled {by_sampling} vs uniform {by_uniform}",
                    p.name
                );
            }
        }
    }
    println!("largest cloth sampled-vs-uniform albedo difference {worst:.4}");
}

#[test]
fn cloth_is_reciprocal() {
    for p in &PRESETS {
        let lobe = ClothLobe::new(
            Vec3::splat(0.1),
            Vec3::ONE,
            p.highlight(Vec2::new(0.3, 0.6), repeat()),
        );
        let mut checked = 0;
        for i in 0..4096 {
            let mut s = PixelSampler::new(7, 0, i, 4096, 5);
            let a = sample_cosine_hemisphere(s.get_2d());
            let b = sample_cosine_hemisphere(s.get_2d());
            let (fab, fba) = (lobe.f(a, b), lobe.f(b, a));
            assert!(
                (fab - fba).abs().max_element() <= 1e-4 * fab.max_element(),
                "{}: f({a}, {b}) = {fab}, f({b}, {a}) = {fba}",
                p.name
            );
            if fab.x > 0.1 / std::f32::consts::PI + 1e-4 {
                checked += 1;
            }
        }
        // The highlight (beyond the diffuse 0.1 / pi) shows in a good part of the pairs.
        assert!(
            checked > 100,
            "{}: {checked} pairs with a highlight",
            p.name
        );
    }
}
