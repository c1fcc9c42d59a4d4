//! `Film "fleximage" "integer xresolution" [800] "integer yresolution" [600] ...`: the film's
//! description, LuxRender's defaults and their reading; sample buffers and the film: per-pixel
//! sums from units, merged in an order-independent way (exact fixed-point sums), tone mapped
//! and written as PNG or linear EXR.
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `xresolution`, `yresolution` | integer in 1..65536 | 800, 600 |
//! | `gamma` | float | 2.2 |
//! | `tonemapkernel` | string: autolinear, linear, reinhard, contrast | autolinear |
//! | `linear_sensitivity`, `linear_exposure`, `linear_fstop` | float | 50, 1, 2.8 |
//! | `reinhard_prescale`, `reinhard_postscale`, `reinhard_burn` | float | 1, 1, 6 |
//! | `contrast_ywa` | float | 1 |
//! | `filename` | string | "luxout" |
//! | `haltspp` | integer | none |
//! | `halttime` | float | none |
//!
//! Every film type is read as "fleximage" (with a warning); a scene without a `Film`
//! statement gets these defaults.

use std::path::Path;

use glam::Vec3;

use crate::diag::SourcePos;
use crate::math::luminance;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::render::unit::{FilmFrame, PixelRect, WorkUnit, BLOCK_SIZE};

/// The film type every `Film` statement is read as.
pub const FILM_TYPE: &str = "fleximage";
pub const DEFAULT_XRESOLUTION: i32 = 800;
pub const DEFAULT_YRESOLUTION: i32 = 600;
pub const DEFAULT_GAMMA: f32 = 2.2;
pub const DEFAULT_TONEMAP_KERNEL: &str = "autolinear";
pub const DEFAULT_LINEAR_SENSITIVITY: f32 = 50.0;
pub const DEFAULT_LINEAR_EXPOSURE: f32 = 1.0;
pub const DEFAULT_LINEAR_FSTOP: f32 = 2.8;
pub const DEFAULT_REINHARD_PRESCALE: f32 = 1.0;
pub const DEFAULT_REINHARD_POSTSCALE: f32 = 1.0;
pub const DEFAULT_REINHARD_BURN: f32 = 6.0;
pub const DEFAULT_CONTRAST_YWA: f32 = 1.0;
/// Output name without extension.
pub const DEFAULT_FILENAME: &str = "luxout";

