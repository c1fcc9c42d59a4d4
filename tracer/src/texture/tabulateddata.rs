//! A spectrum tabulated at irregular wavelengths, as its RGB colour: read from a data file
//! (`tabulateddata`) or given inline (`irregulardata`).
//!
//! ```text
//! Texture "name" "color" "tabulateddata" "string filename" ["spectra/filter.txt"]
//! Texture "name" "color" "irregulardata" "float wavelengths" [400 500 600 700]
//!     "float data" [0.1 0.4 0.8 0.9]
//! ```
//!
//! | parameter | default | notes |
//! |---|---|---|
//! | `string filename` (tabulateddata) | none | the data file, relative to the scene |
//! | `float wavelengths`, `float data` (irregulardata) | none | as many of each, nm and value |
//!
//! The file is read as LuxRender reads it: lines of two numbers (wavelength, value) separated
//! by spaces, a comma or a semicolon; unparseable lines before the data are skipped and the
//! first one after it ends the data; an optional header line `wavelength: <unit> data: <tag>`
//! gives the unit (nm, um, eV or cm-1; nm without one). The spectrum is linear between its
//! samples and 0 outside them, and reduced to RGB by [`spectrum_rgb`] (a flat spectrum keeps
//! its value; negative channels are clipped). Where the data is unusable (fewer than two samples, nothing in the visible
//! range) LuxRender uses a flat spectrum of 1: so does this, with a warning naming the file.
//! A file that cannot be read, or that holds more than [`MAX_SAMPLES`] samples, is an error
//! naming it.

use super::common::Declared;
use super::constant::Constant;
use crate::assets::AssetKind;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::spectra::spectrum_rgb;

/// The most samples a data file may hold (measured spectra have hundreds to thousands).
pub const MAX_SAMPLES: usize = 1 << 16;
/// The largest magnitude a sample's value keeps (far beyond any measured spectrum).
pub const MAX_VALUE: f64 = 1e9;
/// Wavelengths LuxRender renders, nm: data entirely outside them is unusable.
const VISIBLE_NM: (f64, f64) = (380.0, 720.0);

/// A spectrum sampled at increasing wavelengths (nm).
#[derive(Clone, Debug, PartialEq)]
pub struct Tabulated {
    pub wavelengths: Vec<f64>,
    pub values: Vec<f64>,
}

impl Tabulated {
    /// The samples put in increasing order of wavelength (files may list them decreasing),
    /// values bounded by [`MAX_VALUE`] so the colour stays finite; None when fewer than two,
    /// or none in the visible range.
    pub fn new(mut wavelengths: Vec<f64>, values: Vec<f64>) -> Option<Self> {
        let n = wavelengths.len().min(values.len());
        wavelengths.truncate(n);
        let mut values: Vec<f64> = values[..n]
            .iter()
            .map(|v| v.clamp(-MAX_VALUE, MAX_VALUE))
            .collect();
        if n < 2 {
            return None;
        }
        if wavelengths[0] > wavelengths[n - 1] {
            wavelengths.reverse();
            values.reverse();
        }
        if wavelengths[0] > VISIBLE_NM.1 || wavelengths[n - 1] < VISIBLE_NM.0 {
            return None;
        }
        Some(Self {
            wavelengths,
            values,
        })
    }

    /// The value at `lambda` nm: linear between samples, 0 outside them.
    pub fn at(&self, lambda: f64) -> f64 {
        let w = &self.wavelengths;
        let i = w.partition_point(|&x| x < lambda);
        if i == 0 {
            return if lambda == w[0] { self.values[0] } else { 0.0 };
        }
        if i == w.len() {
            return 0.0;
        }
        let (l0, l1) = (w[i - 1], w[i]);
        let t = if l1 > l0 {
            (lambda - l0) / (l1 - l0)
        } else {
            1.0
        };
        self.values[i - 1] + t * (self.values[i] - self.values[i - 1])
    }

    fn rgb(&self) -> Constant {
        Constant {
            // Colours outside the sRGB gamut are clipped, as LuxCore does.
            value: spectrum_rgb(|l| self.at(l)).max(glam::Vec3::ZERO),
        }
    }
}

/// The flat spectrum of 1 LuxRender falls back to.
fn flat() -> Constant {
    Constant {
        value: glam::Vec3::ONE,
    }
}

