//! `PixelFilter "mitchell" "float xwidth" [2] "float ywidth" [2] ...`: pixel reconstruction
//! filters, their description, LuxRender's defaults and their reading.
//!
//! | type | parameters (defaults) | half-width default |
//! |---|---|---|
//! | `box` | | 0.5 |
//! | `triangle` | | 2 |
//! | `gaussian` | `alpha` (2) | 2 |
//! | `mitchell` (the default) | `B` (1/3), `C` (1/3), `supersample` (false) | 2 |
//! | `catmullrom` | (the Mitchell cubic with B = 0, C = 1/2) | 2 |
//! | `blackmanharris` | | 4 |
//! | `sinc` | `tau` (3) | 4 |
//!
//! Every type also takes `xwidth` and `ywidth` (positive half-widths in pixels, at most
//! [`MAX_WIDTH`]: a wider one is a warning and renders at that width). An unknown type is a
//! warning and renders with the default mitchell.
//!
//! As in LuxRender 1.x, mitchell is radial (its weight is that of the sample's distance measured
//! in half-widths, `sqrt((dx / xwidth)^2 + (dy / ywidth)^2)`), the others (catmullrom too) separable (the
//! product of the two axes' weights). A supersampled mitchell (LuxRender's `mitchell_ss`) is
//! 5/3 as wide, its profile the sum of three mitchells a third of a width apart.
//!
//! Samples are splatted through the filter ([`PixelFilter`]): each one adds its radiance,
//! weighted, to every pixel whose centre lies within the filter's half-widths, so a unit's
//! buffer covers its tile and a border of [`FilterDesc::border`] pixels around it
//! (docs/architecture.md). A pixel is the filter-weighted mean of the samples around it.

use glam::Vec2;

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
    Gaussian {
        alpha: f32,
    },
    Mitchell {
        b: f32,
        c: f32,
        supersample: bool,
    },
    /// The Mitchell-Netravali cubic with B = 0, C = 1/2, separable (as LuxRender's).
    CatmullRom,
    BlackmanHarris,
    Sinc {
        tau: f32,
    },
}

impl FilterKind {
    /// LuxRender's default filter: mitchell with B = C = 1/3, not supersampled.
    pub const MITCHELL: Self = Self::Mitchell {
        b: DEFAULT_MITCHELL_B,
        c: DEFAULT_MITCHELL_C,
        supersample: false,
    };

    /// Whether the weight is a function of the sample's distance in half-widths (mitchell, as
    /// LuxRender's), not a product of the axes' weights.
    fn is_radial(self) -> bool {
        matches!(self, Self::Mitchell { .. })
    }

    /// How much wider than its half-widths the filter reaches: 5/3 for a supersampled
    /// mitchell (LuxRender's `mitchell_ss`), else 1.
    fn widening(self) -> f32 {
        match self {
            Self::Mitchell {
                supersample: true, ..
            } => 5.0 / 3.0,
            _ => 1.0,
        }
    }
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
            kind: FilterKind::MITCHELL,
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
            "mitchell" => (
                FilterKind::Mitchell {
                    b: params.float("B", DEFAULT_MITCHELL_B)?,
                    c: params.float("C", DEFAULT_MITCHELL_C)?,
                    supersample: params.bool("supersample", false)?,
                },
                DEFAULT_WIDTH,
            ),
            "catmullrom" => (FilterKind::CatmullRom, DEFAULT_WIDTH),
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
                (FilterKind::MITCHELL, DEFAULT_WIDTH)
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

