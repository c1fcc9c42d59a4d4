//! What every blender_* texture shares (a leaf of the family): the 3D mapping, the two
//! textures the pattern blends between, Blender's brightness and contrast, and the shapes of
//! the noise-based patterns.
//!
//! | parameter        | default | notes |
//! |------------------|---------|-------|
//! | `tex1`           | 0       | float texture or constant: where the pattern is 0 |
//! | `tex2`           | 1       | where it is 1 |
//! | `float bright`   | 1       | Blender's brightness |
//! | `float contrast` | 1       | Blender's contrast |
//! | `string noisetype` | soft_noise | soft_noise, or hard_noise (the basis folded to abs(2n - 1)) |
//! | 3D mapping       | global  | see [`crate::texture::mapping`] |
//!
//! The value is tex1 + f (tex2 - tex1), f the pattern's intensity: (i - 0.5) contrast +
//! bright - 0.5 clamped to [0, 1]; a coloured pattern (clouds "color", magic, voronoi's colour
//! modes) gets brightness and contrast per channel and then f = min(0.35 r + 0.45 g + 0.2 b, 1).

use glam::Vec3;

use crate::diag::SourcePos;
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::texture::common::Declared;
use crate::texture::mapping::Mapping3D;

pub const DEFAULT_TEX1: f32 = 0.0;
pub const DEFAULT_TEX2: f32 = 1.0;
pub const DEFAULT_BRIGHT: f32 = 1.0;
pub const DEFAULT_CONTRAST: f32 = 1.0;
pub const DEFAULT_NOISESIZE: f32 = 0.25;
pub const DEFAULT_TURBULENCE: f32 = 5.0;
pub const DEFAULT_NOISEDEPTH: i32 = 2;

#[derive(Clone, Debug, PartialEq)]
pub struct Base {
    pub tex1: ConstOrTexture,
    pub tex2: ConstOrTexture,
    pub bright: f32,
    pub contrast: f32,
    pub mapping: Mapping3D,
}

/// A pattern's raw result: an intensity or a colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pattern {
    Intensity(f32),
    Rgb(Vec3),
    /// An intensity Blender does not pass through brightness and contrast (stucci).
    Raw(f32),
}

impl Base {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(Self {
            tex1: decl.tex(ctx, params, "tex1", DEFAULT_TEX1)?,
            tex2: decl.tex(ctx, params, "tex2", DEFAULT_TEX2)?,
            bright: params.float("bright", DEFAULT_BRIGHT)?,
            contrast: params.float("contrast", DEFAULT_CONTRAST)?,
            mapping: Mapping3D::read(params, pos, ctx)?,
        })
    }

    /// The blend weight f of a pattern's result.
    pub fn weight(&self, pattern: Pattern) -> f32 {
        let adjust = |v: f32| (v - 0.5) * self.contrast + self.bright - 0.5;
        let f = match pattern {
            Pattern::Intensity(v) => adjust(v).clamp(0.0, 1.0),
            Pattern::Rgb(c) => {
                let c = Vec3::new(adjust(c.x), adjust(c.y), adjust(c.z)).max(Vec3::ZERO);
                (0.35 * c.x + 0.45 * c.y + 0.2 * c.z).min(1.0)
            }
            Pattern::Raw(v) => v,
        };
        // A NaN from a degenerate parameter blends nothing in.
        if f.is_nan() {
            0.0
        } else {
            f
        }
    }
}

/// Whether `string noisetype` asks for hard noise.
pub fn read_hard(
    params: &ParamList,
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<bool, ParseError> {
    Ok(read_choice(params, "noisetype", &["soft_noise", "hard_noise"], pos, ctx)? == 1)
}

/// A string parameter that picks one of `names` (the first is the default); an unknown name
/// warns and gives the default.
pub fn read_choice(
    params: &ParamList,
    name: &str,
    names: &[&str],
    pos: &SourcePos,
    ctx: &mut dyn ParseContext,
) -> Result<usize, ParseError> {
    let value = params.string_or(name, names[0])?;
    Ok(match names.iter().position(|n| *n == value) {
        Some(i) => i,
        None => {
            ctx.warn(
                pos,
                format!("unknown {name} \"{value}\"; using {}", names[0]),
            );
            0
        }
    })
}

/// The noise depth (octaves beyond the first), bounded.
pub fn read_depth(params: &ParamList) -> Result<u32, ParseError> {
    Ok(params.int("noisedepth", DEFAULT_NOISEDEPTH)?.clamp(0, 25) as u32)
}

/// Blender's periodic wave forms (`string noisebasis2`: sin, saw, tri), each from [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wave {
    Sin,
    Saw,
    Tri,
}

impl Wave {
    pub const NAMES: [&'static str; 3] = ["sin", "saw", "tri"];

    pub fn from_index(i: usize) -> Self {
        [Wave::Sin, Wave::Saw, Wave::Tri][i]
    }

    pub fn eval(self, a: f32) -> f32 {
        use std::f32::consts::TAU;
        match self {
            Wave::Sin => 0.5 + 0.5 * libm::sinf(a),
            Wave::Saw => {
                // Blender truncates towards zero, then folds negatives up.
                let mut r = a - (a / TAU).trunc() * TAU;
                if r < 0.0 {
                    r += TAU;
                }
                r / TAU
            }
            Wave::Tri => 1.0 - 2.0 * ((a / TAU + 0.5).floor() - a / TAU).abs(),
        }
    }
}