#[derive(Clone, Debug, PartialEq)]
pub enum ToneMap {
    /// scale = 1.25 / Yavg x (118/255)^gamma over pixels with Y > 0.
    AutoLinear,
    Linear {
        sensitivity: f32,
        exposure: f32,
        fstop: f32,
    },
    Reinhard {
        prescale: f32,
        postscale: f32,
        burn: f32,
    },
    Contrast {
        ywa: f32,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct FilmDesc {
    pub xresolution: u32,
    pub yresolution: u32,
    pub gamma: f32,
    pub tonemap: ToneMap,
    /// Output name without extension, as the file gives it (default "luxout").
    pub filename: String,
    pub haltspp: Option<u32>,
    pub halttime: Option<f32>,
}

impl FilmDesc {
    /// The film of a scene without a `Film` statement: every default, no warnings.
    pub fn defaults(ctx: &mut dyn ParseContext) -> Result<Self, ParseError> {
        Self::read(
            ctx,
            FILM_TYPE,
            &ParamList::new(String::new(), Vec::new()),
            None,
        )
    }

    /// Reads `Film "ty"`; `pos` is None for the defaults (which warn about nothing).
    pub fn read(
        ctx: &mut dyn ParseContext,
        ty: &str,
        params: &ParamList,
        pos: Option<&SourcePos>,
    ) -> Result<Self, ParseError> {
        if let Some(pos) = pos {
            if ty != FILM_TYPE {
                ctx.warn(pos, format!("Film \"{ty}\" is read as \"fleximage\""));
            }
        }
        let resolution = |name: &str, default: i32| -> Result<u32, ParseError> {
            let v = params.int(name, default)?;
            match params.find(name) {
                Some(p) if !(1..=65536).contains(&v) => {
                    Err(params.error(p, format!("{v} is not a resolution in 1..65536")))
                }
                _ => Ok(v as u32),
            }
        };
        let xresolution = resolution("xresolution", DEFAULT_XRESOLUTION)?;
        let yresolution = resolution("yresolution", DEFAULT_YRESOLUTION)?;
        let kernel = params.string_or("tonemapkernel", DEFAULT_TONEMAP_KERNEL)?;
        let tonemap = match kernel.as_str() {
            "autolinear" => ToneMap::AutoLinear,
            "linear" => ToneMap::Linear {
                sensitivity: params.float("linear_sensitivity", DEFAULT_LINEAR_SENSITIVITY)?,
                exposure: params.float("linear_exposure", DEFAULT_LINEAR_EXPOSURE)?,
                fstop: params.float("linear_fstop", DEFAULT_LINEAR_FSTOP)?,
            },
            "reinhard" => ToneMap::Reinhard {
                prescale: params.float("reinhard_prescale", DEFAULT_REINHARD_PRESCALE)?,
                postscale: params.float("reinhard_postscale", DEFAULT_REINHARD_POSTSCALE)?,
                burn: params.float("reinhard_burn", DEFAULT_REINHARD_BURN)?,
            },
            "contrast" => ToneMap::Contrast {
                ywa: params.float("contrast_ywa", DEFAULT_CONTRAST_YWA)?,
            },
            other => {
                if let Some(pos) = pos {
                    ctx.warn(
                        pos,
                        format!("Film: unknown tonemapkernel \"{other}\"; using autolinear"),
                    );
                }
                ToneMap::AutoLinear
            }
        };
        // The parameters of the kernels not chosen are legitimately present in exported files.
        for name in [
            "linear_sensitivity",
            "linear_exposure",
            "linear_fstop",
            "linear_gamma",
            "reinhard_prescale",
            "reinhard_postscale",
            "reinhard_burn",
            "contrast_ywa",
        ] {
            params.ignore(name);
        }
        let haltspp = params.int("haltspp", -1)?;
        let halttime = params.float("halttime", -1.0)?;
        Ok(FilmDesc {
            xresolution,
            yresolution,
            gamma: params.float("gamma", DEFAULT_GAMMA)?,
            tonemap,
            filename: params.string_or("filename", DEFAULT_FILENAME)?,
            haltspp: (haltspp > 0).then_some(haltspp as u32),
            halttime: (halttime > 0.0).then_some(halttime),
        })
    }
}

/// A unit's result: per pixel of its region (its tile and the filter's border around it,
/// [`FilmFrame::region`], row-major), the sum of filter-weighted sample radiance and the sum of
/// the weights (16 bytes per pixel). An adaptive unit (one with a block mask) keeps these sums
/// per source plane ([`FilmFrame::source_planes`] regions, plane-major: a sample's sums go to the
/// plane of the block it was taken in), and the plain sums over its odd-index samples too, the
/// half the adaptive error estimate compares with the whole.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleBuffer {
    pub unit: WorkUnit,
    /// The pixels the sums are of.
    pub region: PixelRect,
    /// Per source plane of an adaptive unit (one plane otherwise), per pixel of the region.
    pub rgb: Vec<[f32; 3]>,
    pub weight: Vec<f32>,
    /// Sums of the odd-index samples: as long as `rgb` for a masked unit, else empty.
    pub half_rgb: Vec<[f32; 3]>,
    pub half_weight: Vec<f32>,
}

impl SampleBuffer {
    /// Zero sums over `unit`'s region of `frame`.
    pub fn new(unit: WorkUnit, frame: &FilmFrame) -> Self {
        let region = frame.region(&unit);
        let n = region.pixel_count();
        let (planes, half) = match unit.mask {
            Some(_) => (frame.source_planes(), n),
            None => (1, 0),
        };
        Self {
            unit,
            region,
            rgb: vec![[0.0; 3]; planes * n],
            weight: vec![0.0; planes * n],
            half_rgb: vec![[0.0; 3]; half],
            half_weight: vec![0.0; half],
        }
    }
}

/// Fixed-point scale of the film's sums: 2^-24 resolution, and room for sums up to 5e11.
const FIXED_ONE: f64 = (1u64 << 24) as f64;

/// The largest magnitude a sum can have in the film (2^39, about 5.5e11): a value beyond it
/// would saturate the fixed-point sums, so no honest sample buffer holds one.
pub const MAX_SUM: f32 = (i64::MAX as f64 / FIXED_ONE) as f32;

/// The largest radiance sum one pixel of a unit reports, half of [`MAX_SUM`]. A pixel that sees
/// the sun (about 1.3e9 cd/m^2, as LuxRender gives it) reaches [`MAX_SUM`] within a few hundred
/// samples: its unit's sums are clamped here, so the buffer stays one that every coordinator
/// accepts and the film saturates (the pixel is white in any tone map) instead of the unit
/// being refused as hostile.
pub const MAX_UNIT_SUM: f32 = MAX_SUM / 2.0;

/// A unit pixel's radiance sum as reported: clamped to [`MAX_UNIT_SUM`] in magnitude.
pub fn unit_sum(rgb: Vec3) -> [f32; 3] {
    rgb.clamp(Vec3::splat(-MAX_UNIT_SUM), Vec3::splat(MAX_UNIT_SUM))
        .to_array()
}

fn to_fixed(v: f32) -> i64 {
    // Truncation is as deterministic as rounding and compiles to one instruction (rounding calls
    // libm, which dominated the coordinator's merge time). `as` saturates and maps NaN to 0, so
    // a hostile buffer cannot wrap the sums.
    (f64::from(v) * FIXED_ONE) as i64
}

/// The accumulated image. Sums are integers, so adding buffers is associative and commutative:
/// the image does not depend on the order in which units arrive.
#[derive(Clone, Debug)]
pub struct Film {
    /// The size, and the border every unit's buffer has around its tile.
    frame: FilmFrame,
    /// Per pixel: R, G, B and weight sums in fixed point; an adaptive film keeps them per
    /// source plane (plane-major), see [`Film::pixel`].
    sums: Vec<[i64; 4]>,
    /// The same sums over the odd-index samples, kept only by an adaptive render's film (which
    /// takes only buffers that carry them); empty otherwise, so a uniform film costs nothing more.
    half: Vec<[i64; 4]>,
    /// An adaptive film's samples per pixel of each block (row-major), as its buffers added
    /// them; empty otherwise.
    block_samples: Vec<u32>,
}

#[derive(Debug, thiserror::Error)]
#[error("sample buffer of unit {index} does not fit the {width}x{height} film")]
pub struct BufferMismatch {
    pub index: u32,
    pub width: u32,
    pub height: u32,
}

impl Film {
    /// An empty film of `frame`'s size, taking buffers of `frame`'s border.
    pub fn new(frame: FilmFrame) -> Self {
        Self {
            frame,
            sums: vec![[0; 4]; frame.width as usize * frame.height as usize],
            half: Vec::new(),
            block_samples: Vec::new(),
        }
    }

