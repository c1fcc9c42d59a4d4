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
//! Every type also takes `xwidth` and `ywidth` (positive half-widths in pixels, at most
//! [`MAX_WIDTH`]: a wider one is a warning and renders at that width). An unknown type is a
//! warning and renders with the default mitchell.
//!
//! Samples are splatted through the filter ([`PixelFilter`]): each one adds its radiance,
//! weighted, to every pixel whose centre lies within the filter's half-widths, so a unit's
//! buffer covers its tile and a border of [`FilterDesc::border`] pixels around it
//! (docs/architecture.md). A pixel is the filter-weighted mean of the samples around it.

use crate::diag::SourcePos;
use crate::math::floor_to_int;
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
/// The widest half-width rendered, in pixels: it bounds a unit's border (and the splat's cost
/// per sample) whatever a file says. LuxRender's widest default is 4.
pub const MAX_WIDTH: f32 = 8.0;
/// The widest border of a unit's buffer, in pixels: that of a [`MAX_WIDTH`] filter.
pub const MAX_BORDER: u32 = 8;
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
        let mut width = |name: &str| -> Result<f32, ParseError> {
            let w = params.float(name, width)?;
            match params.find(name) {
                Some(p) if w.is_nan() || w <= 0.0 => {
                    Err(params.error(p, "the filter width must be positive"))
                }
                Some(_) if w > MAX_WIDTH => {
                    ctx.warn(
                        pos,
                        format!("PixelFilter {name} {w} is rendered as {MAX_WIDTH}, the widest"),
                    );
                    Ok(MAX_WIDTH)
                }
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

/// Intervals of the table each axis's weights are read from (linear interpolation between its
/// ends): within 1e-4 of the filter, with no transcendental function per sample.
const TABLE_SIZE: usize = 256;

/// Pixels a filter's weights reach per axis at most: a sample's own and [`MAX_BORDER`] each
/// side.
pub const MAX_TAPS: usize = 2 * MAX_BORDER as usize + 1;

/// [`Taps`]' weight slots: [`MAX_TAPS`] rounded up to a multiple of four.
const TAP_SLOTS: usize = MAX_TAPS.next_multiple_of(4);

/// One axis of a separable filter: |offset| in [0, radius] to the weight, tabulated, the peak
/// scaled to 1 (a pixel's weights are a ratio, so the scale cancels; the peak at 1 bounds every
/// weight a sample gives a pixel by 1 in magnitude).
#[derive(Clone, Debug)]
struct AxisWeights {
    radius: f32,
    border: u32,
    /// TABLE_SIZE / radius: table steps per pixel of offset.
    steps_per_pixel: f32,
    /// The weight at i x radius / TABLE_SIZE, i in 0..=TABLE_SIZE (an array: the lookups
    /// need no bounds checks).
    table: Box<[f32; TABLE_SIZE + 1]>,
}

impl AxisWeights {
    fn new(radius: f32, f: impl Fn(f32) -> f32) -> Self {
        let step = radius / TABLE_SIZE as f32;
        let mut table = Box::new([0.0; TABLE_SIZE + 1]);
        for (i, v) in table.iter_mut().enumerate() {
            *v = f(i as f32 * step);
        }
        let peak = table.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        if peak > 0.0 && peak.is_finite() {
            table.iter_mut().for_each(|v| *v /= peak);
        } else {
            // A filter that is zero everywhere degenerates to a box.
            table.fill(1.0);
        }
        Self {
            radius,
            border: border(radius),
            steps_per_pixel: TABLE_SIZE as f32 / radius,
            table,
        }
    }

    /// The largest weight in magnitude a sample gives the pixel k pixels from its own, for k in
    /// -border..=border (index k + border). A sample at u in [0, 1) of its pixel gives it the
    /// weight at |k + 0.5 - u|, which lies in [|k| - 0.5, |k| + 0.5] (from 0 for k = 0), and a
    /// weight is interpolated between the two table entries around its offset: the largest
    /// entry from the one before that range to the one after bounds it.
    fn max_weights(&self) -> Vec<f32> {
        let b = i64::from(self.border);
        (-b..=b)
            .map(|k| {
                let k = k.unsigned_abs() as f32;
                let near = ((k - 0.5).max(0.0) * self.steps_per_pixel) as usize;
                let far = ((k + 0.5) * self.steps_per_pixel) as usize + 2;
                self.table[near.saturating_sub(1)..=far.min(TABLE_SIZE)]
                    .iter()
                    .fold(0.0f32, |m, v| m.max(v.abs()))
            })
            .collect()
    }

    /// The weight's integral over offsets in [-radius, radius], in pixels: the interpolated
    /// table's, exactly (a trapezoid rule over its entries).
    #[cfg(test)]
    fn integral(&self) -> f32 {
        let inner: f32 = self.table.windows(2).map(|w| w[0] + w[1]).sum();
        inner * (self.radius / TABLE_SIZE as f32)
    }

    /// Per pixel `c` of an axis `size` pixels long: the weight a sample gives `c` integrated
    /// over the sample's position along the axis within the film (`c`'s filter mass in the
    /// film: the full integral away from the edges, less near them, where the film has no
    /// samples beyond). Integrated with the taps themselves, at [`MASS_STEPS`] positions in
    /// each pixel.
    fn film_mass(&self, size: u32) -> Vec<f32> {
        let b = self.border as usize;
        // The weight's integral over a sample's position in a pixel `k - border` pixels from
        // the one weighed (by the midpoint rule; the table is linear between entries).
        let mut per_offset = vec![0.0f64; 2 * b + 1];
        let far = (2 * b + 1) as u32;
        for i in 0..MASS_STEPS {
            let u = (i as f32 + 0.5) / MASS_STEPS as f32;
            let taps = self.taps(far, u, 0, 2 * far + 1);
            for (j, &w) in taps.weights().iter().enumerate() {
                let offset = (taps.first + j as u32) as i64 - i64::from(far);
                per_offset[(offset + b as i64) as usize] += f64::from(w) / MASS_STEPS as f64;
            }
        }
        (0..i64::from(size))
            .map(|c| {
                let mass: f64 = (-(b as i64)..=b as i64)
                    .filter(|&k| (0..i64::from(size)).contains(&(c - k)))
                    .map(|k| per_offset[(k + b as i64) as usize])
                    .sum();
                mass as f32
            })
            .collect()
    }

    /// Whether some weight is negative: some table entry is (a weight lies between two).
    fn has_negative_weights(&self) -> bool {
        self.table.iter().any(|&v| v < 0.0)
    }

    /// The weight at `offset` pixels from the sample (what `weights4` computes four at a time).
    #[cfg(any(test, not(target_arch = "x86_64")))]
    fn weight(&self, offset: f32) -> f32 {
        use crate::math::{bin_at, count_f32};
        let t = (offset.abs() * self.steps_per_pixel).min(TABLE_SIZE as f32);
        let i = bin_at(t, TABLE_SIZE);
        let (a, b) = (self.table[i], self.table[i + 1]);
        a + (t - count_f32(i)) * (b - a)
    }

    /// The pixels of `lo..hi` a sample at `pixel + u` (u in [0, 1)) reaches: those whose centre
    /// lies within (-radius, radius] of it, and their weights.
    fn taps(&self, pixel: u32, u: f32, lo: u32, hi: u32) -> Taps {
        let b = self.border as i64;
        // Offsets k of the pixels pixel + k reached, k in [-border, border] (clamped: f32
        // rounding of u + radius may reach one further when u is just under 1).
        let first = (floor_to_int(u - self.radius - 0.5) + 1).clamp(-b, b);
        let last = floor_to_int(u + self.radius - 0.5).clamp(-b, b);
        let start = (i64::from(pixel) + first).max(i64::from(lo));
        let end = (i64::from(pixel) + last + 1).min(i64::from(hi));
        let mut taps = Taps {
            first: start.max(0) as u32,
            len: (end - start).clamp(0, MAX_TAPS as i64) as usize,
            weights: [0.0; TAP_SLOTS],
        };
        // Four weights at a time; the slots past `len` are computed and not read.
        let k0 = start - i64::from(pixel);
        for (c, chunk) in taps.weights[..taps.len.next_multiple_of(4)]
            .chunks_exact_mut(4)
            .enumerate()
        {
            let k = [0, 1, 2, 3].map(|j| (k0 + (4 * c + j) as i64) as f32);
            chunk.copy_from_slice(&self.weights4(k, u));
        }
        taps
    }

    /// `weight(k + 0.5 - u)` for four pixel offsets k.
    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    fn weights4(&self, k: [f32; 4], u: f32) -> [f32; 4] {
        k.map(|k| self.weight(k + 0.5 - u))
    }

    /// `weight(k + 0.5 - u)` for four pixel offsets k, on SSE lanes (part of x86-64): each lane
    /// does `weight`'s operations in its order, so the weights have the same bits.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn weights4(&self, k: [f32; 4], u: f32) -> [f32; 4] {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of x86-64; the loads and stores use 4-float arrays. Each entry is
        // in 0..TABLE_SIZE (t is at least 0, a NaN offset becomes TABLE_SIZE at the first `min`,
        // and the second caps it below), so it and the next are inside the table's
        // TABLE_SIZE + 1 weights.
        unsafe {
            let k = _mm_loadu_ps(k.as_ptr());
            let offset = _mm_sub_ps(_mm_add_ps(k, _mm_set1_ps(0.5)), _mm_set1_ps(u));
            let magnitude = _mm_andnot_ps(_mm_set1_ps(-0.0), offset);
            // `min` returns its second operand for a NaN, as f32::min returns the number.
            let t = _mm_min_ps(
                _mm_mul_ps(magnitude, _mm_set1_ps(self.steps_per_pixel)),
                _mm_set1_ps(TABLE_SIZE as f32),
            );
            // bin_at: truncation, at most TABLE_SIZE - 1 (t <= TABLE_SIZE, so capping before
            // truncating gives the same entry).
            let i = _mm_cvttps_epi32(_mm_min_ps(t, _mm_set1_ps((TABLE_SIZE - 1) as f32)));
            let mut entry = [0i32; 4];
            _mm_storeu_si128(entry.as_mut_ptr().cast(), i);
            let at = |j: usize| *self.table.get_unchecked(entry[j] as usize);
            let next = |j: usize| *self.table.get_unchecked(entry[j] as usize + 1);
            let a = _mm_setr_ps(at(0), at(1), at(2), at(3));
            let b = _mm_setr_ps(next(0), next(1), next(2), next(3));
            let w = _mm_add_ps(
                a,
                _mm_mul_ps(_mm_sub_ps(t, _mm_cvtepi32_ps(i)), _mm_sub_ps(b, a)),
            );
            let mut out = [0.0; 4];
            _mm_storeu_ps(out.as_mut_ptr(), w);
            out
        }
    }
}

/// The weights one sample gives a run of pixels along one axis.
#[derive(Clone, Copy, Debug)]
pub struct Taps {
    /// The first pixel reached.
    pub first: u32,
    len: usize,
    weights: [f32; TAP_SLOTS],
}

impl Taps {
    /// The weight of pixels `first`, `first + 1`, ...
    pub fn weights(&self) -> &[f32] {
        &self.weights[..self.len]
    }
}

/// Pixels beyond its own that a filter of this half-width reaches: a sample at offset u in
/// [0, 1) of its pixel reaches the pixels whose centres lie within (-radius, radius] of it.
fn border(radius: f32) -> u32 {
    (radius - 0.5).ceil().max(0.0) as u32
}

/// A filter's half-width as rendered: at most [`MAX_WIDTH`]; a value that is not a positive
/// number (only a hand-made description has one: the parser refuses it) renders as a box's.
fn clamp_width(width: f32) -> f32 {
    if width > 0.0 {
        width.min(MAX_WIDTH)
    } else {
        DEFAULT_BOX_WIDTH
    }
}

/// The pixel filter as samples are splatted through it: every sample adds `w(p - x) L` and
/// `w(p - x)` to each pixel p it reaches (LuxRender's film does the same), `w` the product of
/// the two axes' weights (negative in mitchell's and sinc's lobes).
#[derive(Clone, Debug)]
pub struct PixelFilter {
    x: AxisWeights,
    y: AxisWeights,
}

impl PixelFilter {
    pub fn new(desc: &FilterDesc) -> Self {
        let kind = desc.kind;
        let axis = |width: f32| {
            let radius = clamp_width(width);
            AxisWeights::new(radius, |x| filter_1d(kind, x, radius))
        };
        Self {
            x: axis(desc.xwidth),
            y: axis(desc.ywidth),
        }
    }

    /// The weights a sample at `(x, y) + u` gives the columns `lo..hi`.
    pub fn taps_x(&self, x: u32, u: f32, lo: u32, hi: u32) -> Taps {
        self.x.taps(x, u, lo, hi)
    }

    /// The weights a sample at `(x, y) + u` gives the rows `lo..hi`.
    pub fn taps_y(&self, y: u32, u: f32, lo: u32, hi: u32) -> Taps {
        self.y.taps(y, u, lo, hi)
    }

    /// Each pixel's filter mass in a `width` x `height` film: what its weight sum grows by
    /// per sample per pixel of area (the filter's integral over the film around the pixel;
    /// less at the edges, which have no samples beyond). A light splat, which no weight sum
    /// divides, is spread through the filter with each pixel's weight divided by that pixel's
    /// mass, so the pixel converges to the filtered mean its camera samples' weighted mean
    /// converges to, at the edges too.
    pub fn film_mass(&self, width: u32, height: u32) -> FilmMass {
        FilmMass {
            columns: self.x.film_mass(width),
            rows: self.y.film_mass(height),
        }
    }

    /// What the filter lets one sample add to a pixel's weight sum: the bounds an honest unit's
    /// buffer keeps.
    pub fn weight_bounds(&self) -> WeightBounds {
        WeightBounds {
            negative: self.x.has_negative_weights() || self.y.has_negative_weights(),
            x: self.x.max_weights(),
            y: self.y.max_weights(),
        }
    }
}

/// Sample positions per pixel [`PixelFilter::film_mass`] integrates over.
const MASS_STEPS: usize = 1024;

/// Each pixel's filter mass in a film ([`PixelFilter::film_mass`]), per column and per row
/// (the filter is separable).
#[derive(Clone, Debug)]
pub struct FilmMass {
    columns: Vec<f32>,
    rows: Vec<f32>,
}

impl FilmMass {
    /// The mass of pixel (x, y), which must lie in the film.
    pub fn at(&self, x: u32, y: u32) -> f32 {
        self.columns[x as usize] * self.rows[y as usize]
    }
}

/// What one sample can add to the weight sum of a pixel, by the pixel's offset from the
/// sample's own: a pixel's weight sum over a unit's samples is bounded by these, and is never
/// negative when no weight is.
#[derive(Clone, Debug, PartialEq)]
pub struct WeightBounds {
    /// Whether some sample may weigh a pixel negatively (mitchell's and sinc's lobes, for most
    /// of their parameters; box, triangle, gaussian and blackmanharris never do).
    pub negative: bool,
    /// Per axis, for offsets k from -border to border (index k + border): the largest weight in
    /// magnitude along that axis (a sample's weight is the product of its two axes').
    pub x: Vec<f32>,
    pub y: Vec<f32>,
}

impl FilterDesc {
    /// Pixels a sample reaches beyond its own, per axis: the border of every unit's buffer.
    pub fn border(&self) -> [u32; 2] {
        [
            border(clamp_width(self.xwidth)),
            border(clamp_width(self.ywidth)),
        ]
    }
}

/// One axis of LuxRender's separable filters, `x` in [-radius, radius].
fn filter_1d(kind: FilterKind, x: f32, radius: f32) -> f32 {
    use std::f32::consts::PI;
    match kind {
        FilterKind::Box => 1.0,
        FilterKind::Triangle => (radius - x.abs()).max(0.0),
        FilterKind::Gaussian { alpha } => {
            (libm::expf(-alpha * x * x) - libm::expf(-alpha * radius * radius)).max(0.0)
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
            0.35875 - 0.48829 * libm::cosf(t) + 0.14128 * libm::cosf(2.0 * t)
                - 0.01168 * libm::cosf(3.0 * t)
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
                    libm::sinf(PI * v) / (PI * v)
                }
            };
            sinc(x) * sinc(x / tau)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filter(kind: FilterKind, width: f32) -> PixelFilter {
        PixelFilter::new(&FilterDesc {
            kind,
            xwidth: width,
            ywidth: width,
        })
    }

    /// A sample's weights summed over the pixels it reaches, averaged over its position in its
    /// pixel, are the integral; a pixel's film mass is that inside the film, less at its edge:
    /// what light splats are normalised by.
    #[test]
    fn the_integral_is_the_mean_weight_a_sample_gives() {
        for (kind, width) in [
            (FilterKind::Box, 0.5),
            (FilterKind::Box, 1.5),
            (FilterKind::Gaussian { alpha: 2.0 }, 2.0),
            (
                FilterKind::Mitchell {
                    b: 1.0 / 3.0,
                    c: 1.0 / 3.0,
                },
                2.0,
            ),
            (FilterKind::BlackmanHarris, 1.5),
        ] {
            let f = filter(kind, width);
            let n = 4000;
            let mean: f64 = (0..n)
                .map(|i| {
                    let u = (i as f32 + 0.5) / n as f32;
                    f64::from(f.taps_x(10, u, 0, 20).weights().iter().sum::<f32>())
                })
                .sum::<f64>()
                / f64::from(n);
            let axis = f.x.integral();
            assert!(
                (mean / f64::from(axis) - 1.0).abs() < 1e-3,
                "{kind:?} {width}: {mean} vs {axis}"
            );
            // Inside the film a pixel's mass is the integral; at the edge the part beyond.
            let mass = f.film_mass(20, 20);
            let inside = mass.at(10, 10);
            assert!((inside / (axis * axis) - 1.0).abs() < 1e-3, "{inside}");
            let edge: f64 = (0..n)
                .map(|i| {
                    let u = (i as f32 + 0.5) / n as f32;
                    // Samples in pixels 0, 1, 2 and 3 (the widest border here is 2) weigh pixel 0.
                    (0..4u32)
                        .map(|p| {
                            let taps = f.taps_x(p, u, 0, 20);
                            if taps.first == 0 {
                                f64::from(taps.weights()[0])
                            } else {
                                0.0
                            }
                        })
                        .sum::<f64>()
                })
                .sum::<f64>()
                / f64::from(n);
            let got = f64::from(mass.at(0, 10) / axis);
            assert!(
                (got / edge - 1.0).abs() < 1e-3,
                "{kind:?} {width}: edge {got} vs {edge}"
            );
        }
    }

    #[test]
    fn a_half_pixel_box_gives_each_sample_to_its_own_pixel_alone() {
        let f = filter(FilterKind::Box, 0.5);
        for i in 0..1000 {
            let u = i as f32 / 1000.0;
            let taps = f.taps_x(7, u, 0, 20);
            assert_eq!((taps.first, taps.weights()), (7, &[1.0][..]), "{u}");
        }
    }

    #[test]
    fn weights_follow_the_filter_within_the_radius() {
        let kind = FilterKind::BlackmanHarris;
        let f = filter(kind, 2.0);
        for i in 0..100 {
            let u = (i as f32 + 0.5) / 100.0;
            let taps = f.taps_x(10, u, 0, 20);
            // Pixel centres within (-2, 2] of the sample: always four pixels.
            assert_eq!(taps.weights().len(), 4, "{u}");
            for (k, &w) in taps.weights().iter().enumerate() {
                let offset = (taps.first + k as u32) as f32 + 0.5 - (10.0 + u);
                assert!(offset.abs() <= 2.0, "{offset}");
                let exact = filter_1d(kind, offset, 2.0) / filter_1d(kind, 0.0, 2.0);
                assert!((w - exact).abs() < 1e-4, "{offset}: {w} against {exact}");
            }
        }
    }

    /// The taps' weights, four at a time, have the bits of the weight at each offset, for
    /// every width (up to the widest's 17 taps), at the table's ends (offset 0 and beyond the
    /// radius) and for taps cut short by the region's edge.
    #[test]
    fn tap_weights_equal_the_weights_one_at_a_time() {
        for (kind, radius) in [
            (FilterKind::BlackmanHarris, 2.0),
            (FilterKind::BlackmanHarris, 4.0),
            (FilterKind::Gaussian { alpha: 2.0 }, 2.0),
            (FilterKind::Triangle, 0.7),
            (FilterKind::Sinc { tau: 3.0 }, MAX_WIDTH),
        ] {
            let axis = &filter(kind, radius).x;
            for i in 0..=64 {
                let u = (i as f32 / 64.0).min(1.0f32.next_down());
                for (lo, hi) in [(0, 40), (19, 21), (20, 40), (0, 20)] {
                    let taps = axis.taps(20, u, lo, hi);
                    for (j, &w) in taps.weights().iter().enumerate() {
                        let k = (taps.first + j as u32) as f32 - 20.0;
                        let one = axis.weight(k + 0.5 - u);
                        assert_eq!(w.to_bits(), one.to_bits(), "{kind:?} u {u} tap {k}");
                    }
                }
            }
            // Offsets 0 and far past the radius: the table's first entry and its last.
            let k = [-0.5, 999.5, -1000.5, 2.0];
            let four = axis.weights4(k, 0.0);
            for j in 0..4 {
                assert_eq!(
                    four[j].to_bits(),
                    axis.weight(k[j] + 0.5).to_bits(),
                    "{k:?}"
                );
            }
        }
    }

    /// Every weight a sample gives a pixel is within the bound for its offset, and at least 0
    /// for the filters without negative lobes; the bounds are those weights' largest (within
    /// the table's interpolation), not a loose guess.
    #[test]
    fn weight_bounds_hold_every_weight_and_say_which_filters_weigh_negatively() {
        let mitchell = FilterKind::Mitchell {
            b: DEFAULT_MITCHELL_B,
            c: DEFAULT_MITCHELL_C,
        };
        let catmullrom = FilterKind::Mitchell { b: 0.0, c: 0.5 };
        for (kind, radius, negative) in [
            (FilterKind::Box, 0.5, false),
            (FilterKind::Box, 2.5, false),
            (FilterKind::Triangle, 2.0, false),
            (FilterKind::Gaussian { alpha: 2.0 }, 2.0, false),
            (FilterKind::Gaussian { alpha: 0.5 }, 3.3, false),
            (FilterKind::BlackmanHarris, 2.0, false),
            (FilterKind::BlackmanHarris, 4.0, false),
            (mitchell, 2.0, true),
            (mitchell, 0.5, true),
            (catmullrom, 2.0, true),
            (FilterKind::Sinc { tau: 3.0 }, 4.0, true),
            (FilterKind::Sinc { tau: 3.0 }, 0.9, false),
            (FilterKind::Triangle, MAX_WIDTH, false),
        ] {
            let filter = filter(kind, radius);
            let bounds = filter.weight_bounds();
            assert_eq!(bounds.negative, negative, "{kind:?} {radius}");
            let border = filter.x.border;
            assert_eq!(bounds.x.len(), 2 * border as usize + 1);
            assert_eq!(bounds.x, bounds.y, "{kind:?} {radius}");
            let mut largest = vec![0.0f32; bounds.x.len()];
            for i in 0..1000 {
                let u = (i as f32 / 1000.0).min(1.0f32.next_down());
                let taps = filter.taps_x(20, u, 0, 40);
                for (j, &w) in taps.weights().iter().enumerate() {
                    let at = (taps.first + j as u32 + border - 20) as usize;
                    assert!(w.abs() <= bounds.x[at], "{kind:?} {radius}: {w} at {at}");
                    assert!(negative || w >= 0.0, "{kind:?} {radius}: {w}");
                    largest[at] = largest[at].max(w.abs());
                }
            }
            for (bound, seen) in bounds.x.iter().zip(&largest) {
                assert!(
                    bound - seen <= 0.05,
                    "{kind:?} {radius}: {bounds:?}, {largest:?}"
                );
            }
        }
    }

    #[test]
    fn mitchell_weights_have_negative_lobes() {
        let f = filter(
            FilterKind::Mitchell {
                b: DEFAULT_MITCHELL_B,
                c: DEFAULT_MITCHELL_C,
            },
            2.0,
        );
        // A sample at 10.3 reaches the centres 8.5 to 11.5; those beyond half the radius
        // (offsets -1.8 and 1.2) weigh less than nothing.
        let taps = f.taps_x(10, 0.3, 0, 20);
        assert_eq!(taps.first, 8);
        let w = taps.weights();
        assert_eq!(w.len(), 4);
        assert!(
            w[0] < 0.0 && w[3] < 0.0 && w[1] > 0.0 && w[2] > 0.0,
            "{w:?}"
        );
        assert!(w.iter().all(|w| w.abs() <= 1.0));
    }

    #[test]
    fn taps_stay_within_the_border_and_the_given_range() {
        for width in [0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 4.0, MAX_WIDTH] {
            let f = filter(FilterKind::Triangle, width);
            let b = FilterDesc {
                kind: FilterKind::Triangle,
                xwidth: width,
                ywidth: width,
            }
            .border()[0];
            for u in [0.0, 0.25, 0.5, 0.999_999_94] {
                let taps = f.taps_x(20, u, 0, 100);
                let n = taps.weights().len() as u32;
                assert!(
                    taps.first >= 20 - b && taps.first + n <= 21 + b,
                    "{width} {u}"
                );
                let clipped = f.taps_x(20, u, 19, 21);
                assert!(
                    clipped.first >= 19 && clipped.first + clipped.weights().len() as u32 <= 21
                );
            }
        }
        assert_eq!(border(0.5), 0);
        assert_eq!(border(1.0), 1);
        assert_eq!(border(1.5), 1);
        assert_eq!(border(2.0), 2);
        assert_eq!(border(MAX_WIDTH), MAX_BORDER);
    }
}