    /// The largest weight in magnitude at offsets from `near` on (the table entry before it
    /// included: a weight is interpolated between the two entries around its offset).
    fn max_from(&self, near: f32) -> f32 {
        let first = ((near * self.steps_per_pixel) as usize).min(TABLE_SIZE);
        self.table[first..]
            .iter()
            .fold(0.0f32, |m, v| m.max(v.abs()))
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

    /// The weight at `offset` pixels from the sample (what `weights4` computes four at a time;
    /// the tests hold the SSE lanes to it).
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
        let mut taps = self.reach(pixel, u, lo, hi);
        // Four weights at a time; the slots past `len` are computed and not read.
        let k0 = i64::from(taps.first) - i64::from(pixel);
        for (c, chunk) in taps.weights[..taps.len.next_multiple_of(4)]
            .chunks_exact_mut(4)
            .enumerate()
        {
            let k = [0, 1, 2, 3].map(|j| (k0 + (4 * c + j) as i64) as f32);
            chunk.copy_from_slice(&self.weights4(k.map(|k| k + 0.5 - u)));
        }
        taps
    }

    /// The pixels [`Self::taps`] reaches, their weights left zero.
    #[inline(always)]
    fn reach(&self, pixel: u32, u: f32, lo: u32, hi: u32) -> Taps {
        let b = self.border as i64;
        // Offsets k of the pixels pixel + k reached, k in [-border, border] (clamped: f32
        // rounding of u + radius may reach one further when u is just under 1).
        let first = (floor_to_int(u - self.radius - 0.5) + 1).clamp(-b, b);
        let last = floor_to_int(u + self.radius - 0.5).clamp(-b, b);
        let start = (i64::from(pixel) + first).max(i64::from(lo));
        let end = (i64::from(pixel) + last + 1).min(i64::from(hi));
        Taps {
            first: start.max(0) as u32,
            len: (end - start).clamp(0, MAX_TAPS as i64) as usize,
            weights: [0.0; TAP_SLOTS],
        }
    }

    /// `weight(offset)` for four offsets.
    #[cfg(not(target_arch = "x86_64"))]
    #[inline(always)]
    fn weights4(&self, offsets: [f32; 4]) -> [f32; 4] {
        offsets.map(|offset| self.weight(offset))
    }

