//! `Film "fleximage" "bool write_png" ["true"] "string write_png_channels" ["RGBA"]
//! "bool write_exr" ["true"] "bool write_exr_halftype" ["false"] ...`: which files a render
//! writes, in which channels and precision, how out-of-range colours are brought into an 8- or
//! 16-bit file, and the writers of those files. LuxRender's `FlexImageFilm` reads these and
//! names each file after the Film's `filename` with the format's extension (`name.png`,
//! `name.tga`, `name.exr`).
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `write_png` | bool | true |
//! | `write_png_channels` | string: Y, YA, RGB, RGBA | RGB |
//! | `write_png_16bit` | bool | false |
//! | `write_tga` | bool | false |
//! | `write_tga_channels` | string: Y, RGB, RGBA | RGB |
//! | `write_exr` | bool | false |
//! | `write_exr_channels` | string: Y, YA, RGB, RGBA | RGB |
//! | `write_exr_halftype` | bool | true (`--exr` alone: false) |
//! | `write_exr_applyimaging` | bool | true (`--exr` alone: false) |
//! | `write_exr_straightcolors` | bool | false |
//! | `write_exr_ZBuf` | bool | false: a Z channel of each pixel's depth in the EXR |
//! | `ldr_clamp_method` | string: lum, hue, cut, darken | cut |
//!
//! The 8- and 16-bit files (PNG, TGA) hold the tone-mapped image brought into range by
//! `ldr_clamp_method` (LuxRender's `ColorSystem::Limit`: only a colour with a channel above 1 is
//! changed; "cut" clamps each channel, "darken" divides by the largest, "lum" and "hue" move the
//! colour toward the grey of its luminance, or of a third, until it fits, white when that grey
//! is brighter than 1), then gamma encoded; Y is the luminance of the encoded colour, A the
//! pixel's alpha (the filtered coverage of its camera rays), not gamma encoded. Values are
//! rounded to the nearest step (LuxRender truncates; YAT's PNG always rounded, and its default
//! PNG keeps its bytes), and the PNG carries no gAMA or cHRM chunk.
//!
//! The EXR holds the tone-mapped image (`write_exr_applyimaging`, neither limited nor gamma
//! encoded) or the linear radiance, as 16-bit half or 32-bit floats; with an alpha channel its
//! colours are multiplied by alpha, as OpenEXR's are, unless `write_exr_straightcolors`. Its Y
//! is LuxRender's EXR luminance, 0.3 R + 0.59 G + 0.11 B. `yat render --exr` adds an EXR where
//! the Film writes none: the linear radiance in full floats (YAT's EXR before it read these
//! parameters), unless the Film's own `write_exr_*` parameters say otherwise. The AOVs a
//! render keeps (`--aovs`, and depth for `write_exr_ZBuf`: `render/layers.rs`) are extra
//! channels of the EXR: `albedo.R`, `albedo.G`, `albedo.B`, `N.X`, `N.Y`, `N.Z` in the EXR's
//! precision, `Z` (depth: the mean camera distance of the pixel's samples that hit a surface,
//! infinite where none did) and `samples` (the camera samples taken in the pixel) in full
//! floats, as LuxRender writes its Z. A render that keeps its light groups apart
//! (`light_groups`) adds one layer per group, `lightgroup.<name>.R`, `.G`, `.B`: the group's
//! linear radiance as rendered, before the weighing its settings give it in the image (the
//! EXR's own RGB, the groups' weighed sum), for weighing again elsewhere.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use glam::Vec3;

use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_WRITE_PNG: bool = true;
pub const DEFAULT_PNG_CHANNELS: Channels = Channels::Rgb;
pub const DEFAULT_PNG_16BIT: bool = false;
pub const DEFAULT_WRITE_TGA: bool = false;
pub const DEFAULT_TGA_CHANNELS: Channels = Channels::Rgb;
pub const DEFAULT_WRITE_EXR: bool = false;
pub const DEFAULT_EXR_CHANNELS: Channels = Channels::Rgb;
pub const DEFAULT_EXR_HALFTYPE: bool = true;
pub const DEFAULT_EXR_APPLYIMAGING: bool = true;
pub const DEFAULT_EXR_STRAIGHT_COLORS: bool = false;
pub const DEFAULT_EXR_ZBUF: bool = false;
pub const DEFAULT_LDR_CLAMP: LdrClamp = LdrClamp::Cut;
/// The EXR `--exr` adds where the Film writes none: full floats...
pub const FLAG_EXR_HALFTYPE: bool = false;
/// ... of the linear radiance.
pub const FLAG_EXR_APPLYIMAGING: bool = false;

/// The Y row of LuxRender's default colour system's RGB-to-XYZ matrix (its SMPTE primaries and
/// white point, luminance 1): the luminance "lum" limits a colour by.
const LIMIT_LUMINANCE: [f32; 3] = [0.215_907_08, 0.698_183_07, 0.085_909_85];
/// The luminance of an encoded colour in the PNG's and TGA's Y channel (LuxRender's
/// `RGBColor::Y`).
const LDR_LUMINANCE: [f32; 3] = [0.212_671, 0.715_160, 0.072_169];
/// The luminance in the EXR's Y channel, as LuxRender writes it.
const EXR_LUMINANCE: [f32; 3] = [0.3, 0.59, 0.11];

/// The widest or tallest TGA: its header holds each side in 16 bits.
pub const MAX_TGA_SIDE: u32 = u16::MAX as u32;

/// The channels of a file: grey or colour, with or without alpha.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channels {
    Y,
    Ya,
    Rgb,
    Rgba,
}