    /// Bytes a film of `frame` (an adaptive render's if `adaptive`) takes at most: its sums,
    /// a copy of them while a checkpoint is written, and the radiance and image a file is
    /// written from.
    pub fn memory_bytes(frame: FilmFrame, adaptive: bool) -> u64 {
        let pixels = u64::from(frame.width) * u64::from(frame.height);
        let sum = std::mem::size_of::<[i64; 4]>() as u64;
        let sums = if adaptive {
            pixels * sum * (frame.source_planes() as u64 + 1)
                + block_count(&frame) as u64 * std::mem::size_of::<u32>() as u64
        } else {
            pixels * sum
        };
        let output = pixels * 2 * std::mem::size_of::<Vec3>() as u64;
        2 * sums + output
    }

    /// The film of an adaptive render: it keeps its sums per source plane, the sums of the
    /// odd-index samples and each block's samples, and takes only buffers of masked units.
    pub fn adaptive(frame: FilmFrame) -> Self {
        let pixels = frame.width as usize * frame.height as usize;
        Self {
            frame,
            sums: vec![[0; 4]; frame.source_planes() * pixels],
            half: vec![[0; 4]; pixels],
            block_samples: vec![0; block_count(&frame)],
        }
    }

    /// Whether the film is an adaptive render's (it keeps the half sums).
    pub fn has_half(&self) -> bool {
        !self.half.is_empty()
    }