    /// `weight(offset)` for four offsets, on SSE lanes (part of x86-64): each lane does
    /// `weight`'s operations in its order, so the weights have the same bits.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn weights4(&self, offsets: [f32; 4]) -> [f32; 4] {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of x86-64; the loads and stores use 4-float arrays. Each entry is
        // in 0..TABLE_SIZE (t is at least 0, a NaN offset becomes TABLE_SIZE at the first `min`,
        // and the second caps it below), so it and the next are inside the table's
        // TABLE_SIZE + 1 weights.
        unsafe {
            let offset = _mm_loadu_ps(offsets.as_ptr());
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
/// the two axes' weights or, for a radial filter, the weight of the offset's length in
/// half-widths (negative in mitchell's and sinc's lobes).
#[derive(Clone, Debug)]
pub struct PixelFilter {
    /// Per axis, the pixels a sample reaches and, for a separable filter, their weights.
    x: AxisWeights,
    y: AxisWeights,
    /// A radial filter's weight over the squared distance in half-widths, in [0, 1] (one axis
    /// of radius 1: no square root per pixel), and the half-widths it is measured in.
    radial: Option<(AxisWeights, [f32; 2])>,
}

impl PixelFilter {
    pub fn new(desc: &FilterDesc) -> Self {
        let kind = desc.kind;
        let [rx, ry] = desc.half_widths();
        if kind.is_radial() {
            // The axes only say which pixels a sample reaches: those of the bounding box.
            let reach = |radius: f32| AxisWeights::new(radius, |_| 1.0);
            return Self {
                x: reach(rx),
                y: reach(ry),
                radial: Some((
                    AxisWeights::new(1.0, |squared| filter_1d(kind, squared.sqrt(), 1.0)),
                    [rx, ry],
                )),
            };
        }
        let axis = |radius: f32| AxisWeights::new(radius, |x| filter_1d(kind, x, radius));
        Self {
            x: axis(rx),
            y: axis(ry),
            radial: None,
        }
    }

    /// The pixels of columns `lo.0..hi.0` and rows `lo.1..hi.1` a sample at `pixel + u`
    /// reaches, and their weights.
    #[inline(always)]
    pub fn footprint(
        &self,
        pixel: (u32, u32),
        u: Vec2,
        lo: (u32, u32),
        hi: (u32, u32),
    ) -> Footprint<'_> {
        let Some((profile, [rx, ry])) = &self.radial else {
            return Footprint {
                columns: self.x.taps(pixel.0, u.x, lo.0, hi.0),
                rows: self.y.taps(pixel.1, u.y, lo.1, hi.1),
                radial: None,
            };
        };
        // A radial filter's axes give only the pixels reached; each column's and row's squared
        // offset in half-widths gives the weights.
        let columns = self.x.reach(pixel.0, u.x, lo.0, hi.0);
        let rows = self.y.reach(pixel.1, u.y, lo.1, hi.1);
        let squares = |taps: &Taps, pixel: u32, u: f32, radius: f32| {
            let mut out = [0.0; TAP_SLOTS];
            let k0 = (i64::from(taps.first) - i64::from(pixel)) as f32;
            for (j, v) in out[..taps.len].iter_mut().enumerate() {
                let d = (k0 + j as f32 + 0.5 - u) / radius;
                *v = d * d;
            }
            out
        };
        Footprint {
            radial: Some(Radial {
                profile,
                columns: squares(&columns, pixel.0, u.x, *rx),
                rows: squares(&rows, pixel.1, u.y, *ry),
            }),
            columns,
            rows,
        }
    }

    /// Each pixel's filter mass in a `width` x `height` film: what its weight sum grows by
    /// per sample per pixel of area (the filter's integral over the film around the pixel;
    /// less at the edges, which have no samples beyond). A light splat, which no weight sum
    /// divides, is spread through the filter with each pixel's weight divided by that pixel's
    /// mass, so the pixel converges to the filtered mean its camera samples' weighted mean
    /// converges to, at the edges too.
    pub fn film_mass(&self, width: u32, height: u32) -> FilmMass {
        if self.radial.is_none() {
            return FilmMass::Separable {
                columns: self.x.film_mass(width),
                rows: self.y.film_mass(height),
            };
        }
        // The weight a sample gives the pixel (kx, ky) pixels from its own, integrated over
        // its position in its pixel (the midpoint rule on a grid).
        let (bx, by) = (self.x.border as i64, self.y.border as i64);
        let (nx, ny) = (2 * bx + 1, 2 * by + 1);
        let mut per_offset = vec![0.0f64; (nx * ny) as usize];
        let centre = (nx as u32, ny as u32);
        let cell = 1.0 / (RADIAL_MASS_STEPS * RADIAL_MASS_STEPS) as f64;
        for i in 0..RADIAL_MASS_STEPS {
            for j in 0..RADIAL_MASS_STEPS {
                let u = Vec2::new(
                    (i as f32 + 0.5) / RADIAL_MASS_STEPS as f32,
                    (j as f32 + 0.5) / RADIAL_MASS_STEPS as f32,
                );
                let f = self.footprint(centre, u, (0, 0), (2 * centre.0 + 1, 2 * centre.1 + 1));
                for row in 0..f.rows.len {
                    let ky = i64::from(f.rows.first) + row as i64 - i64::from(centre.1);
                    let weights = f.row(row);
                    for (column, &w) in weights[..f.columns.len].iter().enumerate() {
                        let kx = i64::from(f.columns.first) + column as i64 - i64::from(centre.0);
                        per_offset[((ky + by) * nx + kx + bx) as usize] += f64::from(w) * cell;
                    }
                }
            }
        }
        // A pixel's mass sums the offsets whose samples lie in the film: all of them away from
        // the edges.
        let full: f64 = per_offset.iter().sum();
        let (w, h) = (i64::from(width), i64::from(height));
        let mut pixels = Vec::with_capacity((width as usize) * (height as usize));
        for y in 0..h {
            for x in 0..w {
                let inside = x >= bx && x < w - bx && y >= by && y < h - by;
                let mass = if inside {
                    full
                } else {
                    let mut sum = 0.0;
                    for ky in -by..=by {
                        for kx in -bx..=bx {
                            if (0..w).contains(&(x - kx)) && (0..h).contains(&(y - ky)) {
                                sum += per_offset[((ky + by) * nx + kx + bx) as usize];
                            }
                        }
                    }
                    sum
                };
                pixels.push(mass as f32);
            }
        }
        FilmMass::PerPixel { width, pixels }
    }

    /// What the filter lets one sample add to a pixel's weight sum: the bounds an honest unit's
    /// buffer keeps.
    pub fn weight_bounds(&self) -> WeightBounds {
        match &self.radial {
            // A pixel k columns and l rows away lies at least t_k = (|k| - 1/2) / rx half-widths
            // away (and t_l), so its weight is at most M(max(t_k, t_l)) = min(M(t_k), M(t_l)),
            // M(t) the profile's largest magnitude from t on; a product bound is the square
            // roots', whose product is at least the smaller of the two.
            Some((profile, [rx, ry])) => {
                let axis = |border: u32, radius: f32| -> Vec<f32> {
                    let b = i64::from(border);
                    (-b..=b)
                        .map(|k| {
                            let near = (k.unsigned_abs() as f32 - 0.5).max(0.0) / radius;
                            profile.max_from(near * near).sqrt().next_up()
                        })
                        .collect()
                };
                WeightBounds {
                    negative: profile.has_negative_weights(),
                    x: axis(self.x.border, *rx),
                    y: axis(self.y.border, *ry),
                }
            }
            None => WeightBounds {
                negative: self.x.has_negative_weights() || self.y.has_negative_weights(),
                x: self.x.max_weights(),
                y: self.y.max_weights(),
            },
        }
    }
}

/// The weights one sample gives the pixels it reaches ([`PixelFilter::footprint`]): a run of
/// columns in each of a run of rows.
pub struct Footprint<'a> {
    pub columns: Taps,
    pub rows: Taps,
    radial: Option<Radial<'a>>,
}