impl Channels {
    /// As a scene file names them.
    pub fn name(self) -> &'static str {
        match self {
            Channels::Y => "Y",
            Channels::Ya => "YA",
            Channels::Rgb => "RGB",
            Channels::Rgba => "RGBA",
        }
    }

    pub fn has_alpha(self) -> bool {
        matches!(self, Channels::Ya | Channels::Rgba)
    }

    pub fn is_grey(self) -> bool {
        matches!(self, Channels::Y | Channels::Ya)
    }

    /// Samples per pixel.
    pub fn count(self) -> usize {
        match self {
            Channels::Y => 1,
            Channels::Ya => 2,
            Channels::Rgb => 3,
            Channels::Rgba => 4,
        }
    }
}

/// How a tone-mapped colour brighter than 1 in some channel is brought into an 8- or 16-bit
/// file (`ldr_clamp_method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LdrClamp {
    /// Toward the grey of its luminance: the hue and luminance kept, saturation lost.
    Lum,
    /// Toward the grey of a third: the hue kept.
    Hue,
    /// Each channel clamped to [0, 1].
    Cut,
    /// Divided by its largest channel.
    Darken,
}

impl LdrClamp {
    pub fn name(self) -> &'static str {
        match self {
            LdrClamp::Lum => "lum",
            LdrClamp::Hue => "hue",
            LdrClamp::Cut => "cut",
            LdrClamp::Darken => "darken",
        }
    }

    /// `c` brought into range as LuxRender's `ColorSystem::Limit` does: unchanged unless a
    /// channel is above 1.
    pub fn limit(self, c: Vec3) -> Vec3 {
        let max = c.max_element();
        if max <= 1.0 || max.is_nan() {
            return c;
        }
        match self {
            LdrClamp::Cut => c.clamp(Vec3::ZERO, Vec3::ONE),
            LdrClamp::Darken => c / max,
            LdrClamp::Lum | LdrClamp::Hue => {
                let grey = if self == LdrClamp::Lum {
                    Vec3::from_array(LIMIT_LUMINANCE).dot(c)
                } else {
                    1.0 / 3.0
                };
                if grey > 1.0 {
                    return Vec3::ONE;
                }
                // The point where the line from the grey to the colour leaves the unit cube
                // through the largest channel.
                let t = (1.0 - grey) / (max - grey);
                Vec3::splat(grey) + (c - grey) * t
            }
        }
    }
}

/// The Film's output parameters, as the file gives them.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmOutputs {
    pub write_png: bool,
    pub png_channels: Channels,
    pub png_16bit: bool,
    pub write_tga: bool,
    pub tga_channels: Channels,
    pub write_exr: bool,
    pub exr_channels: Channels,
    /// None when the file does not say (LuxRender's default, or `--exr`'s).
    pub exr_halftype: Option<bool>,
    /// None when the file does not say (LuxRender's default, or `--exr`'s).
    pub exr_applyimaging: Option<bool>,
    pub exr_straight_colors: bool,
    /// The EXR has a Z channel (`write_exr_ZBuf`).
    pub exr_zbuf: bool,
    pub ldr_clamp: LdrClamp,
}

impl Default for FilmOutputs {
    fn default() -> Self {
        Self {
            write_png: DEFAULT_WRITE_PNG,
            png_channels: DEFAULT_PNG_CHANNELS,
            png_16bit: DEFAULT_PNG_16BIT,
            write_tga: DEFAULT_WRITE_TGA,
            tga_channels: DEFAULT_TGA_CHANNELS,
            write_exr: DEFAULT_WRITE_EXR,
            exr_channels: DEFAULT_EXR_CHANNELS,
            exr_halftype: None,
            exr_applyimaging: None,
            exr_straight_colors: DEFAULT_EXR_STRAIGHT_COLORS,
            exr_zbuf: DEFAULT_EXR_ZBUF,
            ldr_clamp: DEFAULT_LDR_CLAMP,
        }
    }
}

/// One file a render writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFile {
    Png {
        channels: Channels,
        sixteen_bit: bool,
    },
    Tga {
        channels: Channels,
    },
    Exr(ExrFormat),
}

/// What an EXR holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExrFormat {
    pub channels: Channels,
    /// 16-bit half floats, else 32-bit floats.
    pub half: bool,
    /// The tone-mapped image, else the linear radiance.
    pub tone_mapped: bool,
    /// Colours not multiplied by alpha.
    pub straight: bool,
}

impl OutputFile {
    /// The file's extension, as LuxRender adds it to the Film's filename.
    pub fn extension(&self) -> &'static str {
        match self {
            OutputFile::Png { .. } => "png",
            OutputFile::Tga { .. } => "tga",
            OutputFile::Exr(_) => "exr",
        }
    }

    /// What the file holds, as `yat check` says it ("RGB, 8-bit", "RGBA, half floats, linear").
    pub fn describe(&self) -> String {
        match *self {
            OutputFile::Png {
                channels,
                sixteen_bit,
            } => format!(
                "{}, {}-bit",
                channels.name(),
                if sixteen_bit { 16 } else { 8 }
            ),
            OutputFile::Tga { channels } => format!("{}, 8-bit", channels.name()),
            OutputFile::Exr(f) => format!(
                "{}, {} floats, {}{}",
                f.channels.name(),
                if f.half { "half" } else { "full" },
                if f.tone_mapped {
                    "tone-mapped"
                } else {
                    "linear"
                },
                if f.channels.has_alpha() && f.straight {
                    ", straight colours"
                } else {
                    ""
                }
            ),
        }
    }

    pub fn channels(&self) -> Channels {
        match *self {
            OutputFile::Png { channels, .. } | OutputFile::Tga { channels } => channels,
            OutputFile::Exr(f) => f.channels,
        }
    }
}

