//! The sun: LuxRender 1.x's `sun`, a disc of the sun's angular size whose radiance is the
//! extraterrestrial solar spectrum attenuated by the atmosphere along the sun's elevation
//! (Preetham, Shirley and Smits 1999, after Iqbal's "An Introduction to Solar Radiation"),
//! reduced to RGB the way LuxRender's film does ([`emission_rgb`]).
//!
//! ```text
//! LightSource "sun" "vector sundir" [0 0 -1] "float turbidity" [2] "float relsize" [1]
//!     "float gain" [1]
//! ```
//!
//! | parameter   | default  | meaning                                                          |
//! |-------------|----------|------------------------------------------------------------------|
//! | `sundir`    | 0 0 -1   | towards the sun, in light space (z up); the current transform maps it to the world |
//! | `turbidity` | 2        | haze: aerosol attenuation grows with it                           |
//! | `relsize`   | 1        | the disc's radius relative to the real sun's; the radiance is divided by relsize^2 so the power stays |
//! | `gain`      | 1        | multiplies the radiance                                          |
//! | `nsamples`  | 1        | a sampling hint: read and ignored                                |
//!
//! Units are LuxRender's: W/(m^2 sr nm) integrated against the CIE functions times 683, so
//! the sun at the zenith has a luminance near 1.3e9 cd/m^2 (scenes use a small gain or a
//! camera-like tone map). The elevation is the world's: LuxRender takes the optical mass from
//! the transformed direction. Below the horizon, where the optical-mass formula has no
//! meaning, the sun emits nothing.
//!
//! Sampled uniformly inside its cone; an escaping ray inside the cone sees its radiance.

use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};

use crate::diag::SourcePos;
use crate::math::{luminance, Frame};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::spectra::emission_rgb;

use super::emission::{self, emits};
use super::error::LightError;
use super::kind::{LightKind, MapSource};
use super::sample::uniform_cone;

/// `sundir` (LuxRender 1.x's sun default points down: a sun with no direction is set).
pub const DEFAULT_SUNDIR: Vec3 = Vec3::new(0.0, 0.0, -1.0);
/// `turbidity`.
pub const DEFAULT_TURBIDITY: f32 = 2.0;
/// `relsize`.
pub const DEFAULT_RELSIZE: f32 = 1.0;

/// The sun's radius and mean distance, km: its angular radius is their ratio.
const SUN_RADIUS_KM: f64 = 695_500.0;
const SUN_DISTANCE_KM: f64 = 149_600_000.0;

#[derive(Clone, Debug, PartialEq)]
pub struct SunLight {
    /// Unit world direction towards the sun's centre.
    pub to_sun: Vec3,
    pub turbidity: f32,
    pub relsize: f32,
    pub gain: f32,
}

impl SunLight {
    pub(crate) fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let gain = params.float("gain", emission::DEFAULT_GAIN)?;
        let sundir = params.vec3("sundir", DEFAULT_SUNDIR)?;
        let turbidity = params.float("turbidity", DEFAULT_TURBIDITY)?;
        let relsize = params.float("relsize", DEFAULT_RELSIZE)?;
        params.ignore("nsamples");
        let Some(to_sun) = ctx.ctm().transform_vector3(sundir).try_normalize() else {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: "LightSource \"sun\": \"sundir\" must not be zero".into(),
            });
        };
        if !(relsize > 0.0 && relsize.is_finite()) {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!(
                    "LightSource \"sun\": \"relsize\" must be positive, got {relsize}"
                ),
            });
        }
        let sun = Self {
            to_sun,
            turbidity,
            relsize,
            gain,
        };
        if sun.radiance() == Vec3::ZERO && gain != 0.0 {
            ctx.note(
                pos,
                "LightSource \"sun\": the sun is below the horizon and gives no light".into(),
            );
        }
        Ok(sun)
    }

    /// The disc's radiance: gain / relsize^2 x the sun's at its elevation.
    pub fn radiance(&self) -> Vec3 {
        let theta = libm::acosf(self.to_sun.normalize_or_zero().z.clamp(-1.0, 1.0));
        sun_rgb(theta, self.turbidity) * (self.gain / (self.relsize * self.relsize))
    }

    /// sin^2 of the disc's angular radius, at most 1 (LuxRender's cap: a larger sun is the
    /// whole hemisphere).
    pub fn sin2_max(&self) -> f32 {
        let sin = f64::from(self.relsize) * SUN_RADIUS_KM / SUN_DISTANCE_KM;
        sin.min(1.0).powi(2) as f32
    }
}

impl LightKind for SunLight {
    type Sampler = SunDisc;