/// A radial filter's profile and the squared offsets, in half-widths, of a footprint's columns
/// and rows.
struct Radial<'a> {
    profile: &'a AxisWeights,
    columns: [f32; TAP_SLOTS],
    rows: [f32; TAP_SLOTS],
}

impl Footprint<'_> {
    /// The number of rows reached (`rows.first` the first).
    pub fn row_count(&self) -> usize {
        self.rows.len
    }

    /// The number of columns reached in each row (`columns.first` the first).
    pub fn column_count(&self) -> usize {
        self.columns.len
    }

    /// The weights of row `row`'s pixels (the first [`Self::column_count`] slots): a separable
    /// filter's `wx * wy`, a radial one's weight at the offset's length.
    #[inline(always)]
    pub fn row(&self, row: usize) -> [f32; TAP_SLOTS] {
        let mut out = [0.0; TAP_SLOTS];
        let n = self.columns.len;
        match &self.radial {
            None => {
                let wy = self.rows.weights[row];
                for (w, &wx) in out[..n].iter_mut().zip(&self.columns.weights[..n]) {
                    *w = wx * wy;
                }
            }
            Some(r) => {
                // Four weights at a time; the slots past `n` are computed and not read.
                let dy = r.rows[row];
                let slots = n.next_multiple_of(4);
                for (w, dx) in out[..slots]
                    .chunks_exact_mut(4)
                    .zip(r.columns[..slots].chunks_exact(4))
                {
                    w.copy_from_slice(&r.profile.weights4([0, 1, 2, 3].map(|j| dx[j] + dy)));
                }
            }
        }
        out
    }
}

/// Sample positions per pixel and axis [`PixelFilter::film_mass`] integrates a radial filter
/// over (a separable one's axes take [`MASS_STEPS`] each).
const RADIAL_MASS_STEPS: usize = 256;