    /// An adaptive film's samples per pixel of each block (row-major); empty otherwise.
    pub fn block_samples(&self) -> &[u32] {
        &self.block_samples
    }

    pub fn width(&self) -> u32 {
        self.frame.width
    }

    pub fn height(&self) -> u32 {
        self.frame.height
    }

    pub fn frame(&self) -> FilmFrame {
        self.frame
    }

    /// Per pixel (rows top to bottom): the R, G, B and weight sums in fixed point, exactly as
    /// merged; with [`Film::from_sums`] this is how a render is kept and resumed losslessly.
    pub fn sums(&self) -> &[[i64; 4]] {
        &self.sums
    }

    /// The half sums (of the odd-index samples) per pixel, as [`Film::sums`]; empty unless
    /// [`Film::has_half`].
    pub fn half_sums(&self) -> &[[i64; 4]] {
        &self.half
    }

    /// A film of `frame` holding these sums: a uniform film's (width x height sums, no half
    /// sums, no block samples) or an adaptive one's (as [`Film::adaptive`] has them); None
    /// otherwise.
    pub fn from_sums(
        frame: FilmFrame,
        sums: Vec<[i64; 4]>,
        half: Vec<[i64; 4]>,
        block_samples: Vec<u32>,
    ) -> Option<Self> {
        let pixels = frame.width as usize * frame.height as usize;
        let fits = if half.is_empty() {
            sums.len() == pixels && block_samples.is_empty()
        } else {
            sums.len() == frame.source_planes() * pixels
                && half.len() == pixels
                && block_samples.len() == block_count(&frame)
        };
        fits.then_some(Self {
            frame,
            sums,
            half,
            block_samples,
        })
    }

    /// Adds a unit's buffer. Exact and order-independent: adding the same buffers in any order
    /// gives the same bits, overlapping borders included. A buffer that does not fit (a tile
    /// outside the film, another region than the film's border gives the tile, a length not
    /// the region's, half sums where the film keeps none or none where it does) is refused.
    pub fn add(&mut self, buffer: &SampleBuffer) -> Result<(), BufferMismatch> {
        let u = &buffer.unit;
        let region = buffer.region;
        let tile_fits =
            u.x0 < u.x1 && u.y0 < u.y1 && u.x1 <= self.frame.width && u.y1 <= self.frame.height;
        // The region is only measured once it is known to be the tile's, grown and clipped.
        let n = if tile_fits && region == self.frame.region(u) {
            region.pixel_count()
        } else {
            usize::MAX
        };
        let (planes, half_len) = if self.has_half() {
            (self.frame.source_planes(), n)
        } else {
            (1, 0)
        };
        let fits = n != usize::MAX
            && buffer.rgb.len() == planes * n
            && buffer.weight.len() == planes * n
            && buffer.half_rgb.len() == half_len
            && buffer.half_weight.len() == half_len;
        if !fits {
            return Err(BufferMismatch {
                index: u.index,
                width: self.frame.width,
                height: self.frame.height,
            });
        }
        let width = self.frame.width;
        let pixels = width as usize * self.frame.height as usize;
        let planes = self.sums.chunks_exact_mut(pixels);
        let buffer_planes = buffer
            .rgb
            .chunks_exact(n)
            .zip(buffer.weight.chunks_exact(n));
        for (sums, (rgb, weight)) in planes.zip(buffer_planes) {
            add_region(sums, width, &region, rgb, weight);
        }
        if half_len > 0 {
            let columns = self.frame.width.div_ceil(BLOCK_SIZE);
            let samples = u.sample_end - u.sample_start;
            for (x, y, bit) in u.tile_blocks() {
                if u.mask.is_some_and(|mask| mask & bit != 0) {
                    let b = (y / BLOCK_SIZE * columns + x / BLOCK_SIZE) as usize;
                    self.block_samples[b] = self.block_samples[b].saturating_add(samples);
                }
            }
            add_region(
                &mut self.half,
                width,
                &region,
                &buffer.half_rgb,
                &buffer.half_weight,
            );
        }
        Ok(())
    }

