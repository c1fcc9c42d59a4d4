//! One wavelength for a path that meets a dispersive interface (`glass` with `cauchyb`), as
//! LuxRender's spectral paths collapse to a single wavelength there. YAT carries RGB, so the
//! path draws the wavelength at its first dispersive vertex from the table below, and from then
//! on carries that wavelength's RGB weight: each wavelength's linear sRGB weight (the weights of
//! each channel sum to 1 over the visible range, [`spectrum_rgb_weights`]) over the probability
//! of drawing it. On average the weight is white, so a dispersive white surface reflects and
//! transmits white light; the spread of its indices over the wavelengths casts the spectra.
//! A leaf module: the integrators draw, the dielectric BxDF takes the wavelength's index.

use std::sync::LazyLock;

use glam::Vec3;

use crate::spectra::spectrum_rgb_weights;

/// The table's spacing in nm: a wavelength is drawn uniformly within its 1 nm bin, so a
/// prism's spectrum is continuous, not banded.
const STEP_NM: f64 = 1.0;

/// A path's wavelength: where it is, in nm, and the RGB weight the path carries from the vertex
/// that drew it on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wavelength {
    pub nm: f32,
    pub weight: Vec3,
}

struct Table {
    /// Each bin's centre (nm) and RGB weight over its probability.
    bins: Vec<(f32, Vec3)>,
    /// The cumulative probabilities of the bins (the last is 1).
    cdf: Vec<f32>,
}

/// Bins are drawn in proportion to the magnitude of their weights (|r| + |g| + |b|: the sRGB
/// weights of the spectrum's ends are negative in some channel), so no channel's weight
/// exceeds 1 over the least probable bin's share, and bins with no weight are never drawn.
static TABLE: LazyLock<Table> = LazyLock::new(|| {
    let weights = spectrum_rgb_weights(STEP_NM);
    let magnitude = |w: Vec3| f64::from(w.abs().element_sum());
    let total: f64 = weights.iter().map(|&(_, w)| magnitude(w)).sum();
    let mut running = 0.0;
    let mut cdf = Vec::with_capacity(weights.len());
    let mut bins = Vec::with_capacity(weights.len());
    for &(nm, w) in &weights {
        let p = magnitude(w) / total;
        running += p;
        cdf.push(running as f32);
        let weight = if p > 0.0 {
            (w.as_dvec3() / p).as_vec3()
        } else {
            Vec3::ZERO
        };
        bins.push((nm as f32, weight));
    }
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    Table { bins, cdf }
});

impl Wavelength {
    /// The wavelength of the number `u` in [0, 1): stratified numbers give stratified
    /// wavelengths (the bins in the cumulative order, each bin's share spread over its width).
    pub fn draw(u: f32) -> Self {
        let table = &*TABLE;
        let i = table
            .cdf
            .partition_point(|&c| c <= u)
            .min(table.cdf.len() - 1);
        let below = if i == 0 { 0.0 } else { table.cdf[i - 1] };
        let share = table.cdf[i] - below;
        let within = if share > 0.0 {
            ((u - below) / share).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let (centre, weight) = table.bins[i];
        Self {
            nm: centre + (within - 0.5) * STEP_NM as f32,
            weight,
        }
    }
}

/// The index of refraction at `nm` of a Cauchy glass `index + b / nm^2` with `b` in nm^2
/// (LuxRender's `cauchyb`, given in um^2, times 10^6; [`CAUCHY_B_PER_UM2`]).
pub fn cauchy_index(index: f32, b_nm2: f32, nm: f32) -> f32 {
    index + b_nm2 / (nm * nm)
}

/// `cauchyb` in um^2 to the nm^2 of [`cauchy_index`].
pub const CAUCHY_B_PER_UM2: f32 = 1e6;

#[cfg(test)]
mod tests {
    use super::*;

    /// Stratified numbers' mean weight: white, whatever the channel.
    #[test]
    fn weights_average_to_white() {
        let n = 1 << 16;
        let sum: glam::DVec3 = (0..n)
            .map(|i| {
                let u = (i as f32 + 0.5) / n as f32;
                Wavelength::draw(u).weight.as_dvec3()
            })
            .sum();
        let mean = sum / f64::from(n);
        for c in mean.to_array() {
            assert!((c - 1.0).abs() < 2e-3, "mean weight {mean:?}");
        }
    }

    #[test]
    fn draws_span_the_spectrum_in_order() {
        let first = Wavelength::draw(0.0).nm;
        let last = Wavelength::draw(0.999_999).nm;
        assert!(first < 400.0 && last > 680.0, "{first} .. {last}");
        let mut prev = first;
        for i in 1..1000 {
            let nm = Wavelength::draw(i as f32 / 1000.0).nm;
            assert!(nm >= prev, "{nm} after {prev}");
            prev = nm;
        }
        // Blue light draws blue weight, red light red.
        let blue = Wavelength::draw(0.1).weight;
        let red = Wavelength::draw(0.9).weight;
        assert!(blue.z > blue.x && red.x > red.z, "{blue} {red}");
    }

    #[test]
    fn cauchy_index_is_larger_for_blue() {
        let b = 0.00420 * CAUCHY_B_PER_UM2;
        let blue = cauchy_index(1.5, b, 450.0);
        let red = cauchy_index(1.5, b, 650.0);
        assert!((blue - 1.520_74).abs() < 1e-4 && (red - 1.509_94).abs() < 1e-4);
    }
}
