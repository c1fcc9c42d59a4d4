//! The thin lens's aperture: LuxRender 1.x's perspective `blades`, `distribution` and `power`
//! (polygonal and weighted apertures), and the lens point they give a sample.
//!
//! Below three blades the aperture is the round disk (Shirley and Chiu's concentric mapping,
//! whatever the distribution: LuxRender ignores it there too). From three blades on it is a
//! regular polygon inscribed in the unit circle, its vertices at odd multiples of pi/blades
//! (an edge's middle on the lens's +x axis), sampled as LuxRender samples it: the angle
//! uniform, the radius the polygon's edge distance at that angle times `sqrt(s)`, `s` drawn
//! from the distribution (uniform: the area under a uniform angle; the others weigh the
//! aperture's centre or its rim). The lens point's density is never needed: the camera and
//! light-tracing strategies sample lens points alike, so it cancels ([`super::importance`]).

use std::f32::consts::PI;

use glam::Vec2;

use crate::bxdf::local::{concentric_disk, sample_disk_concentric};
use crate::lanes::{Lanes, MAX_LANES};
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_BLADES: i32 = 0;
pub const DEFAULT_DISTRIBUTION: &str = "uniform";
pub const DEFAULT_POWER: i32 = 3;
/// More blades than this draw a polygon no sample tells from the disk; a scene's larger count
/// is read as this (it keeps the sector arithmetic in range).
pub const MAX_BLADES: u32 = 1024;

/// How a weighted aperture draws the squared relative radius `s` in [0, 1] (LuxRender 1.x's
/// `distribution`, its `power` for the exponential ones).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LensDistribution {
    /// `s = u`: as much light through every part of the aperture's angle.
    Uniform,
    /// `s = min(-ln(u) / power, 1)`: brighter towards the centre.
    Exponential { power: f32 },
    /// `s = max(1 + ln(u) / power, 0)`: brighter towards the rim.
    InverseExponential { power: f32 },
    /// `s` the standard normal quantile of `u`, clamped to [0, 1].
    Gaussian,
    /// `s` one less the standard normal quantile of `u`, clamped to [0, 1].
    InverseGaussian,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aperture {
    /// Polygon sides; below 3 the round disk.
    pub blades: u32,
    pub distribution: LensDistribution,
}

impl Default for Aperture {
    fn default() -> Self {
        Self {
            blades: DEFAULT_BLADES as u32,
            distribution: LensDistribution::Uniform,
        }
    }
}

impl Aperture {
    /// Reads a perspective camera's `blades`, `distribution` and `power`. An unknown
    /// distribution is an error naming the ones there are (LuxRender warns and renders
    /// uniform; a typo should not silently change the bokeh).
    pub fn read(p: &ParamList) -> Result<Self, ParseError> {
        let blades = p.int("blades", DEFAULT_BLADES)?.clamp(0, MAX_BLADES as i32) as u32;
        let power = p.int("power", DEFAULT_POWER)?;
        let Some(param) = p.find("distribution") else {
            return Ok(Self {
                blades,
                distribution: LensDistribution::Uniform,
            });
        };
        let name = p.string_or("distribution", DEFAULT_DISTRIBUTION)?;
        let exponential = || match p.find("power").filter(|_| power <= 0) {
            Some(power_param) => Err(p.error(power_param, "power must be at least 1")),
            None => Ok(power as f32),
        };
        let distribution = match name.as_str() {
            "uniform" => LensDistribution::Uniform,
            "exponential" => LensDistribution::Exponential {
                power: exponential()?,
            },
            "inverse exponential" => LensDistribution::InverseExponential {
                power: exponential()?,
            },
            "gaussian" => LensDistribution::Gaussian,
            "inverse gaussian" => LensDistribution::InverseGaussian,
            other => {
                return Err(p.error(
                    param,
                    format!(
                        "unknown distribution \"{other}\" (uniform, exponential, inverse \
                         exponential, gaussian, inverse gaussian)"
                    ),
                ))
            }
        };
        Ok(Self {
            blades,
            distribution,
        })
    }

    pub fn is_round(&self) -> bool {
        self.blades < 3
    }