impl FilmOutputs {
    /// Reads the output parameters of `Film` statement `params` (at `pos`; None for a scene
    /// without one, which warns about nothing). An unknown channel set or clamp method is
    /// LuxRender's default, with a note, as LuxRender falls back to it.
    pub fn read(
        ctx: &mut dyn ParseContext,
        params: &ParamList,
        pos: Option<&SourcePos>,
    ) -> Result<Self, ParseError> {
        let mut fallback = |name: &str, given: &str, used: &str| {
            if let Some(pos) = pos {
                ctx.note(
                    pos,
                    format!(
                        "Film: \"{name}\" \"{given}\" is none LuxRender knows; \"{used}\" in \
                         its place, as LuxRender has it"
                    ),
                );
            }
        };
        let mut channels = |name: &str, grey_alpha: bool| -> Result<Channels, ParseError> {
            let given = params.string_or(name, Channels::Rgb.name())?;
            Ok(match given.as_str() {
                "Y" => Channels::Y,
                "YA" if grey_alpha => Channels::Ya,
                "RGB" => Channels::Rgb,
                "RGBA" => Channels::Rgba,
                _ => {
                    fallback(name, &given, Channels::Rgb.name());
                    Channels::Rgb
                }
            })
        };
        let png_channels = channels("write_png_channels", true)?;
        // LuxRender's TGA has no grey with alpha.
        let tga_channels = channels("write_tga_channels", false)?;
        let exr_channels = channels("write_exr_channels", true)?;
        let clamp = params.string_or("ldr_clamp_method", DEFAULT_LDR_CLAMP.name())?;
        let known = [
            LdrClamp::Lum,
            LdrClamp::Hue,
            LdrClamp::Cut,
            LdrClamp::Darken,
        ];
        let ldr_clamp = match known.into_iter().find(|c| c.name() == clamp) {
            Some(c) => c,
            None => {
                fallback("ldr_clamp_method", &clamp, DEFAULT_LDR_CLAMP.name());
                DEFAULT_LDR_CLAMP
            }
        };
        let given_bool = |name: &str| -> Result<Option<bool>, ParseError> {
            match params.find(name) {
                Some(_) => params.bool(name, false).map(Some),
                None => Ok(None),
            }
        };
        Ok(Self {
            write_png: params.bool("write_png", DEFAULT_WRITE_PNG)?,
            png_channels,
            png_16bit: params.bool("write_png_16bit", DEFAULT_PNG_16BIT)?,
            write_tga: params.bool("write_tga", DEFAULT_WRITE_TGA)?,
            tga_channels,
            write_exr: params.bool("write_exr", DEFAULT_WRITE_EXR)?,
            exr_channels,
            exr_halftype: given_bool("write_exr_halftype")?,
            exr_applyimaging: given_bool("write_exr_applyimaging")?,
            exr_straight_colors: params
                .bool("write_exr_straightcolors", DEFAULT_EXR_STRAIGHT_COLORS)?,
            exr_zbuf: params.bool("write_exr_ZBuf", DEFAULT_EXR_ZBUF)?,
            ldr_clamp,
        })
    }

    /// The files a render writes, in the order they are written: the PNG, the TGA, the EXR,
    /// each when the Film asks for it; `flag_exr` (`yat render --exr`) adds the EXR where the
    /// Film writes none: always the linear radiance in full floats (what the benchmarks and
    /// byte comparisons read), whatever the Film's `write_exr_halftype` and
    /// `write_exr_applyimaging` say of the EXR it does not write.
    pub fn files(&self, flag_exr: bool) -> Vec<OutputFile> {
        let mut files = Vec::new();
        if self.write_png {
            files.push(OutputFile::Png {
                channels: self.png_channels,
                sixteen_bit: self.png_16bit,
            });
        }
        if self.write_tga {
            files.push(OutputFile::Tga {
                channels: self.tga_channels,
            });
        }
        let (half, tone_mapped) = if self.write_exr {
            (
                self.exr_halftype.unwrap_or(DEFAULT_EXR_HALFTYPE),
                self.exr_applyimaging.unwrap_or(DEFAULT_EXR_APPLYIMAGING),
            )
        } else {
            (FLAG_EXR_HALFTYPE, FLAG_EXR_APPLYIMAGING)
        };
        if self.write_exr || flag_exr {
            files.push(OutputFile::Exr(ExrFormat {
                channels: self.exr_channels,
                half,
                tone_mapped,
                straight: self.exr_straight_colors,
            }));
        }
        files
    }

    /// Whether a render of this film needs its pixels' alpha: a PNG or TGA it writes has an
    /// alpha channel, or the EXR's channels have one (whether the Film writes the EXR or
    /// `--exr` adds it, so the scene alone decides).
    pub fn needs_alpha(&self) -> bool {
        (self.write_png && self.png_channels.has_alpha())
            || (self.write_tga && self.tga_channels.has_alpha())
            || self.exr_channels.has_alpha()
    }
}

