//! `Film "fleximage" "integer xresolution" [800] "integer yresolution" [600] ...`: the film's
//! description, LuxRender's defaults and their reading; sample buffers and the film: per-pixel
//! sums from units, merged in an order-independent way (exact fixed-point sums), tone mapped
//! and handed to the writers of the files the Film asks for ([`outputs`]). A bidirectional
//! render's units carry light splats too, merged into sums of their own ([`splats`]).
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `xresolution`, `yresolution` | integer in 1..65536 | 800, 600 |
//! | `gamma` | float | 2.2 |
//! | `tonemapkernel` | string: autolinear, linear, reinhard, contrast | autolinear |
//! | `linear_sensitivity`, `linear_exposure`, `linear_fstop` | float | 50, 1, 2.8 |
//! | `linear_gamma` | float | 1: the linear kernel aims its exposure at (118/255)^linear_gamma |
//! | `reinhard_prescale`, `reinhard_postscale`, `reinhard_burn` | float | 1, 1, 6 |
//! | `contrast_ywa` | float | 1 |
//! | `filename` | string | "luxout" |
//! | `haltspp` | integer | none |
//! | `halttime` | float | none |
//! | `outlierrejection_k` | integer | 0 (off): LuxRender's outlier rejection (`render::outliers`) |
//! | `haltthreshold` | float | none (LuxRender's -1): from 0 on, rendering halts once at most this fraction of the pixels still fails LuxRender's convergence test (a perceptual comparison of the image with itself every `convergencestep` samples per pixel); 1 halts at the first test |
//! | `write_*`, `ldr_clamp_method` | | the files written: [`outputs`] |
//!
//! LuxRender 1.x registers "multiimage" (LuxRender 0.x's film) as another name of fleximage:
//! it is read as fleximage, and the parameters only multiimage had are ignored, as LuxRender
//! 1.x ignores them. Any other film type fails LuxRender's scene; YAT reads it as fleximage
//! with a warning. A scene without a `Film` statement gets these defaults. What the other
//! parameters LuxRender reads do here: [`crate::parse::luxrender_params`].

use glam::Vec3;

use crate::diag::SourcePos;
use crate::math::luminance;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::render::outliers::MAX_OUTLIER_K;
use crate::render::unit::{FilmFrame, PixelRect, WorkUnit, BLOCK_SIZE};

pub mod light_groups;
pub mod outputs;
pub mod splats;

pub use light_groups::{LightGroupDesc, LightGroups, MAX_LIGHT_GROUPS};
pub use outputs::{AovImages, FilmImage, FilmOutputs, OutputError, OutputFile};
pub use splats::{FilmSplats, LightSplats, SplatMisfit, SplatSums, MAX_SPLAT_PIXELS};

/// The film type every `Film` statement is read as.
pub const FILM_TYPE: &str = "fleximage";
/// The other name LuxRender 1.x registers fleximage under.
pub const FILM_ALIAS: &str = "multiimage";
pub const DEFAULT_XRESOLUTION: i32 = 800;
pub const DEFAULT_YRESOLUTION: i32 = 600;
pub const DEFAULT_GAMMA: f32 = 2.2;
pub const DEFAULT_TONEMAP_KERNEL: &str = "autolinear";
pub const DEFAULT_LINEAR_SENSITIVITY: f32 = 50.0;
pub const DEFAULT_LINEAR_EXPOSURE: f32 = 1.0;
pub const DEFAULT_LINEAR_FSTOP: f32 = 2.8;
pub const DEFAULT_LINEAR_GAMMA: f32 = 1.0;
pub const DEFAULT_REINHARD_PRESCALE: f32 = 1.0;
pub const DEFAULT_REINHARD_POSTSCALE: f32 = 1.0;
pub const DEFAULT_REINHARD_BURN: f32 = 6.0;
pub const DEFAULT_CONTRAST_YWA: f32 = 1.0;
/// Output name without extension.
pub const DEFAULT_FILENAME: &str = "luxout";
/// LuxRender 1.x's samples per pixel between convergence tests, and the fewest it takes.
pub const DEFAULT_CONVERGENCE_STEP: f32 = 32.0;
pub const MIN_CONVERGENCE_STEP: f32 = 4.0;
/// The most YAT takes: a round between tests is one unit per tile, and 1024 samples keep such
/// a unit to seconds.
pub const MAX_CONVERGENCE_STEP: f32 = 1024.0;