/// Sample positions per pixel [`PixelFilter::film_mass`] integrates over.
const MASS_STEPS: usize = 1024;

/// Each pixel's filter mass in a film ([`PixelFilter::film_mass`]): per column and per row for
/// a separable filter, per pixel for a radial one.
#[derive(Clone, Debug)]
pub enum FilmMass {
    Separable { columns: Vec<f32>, rows: Vec<f32> },
    PerPixel { width: u32, pixels: Vec<f32> },
}

impl FilmMass {
    /// The mass of pixel (x, y), which must lie in the film.
    pub fn at(&self, x: u32, y: u32) -> f32 {
        match self {
            Self::Separable { columns, rows } => columns[x as usize] * rows[y as usize],
            Self::PerPixel { width, pixels } => pixels[(y * width + x) as usize],
        }
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
    /// magnitude along that axis (a sample's weight is at most the product of its two axes').
    pub x: Vec<f32>,
    pub y: Vec<f32>,
}

impl FilterDesc {
    /// Pixels a sample reaches beyond its own, per axis: the border of every unit's buffer.
    pub fn border(&self) -> [u32; 2] {
        self.half_widths().map(border)
    }

    /// The half-widths as rendered: a supersampled mitchell's 5/3 of the file's, each at most
    /// [`MAX_WIDTH`].
    pub fn half_widths(&self) -> [f32; 2] {
        let widening = self.kind.widening();
        [self.xwidth, self.ywidth].map(|w| clamp_width(w * widening))
    }
}

/// Mitchell-Netravali's cubic at `t` half-widths (LuxRender's `Mitchell1D`), 0 from one
/// half-width on.
fn mitchell_cubic(b: f32, c: f32, t: f32) -> f32 {
    let x = (2.0 * t).abs();
    if x >= 2.0 {
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

/// One axis of LuxRender's separable filters, `x` in [-radius, radius]; for mitchell, which is
/// radial, its profile over the distance `x` (in [0, radius]).
fn filter_1d(kind: FilterKind, x: f32, radius: f32) -> f32 {
    use std::f32::consts::PI;
    match kind {
        FilterKind::Box => 1.0,
        FilterKind::Triangle => (radius - x.abs()).max(0.0),
        FilterKind::Gaussian { alpha } => {
            (libm::expf(-alpha * x * x) - libm::expf(-alpha * radius * radius)).max(0.0)
        }
        FilterKind::Mitchell { b, c, supersample } => {
            let t = x / radius;
            if supersample {
                // LuxRender's mitchell_ss: three cubics 0.4 half-widths apart, weighed so the
                // sum's integral is the cubic's.
                let a0 = (76.0 - 16.0 * b + 8.0 * c) / 81.0;
                let a1 = (1.0 - a0) / 2.0;
                let d = t.abs() / 0.6;
                a1 * mitchell_cubic(b, c, d - 2.0 / 3.0)
                    + a0 * mitchell_cubic(b, c, d)
                    + a1 * mitchell_cubic(b, c, d + 2.0 / 3.0)
            } else {
                mitchell_cubic(b, c, t)
            }
        }
        FilterKind::CatmullRom => mitchell_cubic(0.0, 0.5, x / radius),
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
            (FilterKind::BlackmanHarris, 1.5),
        ] {
            let f = filter(kind, width);
            let n = 4000;
            let mean: f64 = (0..n)
                .map(|i| {
                    let u = (i as f32 + 0.5) / n as f32;
                    f64::from(f.x.taps(10, u, 0, 20).weights().iter().sum::<f32>())
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
                            let taps = f.x.taps(p, u, 0, 20);
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
            let taps = f.x.taps(7, u, 0, 20);
            assert_eq!((taps.first, taps.weights()), (7, &[1.0][..]), "{u}");
        }
    }

    #[test]
    fn weights_follow_the_filter_within_the_radius() {
        let kind = FilterKind::BlackmanHarris;
        let f = filter(kind, 2.0);
        for i in 0..100 {
            let u = (i as f32 + 0.5) / 100.0;
            let taps = f.x.taps(10, u, 0, 20);
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
            let offsets = [0.0, 1000.0, -1000.0, 2.5];
            let four = axis.weights4(offsets);
            for j in 0..4 {
                assert_eq!(
                    four[j].to_bits(),
                    axis.weight(offsets[j]).to_bits(),
                    "{offsets:?}"
                );
            }
        }
    }

    /// Every weight a sample gives a pixel is within the bound for its offset, and at least 0
    /// for the filters without negative lobes; the bounds are those weights' largest (within
    /// the table's interpolation), not a loose guess.
    #[test]
    fn weight_bounds_hold_every_weight_and_say_which_filters_weigh_negatively() {
        for (kind, radius, negative) in [
            (FilterKind::Box, 0.5, false),
            (FilterKind::Box, 2.5, false),
            (FilterKind::Triangle, 2.0, false),
            (FilterKind::Gaussian { alpha: 2.0 }, 2.0, false),
            (FilterKind::Gaussian { alpha: 0.5 }, 3.3, false),
            (FilterKind::BlackmanHarris, 2.0, false),
            (FilterKind::BlackmanHarris, 4.0, false),
            (FilterKind::CatmullRom, 2.0, true),
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
                let taps = filter.x.taps(20, u, 0, 40);
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

    /// A radial filter's weights, in any footprint: within their bounds by offset, at most 1
    /// (and negative for mitchell's parameters that have lobes), the offsets' length in half-widths through its
    /// profile, so not the product of the axes' weights.
    #[test]
    fn mitchell_is_radial_as_luxrenders_and_within_its_bounds() {
        let sharper = FilterKind::Mitchell {
            b: 0.0,
            c: 0.5,
            supersample: false,
        };
        for (kind, rx, ry) in [(FilterKind::MITCHELL, 2.0, 1.5), (sharper, 2.0, 2.0)] {
            let f = PixelFilter::new(&FilterDesc {
                kind,
                xwidth: rx,
                ywidth: ry,
            });
            let bounds = f.weight_bounds();
            assert!(bounds.negative, "{kind:?}");
            let peak = filter_1d(kind, 0.0, 1.0);
            let mut worst = 0.0f32;
            for i in 0..40 {
                let u = Vec2::new((i as f32 + 0.5) / 40.0, ((i * 7) % 40) as f32 / 40.0);
                let fp = f.footprint((20, 20), u, (0, 0), (40, 40));
                for row in 0..fp.row_count() {
                    let weights = fp.row(row);
                    let dy = (fp.rows.first + row as u32) as f32 + 0.5 - (20.0 + u.y);
                    for (column, &w) in weights[..fp.column_count()].iter().enumerate() {
                        let dx = (fp.columns.first + column as u32) as f32 + 0.5 - (20.0 + u.x);
                        let d = ((dx / rx).powi(2) + (dy / ry).powi(2)).sqrt();
                        let exact = filter_1d(kind, d.min(1.0), 1.0) / peak;
                        let (kx, ky) = (
                            (fp.columns.first + column as u32 + f.x.border - 20) as usize,
                            (fp.rows.first + row as u32 + f.y.border - 20) as usize,
                        );
                        let bound = bounds.x[kx] * bounds.y[ky];
                        assert!(w.abs() <= bound.min(1.0), "{kind:?}: {w} over {bound}");
                        worst = worst.max((w - exact).abs());
                    }
                }
            }
            assert!(worst < 1e-3, "{kind:?}: off the radial profile by {worst}");
        }
        // At (1.2, 1.2) half-widths of 2 pixels from the sample, the product of the axes'
        // weights would be positive (two negative lobes); the radial weight at 0.85 half-widths
        // is negative.
        let f = filter(FilterKind::MITCHELL, 2.0);
        let fp = f.footprint((10, 10), Vec2::splat(0.3), (0, 0), (20, 20));
        assert_eq!((fp.columns.first, fp.rows.first), (8, 8));
        let w = fp.row(3)[3];
        assert!(
            w < 0.0 && filter_1d(FilterKind::MITCHELL, 1.2, 2.0) < 0.0,
            "{w}"
        );
    }

    /// LuxRender's supersampled mitchell: 5/3 the half-widths, its profile three cubics whose
    /// sum integrates as one does (along the distance, in pixels) and peaks at the centre.
    #[test]
    fn supersampled_mitchell_is_wider_with_three_lobes() {
        let ss = FilterKind::Mitchell {
            b: DEFAULT_MITCHELL_B,
            c: DEFAULT_MITCHELL_C,
            supersample: true,
        };
        let desc = FilterDesc {
            kind: ss,
            xwidth: 1.5,
            ywidth: 1.5,
        };
        assert_eq!(desc.half_widths(), [2.5, 2.5]);
        assert_eq!(desc.border(), [2, 2]);
        let integral = |kind: FilterKind| -> f64 {
            let n = 100_000;
            (0..n)
                .map(|i| f64::from(filter_1d(kind, (i as f32 + 0.5) / n as f32, 1.0)))
                .sum::<f64>()
                / f64::from(n)
        };
        // Over the distance in pixels, 5/3 as wide: the cubic's integral at the file's width.
        let (one, three) = (integral(FilterKind::MITCHELL), integral(ss));
        assert!(
            (three * 5.0 / 3.0 / one - 1.0).abs() < 0.01,
            "{three} vs {one}"
        );
        assert!(filter_1d(ss, 0.0, 1.0) > filter_1d(ss, 0.3, 1.0));
        assert!(filter_1d(ss, 1.0, 1.0).abs() < 1e-6);
    }

    /// A radial filter's film mass: its 2D integral inside the film, the part whose samples lie
    /// in the film at an edge and a corner (summed here sample by sample).
    #[test]
    fn a_radial_filters_film_mass_is_its_integral_within_the_film() {
        let f = PixelFilter::new(&FilterDesc {
            kind: FilterKind::MITCHELL,
            xwidth: 2.0,
            ywidth: 1.5,
        });
        let mass = f.film_mass(12, 10);
        let n = 200;
        let measured = |x: u32, y: u32| -> f64 {
            let mut sum = 0.0;
            for sy in 0..10u32 {
                for sx in 0..12u32 {
                    for i in 0..n {
                        let u = Vec2::new(
                            (i as f32 + 0.5) / n as f32,
                            ((i * 37) % n) as f32 / n as f32 + 0.5 / n as f32,
                        );
                        let fp = f.footprint((sx, sy), u, (0, 0), (12, 10));
                        if (fp.rows.first..fp.rows.first + fp.row_count() as u32).contains(&y)
                            && (fp.columns.first..fp.columns.first + fp.column_count() as u32)
                                .contains(&x)
                        {
                            let row = fp.row((y - fp.rows.first) as usize);
                            sum += f64::from(row[(x - fp.columns.first) as usize]);
                        }
                    }
                }
            }
            sum / f64::from(n)
        };
        for (x, y) in [(6, 5), (0, 5), (0, 0)] {
            let (want, got) = (measured(x, y), f64::from(mass.at(x, y)));
            assert!(
                (got / want - 1.0).abs() < 0.01,
                "({x}, {y}): {got} vs {want}"
            );
        }
        assert!(mass.at(0, 0) < mass.at(0, 5) && mass.at(0, 5) < mass.at(6, 5));
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
                let taps = f.x.taps(20, u, 0, 100);
                let n = taps.weights().len() as u32;
                assert!(
                    taps.first >= 20 - b && taps.first + n <= 21 + b,
                    "{width} {u}"
                );
                let clipped = f.x.taps(20, u, 19, 21);
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