/// A finished film as the writers take it, rows top to bottom.
#[derive(Clone, Debug)]
pub struct FilmImage {
    pub width: u32,
    pub height: u32,
    /// Linear radiance.
    pub linear: Vec<Vec3>,
    /// The tone-mapped image: neither limited nor gamma encoded.
    pub tone_mapped: Vec<Vec3>,
    /// Each pixel's alpha; None when the render kept none (every pixel is then opaque).
    pub alpha: Option<Vec<f32>>,
    /// The AOVs the render kept, each None when it kept none.
    pub aovs: AovImages,
    /// Each light group's linear radiance, as rendered (before its weighing), with the group's
    /// name, when the render kept them apart (`film::light_groups`); empty otherwise.
    pub light_groups: Vec<(String, Vec<Vec3>)>,
    /// The Film's gamma.
    pub gamma: f32,
    pub ldr_clamp: LdrClamp,
}

/// A render's AOVs, per pixel, rows top to bottom (`render/layers.rs`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AovImages {
    pub albedo: Option<Vec<Vec3>>,
    pub normal: Option<Vec<Vec3>>,
    /// Infinite where no sample hit a surface.
    pub depth: Option<Vec<f32>>,
    pub samples: Option<Vec<f32>>,
}

impl AovImages {
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}

/// Why a file could not be written (the caller names the file).
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error(transparent)]
    Image(#[from] image::ImageError),
    #[error(transparent)]
    Exr(#[from] exr::error::Error),
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error("a TGA holds at most {MAX_TGA_SIDE} pixels a side; the image is {width}x{height}")]
    TgaTooLarge { width: u32, height: u32 },
}

impl FilmImage {
    fn alpha_at(&self, i: usize) -> f32 {
        self.alpha.as_ref().map_or(1.0, |a| a[i])
    }

    /// Pixel `i` as an 8- or 16-bit file holds it before quantisation: limited, clamped to
    /// [0, 1] and gamma encoded.
    pub fn encoded(&self, i: usize) -> Vec3 {
        let inv_gamma = 1.0 / self.gamma.max(1e-3);
        let c = self.ldr_clamp.limit(self.tone_mapped[i]);
        let encode = |v: f32| libm::powf(v.clamp(0.0, 1.0), inv_gamma);
        Vec3::new(encode(c.x), encode(c.y), encode(c.z))
    }

    /// Pixel `i`'s samples in an 8- or 16-bit file of `channels`, each in [0, 1].
    fn ldr_samples(&self, i: usize, channels: Channels) -> ([f32; 4], usize) {
        let c = self.encoded(i);
        let a = self.alpha_at(i).clamp(0.0, 1.0);
        let y = || Vec3::from_array(LDR_LUMINANCE).dot(c).clamp(0.0, 1.0);
        let samples = match channels {
            Channels::Y => [y(), 0.0, 0.0, 0.0],
            Channels::Ya => [y(), a, 0.0, 0.0],
            Channels::Rgb => [c.x, c.y, c.z, 0.0],
            Channels::Rgba => [c.x, c.y, c.z, a],
        };
        (samples, channels.count())
    }

    /// Every pixel's samples quantised to `steps` (255 or 65535), rows top to bottom.
    fn quantised<T: Copy>(&self, channels: Channels, steps: f32, to: impl Fn(f32) -> T) -> Vec<T> {
        let n = self.width as usize * self.height as usize;
        let mut out = Vec::with_capacity(n * channels.count());
        for i in 0..n {
            let (samples, count) = self.ldr_samples(i, channels);
            out.extend(samples[..count].iter().map(|&v| to(v * steps + 0.5)));
        }
        out
    }

    /// The 8-bit RGB image of the PNG, the preview and the status page.
    pub fn to_rgb8(&self) -> image::RgbImage {
        let bytes = self.quantised(Channels::Rgb, 255.0, |v| v as u8);
        image::RgbImage::from_raw(self.width, self.height, bytes)
            .expect("width x height pixels of three bytes")
    }

    /// Writes `file` to `path`.
    pub fn write(&self, file: &OutputFile, path: &Path) -> Result<(), OutputError> {
        match *file {
            OutputFile::Png {
                channels,
                sixteen_bit,
            } => self.write_png(path, channels, sixteen_bit),
            OutputFile::Tga { channels } => self.write_tga(path, channels),
            OutputFile::Exr(format) => self.write_exr(path, format),
        }
    }

    fn write_png(
        &self,
        path: &Path,
        channels: Channels,
        sixteen_bit: bool,
    ) -> Result<(), OutputError> {
        use image::DynamicImage as D;
        let (w, h) = (self.width, self.height);
        let fits = "width x height pixels of the channels' samples";
        let image = if sixteen_bit {
            let s = self.quantised(channels, 65535.0, |v| v as u16);
            match channels {
                Channels::Y => D::ImageLuma16(image::ImageBuffer::from_raw(w, h, s).expect(fits)),
                Channels::Ya => D::ImageLumaA16(image::ImageBuffer::from_raw(w, h, s).expect(fits)),
                Channels::Rgb => D::ImageRgb16(image::ImageBuffer::from_raw(w, h, s).expect(fits)),
                Channels::Rgba => {
                    D::ImageRgba16(image::ImageBuffer::from_raw(w, h, s).expect(fits))
                }
            }
        } else {
            let s = self.quantised(channels, 255.0, |v| v as u8);
            match channels {
                Channels::Y => D::ImageLuma8(image::ImageBuffer::from_raw(w, h, s).expect(fits)),
                Channels::Ya => D::ImageLumaA8(image::ImageBuffer::from_raw(w, h, s).expect(fits)),
                Channels::Rgb => D::ImageRgb8(image::ImageBuffer::from_raw(w, h, s).expect(fits)),
                Channels::Rgba => D::ImageRgba8(image::ImageBuffer::from_raw(w, h, s).expect(fits)),
            }
        };
        image.save_with_format(path, image::ImageFormat::Png)?;
        Ok(())
    }