#[derive(Clone, Debug, PartialEq)]
pub enum ToneMap {
    /// scale = 1.25 / Yavg x (118/255)^gamma over pixels with Y > 0.
    AutoLinear,
    /// scale = exposure / fstop^2 x sensitivity x 0.65 / 10 x (118/255)^gamma, with the
    /// kernel's own gamma (`linear_gamma`), not the film's.
    Linear {
        sensitivity: f32,
        exposure: f32,
        fstop: f32,
        gamma: f32,
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
    /// The fraction of pixels still failing LuxRender's convergence test at which it halts
    /// (in [0, 1]; None when the file gives none or a negative one, LuxRender's "off").
    pub haltthreshold: Option<f32>,
    /// Samples per pixel between convergence tests (LuxRender's `convergencestep`; at least
    /// [`MIN_CONVERGENCE_STEP`]).
    pub convergence_step: f32,
    /// Which files the render writes, and how ([`outputs`]).
    pub outputs: FilmOutputs,
    /// The scene's light groups ([`light_groups`]): the `LightGroup` statements of the world
    /// block, which the parser adds once it has read them.
    pub light_groups: LightGroups,
    /// LuxRender's `outlierrejection_k`: 0 keeps every sample, k > 0 drops the samples
    /// `render::outliers` finds to be outliers among their k nearest (at most
    /// [`MAX_OUTLIER_K`]).
    pub outlier_k: u32,
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
            if ty != FILM_TYPE && ty != FILM_ALIAS {
                ctx.warn(
                    pos,
                    format!("Film \"{ty}\" is not a LuxRender 1.x film (LuxRender cannot render the scene); read as \"fleximage\""),
                );
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
                gamma: params.float("linear_gamma", DEFAULT_LINEAR_GAMMA)?,
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
        // The parameters of the kernels not chosen are legitimately present in exported files
        // (and those of falsecolors, which is reported above where it is chosen).
        for name in [
            "linear_sensitivity",
            "linear_exposure",
            "linear_fstop",
            "linear_gamma",
            "reinhard_prescale",
            "reinhard_postscale",
            "reinhard_burn",
            "contrast_ywa",
            "false_method",
            "false_colorscale",
            "false_max",
            "false_min",
        ] {
            params.ignore(name);
        }
        let outlier_k = params.int("outlierrejection_k", 0)?;
        if outlier_k > MAX_OUTLIER_K as i32 {
            if let Some(pos) = pos {
                ctx.warn(
                    pos,
                    format!(
                        "outlierrejection_k {outlier_k} is read as {MAX_OUTLIER_K}, the most \
                         neighbours YAT's outlier test asks for"
                    ),
                );
            }
        }
        let haltspp = params.int("haltspp", -1)?;
        let halttime = params.float("halttime", -1.0)?;
        let haltthreshold = params.float("haltthreshold", -1.0)?;
        let convergence_step = params.float("convergencestep", DEFAULT_CONVERGENCE_STEP)?;
        Ok(FilmDesc {
            xresolution,
            yresolution,
            gamma: params.float("gamma", DEFAULT_GAMMA)?,
            tonemap,
            filename: params.string_or("filename", DEFAULT_FILENAME)?,
            haltspp: (haltspp > 0).then_some(haltspp as u32),
            halttime: (halttime > 0.0).then_some(halttime),
            haltthreshold: (haltthreshold >= 0.0).then_some(haltthreshold.min(1.0)),
            convergence_step: if convergence_step.is_finite() {
                convergence_step.clamp(MIN_CONVERGENCE_STEP, MAX_CONVERGENCE_STEP)
            } else {
                DEFAULT_CONVERGENCE_STEP
            },
            outputs: FilmOutputs::read(ctx, params, pos)?,
            light_groups: LightGroups::default(),
            outlier_k: outlier_k.clamp(0, MAX_OUTLIER_K as i32) as u32,
        })
    }
}

/// A unit's result: per pixel of its region (its tile and the filter's border around it,
/// [`FilmFrame::region`], row-major), the sum of filter-weighted sample radiance and the sum of
/// the weights (16 bytes per pixel). An adaptive unit (one with a block mask) keeps these sums
/// per source plane ([`FilmFrame::source_planes`] regions, plane-major: a sample's sums go to the
/// plane of the block it was taken in), and the plain sums over its odd-index samples too, the
/// half the adaptive error estimate compares with the whole. A unit of a film with light splats
/// carries those as well, wherever on the film they land; one of a film with layers
/// ([`FilmFrame::layers`]: alpha) their filter-weighted sums per pixel.
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
    /// The unit's light splats; empty unless its film keeps them ([`FilmFrame::light_splats`]).
    pub splats: LightSplats,
    /// The layers' sums: `frame.layers.len()` per pixel (pixel-major), per source plane as
    /// `rgb` is; empty when the film keeps no layer.
    pub layers: Vec<f32>,
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
            splats: LightSplats::default(),
            layers: vec![0.0; planes * n * frame.layers.len()],
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
    /// The light splats' sums, kept only when the frame has light splats.
    splats: Option<FilmSplats>,
    /// The layers' sums in fixed point, `frame.layers.len()` per pixel, per source plane as
    /// `sums`; empty when the frame has no layer.
    layers: Vec<i64>,
}

