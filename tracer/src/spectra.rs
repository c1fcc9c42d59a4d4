//! Spectral data reduced to RGB: LuxRender's built-in metal presets (complex index of
//! refraction per channel), blackbody colours, and the conversion of an emitted spectrum to
//! linear sRGB in LuxRender's absolute units (the sun light). A leaf module: the texture,
//! material and light readers use it; `crate::parse` re-exports the first two functions.

use glam::{DMat3, DVec3, Vec3};

use crate::math::luminance;

/// Complex index of refraction (eta, k) of LuxRender's named metals, sampled at 650, 550 and
/// 450 nm for the R, G and B channels. Aluminium: Rakic 1995; gold, silver, copper: Johnson
/// and Christy 1972; amorphous carbon: the Sopra a-C data LuxRender ships (approximate).
pub fn metal_preset(name: &str) -> Option<(Vec3, Vec3)> {
    let (eta, k) = match name {
        "aluminium" | "aluminum" => ([1.49, 0.96, 0.62], [7.82, 6.69, 5.47]),
        "gold" => ([0.17, 0.43, 1.38], [3.15, 2.46, 1.91]),
        "silver" => ([0.14, 0.12, 0.13], [4.15, 3.35, 2.60]),
        "copper" => ([0.21, 1.02, 1.24], [3.67, 2.58, 2.40]),
        "amorphous carbon" => ([1.97, 1.88, 1.78], [0.78, 0.78, 0.79]),
        _ => return None,
    };
    Some((Vec3::from_array(eta), Vec3::from_array(k)))
}

/// Linear sRGB colour of a blackbody at `kelvin`, scaled to luminance 1 (a blackbody texture
/// sets a hue; the light's gain sets the brightness).
pub fn blackbody_rgb(kelvin: f32) -> Vec3 {
    let t = f64::from(kelvin.max(100.0));
    let xyz = cie_xyz(|l| planck(l, t), VISIBLE_NM, 5.0);
    hue_rgb(xyz)
}

/// The hue of an emitted spectrum (nm -> relative radiance) as LuxRender's film sees it (1 nm
/// steps over its wavelengths): linear sRGB scaled to luminance 1, as [`blackbody_rgb`]. What
/// the lamp spectra of the `lampspectrum` texture reduce to.
pub fn emission_hue(spectrum: impl Fn(f64) -> f64) -> Vec3 {
    hue_rgb(cie_xyz(spectrum, FILM_NM, 1.0))
}

/// The linear sRGB hue of an emitted XYZ colour, negative channels clipped, scaled to
/// luminance 1 (white when it has none).
fn hue_rgb(xyz: DVec3) -> Vec3 {
    let rgb = xyz_to_linear_srgb(xyz).max(Vec3::ZERO);
    let yl = luminance(rgb);
    if yl > 0.0 {
        rgb / yl
    } else {
        Vec3::ONE
    }
}

/// LuxRender 1.x's film integrates spectra over this range of wavelengths, in nm.
const FILM_NM: (f64, f64) = (380.0, 720.0);

/// Luminous efficacy of radiation at 555 nm, lm/W: LuxRender's scale from W/(m^2 sr nm) to
/// the XYZ its film accumulates (so Y is in cd/m^2).
const LUMENS_PER_WATT: f64 = 683.0;

/// Linear sRGB of an emitted spectral radiance `spectrum(lambda_nm)` in W/(m^2 sr nm), in
/// LuxRender's units: XYZ = 683 x the integral of spectrum x CIE 1931 over the film's
/// wavelengths (1 nm steps), then the sRGB (D65) matrix. Y, and so the luminance of the
/// result, is in cd/m^2, the scale on which an RGB light colour of 1 has luminance 1.
pub fn emission_rgb(spectrum: impl Fn(f64) -> f64) -> Vec3 {
    let xyz = cie_xyz(spectrum, FILM_NM, 1.0);
    xyz_to_linear_srgb(xyz * LUMENS_PER_WATT)
}

/// CIE XYZ to linear sRGB (D65 white).
pub fn xyz_to_linear_srgb(xyz: DVec3) -> Vec3 {
    xyz_to_srgb(xyz).as_vec3()
}

/// Linear sRGB to CIE XYZ (D65 white), by columns: the inverse of [`xyz_to_linear_srgb`]'s
/// matrix.
pub const LINEAR_SRGB_TO_XYZ: DMat3 = DMat3::from_cols_array(&[
    0.4124, 0.2126, 0.0193, 0.3576, 0.7152, 0.1192, 0.1805, 0.0722, 0.9505,
]);

/// Linear sRGB to CIE XYZ (D65 white).
pub fn linear_srgb_to_xyz(rgb: DVec3) -> DVec3 {
    LINEAR_SRGB_TO_XYZ * rgb
}

/// CIE XYZ of a blackbody at `kelvin` over LuxRender 1.x's film wavelengths, scaled to Y = 1:
/// the white point a light group's colour temperature adapts to.
pub fn blackbody_xyz(kelvin: f32) -> DVec3 {
    let t = f64::from(kelvin.max(100.0));
    let xyz = cie_xyz(|l| planck(l, t), FILM_NM, 1.0);
    xyz / xyz.y
}

fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    let (x, y, z) = (xyz.x, xyz.y, xyz.z);
    DVec3::new(
        3.2406 * x - 1.5372 * y - 0.4986 * z,
        -0.9689 * x + 1.8758 * y + 0.0415 * z,
        0.0557 * x - 0.2040 * y + 1.0570 * z,
    )
}