    /// An uncompressed Truevision TGA, as LuxRender writes it: rows bottom to top, blue, green,
    /// red (and alpha) per pixel, or grey; 8 bits each.
    fn write_tga(&self, path: &Path, channels: Channels) -> Result<(), OutputError> {
        let (width, height) = (self.width, self.height);
        if width > MAX_TGA_SIDE || height > MAX_TGA_SIDE {
            return Err(OutputError::TgaTooLarge { width, height });
        }
        let channels = match channels {
            // LuxRender's TGA has no grey with alpha (the reader never gives it one).
            Channels::Ya => Channels::Y,
            c => c,
        };
        let samples = self.quantised(channels, 255.0, |v| v as u8);
        let mut header = [0u8; 18];
        header[2] = if channels.is_grey() { 3 } else { 2 };
        header[12..14].copy_from_slice(&(width as u16).to_le_bytes());
        header[14..16].copy_from_slice(&(height as u16).to_le_bytes());
        header[16] = 8 * channels.count() as u8;
        // The alpha bits; origin at the bottom left.
        header[17] = if channels.has_alpha() { 8 } else { 0 };
        let mut out = BufWriter::new(File::create(path)?);
        out.write_all(&header)?;
        let row = width as usize * channels.count();
        let mut swapped = vec![0u8; row];
        for line in samples.chunks_exact(row).rev() {
            swapped.copy_from_slice(line);
            if !channels.is_grey() {
                for px in swapped.chunks_exact_mut(channels.count()) {
                    px.swap(0, 2);
                }
            }
            out.write_all(&swapped)?;
        }
        out.flush()?;
        Ok(())
    }

    fn write_exr(&self, path: &Path, format: ExrFormat) -> Result<(), OutputError> {
        use exr::prelude::*;
        let source = if format.tone_mapped {
            &self.tone_mapped
        } else {
            &self.linear
        };
        let size = (self.width as usize, self.height as usize);
        let premultiply = format.channels.has_alpha() && !format.straight;
        let colour = |i: usize| {
            if premultiply {
                source[i] * self.alpha_at(i)
            } else {
                source[i]
            }
        };
        if format.channels == Channels::Rgb
            && !format.half
            && self.aovs.is_empty()
            && self.light_groups.is_empty()
        {
            // The layout `image` writes (and YAT's EXR always had): the same bytes.
            Image::from_channels(
                size,
                SpecificChannels::rgb(|p: Vec2<usize>| {
                    let c = colour(p.flat_index_for_size(Vec2(size.0, size.1)));
                    (c.x, c.y, c.z)
                }),
            )
            .write()
            .to_file(path)?;
            return Ok(());
        }
        let n = size.0 * size.1;
        let plane = |value: &dyn Fn(usize) -> f32| -> FlatSamples {
            if format.half {
                FlatSamples::F16((0..n).map(|i| f16::from_f32(value(i))).collect())
            } else {
                FlatSamples::F32((0..n).map(value).collect())
            }
        };
        let mut list: Vec<AnyChannel<FlatSamples>> = Vec::new();
        if format.channels.is_grey() {
            let y = |i: usize| Vec3::from_array(EXR_LUMINANCE).dot(colour(i));
            list.push(AnyChannel::new("Y", plane(&y)));
        } else {
            list.push(AnyChannel::new("R", plane(&|i| colour(i).x)));
            list.push(AnyChannel::new("G", plane(&|i| colour(i).y)));
            list.push(AnyChannel::new("B", plane(&|i| colour(i).z)));
        }
        if format.channels.has_alpha() {
            list.push(AnyChannel::new("A", plane(&|i| self.alpha_at(i))));
        }
        let aovs = &self.aovs;
        let vectors = [
            (&aovs.albedo, ["albedo.R", "albedo.G", "albedo.B"]),
            (&aovs.normal, ["N.X", "N.Y", "N.Z"]),
        ];
        for (values, names) in vectors {
            if let Some(values) = values {
                for (c, name) in names.into_iter().enumerate() {
                    list.push(AnyChannel::new(name, plane(&|i| values[i][c])));
                }
            }
        }
        for (name, values) in &self.light_groups {
            for (c, channel) in ["R", "G", "B"].into_iter().enumerate() {
                let name = format!("{}.{channel}", light_group_layer(name));
                list.push(AnyChannel::new(name.as_str(), plane(&|i| values[i][c])));
            }
        }
        let full = |values: &[f32]| FlatSamples::F32(values.to_vec());
        if let Some(depth) = &aovs.depth {
            list.push(AnyChannel::new("Z", full(depth)));
        }
        if let Some(samples) = &aovs.samples {
            list.push(AnyChannel::new("samples", full(samples)));
        }
        let layer = Layer::new(
            size,
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(list)),
        );
        Image::from_layer(layer).write().to_file(path)?;
        Ok(())
    }
}

