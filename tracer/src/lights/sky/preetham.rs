//! Preetham, Shirley and Smits' daylight model (1999), as LuxRender 1.x's `sky` computes it:
//! the Perez distribution for the luminance Y and the chromaticities x and y, each scaled to
//! its zenith value, with the five Perez coefficients multiplied by the scene's constants.
//!
//! | parameter                        | default | multiplies the Perez coefficient       |
//! |----------------------------------|---------|----------------------------------------|
//! | `aconst` (or `horizonbrightness`) | 1       | A: darkening or brightening at the horizon |
//! | `bconst` (or `horizonsize`)       | 1       | B: the gradient's width near the horizon |
//! | `cconst` (or `sunhalobrightness`) | 1       | C: the circumsolar region's intensity |
//! | `dconst` (or `sunhalosize`)       | 1       | D: its width                           |
//! | `econst` (or `backscattering`)    | 1       | E: light scattered back                |
//!
//! Units are LuxRender's: the zenith luminance in cd/m^2 (the model's kcd/m^2 x 1000). xyY is
//! converted to linear sRGB; LuxRender rebuilds a daylight spectrum of that chromaticity from
//! the CIE daylight basis, whose colour is the same xy. Below the horizon the sky shows its
//! horizon (LuxRender clamps the zenith angle just short of 90 degrees).

use std::f32::consts::{FRAC_PI_2, PI};

use glam::{DVec3, Vec3};

use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::spectra::xyz_to_linear_srgb;

/// Each Perez multiplier's default.
pub const DEFAULT_CONST: f32 = 1.0;

/// The zenith angle below which the horizon is used (LuxRender's pi/2 - 0.001).
const HORIZON_THETA: f32 = FRAC_PI_2 - 0.001;

/// The five Perez multipliers, under their two LuxRender names each (the letter wins).
const CONSTS: [(&str, &str); 5] = [
    ("aconst", "horizonbrightness"),
    ("bconst", "horizonsize"),
    ("cconst", "sunhalobrightness"),
    ("dconst", "sunhalosize"),
    ("econst", "backscattering"),
];

/// Reads the Perez multipliers.
pub fn read_consts(params: &ParamList) -> Result<[f32; 5], ParseError> {
    let mut out = [DEFAULT_CONST; 5];
    for (value, (letter, word)) in out.iter_mut().zip(CONSTS) {
        let by_word = params.float(word, DEFAULT_CONST)?;
        *value = params.float(letter, by_word)?;
    }
    Ok(out)
}

/// The model for one sun position and turbidity.
pub struct Preetham {
    /// Unit light-space direction towards the sun.
    sun: Vec3,
    /// Perez coefficients A..E for Y, x, y.
    perez: [[f32; 5]; 3],
    /// Zenith values of Y, x, y divided by the Perez function at the zenith.
    zenith: [f32; 3],
}

impl Preetham {
    /// `sun`: unit light-space direction towards the sun.
    pub fn new(sun: Vec3, turbidity: f32, consts: [f32; 5]) -> Self {
        let theta_s = libm::acosf(sun.z.clamp(-1.0, 1.0));
        let t = turbidity;
        let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
        let zenith_y = ((4.0453 * t - 4.9710) * libm::tanf(chi) - 0.2155 * t + 2.4192) * 1000.0;
        let (th, th2, th3, t2) = (theta_s, theta_s * theta_s, theta_s.powi(3), t * t);
        let zenith_x = (0.00166 * th3 - 0.00375 * th2 + 0.00209 * th) * t2
            + (-0.02903 * th3 + 0.06377 * th2 - 0.03202 * th + 0.00394) * t
            + (0.11693 * th3 - 0.21196 * th2 + 0.06052 * th + 0.25886);
        let zenith_yc = (0.00275 * th3 - 0.00610 * th2 + 0.00317 * th) * t2
            + (-0.04214 * th3 + 0.08970 * th2 - 0.04153 * th + 0.00516) * t
            + (0.15346 * th3 - 0.26756 * th2 + 0.06670 * th + 0.26688);
        // Linear in the turbidity, per quantity and coefficient: (slope, intercept).
        const FITS: [[(f32, f32); 5]; 3] = [
            [
                (0.1787, -1.4630),
                (-0.3554, 0.4275),
                (-0.0227, 5.3251),
                (0.1206, -2.5771),
                (-0.0670, 0.3703),
            ],
            [
                (-0.0193, -0.2592),
                (-0.0665, 0.0008),
                (-0.0004, 0.2125),
                (-0.0641, -0.8989),
                (-0.0033, 0.0452),
            ],
            [
                (-0.0167, -0.2608),
                (-0.0950, 0.0092),
                (-0.0079, 0.2102),
                (-0.0441, -1.6537),
                (-0.0109, 0.0529),
            ],
        ];
        let perez = FITS.map(|fit| {
            let mut c = [0.0; 5];
            for (i, (slope, intercept)) in fit.into_iter().enumerate() {
                c[i] = (slope * t + intercept) * consts[i];
            }
            c
        });
        let zenith = [zenith_y, zenith_x, zenith_yc];
        let zenith = std::array::from_fn(|i| zenith[i] / perez_f(&perez[i], 0.0, theta_s));
        Self { sun, perez, zenith }
    }

    /// Radiance (linear sRGB, cd/m^2 scale) from unit light-space direction `dir`.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let theta = libm::acosf(dir.z.clamp(-1.0, 1.0)).min(HORIZON_THETA);
        let gamma = libm::acosf(dir.dot(self.sun).clamp(-1.0, 1.0));
        let [lum, x, y] =
            std::array::from_fn(|i| self.zenith[i] * perez_f(&self.perez[i], theta, gamma));
        if y <= 0.0 || !y.is_finite() || !lum.is_finite() {
            return Vec3::ZERO;
        }
        let (x, y, lum) = (f64::from(x), f64::from(y), f64::from(lum));
        xyz_to_linear_srgb(DVec3::new(x / y * lum, lum, (1.0 - x - y) / y * lum)).max(Vec3::ZERO)
    }
}

/// The Perez sky distribution for coefficients A..E at zenith angle `theta` and angle `gamma`
/// from the sun.
fn perez_f(c: &[f32; 5], theta: f32, gamma: f32) -> f32 {
    let cos_gamma = libm::cosf(gamma);
    (1.0 + c[0] * libm::expf(c[1] / libm::cosf(theta)))
        * (1.0 + c[2] * libm::expf(c[3] * gamma) + c[4] * cos_gamma * cos_gamma)
}