    /// The radiance estimate of the pixel at `i` (row-major) from its odd-index samples alone
    /// (black without them, or when the film keeps no half sums).
    pub fn half_pixel(&self, i: usize) -> Vec3 {
        self.half.get(i).map_or(Vec3::ZERO, mean)
    }

    /// The pixel's radiance estimate: the weighted mean of its samples (black without samples).
    /// An adaptive film's blocks have different samples per pixel, and a wide filter reaches
    /// across blocks: a plain weighted mean would lean toward the block with more samples, a
    /// bias at every edge between blocks that no number of samples removes. So each source
    /// plane's sums (the samples of one block, [`FilmFrame::source_plane`]) are divided by that
    /// block's samples per pixel before they are added: every block then weighs as it would in
    /// a uniform render, whatever its samples.
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        let i = (y * self.frame.width + x) as usize;
        if !self.has_half() {
            return mean(&self.sums[i]);
        }
        let pixels = self.frame.width as usize * self.frame.height as usize;
        let [bx, by] = self.frame.border;
        // The blocks the filter reaches from (x, y): at most one per source plane.
        let span = |v: u32, border: u32, size: u32| {
            v.saturating_sub(border) / BLOCK_SIZE..=(v + border).min(size - 1) / BLOCK_SIZE
        };
        let columns = self.frame.width.div_ceil(BLOCK_SIZE);
        let mut total = [0.0f64; 4];
        for row in span(y, by, self.frame.height) {
            for column in span(x, bx, self.frame.width) {
                let n = self.block_samples[(row * columns + column) as usize];
                let plane = self
                    .frame
                    .source_plane(column * BLOCK_SIZE, row * BLOCK_SIZE);
                if n > 0 {
                    let sums = &self.sums[plane * pixels + i];
                    for (t, &s) in total.iter_mut().zip(sums) {
                        *t += s as f64 / f64::from(n);
                    }
                }
            }
        }
        let [r, g, b, w] = total;
        if w <= 0.0 {
            return Vec3::ZERO;
        }
        Vec3::new((r / w) as f32, (g / w) as f32, (b / w) as f32)
    }

    /// The plain weighted mean of all the samples that reach pixel `i` (row-major), whatever
    /// block they were taken in: what the half sums estimate too, so the two compare (the
    /// adaptive error estimate). The same as [`Film::pixel`] for a uniform film.
    pub fn plain_pixel(&self, i: usize) -> Vec3 {
        let pixels = self.frame.width as usize * self.frame.height as usize;
        let mut total = [0i64; 4];
        for sums in self.sums.iter().skip(i).step_by(pixels) {
            for (t, &s) in total.iter_mut().zip(sums) {
                *t = t.saturating_add(s);
            }
        }
        mean(&total)
    }

    /// Linear radiance of every pixel, rows top to bottom.
    pub fn radiance(&self) -> Vec<Vec3> {
        (0..self.frame.height)
            .flat_map(|y| (0..self.frame.width).map(move |x| (x, y)))
            .map(|(x, y)| self.pixel(x, y))
            .collect()
    }