/// The EXR layer of light group `name`: `lightgroup.` and the name, its characters other than
/// letters, digits, `_` and `-` made `_` (a dot would start another layer).
pub fn light_group_layer(name: &str) -> String {
    let name: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("lightgroup.{name}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assets::MemorySource;
    use crate::diag::Severity;
    use crate::parse::parse_scene;

    /// The outputs of a Film statement with `params`, and the notes it gave.
    fn read(params: &str) -> (FilmOutputs, Vec<String>) {
        let mut source = MemorySource::new();
        let text = format!("Film \"fleximage\" {params}\nWorldBegin\nWorldEnd\n");
        source.insert("main.lxs", text.as_bytes().into());
        let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
        let notes = desc
            .warnings
            .iter()
            .filter(|w| w.severity != Severity::NoEffect && w.message.starts_with("Film"))
            .map(|w| w.to_string())
            .collect();
        (desc.film.outputs, notes)
    }

    /// A 5x3 image whose tone-mapped values run from black past white, and alpha from 0 to 1.
    fn image(ldr_clamp: LdrClamp) -> FilmImage {
        let (width, height) = (5, 3);
        let n = width as usize * height as usize;
        let linear: Vec<Vec3> = (0..n)
            .map(|i| {
                let v = i as f32 / 7.0;
                Vec3::new(v, 0.5 * v * v, 0.05 + 0.1 * (i % 4) as f32)
            })
            .collect();
        FilmImage {
            width,
            height,
            tone_mapped: linear.iter().map(|&c| c * 0.8).collect(),
            linear,
            alpha: Some((0..n).map(|i| i as f32 / (n - 1) as f32).collect()),
            aovs: AovImages::default(),
            light_groups: Vec::new(),
            gamma: 2.2,
            ldr_clamp,
        }
    }

    #[test]
    fn defaults_write_one_rgb_png_and_exr_only_when_asked() {
        let (outputs, notes) = read("");
        assert_eq!(outputs, FilmOutputs::default());
        assert!(notes.is_empty(), "{notes:?}");
        let png = OutputFile::Png {
            channels: Channels::Rgb,
            sixteen_bit: false,
        };
        assert_eq!(outputs.files(false), [png]);
        // --exr: YAT's linear full-float EXR.
        let flag_exr = ExrFormat {
            channels: Channels::Rgb,
            half: false,
            tone_mapped: false,
            straight: false,
        };
        assert_eq!(outputs.files(true), [png, OutputFile::Exr(flag_exr)]);
        assert!(!outputs.needs_alpha());
        // The Film's EXR: LuxRender's half floats of the tone-mapped image, with or without
        // --exr.
        let (outputs, _) = read("\"bool write_exr\" [\"true\"] \"bool write_png\" [\"false\"]");
        let luxrender = ExrFormat {
            half: true,
            tone_mapped: true,
            ..flag_exr
        };
        assert_eq!(outputs.files(false), [OutputFile::Exr(luxrender)]);
        assert_eq!(outputs.files(true), [OutputFile::Exr(luxrender)]);
        let (outputs, _) = read(
            "\"string write_exr_channels\" [\"YA\"] \"bool write_exr_applyimaging\" [\"true\"] \
             \"bool write_tga\" [\"true\"] \"string write_tga_channels\" [\"Y\"]",
        );
        // --exr where the Film writes none: linear full floats whatever write_exr_applyimaging
        // says of the EXR the Film does not write (its channels are the Film's).
        let exr = ExrFormat {
            channels: Channels::Ya,
            ..flag_exr
        };
        assert_eq!(
            outputs.files(true),
            [
                png,
                OutputFile::Tga {
                    channels: Channels::Y
                },
                OutputFile::Exr(exr)
            ]
        );
        assert!(outputs.needs_alpha(), "an EXR of YA, which --exr may write");
    }

    #[test]
    fn unknown_names_fall_back_as_luxrender_does_with_a_note() {
        let (outputs, notes) = read(
            "\"string write_tga_channels\" [\"YA\"] \"string write_png_channels\" [\"rgb\"] \
             \"string ldr_clamp_method\" [\"clip\"] \"string write_exr_channels\" [\"RGBA\"]",
        );
        assert_eq!(outputs.tga_channels, Channels::Rgb);
        assert_eq!(outputs.png_channels, Channels::Rgb);
        assert_eq!(outputs.exr_channels, Channels::Rgba);
        assert_eq!(outputs.ldr_clamp, LdrClamp::Cut);
        assert_eq!(notes.len(), 3, "{notes:?}");
        for given in ["\"write_tga_channels\" \"YA\"", "\"rgb\"", "\"clip\""] {
            assert!(
                notes.iter().any(|n| n.contains(given)),
                "{given}: {notes:?}"
            );
        }
    }

    /// Each method on (2, 0.5, 0.25), whose red is out of range: the numbers LuxRender's
    /// `ColorSystem::Limit` gives; colours in range are left alone.
    #[test]
    fn ldr_clamp_methods_limit_as_luxrender_does() {
        let c = Vec3::new(2.0, 0.5, 0.25);
        let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-6;
        assert_eq!(LdrClamp::Cut.limit(c), Vec3::new(1.0, 0.5, 0.25));
        assert_eq!(LdrClamp::Darken.limit(c), Vec3::new(1.0, 0.25, 0.125));
        // Toward the grey 1/3 until red is 1: t = (1 - 1/3) / (2 - 1/3) = 0.4.
        let hue = LdrClamp::Hue.limit(c);
        assert!(close(hue, Vec3::new(1.0, 0.4, 0.3)), "{hue}");
        // Toward the grey of its luminance, which it keeps.
        let y = Vec3::from_array(LIMIT_LUMINANCE).dot(c);
        assert!((y - 0.802_383).abs() < 1e-5, "{y}");
        let lum = LdrClamp::Lum.limit(c);
        let t = (1.0 - y) / (2.0 - y);
        assert!(close(lum, Vec3::splat(y) + (c - y) * t), "{lum}");
        assert_eq!(lum.x, 1.0);
        assert!((Vec3::from_array(LIMIT_LUMINANCE).dot(lum) - y).abs() < 1e-6);
        // Brighter than white in luminance: white.
        assert_eq!(LdrClamp::Lum.limit(Vec3::new(3.0, 1.5, 1.0)), Vec3::ONE);
        for method in [
            LdrClamp::Lum,
            LdrClamp::Hue,
            LdrClamp::Cut,
            LdrClamp::Darken,
        ] {
            let inside = Vec3::new(1.0, 0.2, -0.1);
            assert_eq!(method.limit(inside), inside, "{}", method.name());
        }
    }

    /// The default PNG's samples are YAT's 8-bit encoding of every earlier release: the
    /// tone-mapped value clamped, gamma encoded, rounded.
    #[test]
    fn the_default_8_bit_encoding_is_unchanged() {
        let image = image(LdrClamp::Cut);
        let rgb = image.to_rgb8();
        for (i, px) in rgb.pixels().enumerate() {
            let c = image.tone_mapped[i];
            let old = |v: f32| (libm::powf(v.clamp(0.0, 1.0), 1.0 / 2.2) * 255.0 + 0.5) as u8;
            assert_eq!(px.0, [old(c.x), old(c.y), old(c.z)], "pixel {i}");
        }
    }

    fn write(image: &FilmImage, file: OutputFile) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(format!("x.{}", file.extension()));
        image.write(&file, &path).unwrap();
        (dir, path)
    }

    /// A 16-bit RGBA PNG holds each channel of the encoded image within half a step of 65535,
    /// and alpha as is; a YA one holds the luminance of the encoded colour.
    #[test]
    fn sixteen_bit_and_grey_pngs_hold_the_encoded_values() {
        let image = image(LdrClamp::Lum);
        let rgba = OutputFile::Png {
            channels: Channels::Rgba,
            sixteen_bit: true,
        };
        let (_dir, path) = write(&image, rgba);
        let read = image::open(&path).unwrap();
        assert_eq!(read.color(), image::ColorType::Rgba16);
        let read = read.to_rgba16();
        let alpha = image.alpha.as_ref().unwrap();
        for (i, px) in read.pixels().enumerate() {
            let c = image.encoded(i);
            for (got, want) in px.0.iter().zip([c.x, c.y, c.z, alpha[i]]) {
                let err = (f32::from(*got) - want * 65535.0).abs();
                assert!(err <= 0.5, "pixel {i}: {got} for {want}");
            }
        }
        let ya = OutputFile::Png {
            channels: Channels::Ya,
            sixteen_bit: false,
        };
        let (_dir, path) = write(&image, ya);
        let read = image::open(&path).unwrap();
        assert_eq!(read.color(), image::ColorType::La8);
        for (i, px) in read.to_luma_alpha8().pixels().enumerate() {
            let y = Vec3::from_array(LDR_LUMINANCE).dot(image.encoded(i));
            assert!((f32::from(px.0[0]) - y * 255.0).abs() <= 0.5, "pixel {i}");
            assert_eq!(px.0[1], (alpha[i] * 255.0 + 0.5) as u8, "pixel {i}");
        }
        // The alpha ramp's ends: transparent and opaque.
        let first = read.to_luma_alpha8().get_pixel(0, 0).0[1];
        let last = read.to_luma_alpha8().get_pixel(4, 2).0[1];
        assert_eq!((first, last), (0, 255));
    }

    /// The TGA: LuxRender's header and layout (bottom row first, blue green red alpha), the
    /// same 8-bit values as the PNG; a grey one of the PNG's Y.
    #[test]
    fn tga_files_are_uncompressed_bottom_up_bgra() {
        let image = image(LdrClamp::Darken);
        let (_dir, path) = write(
            &image,
            OutputFile::Tga {
                channels: Channels::Rgba,
            },
        );
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes.len(), 18 + 5 * 3 * 4);
        assert_eq!(
            &bytes[..18],
            &[0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 5, 0, 3, 0, 32, 8]
        );
        let rgb = image.to_rgb8();
        let alpha = image.alpha.as_ref().unwrap();
        // The file's first pixel is the image's bottom-left one.
        let bottom_left = 2 * 5;
        let p = rgb.get_pixel(0, 2).0;
        let a = (alpha[bottom_left] * 255.0 + 0.5) as u8;
        assert_eq!(&bytes[18..22], &[p[2], p[1], p[0], a]);
        // `image` reads it back as the PNG's pixels.
        let read = image::open(&path).unwrap().to_rgba8();
        for (x, y, px) in read.enumerate_pixels() {
            let i = (y * 5 + x) as usize;
            let want = rgb.get_pixel(x, y).0;
            assert_eq!(
                px.0,
                [want[0], want[1], want[2], (alpha[i] * 255.0 + 0.5) as u8]
            );
        }
        let (_dir, path) = write(
            &image,
            OutputFile::Tga {
                channels: Channels::Y,
            },
        );
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!((bytes[2], bytes[16], bytes.len()), (3, 8, 18 + 15));
        let too_wide = FilmImage {
            width: MAX_TGA_SIDE + 1,
            height: 1,
            ..image
        };
        let error = too_wide
            .write_tga(&path, Channels::Rgb)
            .unwrap_err()
            .to_string();
        assert!(error.contains("65535 pixels a side"), "{error}");
    }

    /// The channels of an EXR, read back: name -> values.
    fn exr_channels(path: &Path) -> Vec<(String, Vec<f32>)> {
        use exr::prelude::*;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .unwrap();
        image
            .layer_data
            .channel_data
            .list
            .iter()
            .map(|c| {
                let values = c.sample_data.values_as_f32().collect();
                (c.name.to_string(), values)
            })
            .collect()
    }

    /// Half-float EXRs hold the full ones' values to half precision; an RGBA one has its
    /// colours multiplied by alpha (not with straight colours); a Y one LuxRender's
    /// luminance; the tone-mapped one the tone-mapped values.
    #[test]
    fn exr_files_hold_linear_or_tone_mapped_values_in_half_or_full_floats() {
        let image = image(LdrClamp::Cut);
        let alpha = image.alpha.clone().unwrap();
        let format = ExrFormat {
            channels: Channels::Rgba,
            half: false,
            tone_mapped: false,
            straight: false,
        };
        let (_d1, full) = write(&image, OutputFile::Exr(format));
        let (_d2, half) = write(
            &image,
            OutputFile::Exr(ExrFormat {
                half: true,
                ..format
            }),
        );
        let full = exr_channels(&full);
        let half = exr_channels(&half);
        let names: Vec<&str> = full.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["A", "B", "G", "R"]);
        for ((name, full), (_, half)) in full.iter().zip(&half) {
            for (i, (&f, &h)) in full.iter().zip(half).enumerate() {
                // Half floats keep 11 significant bits: within 2^-11 relative (and half's
                // smallest normal step near zero).
                assert!(
                    (f - h).abs() <= f.abs() * libm::exp2f(-11.0) + 6.2e-5,
                    "{name} {i}: {f} {h}"
                );
                let c = image.linear[i];
                let want = match name.as_str() {
                    "A" => alpha[i],
                    "R" => c.x * alpha[i],
                    "G" => c.y * alpha[i],
                    _ => c.z * alpha[i],
                };
                assert_eq!(f, want, "{name} {i}");
            }
        }
        let straight = ExrFormat {
            channels: Channels::Ya,
            tone_mapped: true,
            straight: true,
            ..format
        };
        let (_d3, path) = write(&image, OutputFile::Exr(straight));
        let read = exr_channels(&path);
        assert_eq!(read[0].0, "A");
        assert_eq!(read[1].0, "Y");
        for (i, &y) in read[1].1.iter().enumerate() {
            let c = image.tone_mapped[i];
            assert_eq!(y, 0.3 * c.x + 0.59 * c.y + 0.11 * c.z, "{i}");
        }
    }

    /// The AOVs are extra channels of the EXR: albedo and normal in its precision, Z and
    /// samples in full floats (Z infinite where no sample hit), values as given.
    #[test]
    fn aovs_are_extra_exr_channels() {
        let mut image = image(LdrClamp::Cut);
        let n = 15;
        image.aovs = AovImages {
            albedo: Some((0..n).map(|i| Vec3::splat(i as f32 / 16.0)).collect()),
            normal: Some(vec![Vec3::new(0.0, -0.6, 0.8); n]),
            depth: Some(
                (0..n)
                    .map(|i| {
                        if i == 3 {
                            f32::INFINITY
                        } else {
                            1.0 + i as f32 / 3.0
                        }
                    })
                    .collect(),
            ),
            samples: Some(vec![4097.0; n]),
        };
        let format = ExrFormat {
            channels: Channels::Rgb,
            half: true,
            tone_mapped: false,
            straight: false,
        };
        let (_dir, path) = write(&image, OutputFile::Exr(format));
        let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
        let types: Vec<(String, bool)> = meta.headers[0]
            .channels
            .list
            .iter()
            .map(|c| {
                (
                    c.name.to_string(),
                    c.sample_type == exr::meta::attribute::SampleType::F16,
                )
            })
            .collect();
        let names: Vec<&str> = types.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "B", "G", "N.X", "N.Y", "N.Z", "R", "Z", "albedo.B", "albedo.G", "albedo.R",
                "samples"
            ]
        );
        for (name, half) in &types {
            assert_eq!(*half, !matches!(name.as_str(), "Z" | "samples"), "{name}");
        }
        let read = exr_channels(&path);
        let channel = |name: &str| &read.iter().find(|(n, _)| n == name).unwrap().1;
        assert_eq!(channel("samples")[0], 4097.0, "exact in full floats");
        assert_eq!(channel("Z")[3], f32::INFINITY);
        assert_eq!(channel("Z")[6], 3.0);
        assert_eq!(channel("N.Y")[0], f16_of(-0.6));
        assert_eq!(channel("albedo.G")[5], 5.0 / 16.0);
    }

    fn f16_of(v: f32) -> f32 {
        exr::prelude::f16::from_f32(v).to_f32()
    }

    /// The RGB full-float EXR is the file `image`'s OpenEXR encoder writes: `--exr` keeps its
    /// bytes.
    #[test]
    fn the_linear_rgb_exr_is_the_image_crates() {
        let image = image(LdrClamp::Cut);
        let format = ExrFormat {
            channels: Channels::Rgb,
            half: false,
            tone_mapped: false,
            straight: false,
        };
        let (dir, path) = write(&image, OutputFile::Exr(format));
        let data: Vec<f32> = image.linear.iter().flat_map(|c| c.to_array()).collect();
        let old = image::Rgb32FImage::from_raw(5, 3, data).unwrap();
        let old_path = dir.path().join("old.exr");
        image::DynamicImage::ImageRgb32F(old)
            .save_with_format(&old_path, image::ImageFormat::OpenExr)
            .unwrap();
        assert_eq!(
            std::fs::read(path).unwrap(),
            std::fs::read(old_path).unwrap()
        );
    }
}