#[derive(Debug, thiserror::Error)]
#[error("sample buffer of unit {index} does not fit the {width}x{height} film: {reason}")]
pub struct BufferMismatch {
    pub index: u32,
    pub width: u32,
    pub height: u32,
    pub reason: String,
}

impl Film {
    /// An empty film of `frame`'s size, taking buffers of `frame`'s border (and light splats,
    /// if the frame has them).
    pub fn new(frame: FilmFrame) -> Self {
        let pixels = frame.width as usize * frame.height as usize;
        Self {
            frame,
            sums: vec![[0; 4]; pixels],
            half: Vec::new(),
            block_samples: Vec::new(),
            splats: frame
                .light_splats
                .then(|| FilmSplats::new(frame.splat_entries() as usize)),
            layers: vec![0; pixels * frame.layers.len()],
        }
    }

    /// Bytes a film of `frame` (an adaptive render's if `adaptive`) takes at most: its sums,
    /// a copy of them while a checkpoint is written, and what a file is written from (the
    /// linear and tone-mapped radiance, alpha, and the file's samples: at most four 32-bit
    /// floats a pixel; and each layer's values, twice: the AOVs' images and the EXR's
    /// channels).
    pub fn memory_bytes(frame: FilmFrame, adaptive: bool) -> u64 {
        let pixels = u64::from(frame.width) * u64::from(frame.height);
        let sum = std::mem::size_of::<[i64; 4]>() as u64;
        let splat_sum = std::mem::size_of::<[i64; 3]>() as u64;
        let planes = if adaptive {
            frame.source_planes() as u64
        } else {
            1
        };
        let sums = if adaptive {
            pixels * sum * (planes + 1)
                + block_count(&frame) as u64 * std::mem::size_of::<u32>() as u64
        } else {
            pixels * sum
        } + frame.splat_entries() * splat_sum
            + planes * pixels * 8 * frame.layers.len() as u64;
        let layers = 2 * 4 * frame.layers.len() as u64;
        let output = pixels * (2 * std::mem::size_of::<Vec3>() as u64 + 4 + 16 + layers);
        2 * sums + output
    }