    /// The lens point `u` in [0,1)^2 chooses, on the unit aperture.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        if self.is_round() {
            return sample_disk_concentric(u);
        }
        let half_angle = PI / self.blades as f32;
        let theta = 2.0 * PI * u.y;
        // The angle from the nearest edge's middle: sectors of half an edge alternate between
        // running away from an edge's middle and towards the next one.
        let sector = (theta / half_angle) as u32;
        let from_middle = if sector.is_multiple_of(2) {
            theta - sector as f32 * half_angle
        } else {
            (sector + 1) as f32 * half_angle - theta
        };
        let edge = libm::cosf(half_angle) / libm::cosf(from_middle);
        let r = edge * self.squared_radius(u.x).sqrt();
        let (sin, cos) = libm::sincosf(theta);
        Vec2::new(r * cos, r * sin)
    }

    /// [`Self::sample`] in lanes: the same bits on every lane type (the polygon lane by lane).
    #[inline(always)]
    pub fn sample_lanes<L: Lanes>(&self, u: [L; 2]) -> [L; 2] {
        if self.is_round() {
            return concentric_disk(u);
        }
        let (ux, uy) = (u[0].values(), u[1].values());
        let (mut x, mut y) = ([0.0; MAX_LANES], [0.0; MAX_LANES]);
        for i in 0..L::N {
            let p = self.sample(Vec2::new(ux[i], uy[i]));
            (x[i], y[i]) = (p.x, p.y);
        }
        [L::load(&x), L::load(&y)]
    }

    /// The squared radius relative to the edge, `s` in [0, 1], the distribution gives `u`.
    fn squared_radius(&self, u: f32) -> f32 {
        let s = match self.distribution {
            LensDistribution::Uniform => u,
            LensDistribution::Exponential { power } => -libm::logf(u) / power,
            LensDistribution::InverseExponential { power } => 1.0 + libm::logf(u) / power,
            LensDistribution::Gaussian => normal_quantile_in_unit(u),
            LensDistribution::InverseGaussian => 1.0 - normal_quantile_in_unit(u),
        };
        // ln(0) is -inf: clamped as LuxRender clamps it.
        s.clamp(0.0, 1.0)
    }
}