/// The RGB of a reflectance (or any relative) spectrum `f` (nm -> value): its CIE XYZ under an
/// equal-energy light, in linear sRGB, divided channel by channel by that of the constant
/// spectrum 1, so that a flat spectrum of value v is exactly (v, v, v).
pub fn spectrum_rgb(f: impl Fn(f64) -> f64) -> Vec3 {
    let rgb = |f: &dyn Fn(f64) -> f64| xyz_to_srgb(cie_xyz(f, VISIBLE_NM, 5.0));
    (rgb(&f) / rgb(&|_| 1.0)).as_vec3()
}

/// The wavelengths a reflectance or a hue is integrated over, in nm.
const VISIBLE_NM: (f64, f64) = (380.0, 780.0);

/// [`spectrum_rgb`] as weights: each wavelength of the visible range at `step` nm with its
/// linear sRGB weight, so that a reflectance spectrum's RGB is the sum of weight x value (the
/// weights of each channel sum to 1). For spectra evaluated many times over, as a thin film's
/// interference is.
pub fn spectrum_rgb_weights(step: f64) -> Vec<(f64, Vec3)> {
    let count = ((VISIBLE_NM.1 - VISIBLE_NM.0) / step).round() as u32;
    let weights: Vec<(f64, DVec3)> = (0..=count)
        .map(|i| {
            let lambda = VISIBLE_NM.0 + f64::from(i) * step;
            let (x, y, z) = cie_1931(lambda);
            (lambda, xyz_to_srgb(DVec3::new(x, y, z)))
        })
        .collect();
    let total: DVec3 = weights.iter().map(|&(_, w)| w).sum();
    weights
        .into_iter()
        .map(|(lambda, w)| (lambda, (w / total).as_vec3()))
        .collect()
}

/// CIE 1931 XYZ of `spectrum` (nm -> value): the sum of spectrum x the colour matching
/// functions at `step` nm from `range.0` to `range.1` (both included). The one integration
/// loop every conversion here shares.
fn cie_xyz(spectrum: impl Fn(f64) -> f64, range: (f64, f64), step: f64) -> DVec3 {
    let count = ((range.1 - range.0) / step).round() as u32;
    (0..=count)
        .map(|i| {
            let lambda = range.0 + f64::from(i) * step;
            let (x, y, z) = cie_1931(lambda);
            spectrum(lambda) * DVec3::new(x, y, z)
        })
        .sum()
}

/// Planck's law, spectral radiance up to a constant factor (normalised away by the caller).
fn planck(lambda_nm: f64, t: f64) -> f64 {
    const C2: f64 = 1.438_776_9e-2; // hc/k in m K
    let l = lambda_nm * 1e-9;
    1.0 / (l.powi(5) * (libm::exp(C2 / (l * t)) - 1.0))
}

/// The CIE 1931 2-degree colour matching functions, multi-lobe Gaussian fit of Wyman, Sloan
/// and Shirley 2013 ("Simple Analytic Approximations to the CIE XYZ Color Matching Functions").
fn cie_1931(l: f64) -> (f64, f64, f64) {
    let g = |x: f64, mu: f64, s1: f64, s2: f64| {
        let t = (x - mu) / if x < mu { s1 } else { s2 };
        libm::exp(-0.5 * t * t)
    };
    let x = 1.056 * g(l, 599.8, 37.9, 31.0) + 0.362 * g(l, 442.0, 16.0, 26.7)
        - 0.065 * g(l, 501.1, 20.4, 26.2);
    let y = 0.821 * g(l, 568.8, 46.9, 40.5) + 0.286 * g(l, 530.9, 16.3, 31.1);
    let z = 1.217 * g(l, 437.0, 11.8, 36.0) + 0.681 * g(l, 459.0, 26.0, 13.8);
    (x, y, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Normal-incidence reflectance of a conductor.
    fn f0(eta: Vec3, k: Vec3) -> Vec3 {
        ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k)
    }

    #[test]
    fn metal_presets_have_the_expected_colours() {
        let (e, k) = metal_preset("gold").unwrap();
        let gold = f0(e, k);
        assert!(
            gold.x > 0.9 && gold.x > gold.y && gold.y > gold.z && gold.z < 0.5,
            "{gold}"
        );
        let (e, k) = metal_preset("aluminium").unwrap();
        let al = f0(e, k);
        assert!(al.min_element() > 0.85, "{al}");
        let (e, k) = metal_preset("copper").unwrap();
        let cu = f0(e, k);
        assert!(cu.x > 0.9 && cu.y < 0.7, "{cu}");
        let (e, k) = metal_preset("amorphous carbon").unwrap();
        assert!(f0(e, k).max_element() < 0.25);
        assert!(metal_preset("unobtainium").is_none());
    }

    #[test]
    fn blackbody_hue_follows_temperature() {
        let warm = blackbody_rgb(2700.0);
        let d65ish = blackbody_rgb(6504.0);
        let cool = blackbody_rgb(12000.0);
        for c in [warm, d65ish, cool] {
            assert!((luminance(c) - 1.0).abs() < 1e-4);
        }
        assert!(warm.x > warm.y && warm.y > warm.z, "{warm}");
        assert!(cool.z > cool.x, "{cool}");
        // Near 6500 K a blackbody is close to white in sRGB.
        assert!((d65ish.x / d65ish.z - 1.0).abs() < 0.2, "{d65ish}");
    }
}