    /// Tone maps as the scene's film asks and applies its gamma: 8-bit RGB, rows top to bottom.
    pub fn to_display(&self, film: &FilmDesc) -> image::RgbImage {
        let mut mapped = self.radiance();
        tone_map(&mut mapped, &film.tonemap, film.gamma);
        let inv_gamma = 1.0 / film.gamma.max(1e-3);
        let mut img = image::RgbImage::new(self.frame.width, self.frame.height);
        for (px, c) in img.pixels_mut().zip(mapped) {
            let encode = |v: f32| (libm::powf(v.clamp(0.0, 1.0), inv_gamma) * 255.0 + 0.5) as u8;
            *px = image::Rgb([encode(c.x), encode(c.y), encode(c.z)]);
        }
        img
    }

    pub fn write_png(&self, path: &Path, film: &FilmDesc) -> Result<(), image::ImageError> {
        self.to_display(film)
            .save_with_format(path, image::ImageFormat::Png)
    }

    /// Linear radiance as 32-bit float OpenEXR, no tone mapping.
    pub fn write_exr(&self, path: &Path) -> Result<(), image::ImageError> {
        let data: Vec<f32> = self
            .radiance()
            .into_iter()
            .flat_map(|c| [c.x, c.y, c.z])
            .collect();
        let img = image::Rgb32FImage::from_raw(self.frame.width, self.frame.height, data)
            .expect("buffer has width x height pixels");
        image::DynamicImage::ImageRgb32F(img).save_with_format(path, image::ImageFormat::OpenExr)
    }
}

/// Adds a region's f32 sums into rows of fixed-point sums.
fn add_region(
    sums: &mut [[i64; 4]],
    width: u32,
    region: &PixelRect,
    rgb: &[[f32; 3]],
    weight: &[f32],
) {
    let region_width = region.width() as usize;
    let rows = rgb
        .chunks_exact(region_width)
        .zip(weight.chunks_exact(region_width));
    for ((rgb, weight), y) in rows.zip(region.y0..region.y1) {
        let start = y as usize * width as usize + region.x0 as usize;
        let film_row = &mut sums[start..start + region_width];
        for ((sum, &[r, g, b]), &w) in film_row.iter_mut().zip(rgb).zip(weight) {
            for (s, v) in sum.iter_mut().zip([r, g, b, w]) {
                *s = s.saturating_add(to_fixed(v));
            }
        }
    }
}

/// Blocks of an adaptive film: [`BLOCK_SIZE`] squares, the last row and column cut short.
fn block_count(frame: &FilmFrame) -> usize {
    frame.width.div_ceil(BLOCK_SIZE) as usize * frame.height.div_ceil(BLOCK_SIZE) as usize
}

/// The weighted mean radiance of fixed-point sums; black without weight.
fn mean(&[r, g, b, w]: &[i64; 4]) -> Vec3 {
    if w <= 0 {
        return Vec3::ZERO;
    }
    let w = w as f64;
    Vec3::new(
        (r as f64 / w) as f32,
        (g as f64 / w) as f32,
        (b as f64 / w) as f32,
    )
}