    /// The film of an adaptive render: it keeps its sums per source plane, the sums of the
    /// odd-index samples and each block's samples, and takes only buffers of masked units.
    ///
    /// # Panics
    ///
    /// If `frame` has light splats: a bidirectional render is never adaptive (its light
    /// splats land outside the blocks whose samples an adaptive film counts, so no block's
    /// error estimate would hold them), and the render is refused before a film is made.
    pub fn adaptive(frame: FilmFrame) -> Self {
        assert!(
            !frame.light_splats,
            "adaptive sampling is refused for renders with light splats"
        );
        let pixels = frame.width as usize * frame.height as usize;
        Self {
            frame,
            sums: vec![[0; 4]; frame.source_planes() * pixels],
            half: vec![[0; 4]; pixels],
            block_samples: vec![0; block_count(&frame)],
            splats: None,
            layers: vec![0; frame.source_planes() * pixels * frame.layers.len()],
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

    /// The light splats' sums and the light paths they are over: Some exactly when the frame
    /// has light splats. With [`Film::from_sums`], kept and resumed losslessly as the sums are.
    pub fn splats(&self) -> Option<&FilmSplats> {
        self.splats.as_ref()
    }

    /// The layers' sums (`frame.layers.len()` per pixel, per source plane), as
    /// [`Film::sums`]; empty when the frame has no layer.
    pub fn layer_sums(&self) -> &[i64] {
        &self.layers
    }

    /// A film of `frame` holding these sums: a uniform film's (width x height sums, no half
    /// sums, no block samples) or an adaptive one's (as [`Film::adaptive`] has them), with
    /// light splat sums over width x height pixels exactly when the frame has light splats
    /// (and is not adaptive), and the layers' sums per pixel of every plane the sums have;
    /// None otherwise.
    pub fn from_sums(
        frame: FilmFrame,
        sums: Vec<[i64; 4]>,
        half: Vec<[i64; 4]>,
        block_samples: Vec<u32>,
        splats: Option<FilmSplats>,
        layers: Vec<i64>,
    ) -> Option<Self> {
        let pixels = frame.width as usize * frame.height as usize;
        let fits = if half.is_empty() {
            sums.len() == pixels && block_samples.is_empty()
        } else {
            sums.len() == frame.source_planes() * pixels
                && half.len() == pixels
                && block_samples.len() == block_count(&frame)
                && !frame.light_splats
        };
        let splats_fit = match &splats {
            Some(splats) => frame.light_splats && splats.sums.len() as u64 == frame.splat_entries(),
            None => !frame.light_splats,
        };
        let layers_fit = layers.len() == sums.len() * frame.layers.len();
        (fits && splats_fit && layers_fit).then_some(Self {
            frame,
            sums,
            half,
            block_samples,
            splats,
            layers,
        })
    }

    /// Adds a unit's buffer. Exact and order-independent: adding the same buffers in any order
    /// gives the same bits, overlapping borders included. A buffer that does not fit (a tile
    /// outside the film, another region than the film's border gives the tile, a length not
    /// the region's, half sums where the film keeps none or none where it does, layer sums not
    /// those of the film's layers, light splats that fail [`LightSplats::check`]) is refused. The unit's light paths (one per camera
    /// sample) count toward the film's when it keeps light splats, whether or not any of them
    /// reached the camera.
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
            && buffer.half_weight.len() == half_len
            && buffer.layers.len() == planes * n * self.frame.layers.len();
        let misfit = |reason: String| BufferMismatch {
            index: u.index,
            width: self.frame.width,
            height: self.frame.height,
            reason,
        };
        if !fits {
            return Err(misfit(format!(
                "its tile, region or lengths are not those the film's border of {:?} gives",
                self.frame.border
            )));
        }
        buffer
            .splats
            .check(&self.frame)
            .map_err(|e| misfit(e.to_string()))?;
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
        let k = self.frame.layers.len();
        if k > 0 {
            let film_planes = self.layers.chunks_exact_mut(pixels * k);
            for (sums, values) in film_planes.zip(buffer.layers.chunks_exact(n * k)) {
                add_layer_region(sums, width, &region, k, values);
            }
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
        if let Some(splats) = &mut self.splats {
            splats.add(&buffer.splats, u.sample_count());
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
    /// a uniform render, whatever its samples. A film with light splats adds their estimate
    /// ([`FilmSplats`]) to the weighted mean.
    pub fn pixel(&self, x: u32, y: u32) -> Vec3 {
        let i = (y * self.frame.width + x) as usize;
        if !self.has_half() {
            return self.with_splats(i, mean(&self.sums[i]));
        }
        let pixels = self.frame.width as usize * self.frame.height as usize;
        let mut total = [0.0f64; 4];
        self.reached_planes(x, y, |plane, n| {
            let sums = &self.sums[plane * pixels + i];
            for (t, &s) in total.iter_mut().zip(sums) {
                *t += s as f64 / f64::from(n);
            }
        });
        let [r, g, b, w] = total;
        if w <= 0.0 {
            return Vec3::ZERO;
        }
        Vec3::new((r / w) as f32, (g / w) as f32, (b / w) as f32)
    }

    /// For an adaptive film, `f(plane, n)` for each block with samples the filter reaches from
    /// pixel (x, y) (at most one per source plane), `n` its samples per pixel.
    fn reached_planes(&self, x: u32, y: u32, mut f: impl FnMut(usize, u32)) {
        let [bx, by] = self.frame.border;
        let span = |v: u32, border: u32, size: u32| {
            v.saturating_sub(border) / BLOCK_SIZE..=(v + border).min(size - 1) / BLOCK_SIZE
        };
        let columns = self.frame.width.div_ceil(BLOCK_SIZE);
        for row in span(y, by, self.frame.height) {
            for column in span(x, bx, self.frame.width) {
                let n = self.block_samples[(row * columns + column) as usize];
                if n > 0 {
                    let plane = self
                        .frame
                        .source_plane(column * BLOCK_SIZE, row * BLOCK_SIZE);
                    f(plane, n);
                }
            }
        }
    }

    /// Layer sum `k` of the pixel and its weight sum, in fixed-point units: a uniform film's
    /// own; an adaptive film's over the planes with samples ([`Film::pixel`]'s weighing), each
    /// divided by its block's samples per pixel.
    fn layer_and_weight(&self, x: u32, y: u32, k: usize) -> (f64, f64) {
        let count = self.frame.layers.len();
        assert!(k < count, "layer sum {k} of {count}");
        let i = (y * self.frame.width + x) as usize;
        if !self.has_half() {
            return (self.layers[i * count + k] as f64, self.sums[i][3] as f64);
        }
        let pixels = self.frame.width as usize * self.frame.height as usize;
        let (mut sum, mut weight) = (0.0f64, 0.0f64);
        self.reached_planes(x, y, |plane, n| {
            let at = plane * pixels + i;
            sum += self.layers[at * count + k] as f64 / f64::from(n);
            weight += self.sums[at][3] as f64 / f64::from(n);
        });
        (sum, weight)
    }

    /// The samples taken in the pixel, as the count sum `k` holds them (an adaptive film's in
    /// the plane of the pixel's block).
    fn layer_count(&self, x: u32, y: u32, k: usize) -> f32 {
        let count = self.frame.layers.len();
        let i = (y * self.frame.width + x) as usize;
        let pixels = self.frame.width as usize * self.frame.height as usize;
        let planes = self.sums.len() / pixels;
        let total: i64 = (0..planes)
            .map(|plane| self.layers[(plane * pixels + i) * count + k])
            .sum();
        (total as f64 / FIXED_ONE) as f32
    }

    /// The pixel's value of the filtered layer sum `k` (of the frame's
    /// [`crate::render::layers::Layers`]): the weighted mean of its samples' values, as
    /// [`Film::pixel`] takes the colour's (each block's samples weighed alike in an adaptive
    /// film); 0 without samples.
    pub fn layer_pixel(&self, x: u32, y: u32, k: usize) -> f32 {
        let (sum, weight) = self.layer_and_weight(x, y, k);
        if weight <= 0.0 {
            return 0.0;
        }
        (sum / weight) as f32
    }

    /// The film's pixels.
    fn pixel_count(&self) -> usize {
        self.frame.width as usize * self.frame.height as usize
    }

    /// Every pixel's value of `f(x, y)`, rows top to bottom.
    fn per_pixel<T>(&self, f: impl Fn(u32, u32) -> T) -> Vec<T> {
        (0..self.frame.height)
            .flat_map(|y| (0..self.frame.width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect()
    }

    /// The AOVs the frame keeps, per pixel: albedo and normal as weighted means; depth as the
    /// mean distance of the samples that hit (infinite where none did); the samples taken in
    /// the pixel.
    pub fn aovs(&self) -> AovImages {
        let o = self.frame.layers.offsets();
        let vector = |at: usize| {
            self.per_pixel(|x, y| {
                Vec3::new(
                    self.layer_pixel(x, y, at),
                    self.layer_pixel(x, y, at + 1),
                    self.layer_pixel(x, y, at + 2),
                )
            })
        };
        AovImages {
            albedo: o.albedo.map(vector),
            normal: o.normal.map(vector),
            depth: o.depth.map(|at| {
                self.per_pixel(|x, y| {
                    let (distance, _) = self.layer_and_weight(x, y, at);
                    let (hits, _) = self.layer_and_weight(x, y, at + 1);
                    if hits > 0.0 {
                        (distance / hits) as f32
                    } else {
                        f32::INFINITY
                    }
                })
            }),
            samples: o
                .samples
                .map(|at| self.per_pixel(|x, y| self.layer_count(x, y, at))),
        }
    }

    /// Each light group's linear radiance per pixel (rows top to bottom), with its name, when
    /// the frame keeps them apart; empty otherwise.
    pub fn light_group_images(&self, groups: &LightGroups) -> Vec<(String, Vec<Vec3>)> {
        let Some(at) = self.frame.layers.offsets().light_groups else {
            return Vec::new();
        };
        let count = usize::from(self.frame.layers.light_groups);
        groups
            .groups
            .iter()
            .take(count)
            .enumerate()
            .map(|(g, desc)| {
                let k = at + 3 * g;
                let pixels = self.pixel_count();
                let light = self.per_pixel(|x, y| {
                    let camera = Vec3::new(
                        self.layer_pixel(x, y, k),
                        self.layer_pixel(x, y, k + 1),
                        self.layer_pixel(x, y, k + 2),
                    );
                    // A bidirectional render's light splats of the group, in its plane.
                    let i = (y * self.frame.width + x) as usize;
                    match &self.splats {
                        Some(splats) => camera + splats.radiance((1 + g) * pixels + i, pixels),
                        None => camera,
                    }
                });
                (desc.name.clone(), light)
            })
            .collect()
    }

    /// Every pixel's alpha (rows top to bottom), when the frame keeps it.
    pub fn alpha(&self) -> Option<Vec<f32>> {
        let at = self.frame.layers.offsets().alpha?;
        Some(self.per_pixel(|x, y| self.layer_pixel(x, y, at)))
    }

    /// The plain weighted mean of all the samples that reach pixel `i` (row-major), whatever
    /// block they were taken in: what the half sums estimate too, so the two compare (the
    /// adaptive error estimate). The same as [`Film::pixel`] for a uniform film, light splats
    /// included.
    pub fn plain_pixel(&self, i: usize) -> Vec3 {
        let pixels = self.frame.width as usize * self.frame.height as usize;
        let mut total = [0i64; 4];
        for sums in self.sums.iter().skip(i).step_by(pixels) {
            for (t, &s) in total.iter_mut().zip(sums) {
                *t = t.saturating_add(s);
            }
        }
        self.with_splats(i, mean(&total))
    }

    /// `camera`, the camera samples' estimate of pixel `i`, with the light splats' added when
    /// the film keeps them (and exactly `camera` when it does not).
    fn with_splats(&self, i: usize, camera: Vec3) -> Vec3 {
        match &self.splats {
            Some(splats) => camera + splats.radiance(i, self.pixel_count()),
            None => camera,
        }
    }

    /// Linear radiance of every pixel, rows top to bottom.
    pub fn radiance(&self) -> Vec<Vec3> {
        (0..self.frame.height)
            .flat_map(|y| (0..self.frame.width).map(move |x| (x, y)))
            .map(|(x, y)| self.pixel(x, y))
            .collect()
    }

    /// Tone mapped, limited and gamma encoded as the scene's film asks, in [0, 1]: the values
    /// an 8- or 16-bit file quantises (and LuxRender's convergence test compares), rows top to
    /// bottom.
    pub fn display_values(&self, film: &FilmDesc) -> Vec<[f32; 3]> {
        let image = self.image(film);
        (0..image.tone_mapped.len())
            .map(|i| image.encoded(i).to_array())
            .collect()
    }

    /// The finished image as the scene's film makes it: the linear radiance, the tone-mapped
    /// radiance, and how an 8- or 16-bit file limits and encodes it; what every file is
    /// written from ([`FilmImage::write`]).
    pub fn image(&self, film: &FilmDesc) -> FilmImage {
        let mut linear = self.radiance();
        let light_groups = self.light_group_images(&film.light_groups);
        film.light_groups.weigh_image(&mut linear, &light_groups);
        let mut tone_mapped = linear.clone();
        tone_map(&mut tone_mapped, &film.tonemap, film.gamma);
        FilmImage {
            width: self.frame.width,
            height: self.frame.height,
            linear,
            tone_mapped,
            alpha: self.alpha(),
            aovs: self.aovs(),
            light_groups,
            gamma: film.gamma,
            ldr_clamp: film.outputs.ldr_clamp,
        }
    }

    /// Tone maps as the scene's film asks, limits and applies its gamma: 8-bit RGB, rows top
    /// to bottom, as the PNG has it by default (the preview's and the status page's image).
    pub fn to_display(&self, film: &FilmDesc) -> image::RgbImage {
        self.image(film).to_rgb8()
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

/// Adds a region's f32 layer sums (`k` per pixel) into rows of fixed-point sums.
fn add_layer_region(sums: &mut [i64], width: u32, region: &PixelRect, k: usize, values: &[f32]) {
    let region_row = region.width() as usize * k;
    for (row, y) in values.chunks_exact(region_row).zip(region.y0..region.y1) {
        let start = (y as usize * width as usize + region.x0 as usize) * k;
        for (sum, &v) in sums[start..start + region_row].iter_mut().zip(row) {
            *sum = sum.saturating_add(to_fixed(v));
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
    // The mid-grey LuxRender aims autolinear exposure at.
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
            gamma,
        } => {
            // LuxRender's linear kernel aims at mid-grey with its own gamma, not the film's.
            let middle_grey = libm::powf(118.0f32 / 255.0, gamma);
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
    use crate::render::layers::Layers;

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

    /// A light-splat frame of 4x2 pixels.
    fn splat_frame() -> FilmFrame {
        FilmFrame {
            light_splats: true,
            ..FilmFrame::unbordered(4, 2)
        }
    }

    /// A film's memory estimate counts a light splat plane per light group kept apart (two
    /// copies of its 24 bytes a pixel, the film's and a checkpoint's), besides their layers.
    #[test]
    fn memory_counts_the_light_groups_splat_planes() {
        let grouped = FilmFrame {
            layers: Layers {
                light_groups: 2,
                ..Layers::NONE
            },
            ..splat_frame()
        };
        let ungrouped_layers = FilmFrame {
            light_splats: false,
            ..grouped
        };
        let planes =
            Film::memory_bytes(grouped, false) - Film::memory_bytes(ungrouped_layers, false);
        assert_eq!(planes, 2 * 3 * 8 * 24);
        assert_eq!(Film::new(grouped).splats().unwrap().sums.len(), 3 * 8);
    }

    /// `u`'s buffer of [`splat_frame`] with sums from [`buffer`] and splats to `pixels`.
    fn splat_buffer(u: WorkUnit, seed: u32, pixels: &[u32]) -> SampleBuffer {
        let mut b = buffer(u, &splat_frame(), seed);
        b.splats = LightSplats {
            pixels: pixels.to_vec(),
            rgb: pixels
                .iter()
                .map(|&p| {
                    let v = (p.wrapping_mul(2_654_435_761) ^ seed) as f32 / u32::MAX as f32;
                    [v * 3e3, v * 1e-5, 0.5 + v]
                })
                .collect(),
        };
        b
    }

    /// Buffers with light splats merged in different orders give the same bits, sample sums,
    /// splat sums and light paths alike; the light paths are the units' camera samples.
    #[test]
    fn light_splats_merge_in_any_order() {
        let frame = splat_frame();
        let splat_pixels: [&[u32]; 4] = [&[0, 3, 7], &[3], &[], &[1, 2, 3, 4, 5, 6, 7]];
        let bufs: Vec<_> = splat_pixels
            .iter()
            .enumerate()
            .map(|(i, pixels)| {
                let u = WorkUnit {
                    sample_end: 3 + i as u32,
                    ..unit(i as u32, (i as u32 % 2) * 2, 0, (i as u32 % 2) * 2 + 2, 2)
                };
                splat_buffer(u, 31 * i as u32, pixels)
            })
            .collect();
        let films: Vec<_> = [[0, 1, 2, 3], [3, 2, 1, 0], [2, 0, 3, 1]]
            .iter()
            .map(|order| {
                let mut film = Film::new(frame);
                order.iter().for_each(|&i| film.add(&bufs[i]).unwrap());
                film
            })
            .collect();
        for film in &films[1..] {
            assert_eq!(film.sums, films[0].sums);
            assert_eq!(film.splats, films[0].splats);
        }
        let splats = films[0].splats().unwrap();
        // 4 pixels per tile, 3 + i samples each.
        assert_eq!(splats.light_paths, 4 * (3 + 4 + 5 + 6));
        // Pixel 3: the second splat of buffer 0, the first of 1 and the third of 3.
        let expected: i64 = [(0, 1), (1, 0), (3, 2)]
            .iter()
            .map(|&(b, at)| to_fixed(bufs[b].splats.rgb[at][0]))
            .sum();
        assert_eq!(splats.sums[3][0], expected);
    }

    /// A pixel of a film with light splats is the camera samples' weighted mean plus the splat
    /// sum times the film's 8 pixels over the light paths.
    #[test]
    fn splats_are_normalised_by_light_paths_per_pixel() {
        let frame = splat_frame();
        let mut film = Film::new(frame);
        assert_eq!(film.pixel(1, 0), Vec3::ZERO, "no light paths yet");
        // Two units of the whole film: 8 pixels x 5 samples, 8 x 2: N = 56 light paths.
        let units = [(0, 5), (1, 2)].map(|(index, samples)| WorkUnit {
            sample_end: samples,
            ..unit(index, 0, 0, 4, 2)
        });
        let mut a = SampleBuffer::new(units[0], &frame);
        let mut b = SampleBuffer::new(units[1], &frame);
        a.rgb[1] = [2.0, 4.0, 8.0];
        a.weight[1] = 2.0;
        b.rgb[1] = [1.0, 0.0, 0.0];
        b.weight[1] = 2.0;
        a.splats = LightSplats {
            pixels: vec![1, 6],
            rgb: vec![[0.75, 1.5, 0.0], [9.0, 9.0, 9.0]],
        };
        b.splats = LightSplats {
            pixels: vec![1],
            rgb: vec![[0.25, 0.5, 7.0]],
        };
        film.add(&a).unwrap();
        film.add(&b).unwrap();
        assert_eq!(film.splats().unwrap().light_paths, 56);
        let mean = Vec3::new(3.0, 4.0, 8.0) / 4.0;
        let splat = Vec3::new(1.0, 2.0, 7.0);
        let expected = mean + splat * 8.0 / 56.0;
        let got = film.pixel(1, 0);
        assert!(
            (got - expected).abs().max_element() <= 2.0 * f32::EPSILON * expected.max_element(),
            "{got} {expected}"
        );
        assert_eq!(film.plain_pixel(1), got);
        // A pixel with splats alone.
        let alone = Vec3::splat(9.0 * 8.0 / 56.0);
        assert!((film.pixel(2, 1) - alone).abs().max_element() <= 4.0 * f32::EPSILON);
        assert_eq!(film.radiance()[6], film.pixel(2, 1));
    }

    /// Splats a film cannot hold, or on a film that keeps none, are refused with the reason.
    #[test]
    fn hostile_light_splats_are_refused() {
        let frame = splat_frame();
        let u = unit(0, 0, 0, 4, 2);
        for (pixels, rgb) in [
            (vec![3, 1], vec![[1.0; 3]; 2]),
            (vec![2, 2], vec![[1.0; 3]; 2]),
            (vec![8], vec![[1.0; 3]]),
            (vec![0], vec![[f32::NAN; 3]]),
            (vec![0], vec![[MAX_SUM; 3]]),
            (vec![0, 1], vec![[1.0; 3]]),
        ] {
            let mut film = Film::new(frame);
            let mut b = buffer(u, &frame, 1);
            b.splats = LightSplats { pixels, rgb };
            let error = film.add(&b).unwrap_err();
            assert!(error.reason.contains("light splat"), "{error}");
            assert_eq!(film.splats().unwrap().light_paths, 0, "nothing merged");
        }
        let plain = FilmFrame::unbordered(4, 2);
        let mut film = Film::new(plain);
        let mut b = buffer(u, &plain, 1);
        b.splats = LightSplats {
            pixels: vec![0],
            rgb: vec![[1.0; 3]],
        };
        assert!(film.add(&b).unwrap_err().reason.contains("keeps none"));
        b.splats = LightSplats::default();
        film.add(&b).unwrap();
        assert!(film.splats().is_none());
    }

    /// Sums restored from a film's own give the same film; splat sums where the frame keeps
    /// none (or none where it does, or of another length) do not.
    #[test]
    fn splat_sums_restore_exactly_and_only_where_they_fit() {
        let frame = splat_frame();
        let mut film = Film::new(frame);
        film.add(&splat_buffer(unit(0, 0, 0, 4, 2), 5, &[0, 5]))
            .unwrap();
        let back = Film::from_sums(
            frame,
            film.sums().to_vec(),
            Vec::new(),
            Vec::new(),
            film.splats().cloned(),
            Vec::new(),
        )
        .unwrap();
        assert_eq!(back.splats(), film.splats());
        assert_eq!(back.radiance(), film.radiance());
        let sums = || film.sums().to_vec();
        assert!(Film::from_sums(frame, sums(), Vec::new(), Vec::new(), None, Vec::new()).is_none());
        let short = FilmSplats::new(7);
        assert!(Film::from_sums(
            frame,
            sums(),
            Vec::new(),
            Vec::new(),
            Some(short),
            Vec::new()
        )
        .is_none());
        let plain = FilmFrame::unbordered(4, 2);
        let splats = film.splats().cloned();
        assert!(
            Film::from_sums(plain, sums(), Vec::new(), Vec::new(), splats, Vec::new()).is_none()
        );
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

    /// Alpha is the weighted mean of its samples' values, as the colour is, in any order of
    /// merging; a buffer whose layer sums are not its frame's is refused.
    #[test]
    fn alpha_is_a_weighted_mean_and_misfit_layers_are_refused() {
        let frame = FilmFrame {
            layers: Layers {
                alpha: true,
                ..Layers::NONE
            },
            ..FilmFrame::unbordered(4, 2)
        };
        let u = unit(0, 0, 0, 4, 2);
        let mut a = SampleBuffer::new(u, &frame);
        let mut b = SampleBuffer::new(WorkUnit { index: 1, ..u }, &frame);
        assert_eq!((a.layers.len(), a.weight.len()), (8, 8));
        (a.weight[1], a.layers[1]) = (2.0, 0.5);
        (b.weight[1], b.layers[1]) = (2.0, 2.0);
        (b.weight[6], b.layers[6]) = (0.75, 0.75);
        let mut films = [Film::new(frame), Film::new(frame)];
        films[0].add(&a).unwrap();
        films[0].add(&b).unwrap();
        films[1].add(&b).unwrap();
        films[1].add(&a).unwrap();
        assert_eq!(films[0].layer_sums(), films[1].layer_sums());
        let alpha = films[0].alpha().unwrap();
        assert_eq!(alpha, [0.0, 0.625, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let mut short = a.clone();
        short.layers.pop();
        assert!(Film::new(frame).add(&short).is_err());
        let mut none = a.clone();
        none.layers.clear();
        assert!(Film::new(frame).add(&none).is_err());
        let plain = FilmFrame::unbordered(4, 2);
        assert!(
            Film::new(plain).add(&a).is_err(),
            "alpha the film keeps none of"
        );
        assert!(Film::new(plain).alpha().is_none());
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
            border: [2, 1],
            ..FilmFrame::unbordered(10, 7)
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
            border: [2, 2],
            ..FilmFrame::unbordered(16, 16)
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

    /// LuxRender's linear kernel exposes for mid-grey with its own `linear_gamma` (default 1),
    /// not the film's gamma: radiance 1 at sensitivity 50, exposure 1, f/2.8 becomes
    /// 50 x 0.065 / 2.8^2 x (118/255)^1 = 0.19183.
    #[test]
    fn linear_exposes_with_its_own_gamma() {
        let mut source = crate::assets::MemorySource::new();
        let scene =
            "Film \"fleximage\" \"string tonemapkernel\" [\"linear\"] \"float gamma\" [2.2]\n\
                     WorldBegin\nWorldEnd\n";
        source.insert("main.lxs", scene.as_bytes().into());
        let desc = crate::parse::parse_scene("main.lxs", &source).unwrap();
        let tonemap = desc.film.tonemap;
        assert_eq!(
            tonemap,
            ToneMap::Linear {
                sensitivity: 50.0,
                exposure: 1.0,
                fstop: 2.8,
                gamma: DEFAULT_LINEAR_GAMMA,
            }
        );
        let mut mapped = [Vec3::ONE];
        tone_map(&mut mapped, &tonemap, 2.2);
        assert!((mapped[0].x - 0.191_83).abs() < 1e-5, "{}", mapped[0].x);
        // linear_gamma 2.2 whatever the film's: (118/255)^2.2 = 0.18356.
        let tonemap = ToneMap::Linear {
            sensitivity: 50.0,
            exposure: 1.0,
            fstop: 2.8,
            gamma: 2.2,
        };
        let mut mapped = [Vec3::ONE];
        tone_map(&mut mapped, &tonemap, 1.0);
        assert!((mapped[0].x - 0.076_09).abs() < 1e-5, "{}", mapped[0].x);
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