    fn name(&self) -> &'static str {
        "sun"
    }

    /// The light to sample, if it emits.
    fn light(&self, _maps: &MapSource) -> Result<Option<SunDisc>, LightError> {
        let to_sun = self.to_sun.normalize_or_zero();
        let sin2 = self.sin2_max();
        let radiance = self.radiance();
        Ok((emits(radiance) && to_sun != Vec3::ZERO && sin2 > 0.0).then(|| {
            // 1 - cos theta_max without the cancellation of 1 - sqrt(1 - sin^2) near 1.
            let one_minus_cos = sin2 / (1.0 + (1.0 - sin2).sqrt());
            SunDisc {
                frame: Frame::from_normal(to_sun),
                to_sun,
                radiance,
                sin2_max: sin2,
                one_minus_cos,
                pdf: 1.0 / (TAU * one_minus_cos),
            }
        }))
    }
}

/// A sun ready to sample: a cone of directions of constant radiance.
pub struct SunDisc {
    frame: Frame,
    to_sun: Vec3,
    radiance: Vec3,
    sin2_max: f32,
    one_minus_cos: f32,
    /// 1 / solid angle.
    pdf: f32,
}

impl SunDisc {
    /// Whether unit direction `dir` lies inside the disc: measured by the sine (the cross
    /// product), which keeps its precision for a cone this narrow where a cosine would not.
    fn contains(&self, dir: Vec3) -> bool {
        dir.dot(self.to_sun) > 0.0 && dir.cross(self.to_sun).length_squared() <= self.sin2_max
    }

    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        if self.contains(dir) {
            self.radiance
        } else {
            Vec3::ZERO
        }
    }

    pub fn pdf(&self, dir: Vec3) -> f32 {
        if self.contains(dir) {
            self.pdf
        } else {
            0.0
        }
    }

    pub fn radiance_and_pdf(&self, dir: Vec3) -> (Vec3, f32) {
        if self.contains(dir) {
            (self.radiance, self.pdf)
        } else {
            (Vec3::ZERO, 0.0)
        }
    }

    /// A direction uniform in the cone, its density and radiance.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, f32, Vec3)> {
        let dir = self
            .frame
            .to_world(uniform_cone(u, self.one_minus_cos))
            .normalize_or_zero();
        // Rounding can put a sample on the rim a hair outside what `contains` accepts; keep
        // the two consistent so MIS sees the same density from both sides.
        self.contains(dir).then_some((dir, self.pdf, self.radiance))
    }

    /// The flux through a disk of the scene's size: pi R^2 x irradiance.
    pub fn power(&self, scene_radius: f32) -> f32 {
        PI * scene_radius * scene_radius * luminance(self.radiance) / self.pdf
    }
}

/// The sun's radiance for unit gain and relsize at zenith angle `theta` (radians), or zero
/// below the horizon. The extraterrestrial spectrum is attenuated by Rayleigh scattering,
/// aerosols (Angstrom's formula with beta from the turbidity), ozone, mixed gases and water
/// vapour over the relative optical mass of Kasten's formula.
pub fn sun_rgb(theta: f32, turbidity: f32) -> Vec3 {
    let theta = f64::from(theta);
    // Relative optical mass; not meaningful below the horizon (negative or not a number).
    let m = 1.0 / (libm::cos(theta) + 0.00094 * libm::pow(1.6386 - theta, -1.253));
    if theta >= std::f64::consts::FRAC_PI_2 || !(m > 0.0 && m.is_finite()) {
        return Vec3::ZERO;
    }
    let beta = 0.046_083_658_220_50 * f64::from(turbidity) - 0.045_860_259_285_22;
    // Angstrom's wavelength exponent of the aerosols, ozone column (cm) and precipitable
    // water (cm): the standard atmosphere LuxRender assumes.
    const ALPHA: f64 = 1.3;
    const OZONE_CM: f64 = 0.35;
    const WATER_CM: f64 = 2.0;
    // The attenuated spectrum is tabulated every 5 nm from 350 nm, as LuxRender does, and
    // read between those samples linearly.
    let attenuated: Vec<f64> = (0..91)
        .map(|i| {
            let lambda = 350.0 + 5.0 * f64::from(i);
            let um = lambda / 1000.0;
            let rayleigh = libm::exp(-m * 0.008735 * libm::pow(um, -4.08));
            let aerosol = libm::exp(-m * beta * libm::pow(um, -ALPHA));
            let ozone = libm::exp(-m * lerp_table(&OZONE_K, lambda) * OZONE_CM);
            let kg = lerp_table(&GAS_K, lambda);
            let gas = libm::exp(-1.41 * kg * m / libm::pow(1.0 + 118.93 * kg * m, 0.45));
            let kwa = lerp_table(&WATER_K, lambda);
            let water = libm::exp(
                -0.2385 * kwa * WATER_CM * m / libm::pow(1.0 + 20.07 * kwa * WATER_CM * m, 0.45),
            );
            solar(lambda) * rayleigh * aerosol * ozone * gas * water
        })
        .collect();
    emission_rgb(|lambda| {
        let x = (lambda - 350.0) / 5.0;
        if !(0.0..=90.0).contains(&x) {
            return 0.0;
        }
        let i = (x as usize).min(89);
        let t = x - i as f64;
        attenuated[i] * (1.0 - t) + attenuated[i + 1] * t
    })
    .max(Vec3::ZERO)
}