/// A wavelength unit of a data file's header, as a conversion to nm.
fn unit(name: &str) -> Option<fn(f64) -> f64> {
    Some(match name {
        "nm" => |x| x,
        "um" => |x| x * 1000.0,
        // lambda = h c / E, with h c in eV nm.
        "eV" => |x| 1_239.841_98 / x,
        "cm-1" => |x| 1e7 / x,
        _ => return None,
    })
}

/// The unit named by a header line `wavelength: <unit> [,;] data: <tag>`, if the line is one.
fn header_unit(line: &str) -> Option<fn(f64) -> f64> {
    let rest = line[line.find("wavelength:")? + "wavelength:".len()..].trim_start();
    let end = rest
        .find(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .unwrap_or(rest.len());
    let after = rest[end..].trim_start_matches(|c: char| c.is_whitespace() || c == ',' || c == ';');
    if !after.starts_with("data:") {
        return None;
    }
    unit(&rest[..end])
}

/// A sample line: two numbers at the start, separated by spaces, a comma or a semicolon.
fn sample(line: &str) -> Option<(f64, f64)> {
    let is_sep = |c: char| c.is_whitespace() || c == ',' || c == ';';
    let line = line.trim_start();
    let end = line.find(is_sep)?;
    let second = line[end..].trim_start_matches(is_sep);
    let end2 = second.find(is_sep).unwrap_or(second.len());
    let (a, b) = (
        line[..end].parse::<f64>().ok()?,
        second[..end2].parse::<f64>().ok()?,
    );
    (a.is_finite() && b.is_finite() && a > 0.0).then_some((a, b))
}

/// The samples of a data file's text, in nm; Err when there are too many.
pub fn parse(text: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
    let (mut wavelengths, mut values) = (Vec::new(), Vec::new());
    let mut to_nm: Option<fn(f64) -> f64> = None;
    let mut in_data = false;
    for line in text.lines() {
        if !in_data {
            if let Some(u) = header_unit(line) {
                to_nm = Some(u);
                in_data = true;
                continue;
            }
        }
        let Some((l, v)) = sample(line) else {
            if in_data {
                break;
            }
            continue;
        };
        in_data = true;
        if wavelengths.len() == MAX_SAMPLES {
            return Err(format!("more than {MAX_SAMPLES} samples"));
        }
        wavelengths.push(to_nm.unwrap_or(|x| x)(l));
        values.push(v);
    }
    Ok((wavelengths, values))
}

/// Reads `tabulateddata`: the file's spectrum as a constant colour.
pub fn read_file(
    _decl: &Declared,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Constant, ParseError> {
    let Some(path) = params.string("filename")? else {
        ctx.warn(
            pos,
            "tabulateddata: no \"filename\"; using a flat spectrum of 1".into(),
        );
        return Ok(flat());
    };
    let bytes = ctx.read_asset(&path, AssetKind::Spectrum, pos)?;
    let text = String::from_utf8_lossy(&bytes);
    let (wavelengths, values) = parse(&text).map_err(|message| ParseError::Invalid {
        pos: pos.clone(),
        message: format!("spectral data file \"{path}\": {message}"),
    })?;
    Ok(match Tabulated::new(wavelengths, values) {
        Some(t) => t.rgb(),
        None => {
            ctx.warn(
                pos,
                format!("spectral data file \"{path}\" has fewer than two samples or none in the visible range; using a flat spectrum of 1"),
            );
            flat()
        }
    })
}

/// Reads `irregulardata`: the inline spectrum as a constant colour.
pub fn read_inline(
    _decl: &Declared,
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<Constant, ParseError> {
    let floats = |name: &str| -> Result<Vec<f64>, ParseError> {
        Ok(params
            .floats(name)?
            .map(|(v, _)| v.into_iter().map(f64::from).collect())
            .unwrap_or_default())
    };
    let (wavelengths, values) = (floats("wavelengths")?, floats("data")?);
    if wavelengths.len() != values.len() {
        ctx.warn(
            pos,
            format!(
                "irregulardata: {} wavelengths but {} data values; the extra ones are ignored",
                wavelengths.len(),
                values.len()
            ),
        );
    }
    Ok(match Tabulated::new(wavelengths, values) {
        Some(t) => t.rgb(),
        None => {
            ctx.warn(
                pos,
                "irregulardata: fewer than two samples or none in the visible range; using a flat spectrum of 1".into(),
            );
            flat()
        }
    })
}