/// LuxRender's tone mapping kernels, turning radiance in place into values to be gamma encoded.
pub fn tone_map(radiance: &mut [Vec3], tonemap: &ToneMap, gamma: f32) {
    // The mid-grey LuxRender aims autolinear and linear exposure at.
    let middle_grey = libm::powf(118.0f32 / 255.0, gamma);
    match *tonemap {
        ToneMap::AutoLinear => {
            let (sum, n) = radiance
                .iter()
                .map(|&c| luminance(c))
                .filter(|&y| y > 0.0 && y.is_finite())
                .fold((0.0f64, 0u64), |(s, n), y| (s + f64::from(y), n + 1));
            let y_avg = if n > 0 { (sum / n as f64) as f32 } else { 1.0 };
            let scale = 1.25 / y_avg * middle_grey;
            radiance.iter_mut().for_each(|c| *c *= scale);
        }
        ToneMap::Linear {
            sensitivity,
            exposure,
            fstop,
        } => {
            let scale = exposure / (fstop * fstop) * sensitivity * 0.65 / 10.0 * middle_grey;
            radiance.iter_mut().for_each(|c| *c *= scale);
        }
        ToneMap::Reinhard {
            prescale,
            postscale,
            burn,
        } => {
            let (log_sum, n) = radiance
                .iter()
                .map(|&c| luminance(c))
                .filter(|&y| y > 0.0 && y.is_finite())
                .fold((0.0f64, 0u64), |(s, n), y| {
                    (s + libm::log(f64::from(y)), n + 1)
                });
            let y_wa = if n > 0 {
                libm::exp(log_sum / n as f64) as f32
            } else {
                1.0
            };
            // LuxRender's global Reinhard (2002, equation 4) with key 0.1 over the log-average
            // luminance; burn is the white point, prescale divides the compressed luminance.
            let key = 0.1 / y_wa;
            let pre = key / prescale;
            let post = key * postscale;
            let inv_burn2 = if burn > 0.0 { 1.0 / (burn * burn) } else { 1e5 };
            radiance.iter_mut().for_each(|c| {
                let y = luminance(*c) * pre;
                *c *= post * (1.0 + y * inv_burn2) / (1.0 + y);
            });
        }
        ToneMap::Contrast { ywa } => {
            // Ward's contrast-based scale factor for display luminance 100 cd/m2.
            let ywa = ywa.max(1e-6);
            let scale = libm::powf(
                (1.219 + libm::powf(50f32, 0.4)) / (1.219 + libm::powf(ywa, 0.4)),
                2.5,
            ) / 100.0;
            radiance.iter_mut().for_each(|c| *c *= scale);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(index: u32, x0: u32, y0: u32, x1: u32, y1: u32) -> WorkUnit {
        WorkUnit {
            index,
            x0,
            y0,
            x1,
            y1,
            sample_start: 0,
            sample_end: 1,
            mask: None,
        }
    }

    fn buffer(u: WorkUnit, frame: &FilmFrame, seed: u32) -> SampleBuffer {
        let mut b = SampleBuffer::new(u, frame);
        for (i, (c, w)) in b.rgb.iter_mut().zip(&mut b.weight).enumerate() {
            let v = ((i as u32).wrapping_mul(2_654_435_761) ^ seed) as f32 / u32::MAX as f32;
            *c = [v * 1e3, v * 1e-4, 0.1 + v];
            *w = 3.0;
        }
        b
    }

    #[test]
    fn merging_is_order_independent_and_exact() {
        let frame = FilmFrame::unbordered(4, 3);
        let bufs: Vec<_> = (0..5)
            .map(|i| buffer(unit(i, 0, 0, 4, 3), &frame, i * 977))
            .collect();
        let mut forward = Film::new(frame);
        let mut backward = Film::new(frame);
        bufs.iter().for_each(|b| forward.add(b).unwrap());
        bufs.iter().rev().for_each(|b| backward.add(b).unwrap());
        assert_eq!(forward.sums, backward.sums);
        let expected: f32 = bufs.iter().map(|b| b.rgb[5][2]).sum::<f32>() / 15.0;
        assert!((forward.pixel(1, 1).z - expected).abs() < 1e-6);
    }

    /// Neighbouring tiles' borders overlap: every order of adding them gives the same bits, and
    /// a pixel under several borders holds the sum of what each buffer gave it.
    #[test]
    fn overlapping_borders_merge_in_any_order() {
        let frame = FilmFrame {
            width: 10,
            height: 7,
            border: [2, 1],
        };
        let tiles = [
            (0, 0, 4, 4),
            (4, 0, 8, 4),
            (8, 0, 10, 4),
            (0, 4, 4, 7),
            (4, 4, 10, 7),
        ];
        let bufs: Vec<_> = tiles
            .iter()
            .enumerate()
            .map(|(i, &(x0, y0, x1, y1))| {
                buffer(unit(i as u32, x0, y0, x1, y1), &frame, 31 * i as u32)
            })
            .collect();
        assert_eq!(
            bufs[1].region,
            PixelRect {
                x0: 2,
                y0: 0,
                x1: 10,
                y1: 5
            }
        );
        let orders = [[0, 1, 2, 3, 4], [4, 3, 2, 1, 0], [2, 4, 0, 3, 1]];
        let films: Vec<_> = orders
            .iter()
            .map(|order| {
                let mut film = Film::new(frame);
                order.iter().for_each(|&i| film.add(&bufs[i]).unwrap());
                film.sums
            })
            .collect();
        assert!(films.iter().all(|f| *f == films[0]));
        // Pixel (3, 4) lies in every region but the third's.
        let weight: i64 = [0, 1, 3, 4]
            .iter()
            .map(|&i| {
                let b = &bufs[i];
                let r = b.region;
                to_fixed(b.weight[((4 - r.y0) * r.width() + 3 - r.x0) as usize])
            })
            .sum();
        assert_eq!(films[0][4 * 10 + 3][3], weight);
        assert_eq!(weight, 4 * to_fixed(3.0));
    }

    #[test]
    fn a_misfit_buffer_is_refused() {
        let frame = FilmFrame::unbordered(4, 4);
        let mut film = Film::new(frame);
        let mut b = buffer(unit(0, 2, 2, 6, 4), &FilmFrame::unbordered(6, 4), 1);
        assert!(film.add(&b).is_err());
        b = buffer(unit(0, 0, 0, 4, 2), &frame, 1);
        b.weight.pop();
        assert!(film.add(&b).is_err());
    }

    /// A buffer whose border is not the film's (a worker whose filter reaches further, or less
    /// far) is refused, though its tile fits.
    #[test]
    fn a_buffer_of_another_border_is_refused() {
        let frame = FilmFrame {
            width: 16,
            height: 16,
            border: [2, 2],
        };
        let mut film = Film::new(frame);
        let u = unit(0, 4, 4, 8, 8);
        assert!(film.add(&buffer(u, &frame, 1)).is_ok());
        for border in [[0, 0], [1, 2], [2, 3]] {
            let other = FilmFrame { border, ..frame };
            assert!(film.add(&buffer(u, &other, 1)).is_err(), "{border:?}");
        }
        // The right region but one pixel short.
        let mut short = buffer(u, &frame, 1);
        short.rgb.pop();
        short.weight.pop();
        assert!(film.add(&short).is_err());
    }

    #[test]
    fn autolinear_maps_average_luminance_to_mid_grey() {
        let mut mapped = vec![Vec3::splat(2.0); 4];
        tone_map(&mut mapped, &ToneMap::AutoLinear, 2.2);
        let expected = 1.25 * libm::powf(118.0f32 / 255.0, 2.2);
        assert!((mapped[0].x - expected).abs() < 1e-5);
    }

    #[test]
    fn reinhard_compresses_highlights_and_keeps_hue() {
        let tm = ToneMap::Reinhard {
            prescale: 1.0,
            postscale: 1.0,
            burn: 7.0,
        };
        // A uniform image sits at the key: luminance 0.1 after scaling by 0.1 / Y.
        let mut grey = [Vec3::splat(4.0); 3];
        tone_map(&mut grey, &tm, 2.2);
        let expected = 4.0 * 0.1 / 4.0 * (1.0 + 0.1 / 49.0) / 1.1;
        assert!((grey[0].x - expected).abs() < 1e-6, "{}", grey[0].x);

        let mut mapped = [Vec3::new(0.1, 0.05, 0.02), Vec3::new(100.0, 50.0, 20.0)];
        tone_map(&mut mapped, &tm, 2.2);
        let ratio_out = mapped[1].x / mapped[0].x;
        assert!(ratio_out < 1000.0 / 3.0, "{ratio_out}");
        assert!((mapped[1].x / mapped[1].y - 2.0).abs() < 1e-4);
    }
}