/// The standard normal quantile of `u` where it lies in [0, 1], else the nearer end (all a
/// gaussian aperture keeps of it): Newton's method on libm's error function, which converges
/// in a few steps on that short stretch.
fn normal_quantile_in_unit(u: f32) -> f32 {
    let cdf = |x: f64| 0.5 * libm::erfc(-x / std::f64::consts::SQRT_2);
    let u = u as f64;
    if u <= 0.5 {
        return 0.0;
    }
    if u >= cdf(1.0) {
        return 1.0;
    }
    let mut x = 0.5f64;
    for _ in 0..8 {
        let density = libm::exp(-0.5 * x * x) / (2.0 * std::f64::consts::PI).sqrt();
        x = (x - (cdf(x) - u) / density).clamp(0.0, 1.0);
    }
    x as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polygon(blades: u32, distribution: LensDistribution) -> Aperture {
        Aperture {
            blades,
            distribution,
        }
    }

    /// Stratified points of the unit square.
    fn grid(n: usize) -> impl Iterator<Item = Vec2> {
        (0..n * n).map(move |i| {
            Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32,
                ((i / n) as f32 + 0.5) / n as f32,
            )
        })
    }

    /// The distance from the centre to a regular polygon's boundary at angle `theta`, its
    /// vertices at odd multiples of pi/blades, from the polygon's own geometry: the largest
    /// projection on an edge normal gives the apothem at the boundary.
    fn boundary(blades: u32, theta: f32) -> f32 {
        let apothem = libm::cosf(PI / blades as f32);
        let along = (0..blades)
            .map(|k| libm::cosf(theta - 2.0 * PI * k as f32 / blades as f32))
            .fold(f32::MIN, f32::max);
        apothem / along
    }

    /// A hexagonal aperture's points lie inside the hexagon and fill it out to its vertices
    /// and edges; the round aperture is the concentric disk; a lane type's points are the
    /// scalar ones bit for bit.
    #[test]
    fn polygons_fill_their_polygon_and_nothing_else() {
        for blades in [3, 5, 6, 8] {
            let aperture = polygon(blades, LensDistribution::Uniform);
            let (mut max_x, mut max_y, mut outermost) = (0.0f32, 0.0f32, 0.0f32);
            for u in grid(200) {
                let p = aperture.sample(u);
                let theta = libm::atan2f(p.y, p.x);
                let relative = p.length() / boundary(blades, theta);
                assert!(relative <= 1.0 + 1e-5, "{blades} blades: {p} outside");
                outermost = outermost.max(relative);
                (max_x, max_y) = (max_x.max(p.x.abs()), max_y.max(p.y.abs()));
            }
            assert!(
                outermost > 0.995,
                "{blades} blades reach the edge: {outermost}"
            );
            if blades == 6 {
                // A hexagon with a vertex straight up: as tall as the circle, as wide as its
                // apothem across.
                assert!((max_y - 1.0).abs() < 0.015, "{max_y}");
                assert!((max_x - libm::cosf(PI / 6.0)).abs() < 0.015, "{max_x}");
            }
        }
        let round = Aperture::default();
        for u in grid(20) {
            assert_eq!(round.sample(u), sample_disk_concentric(u));
        }
    }

    /// The mean squared radius relative to the edge is E[s] of each distribution, by its
    /// closed form: 1/2; (1 - e^-p)/p and one less it; E[clamp(Z, 0, 1)] =
    /// phi(0) - phi(1) + Q(1) and E[clamp(1 - Z, 0, 1)] = P(0 < Z < 1) - (phi(0) - phi(1)) + 1/2.
    #[test]
    fn weighted_apertures_put_their_light_where_their_distribution_says() {
        let phi = |x: f64| libm::exp(-0.5 * x * x) / (2.0 * std::f64::consts::PI).sqrt();
        let q1 = 0.5 * libm::erfc(1.0 / std::f64::consts::SQRT_2);
        let exponential = (1.0 - libm::exp(-3.0)) / 3.0;
        let cases = [
            (LensDistribution::Uniform, 0.5),
            (LensDistribution::Exponential { power: 3.0 }, exponential),
            (
                LensDistribution::InverseExponential { power: 3.0 },
                1.0 - exponential,
            ),
            (LensDistribution::Gaussian, phi(0.0) - phi(1.0) + q1),
            (
                LensDistribution::InverseGaussian,
                (0.5 - q1) - (phi(0.0) - phi(1.0)) + 0.5,
            ),
        ];
        for (distribution, want) in cases {
            let aperture = polygon(6, distribution);
            let n = 400;
            let mean = grid(n)
                .map(|u| {
                    let p = aperture.sample(u);
                    let edge = boundary(6, libm::atan2f(p.y, p.x)) as f64;
                    (p.length() as f64 / edge).powi(2)
                })
                .sum::<f64>()
                / (n * n) as f64;
            assert!(
                (mean - want).abs() < 2e-3,
                "{distribution:?}: mean s {mean}, want {want}"
            );
        }
    }

    #[test]
    fn the_quantile_is_the_normal_one_on_the_unit_stretch() {
        for x in [0.05f64, 0.3, 0.5, 0.77, 0.99] {
            let u = 0.5 * libm::erfc(-x / std::f64::consts::SQRT_2);
            let got = normal_quantile_in_unit(u as f32) as f64;
            assert!((got - x).abs() < 1e-5, "{x}: {got}");
        }
        assert_eq!(normal_quantile_in_unit(0.2), 0.0);
        assert_eq!(normal_quantile_in_unit(0.95), 1.0);
    }

    #[test]
    fn polygons_in_lanes_are_the_scalar_polygons() {
        use crate::lanes::tests::on_every_lane_type;
        use crate::lanes::OnLanes;

        struct Agrees(Aperture);
        impl OnLanes for Agrees {
            type Output = ();
            fn run<L: Lanes>(&self) {
                let mut rng = fastrand::Rng::with_seed(9);
                for _ in 0..200 {
                    let mut v = [[0.0; MAX_LANES]; 2];
                    for row in &mut v {
                        for value in &mut row[..L::N] {
                            *value = rng.f32();
                        }
                    }
                    let [x, y] = self.0.sample_lanes([L::load(&v[0]), L::load(&v[1])]);
                    let (x, y) = (x.values(), y.values());
                    for i in 0..L::N {
                        let want = self.0.sample(Vec2::new(v[0][i], v[1][i]));
                        assert_eq!(
                            [x[i], y[i]].map(f32::to_bits),
                            want.to_array().map(f32::to_bits)
                        );
                    }
                }
            }
        }
        on_every_lane_type(&Agrees(polygon(
            7,
            LensDistribution::Exponential { power: 2.0 },
        )));
        on_every_lane_type(&Agrees(Aperture::default()));
    }
}
