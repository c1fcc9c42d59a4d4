//! Thin-film interference on a specular reflection (LuxRender 1.x's `film` and `filmindex` on
//! mirror, glass and shinymetal's mirror lobe): a layer `thickness` nm thick of index `index`
//! over the surface weighs each wavelength of the reflection by cos^2(2 pi / lambda x 2 d s),
//! s = sqrt(index^2 - sin^2 theta), theta the angle of incidence (LuxRender's phase
//! difference, whose extra pi does not change the square). LuxRender weighs its sampled
//! wavelengths so; here the weight is reduced to RGB once per optical thickness x = d s, in a
//! table over [`MAX_OPTICAL_NM`] with linear interpolation between its 2 nm steps, built the
//! first time a scene has a film. A fringe's spectrum can be more saturated than sRGB holds,
//! and its RGB then has a channel above 1 or below 0: the weight is clamped to [0, 1], so that
//! a film never reflects more than the surface under it (in RGB a weight above 1 would grow
//! light at every bounce, where LuxRender's wavelengths keep each reflection below 1).

use std::sync::OnceLock;

use glam::Vec3;

use crate::spectra::spectrum_rgb_weights;

/// The thickest optical layer (nm) the table holds. Beyond it the fringes are narrower than
/// the colour matching functions resolve and the weight is their mean, one half.
pub const MAX_OPTICAL_NM: f32 = 8192.0;
/// The table's step in optical thickness, nm: some 95 steps across the shortest fringe.
const STEP_NM: f32 = 2.0;

/// A film on a reflection: thickness in nm and index of refraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinFilm {
    pub thickness: f32,
    pub index: f32,
}

impl ThinFilm {
    /// The film a material's `film` and `filmindex` describe; None without one (a thickness
    /// of 0 or less, or not a number).
    pub fn new(thickness: f32, index: f32) -> Option<Self> {
        (thickness > 0.0 && index.is_finite()).then_some(Self { thickness, index })
    }

    /// The RGB weight of a reflection at `cos` to the normal.
    pub fn weight(&self, cos: f32) -> Vec3 {
        let sin2 = (1.0 - cos * cos).max(0.0);
        let optical = self.thickness * (self.index * self.index - sin2).max(0.0).sqrt();
        // Not below the table's end (NaN included): the fringes' mean.
        if optical.is_nan() || optical >= MAX_OPTICAL_NM {
            return Vec3::splat(0.5);
        }
        let table = table();
        let at = optical / STEP_NM;
        let i = (at as usize).min(table.len() - 2);
        let t = at - i as f32;
        (table[i] * (1.0 - t) + table[i + 1] * t).clamp(Vec3::ZERO, Vec3::ONE)
    }
}

/// RGB of cos^2(4 pi x / lambda) at x = 0, 2, 4, ... nm up to [`MAX_OPTICAL_NM`] inclusive.
fn table() -> &'static [Vec3] {
    static TABLE: OnceLock<Box<[Vec3]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        // 1 nm: the fringes at the table's far end are 9 nm apart at 380 nm.
        let weights = spectrum_rgb_weights(1.0);
        let steps = (MAX_OPTICAL_NM / STEP_NM) as usize;
        (0..=steps)
            .map(|i| {
                let x = f64::from(i as u32) * f64::from(STEP_NM);
                weights
                    .iter()
                    .map(|&(lambda, w)| {
                        let c = libm::cos(4.0 * std::f64::consts::PI * x / lambda);
                        w * (c * c) as f32
                    })
                    .sum()
            })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectra::spectrum_rgb;

    /// The weight is the film's spectrum reduced to RGB as every reflectance spectrum is
    /// (5 nm steps there, the table's 1 nm and interpolation here), clamped to [0, 1]: within 0.005 at normal
    /// and oblique incidence; a thick film averages to one half; no thickness, no film.
    #[test]
    fn the_weight_is_the_interference_spectrum_in_rgb() {
        for (thickness, index) in [
            (150.0f32, 1.33f32),
            (300.0, 1.5),
            (611.0, 2.0),
            (2500.0, 1.4),
        ] {
            let film = ThinFilm::new(thickness, index).unwrap();
            for cos in [1.0f32, 0.7, 0.2] {
                let s = f64::from(index * index - (1.0 - cos * cos)).sqrt();
                let x = f64::from(thickness) * s;
                let want = spectrum_rgb(|lambda| {
                    libm::cos(4.0 * std::f64::consts::PI * x / lambda).powi(2)
                })
                .clamp(Vec3::ZERO, Vec3::ONE);
                let got = film.weight(cos);
                assert!(
                    (got - want).abs().max_element() < 0.005,
                    "film {thickness} nm, index {index}, cos {cos}: {got} vs {want}"
                );
            }
        }
        // 300 nm at index 1.5 seen head-on: 450 nm of optical path, bright at 450 and 600 nm,
        // dark at 514: magenta.
        let magenta = ThinFilm::new(300.0, 1.5).unwrap().weight(1.0);
        assert!(magenta.y < 0.5 * magenta.x.min(magenta.z), "{magenta}");
        let thick = ThinFilm::new(1e5, 1.5).unwrap().weight(0.5);
        assert_eq!(thick, Vec3::splat(0.5));
        assert!(ThinFilm::new(0.0, 1.5).is_none());
        assert!(ThinFilm::new(f32::NAN, 1.5).is_none());
    }
}
