//! `PixelFilter "mitchell" "float xwidth" [2] "float ywidth" [2] ...`: pixel reconstruction
//! filters, their description, LuxRender's defaults and their reading.
//!
//! | type | parameters (defaults) | half-width default |
//! |---|---|---|
//! | `box` | | 0.5 |
//! | `triangle` | | 2 |
//! | `gaussian` | `alpha` (2) | 2 |
//! | `mitchell` (the default) | `B` (1/3), `C` (1/3) | 2 |
//! | `catmullrom` | (Mitchell with B = 0, C = 1/2) | 2 |
//! | `blackmanharris` | | 4 |
//! | `sinc` | `tau` (3) | 4 |
//!
//! Every type also takes `xwidth` and `ywidth` (positive half-widths in pixels). An unknown
//! type is a warning and renders with the default mitchell.
//!
//! The filters are used by filter importance sampling: a sample's offset from its pixel centre
//! is drawn from |f| and carries weight sign(f), so every sample belongs to exactly one pixel
//! and tiles need no borders (docs/architecture.md).

use glam::Vec2;

use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// Mitchell-Netravali's B and C when the file does not give them (and for unknown filters).
pub const DEFAULT_MITCHELL_B: f32 = 1.0 / 3.0;
pub const DEFAULT_MITCHELL_C: f32 = 1.0 / 3.0;
/// Half-width of the box filter when the file does not say.
pub const DEFAULT_BOX_WIDTH: f32 = 0.5;
/// Half-width of the triangle, gaussian and mitchell filters when the file does not say.
pub const DEFAULT_WIDTH: f32 = 2.0;
/// Half-width of the blackmanharris and sinc filters when the file does not say.
pub const DEFAULT_WIDE_WIDTH: f32 = 4.0;
/// The gaussian's falloff when the file does not say.
pub const DEFAULT_GAUSSIAN_ALPHA: f32 = 2.0;
/// The sinc's tau when the file does not say.
pub const DEFAULT_SINC_TAU: f32 = 3.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterKind {
    Box,
    Triangle,
    Gaussian { alpha: f32 },
    Mitchell { b: f32, c: f32 },
    BlackmanHarris,
    Sinc { tau: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterDesc {
    pub kind: FilterKind,
    /// Half-widths in pixels.
    pub xwidth: f32,
    pub ywidth: f32,
}

/// The filter of a scene without a `PixelFilter` statement.
impl Default for FilterDesc {
    fn default() -> Self {
        Self {
            kind: FilterKind::Mitchell {
                b: DEFAULT_MITCHELL_B,
                c: DEFAULT_MITCHELL_C,
            },
            xwidth: DEFAULT_WIDTH,
            ywidth: DEFAULT_WIDTH,
        }
    }
}

impl FilterDesc {
    /// Reads `PixelFilter "ty"`.
    pub fn read(
        ctx: &mut dyn ParseContext,
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
    ) -> Result<Self, ParseError> {
        let (kind, width) = match ty {
            "box" => (FilterKind::Box, DEFAULT_BOX_WIDTH),
            "triangle" => (FilterKind::Triangle, DEFAULT_WIDTH),
            "gaussian" => (
                FilterKind::Gaussian {
                    alpha: params.float("alpha", DEFAULT_GAUSSIAN_ALPHA)?,
                },
                DEFAULT_WIDTH,
            ),
            "mitchell" => {
                params.ignore("supersample");
                (
                    FilterKind::Mitchell {
                        b: params.float("B", DEFAULT_MITCHELL_B)?,
                        c: params.float("C", DEFAULT_MITCHELL_C)?,
                    },
                    DEFAULT_WIDTH,
                )
            }
            // Catmull-Rom is the Mitchell-Netravali filter with B = 0, C = 1/2.
            "catmullrom" => (FilterKind::Mitchell { b: 0.0, c: 0.5 }, DEFAULT_WIDTH),
            "blackmanharris" => (FilterKind::BlackmanHarris, DEFAULT_WIDE_WIDTH),
            "sinc" => (
                FilterKind::Sinc {
                    tau: params.float("tau", DEFAULT_SINC_TAU)?,
                },
                DEFAULT_WIDE_WIDTH,
            ),
            other => {
                ctx.warn(
                    pos,
                    format!("PixelFilter \"{other}\" is unknown; using mitchell"),
                );
                (
                    FilterKind::Mitchell {
                        b: DEFAULT_MITCHELL_B,
                        c: DEFAULT_MITCHELL_C,
                    },
                    DEFAULT_WIDTH,
                )
            }
        };
        let width = |name: &str| -> Result<f32, ParseError> {
            let w = params.float(name, width)?;
            match params.find(name) {
                Some(p) if w <= 0.0 => Err(params.error(p, "the filter width must be positive")),
                _ => Ok(w),
            }
        };
        Ok(FilterDesc {
            kind,
            xwidth: width("xwidth")?,
            ywidth: width("ywidth")?,
        })
    }
}

const TABLE_SIZE: usize = 256;

/// Samples one axis of a separable filter from a tabulated |f|.
#[derive(Clone, Debug)]
struct AxisSampler {
    radius: f32,
    /// Cumulative |f| at the right edge of each bin, normalised to end at 1.
    cdf: Vec<f32>,
    /// sign(f) over each bin.
    sign: Vec<f32>,
}

impl AxisSampler {
    fn new(radius: f32, f: impl Fn(f32) -> f32) -> Self {
        let radius = if radius.is_finite() && radius > 0.0 {
            radius
        } else {
            0.5
        };
        let bin = 2.0 * radius / TABLE_SIZE as f32;
        let values: Vec<f32> = (0..TABLE_SIZE)
            .map(|i| f(-radius + (i as f32 + 0.5) * bin))
            .collect();
        let mut cdf = Vec::with_capacity(TABLE_SIZE);
        let mut sum = 0.0;
        for v in &values {
            sum += v.abs();
            cdf.push(sum);
        }
        if sum > 0.0 {
            cdf.iter_mut().for_each(|c| *c /= sum);
        } else {
            // A filter that is zero everywhere degenerates to a box.
            cdf = (1..=TABLE_SIZE)
                .map(|i| i as f32 / TABLE_SIZE as f32)
                .collect();
        }
        let sign = values
            .iter()
            .map(|&v| if v < 0.0 { -1.0 } else { 1.0 })
            .collect();
        Self { radius, cdf, sign }
    }

    /// An offset in [-radius, radius] and its weight.
    fn sample(&self, u: f32) -> (f32, f32) {
        let i = self.cdf.partition_point(|&c| c <= u).min(TABLE_SIZE - 1);
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let width = self.cdf[i] - lo;
        let within = if width > 0.0 { (u - lo) / width } else { 0.5 };
        let bin = 2.0 * self.radius / TABLE_SIZE as f32;
        (-self.radius + (i as f32 + within) * bin, self.sign[i])
    }
}

#[derive(Clone, Debug)]
pub struct FilterSampler {
    x: AxisSampler,
    y: AxisSampler,
}

impl FilterSampler {
    pub fn new(desc: &FilterDesc) -> Self {
        let kind = desc.kind;
        let axis = |radius: f32| AxisSampler::new(radius, |x| filter_1d(kind, x, radius));
        Self {
            x: axis(desc.xwidth),
            y: axis(desc.ywidth),
        }
    }

    /// Offset from the pixel centre and the sample's weight (+1 or -1).
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (dx, wx) = self.x.sample(u.x);
        let (dy, wy) = self.y.sample(u.y);
        (Vec2::new(dx, dy), wx * wy)
    }
}

/// One axis of LuxRender's separable filters, `x` in [-radius, radius].
fn filter_1d(kind: FilterKind, x: f32, radius: f32) -> f32 {
    use std::f32::consts::PI;
    match kind {
        FilterKind::Box => 1.0,
        FilterKind::Triangle => (radius - x.abs()).max(0.0),
        FilterKind::Gaussian { alpha } => {
            ((-alpha * x * x).exp() - (-alpha * radius * radius).exp()).max(0.0)
        }
        FilterKind::Mitchell { b, c } => {
            let x = (2.0 * x / radius).abs();
            if x > 2.0 {
                0.0
            } else if x > 1.0 {
                ((-b - 6.0 * c) * x * x * x
                    + (6.0 * b + 30.0 * c) * x * x
                    + (-12.0 * b - 48.0 * c) * x
                    + (8.0 * b + 24.0 * c))
                    / 6.0
            } else {
                ((12.0 - 9.0 * b - 6.0 * c) * x * x * x
                    + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                    + (6.0 - 2.0 * b))
                    / 6.0
            }
        }
        FilterKind::BlackmanHarris => {
            // The window spans [-radius, radius].
            let t = 2.0 * PI * (x / (2.0 * radius) + 0.5);
            0.35875 - 0.48829 * t.cos() + 0.14128 * (2.0 * t).cos() - 0.01168 * (3.0 * t).cos()
        }
        FilterKind::Sinc { tau } => {
            let x = x.abs();
            if x > radius {
                return 0.0;
            }
            let sinc = |v: f32| {
                if v < 1e-5 {
                    1.0
                } else {
                    (PI * v).sin() / (PI * v)
                }
            };
            sinc(x) * sinc(x / tau)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_follow_the_filter_shape() {
        let desc = FilterDesc {
            kind: FilterKind::BlackmanHarris,
            xwidth: 2.0,
            ywidth: 2.0,
        };
        let sampler = FilterSampler::new(&desc);
        let n = 10_000;
        let (mut inner, mut mean) = (0, Vec2::ZERO);
        for i in 0..n {
            let u = Vec2::new(
                (i as f32 + 0.5) / n as f32,
                ((i * 7919) % n) as f32 / n as f32,
            );
            let (d, w) = sampler.sample(u);
            assert_eq!(w, 1.0);
            assert!(d.x.abs() <= 2.0 && d.y.abs() <= 2.0);
            mean += d;
            if d.x.abs() < 0.5 {
                inner += 1;
            }
        }
        assert!((mean / n as f32).length() < 0.01);
        // Blackman-Harris over [-2, 2] puts 62.1% of its mass within half a pixel.
        let frac = inner as f32 / n as f32;
        assert!((frac - 0.621).abs() < 0.01, "{frac}");
    }

    #[test]
    fn mitchell_has_negative_lobes() {
        let desc = FilterDesc {
            kind: FilterKind::Mitchell {
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
            xwidth: 2.0,
            ywidth: 2.0,
        };
        let sampler = FilterSampler::new(&desc);
        let negatives = (0..1000)
            .filter(|&i| sampler.sample(Vec2::new(i as f32 / 1000.0, 0.5)).1 < 0.0)
            .count();
        assert!(negatives > 0 && negatives < 100, "{negatives}");
    }
}