/// Extraterrestrial solar spectral radiance, W/(m^2 sr nm), every 10 nm from 380 to 750 nm;
/// zero outside.
fn solar(lambda: f64) -> f64 {
    const SOLAR: [f64; 38] = [
        16559.0, 16233.7, 21127.5, 25888.2, 25829.1, 24232.3, 26760.5, 29658.3, 30545.4, 30057.5,
        30663.7, 28830.4, 28712.1, 27825.0, 27100.6, 27233.6, 26361.3, 25503.8, 25060.2, 25311.6,
        25355.9, 25134.2, 24631.5, 24173.2, 23685.3, 23212.1, 22827.7, 22339.8, 21970.2, 21526.7,
        21097.9, 20728.3, 20240.4, 19870.8, 19427.2, 19072.4, 18628.9, 18259.2,
    ];
    let x = (lambda - 380.0) / 10.0;
    if !(0.0..=37.0).contains(&x) {
        return 0.0;
    }
    let i = (x as usize).min(36);
    let t = x - i as f64;
    SOLAR[i] * (1.0 - t) + SOLAR[i + 1] * t
}

/// Linear interpolation in a table of (wavelength nm, value) pairs sorted by wavelength;
/// zero outside its range.
fn lerp_table(table: &[(f64, f64)], lambda: f64) -> f64 {
    let (Some(first), Some(last)) = (table.first(), table.last()) else {
        return 0.0;
    };
    if lambda < first.0 || lambda > last.0 {
        return 0.0;
    }
    let k = table.partition_point(|&(l, _)| l < lambda);
    if table[k].0 == lambda || k == 0 {
        return table[k].1;
    }
    let ((l0, v0), (l1, v1)) = (table[k - 1], table[k]);
    v0 + (v1 - v0) * (lambda - l0) / (l1 - l0)
}

/// Ozone absorption coefficient, 1/cm (Iqbal, p. 127).
#[rustfmt::skip]
const OZONE_K: [(f64, f64); 64] = [
    (300.0, 10.0), (305.0, 4.8), (310.0, 2.7), (315.0, 1.35), (320.0, 0.8), (325.0, 0.38),
    (330.0, 0.16), (335.0, 0.075), (340.0, 0.04), (345.0, 0.019), (350.0, 0.007), (355.0, 0.0),
    (445.0, 0.003), (450.0, 0.003), (455.0, 0.004), (460.0, 0.006), (465.0, 0.008),
    (470.0, 0.009), (475.0, 0.012), (480.0, 0.014), (485.0, 0.017), (490.0, 0.021),
    (495.0, 0.025), (500.0, 0.03), (505.0, 0.035), (510.0, 0.04), (515.0, 0.045),
    (520.0, 0.048), (525.0, 0.057), (530.0, 0.063), (535.0, 0.07), (540.0, 0.075),
    (545.0, 0.08), (550.0, 0.085), (555.0, 0.095), (560.0, 0.103), (565.0, 0.11),
    (570.0, 0.12), (575.0, 0.122), (580.0, 0.12), (585.0, 0.118), (590.0, 0.115),
    (595.0, 0.12), (600.0, 0.125), (605.0, 0.13), (610.0, 0.12), (620.0, 0.105),
    (630.0, 0.09), (640.0, 0.079), (650.0, 0.067), (660.0, 0.057), (670.0, 0.048),
    (680.0, 0.036), (690.0, 0.028), (700.0, 0.023), (710.0, 0.018), (720.0, 0.014),
    (730.0, 0.011), (740.0, 0.01), (750.0, 0.009), (760.0, 0.007), (770.0, 0.004),
    (780.0, 0.0), (790.0, 0.0),
];

/// Mixed-gas absorption coefficient (Iqbal, p. 130).
const GAS_K: [(f64, f64); 4] = [(759.0, 0.0), (760.0, 3.0), (770.0, 0.21), (771.0, 0.0)];

/// Water-vapour absorption coefficient (Iqbal, p. 130).
#[rustfmt::skip]
const WATER_K: [(f64, f64); 13] = [
    (689.0, 0.0), (690.0, 0.016), (700.0, 0.024), (710.0, 0.0125), (720.0, 1.0),
    (730.0, 0.87), (740.0, 0.061), (750.0, 0.001), (760.0, 0.00001), (770.0, 0.00001),
    (780.0, 0.0006), (790.0, 0.0175), (800.0, 0.036),
];
