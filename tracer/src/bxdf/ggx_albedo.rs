//! The directional albedo E(mu, alpha) of a white, single-scattering GGX reflector, tabulated
//! once per process. Its complement is the energy that masking and shadowing remove; the
//! glossy coat's multibounce term (Kulla and Conty 2017) gives it back.

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

use super::microfacet::TrowbridgeReitz;
use crate::sampler::PixelSampler;

const MU_STEPS: usize = 32;
const ALPHA_STEPS: usize = 32;
const SAMPLES: u32 = 512;

struct Table {
    /// E at (alpha index, mu index), row-major by alpha.
    albedo: Vec<f32>,
    /// Cosine-weighted hemispherical average 2 * integral E(mu) mu dmu, per alpha.
    average: Vec<f32>,
}

fn grid(i: usize, steps: usize) -> f32 {
    i as f32 / (steps - 1) as f32
}

/// The albedo for wo at cosine `mu`: with visible-normal sampling and F = 1 each sample's
/// weight f cos / pdf is G2 / G1(wo).
fn estimate(alpha: f32, mu: f32) -> f32 {
    let Some(distrib) = TrowbridgeReitz::from_roughness(alpha, alpha) else {
        return 1.0;
    };
    let mu = mu.max(1e-3);
    let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let g1 = distrib.g1(wo);
    let mut sum = 0.0f64;
    for i in 0..SAMPLES {
        let u: Vec2 = PixelSampler::new(0, 0, i, SAMPLES, 0).get_2d();
        let wm = distrib.sample_wm(wo, u);
        let wi = -wo + wm * (2.0 * wo.dot(wm));
        if wi.z > 0.0 {
            sum += f64::from(distrib.g(wo, wi) / g1);
        }
    }
    (sum / f64::from(SAMPLES)) as f32
}

fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut albedo = Vec::with_capacity(ALPHA_STEPS * MU_STEPS);
        let mut average = Vec::with_capacity(ALPHA_STEPS);
        for a in 0..ALPHA_STEPS {
            let alpha = grid(a, ALPHA_STEPS);
            let row: Vec<f32> = (0..MU_STEPS)
                .map(|m| estimate(alpha, grid(m, MU_STEPS)))
                .collect();
            // Trapezoidal 2 * integral of E(mu) mu over [0, 1].
            let h = 1.0 / (MU_STEPS - 1) as f32;
            let avg = (1..MU_STEPS)
                .map(|m| {
                    let (m0, m1) = (grid(m - 1, MU_STEPS), grid(m, MU_STEPS));
                    h * (row[m - 1] * m0 + row[m] * m1)
                })
                .sum::<f32>();
            average.push(avg.min(1.0));
            albedo.extend(row);
        }
        Table { albedo, average }
    })
}

/// Builds the table now rather than at the first lookup (which would stall a render thread
/// and the threads waiting on it).
pub fn prepare() {
    table();
}

fn lerp_index(x: f32, steps: usize) -> (usize, usize, f32) {
    let f = x.clamp(0.0, 1.0) * (steps - 1) as f32;
    let i0 = (f as usize).min(steps - 2);
    (i0, i0 + 1, f - i0 as f32)
}

/// E(mu) for roughness `alpha` (bilinear in the table).
pub fn albedo(alpha: f32, mu: f32) -> f32 {
    let t = table();
    let (a0, a1, fa) = lerp_index(alpha, ALPHA_STEPS);
    let (m0, m1, fm) = lerp_index(mu.abs(), MU_STEPS);
    let at = |a: usize, m: usize| t.albedo[a * MU_STEPS + m];
    let e0 = at(a0, m0) + (at(a0, m1) - at(a0, m0)) * fm;
    let e1 = at(a1, m0) + (at(a1, m1) - at(a1, m0)) * fm;
    (e0 + (e1 - e0) * fa).clamp(0.0, 1.0)
}

/// The cosine-weighted average of E over the hemisphere for roughness `alpha`.
pub fn average_albedo(alpha: f32) -> f32 {
    let t = table();
    let (a0, a1, fa) = lerp_index(alpha, ALPHA_STEPS);
    t.average[a0] + (t.average[a1] - t.average[a0]) * fa
}

#[cfg(test)]
mod tests {
    use std::f32::consts::PI;

    use super::*;

    /// The albedo by uniform integration of D G / (4 cos_o cos_i) cos_i over the hemisphere,
    /// independent of visible-normal sampling.
    fn uniform_estimate(alpha: f32, mu: f32) -> f32 {
        let distrib = TrowbridgeReitz::from_roughness(alpha, alpha).unwrap();
        let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
        let n = 1 << 18;
        let sum: f64 = (0..n)
            .map(|i| {
                let u = PixelSampler::new(4, 4, i, n, 1).get_2d();
                let z = u.x;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                let wi = Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z);
                let wm = (wo + wi).normalize();
                f64::from(distrib.d(wm) * distrib.g(wo, wi) / (4.0 * mu))
            })
            .sum();
        (sum * 2.0 * std::f64::consts::PI / f64::from(n)) as f32
    }

    #[test]
    fn table_matches_uniform_integration() {
        for (alpha, mu) in [
            (0.3f32, 0.8f32),
            (0.5, 1.0),
            (0.7, 0.4),
            (1.0, 0.2),
            (1.0, 0.9),
        ] {
            let (table, reference) = (albedo(alpha, mu), uniform_estimate(alpha, mu));
            assert!(
                (table - reference).abs() < 0.02,
                "alpha {alpha} mu {mu}: {table} vs {reference}"
            );
        }
        assert!(albedo(1e-3, 0.7) > 0.99 && average_albedo(0.0) > 0.98);
        // Rougher loses more.
        assert!(
            average_albedo(1.0) < average_albedo(0.5) && average_albedo(0.5) < average_albedo(0.2)
        );
    }
}
