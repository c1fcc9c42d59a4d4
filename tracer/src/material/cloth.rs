//! `Material "cloth"`: woven cloth, Irawan and Marschner's yarn highlights over a diffuse base
//! (the [`cloth`](crate::bxdf::cloth) lobe), with LuxRender 1.x's six weave presets.
//!
//! ```text
//! Material "cloth" "string presetname" ["denim"]
//!     "color warp_Kd" [0.05 0.1 0.4] "color warp_Ks" [0.1 0.1 0.2]
//!     "color weft_Kd" [0.6 0.6 0.6] "color weft_Ks" [0.1 0.1 0.1]
//!     "float repeat_u" [100] "float repeat_v" [100]
//! ```
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `presetname` | string: denim, silk_charmeuse, silk_shantung, cotton_twill, wool_gabardine, polyester_lining_cloth | denim; an unknown name warns and uses denim ([`PRESETS`]) |
//! | `warp_Kd`, `weft_Kd` | color textures, diffuse reflectance of the warp and weft yarns, clamped to [0, 1] | 0 ([`DEFAULT_COLOR`]) |
//! | `warp_Ks`, `weft_Ks` | color textures, highlight colour of the warp and weft yarns, clamped to [0, 1] | 0 ([`DEFAULT_COLOR`]) |
//! | `repeat_u`, `repeat_v` | floats, weave tiles per unit of the surface's u and v | 100 ([`DEFAULT_REPEAT`]) |
//!
//! The colours default to black as in LuxRender (LuxBlend always writes them). A hit's (u, v)
//! times the repeats picks a cell of the preset's tile and so a yarn segment; its warp or weft
//! colours apply. The polyester and shantung presets vary each segment's inclination by Perlin
//! noise (the tracer's improved-noise lattice rather than Blender's, so the variation is the
//! same in kind and size but not in place), and the presets with a `fineness` give each fibre
//! a random glint, exp-distributed with mean 1 and capped at 10, as in LuxRender.
//!
//! Each preset's highlight is normalised as LuxRender does: its mean over cosine-distributed
//! pairs of directions and uniform points of the weave is 1 ([`Preset::normalization`],
//! measured once and checked by a test). LuxRender lets a bright glint reflect more than it
//! receives; here the highlight's scale is capped so that no point does (see the lobe).

use glam::{Vec2, Vec3};

use super::eval::{texture_ids, HitTextures};
use super::kind::MaterialKind;
use crate::bxdf::cloth::{Cloth as ClothLobe, Highlight, Scattering, Yarn, YarnKind, ALBEDO_STEPS};
use crate::bxdf::Bxdf;
use crate::diag::SourcePos;
use crate::refs::{ConstOrTexture, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::texture::noise::noise;

pub const DEFAULT_COLOR: f32 = 0.0;
pub const DEFAULT_REPEAT: f32 = 100.0;
/// A glint is at most this many times the mean highlight (LuxRender's cap of -ln xi).
pub const MAX_GLINT: f32 = 10.0;
/// Rounds of the TEA hash that seeds a segment's noise and a fibre's glint (LuxRender's 8).
const TEA_ROUNDS: u32 = 8;

/// A weave: its tile of yarn segments and the highlight's parameters.
#[derive(Debug, PartialEq)]
pub struct Preset {
    pub name: &'static str,
    /// Tile size in cells (width along u, height along v).
    pub width: u32,
    pub height: u32,
    /// For each cell, row by row from the top (v = 1) down, the 1-based index of its yarn.
    pub pattern: &'static [u8],
    pub yarns: &'static [Yarn],
    pub scattering: Scattering,
    /// Glint seeds per cell along each axis (0: no glints).
    pub fineness: f32,
    /// Change of a warp's and a weft's inclination (radians) per unit of the noise along the
    /// warp and along the weft: [warp by warp, warp by weft, weft by warp, weft by weft].
    pub inclination_noise: [f32; 4],
    /// Period of that noise in cells (0: none).
    pub period: f32,
    /// LuxRender's specular normalisation: 1 / the highlight's mean (at the default repeat).
    pub normalization: f32,
    /// A bound of the normalised highlight's directional albedo over every point of the
    /// weave, at cos(theta_o) = 1, 0.9, ..., 0 (measured with a margin; `cloth_tests` checks
    /// both constants).
    pub albedo_bound: [f32; ALBEDO_STEPS],
}

const fn deg(d: f32) -> f32 {
    d * (std::f32::consts::PI / 180.0)
}

/// A yarn segment from LuxRender's table: twist and inclination in degrees, curvature, width,
/// length and centre (u, v) in tile units.
const fn yarn(
    kind: YarnKind,
    psi: f32,
    umax: f32,
    kappa: f32,
    size: [f32; 2],
    c: [f32; 2],
) -> Yarn {
    Yarn {
        kind,
        psi: deg(psi),
        umax: deg(umax),
        kappa,
        width: size[0],
        length: size[1],
        center: Vec2::new(c[0], c[1]),
    }
}

use YarnKind::{Warp as W, Weft as F};

const fn scattering(alpha: f32, beta: f32, smoothing: f32, areas: [f32; 2]) -> Scattering {
    Scattering {
        alpha,
        beta,
        smoothing,
        highlight_width: 0.5,
        warp_area: areas[0],
        weft_area: areas[1],
    }
}

/// LuxRender's presets (its table, originally Irawan's); the first is the default.
pub static PRESETS: [Preset; 6] = [
    Preset {
        name: "denim",
        width: 3,
        height: 6,
        pattern: &[1, 3, 8, 1, 3, 5, 1, 7, 5, 1, 4, 5, 6, 4, 5, 2, 4, 5],
        yarns: &[
            yarn(W, -30.0, 12.0, 0.0, [1.0, 5.0], [0.1667, 0.75]),
            yarn(W, -30.0, 12.0, 0.0, [1.0, 5.0], [0.1667, -0.25]),
            yarn(W, -30.0, 12.0, 0.0, [1.0, 5.0], [0.5, 1.0833]),
            yarn(W, -30.0, 12.0, 0.0, [1.0, 5.0], [0.5, 0.0833]),
            yarn(W, -30.0, 12.0, 0.0, [1.0, 5.0], [0.8333, 0.4167]),
            yarn(F, -30.0, 38.0, 0.0, [1.0, 1.0], [0.1667, 0.25]),
            yarn(F, -30.0, 38.0, 0.0, [1.0, 1.0], [0.5, 0.5833]),
            yarn(F, -30.0, 38.0, 0.0, [1.0, 1.0], [0.8333, 0.9167]),
        ],
        scattering: scattering(0.01, 4.0, 0.0, [5.0, 1.0]),
        fineness: 3.0,
        inclination_noise: [0.0; 4],
        period: 0.0,
        normalization: 702.1,
        albedo_bound: [1.6, 1.7, 2.0, 2.4, 3.0, 3.8, 4.9, 5.8, 6.9, 7.9, 9.1],
    },
    Preset {
        name: "silk_charmeuse",
        width: 5,
        height: 10,
        pattern: &[
            10, 2, 4, 6, 8, 1, 2, 4, 6, 8, 1, 2, 4, 13, 8, 1, 2, 4, 7, 8, 1, 11, 4, 7, 8, 1, 3, 4,
            7, 8, 1, 3, 4, 7, 14, 1, 3, 4, 7, 9, 1, 3, 12, 7, 9, 1, 3, 5, 7, 9,
        ],
        yarns: &[
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.1, 0.45]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.3, 1.05]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.3, 0.05]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.5, 0.65]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.5, -0.35]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.7, 1.25]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.7, 0.25]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.9, 0.85]),
            yarn(W, 0.0, 40.0, 2.0, [1.0, 9.0], [0.9, -0.15]),
            yarn(F, 0.0, 60.0, 0.0, [1.0, 1.0], [0.1, 0.95]),
            yarn(F, 0.0, 60.0, 0.0, [1.0, 1.0], [0.3, 0.55]),
            yarn(F, 0.0, 60.0, 0.0, [1.0, 1.0], [0.5, 0.15]),
            yarn(F, 0.0, 60.0, 0.0, [1.0, 1.0], [0.7, 0.75]),
            yarn(F, 0.0, 60.0, 0.0, [1.0, 1.0], [0.9, 0.35]),
        ],
        scattering: scattering(0.02, 7.3, 0.5, [9.0, 1.0]),
        fineness: 3.0,
        inclination_noise: [0.0; 4],
        period: 0.0,
        normalization: 317.1,
        albedo_bound: [5.2, 5.1, 5.0, 4.8, 4.7, 4.8, 5.4, 7.1, 6.9, 7.8, 8.8],
    },
    Preset {
        name: "silk_shantung",
        width: 6,
        height: 8,
        pattern: &[
            3, 3, 3, 3, 2, 2, 3, 3, 3, 3, 2, 2, 3, 3, 3, 3, 2, 2, 3, 3, 3, 3, 2, 2, 4, 1, 1, 5, 5,
            5, 4, 1, 1, 5, 5, 5, 4, 1, 1, 5, 5, 5, 4, 1, 1, 5, 5, 5,
        ],
        yarns: &[
            yarn(W, 0.0, 50.0, -0.5, [2.0, 4.0], [0.3333, 0.25]),
            yarn(W, 0.0, 50.0, -0.5, [2.0, 4.0], [0.8333, 0.75]),
            yarn(F, 0.0, 23.0, -0.3, [4.0, 4.0], [0.3333, 0.75]),
            yarn(F, 0.0, 23.0, -0.3, [4.0, 4.0], [-0.1667, 0.25]),
            yarn(F, 0.0, 23.0, -0.3, [4.0, 4.0], [0.8333, 0.25]),
        ],
        scattering: scattering(0.02, 1.5, 0.5, [8.0, 16.0]),
        fineness: 0.0,
        inclination_noise: [deg(20.0), deg(20.0), deg(10.0), deg(10.0)],
        period: 500.0,
        normalization: 30.8,
        albedo_bound: [3.0, 3.6, 3.9, 4.1, 4.4, 4.4, 4.6, 4.7, 4.8, 4.8, 4.9],
    },
    Preset {
        name: "cotton_twill",
        width: 4,
        height: 8,
        pattern: &[
            7, 2, 4, 6, 7, 2, 4, 6, 1, 8, 4, 6, 1, 8, 4, 6, 1, 3, 9, 6, 1, 3, 9, 6, 1, 3, 5, 10, 1,
            3, 5, 10,
        ],
        yarns: &[
            yarn(W, -30.0, 24.0, 0.0, [1.0, 6.0], [0.125, 0.375]),
            yarn(W, -30.0, 24.0, 0.0, [1.0, 6.0], [0.375, 1.125]),
            yarn(W, -30.0, 24.0, 0.0, [1.0, 6.0], [0.375, 0.125]),
            yarn(W, -30.0, 24.0, 0.0, [1.0, 6.0], [0.625, 0.875]),
            yarn(W, -30.0, 24.0, 0.0, [1.0, 6.0], [0.625, -0.125]),
            yarn(W, -30.0, 24.0, 0.0, [1.0, 6.0], [0.875, 0.625]),
            yarn(F, -30.0, 36.0, 0.0, [2.0, 1.0], [0.125, 0.875]),
            yarn(F, -30.0, 36.0, 0.0, [2.0, 1.0], [0.375, 0.625]),
            yarn(F, -30.0, 36.0, 0.0, [2.0, 1.0], [0.625, 0.375]),
            yarn(F, -30.0, 36.0, 0.0, [2.0, 1.0], [0.875, 0.125]),
        ],
        scattering: scattering(0.01, 4.0, 0.0, [6.0, 2.0]),
        fineness: 4.0,
        inclination_noise: [0.0; 4],
        period: 0.0,
        normalization: 706.2,
        albedo_bound: [2.1, 2.3, 2.6, 3.2, 4.0, 5.2, 6.4, 7.9, 9.3, 11.5, 12.8],
    },
    Preset {
        name: "wool_gabardine",
        width: 6,
        height: 9,
        pattern: &[
            1, 1, 2, 2, 7, 7, 1, 1, 2, 2, 7, 7, 1, 1, 2, 2, 7, 7, 1, 1, 6, 6, 4, 4, 1, 1, 6, 6, 4,
            4, 1, 1, 6, 6, 4, 4, 5, 5, 3, 3, 4, 4, 5, 5, 3, 3, 4, 4, 5, 5, 3, 3, 4, 4,
        ],
        yarns: &[
            yarn(W, 30.0, 30.0, 0.0, [2.0, 6.0], [0.167, 0.667]),
            yarn(W, 30.0, 30.0, 0.0, [2.0, 6.0], [0.5, 1.0]),
            yarn(W, 30.0, 30.0, 0.0, [2.0, 6.0], [0.5, 0.0]),
            yarn(W, 30.0, 30.0, 0.0, [2.0, 6.0], [0.833, 0.333]),
            yarn(F, 30.0, 30.0, 0.0, [3.0, 2.0], [0.167, 0.167]),
            yarn(F, 30.0, 30.0, 0.0, [3.0, 2.0], [0.5, 0.5]),
            yarn(F, 30.0, 30.0, 0.0, [3.0, 2.0], [0.833, 0.833]),
        ],
        scattering: scattering(0.01, 4.0, 0.0, [12.0, 6.0]),
        fineness: 0.0,
        inclination_noise: [0.0; 4],
        period: 0.0,
        normalization: 259.6,
        albedo_bound: [1.8, 1.9, 2.2, 2.6, 3.4, 4.4, 5.6, 7.1, 8.3, 9.8, 11.4],
    },
    Preset {
        name: "polyester_lining_cloth",
        width: 2,
        height: 2,
        pattern: &[3, 2, 1, 4],
        yarns: &[
            yarn(W, 0.0, 22.0, -0.7, [1.0, 1.0], [0.25, 0.25]),
            yarn(W, 0.0, 22.0, -0.7, [1.0, 1.0], [0.75, 0.75]),
            yarn(F, 0.0, 16.0, -0.7, [1.0, 1.0], [0.25, 0.75]),
            yarn(F, 0.0, 16.0, -0.7, [1.0, 1.0], [0.75, 0.25]),
        ],
        scattering: scattering(0.015, 4.0, 0.5, [1.0, 1.0]),
        fineness: 0.0,
        inclination_noise: [deg(8.0), deg(8.0), deg(6.0), deg(6.0)],
        period: 50.0,
        normalization: 893.7,
        albedo_bound: [2.5, 2.6, 2.7, 3.0, 3.8, 5.7, 7.0, 8.0, 8.9, 8.7, 7.9],
    },
];

/// The preset named `name`.
pub fn preset(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

/// The tiny encryption algorithm as a hash of two words (what LuxRender seeds its noise with).
fn tea(v0: u32, v1: u32) -> u64 {
    let (mut v0, mut v1, mut sum) = (v0, v1, 0u32);
    for _ in 0..TEA_ROUNDS {
        sum = sum.wrapping_add(0x9e37_79b9);
        v0 = v0.wrapping_add(
            (v1 << 4).wrapping_add(0xa341_316c)
                ^ v1.wrapping_add(sum)
                ^ (v1 >> 5).wrapping_add(0xc801_3ea4),
        );
        v1 = v1.wrapping_add(
            (v0 << 4).wrapping_add(0xad90_777d)
                ^ v0.wrapping_add(sum)
                ^ (v0 >> 5).wrapping_add(0x7e95_761e),
        );
    }
    (u64::from(v1) << 32) + u64::from(v0)
}

/// A uniform float in [0, 1) from the hash's low 23 bits.
fn tea_float(v0: u32, v1: u32) -> f32 {
    ((tea(v0, v1) & 0xffff_ffff) >> 9) as f32 / (1u32 << 23) as f32
}

/// A float to a hash word the way C's conversion does on the usual targets (negative values
/// wrap instead of saturating at 0).
fn word(x: f32) -> u32 {
    x as i64 as u32
}

impl Preset {
    /// The yarn segment at surface coordinates `uv` with `repeat` tiles per unit, the point
    /// on it and its highlight.
    pub fn highlight(&'static self, uv: Vec2, repeat: Vec2) -> Highlight {
        let (w, h) = (self.width as f32, self.height as f32);
        let p = uv * repeat;
        let base = p.floor();
        let base = if base.is_finite() { base } else { Vec2::ZERO };
        let offset = (p - base).clamp(Vec2::ZERO, Vec2::ONE);
        let offset = if offset.is_finite() {
            offset
        } else {
            Vec2::ZERO
        };
        let column = ((offset.x * w) as u32).min(self.width - 1);
        // The pattern's rows run from the top of the tile down.
        let row = self.height - 1 - ((offset.y * h) as u32).min(self.height - 1);
        let index = self.pattern[(column + self.width * row) as usize] as usize - 1;
        let yarn = &self.yarns[index];
        let tile = Vec2::new(w, h);
        let center = (base + yarn.center) * tile;
        let xy = (offset - yarn.center) * tile;

        let mut umax = yarn.umax;
        if self.period > 0.0 {
            // One seed per segment: correlated noise along each axis of the cloth.
            let along_warp = (center.x
                * (h * repeat.y + tea_float(word(center.x), word(2.0 * center.y)))
                + center.y)
                / self.period;
            let along_weft = (center.y
                * (w * repeat.x + tea_float(word(center.x), word(2.0 * center.y + 1.0)))
                + center.x)
                / self.period;
            let (r1, r2) = (
                noise(Vec3::new(along_warp, 0.0, 0.0)),
                noise(Vec3::new(along_weft, 0.0, 0.0)),
            );
            let [a, b] = match yarn.kind {
                YarnKind::Warp => [self.inclination_noise[0], self.inclination_noise[1]],
                YarnKind::Weft => [self.inclination_noise[2], self.inclination_noise[3]],
            };
            umax += r1 * a + r2 * b;
        }
        let at = match yarn.kind {
            YarnKind::Warp => Vec2::new(
                xy.y * 2.0 * umax / yarn.length,
                xy.x * std::f32::consts::PI / yarn.width,
            ),
            // The weft's point turned a quarter, as its directions are.
            YarnKind::Weft => Vec2::new(
                xy.x * 2.0 * umax / yarn.length,
                -xy.y * std::f32::consts::PI / yarn.width,
            ),
        };
        let glint = if self.fineness > 0.0 {
            let fibre = (center + xy) * self.fineness;
            let xi = tea_float(word(fibre.x), word(fibre.y));
            (-libm::logf(xi)).min(MAX_GLINT)
        } else {
            1.0
        };
        Highlight {
            yarn,
            scattering: &self.scattering,
            at,
            umax,
            glint,
            normalization: self.normalization,
            albedo_bound: &self.albedo_bound,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Cloth {
    pub preset: &'static Preset,
    /// Diffuse and highlight colours of the warp, then of the weft.
    pub warp: [ConstOrTexture; 2],
    pub weft: [ConstOrTexture; 2],
    pub repeat: Vec2,
}

impl Cloth {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let name = params.string_or("presetname", PRESETS[0].name)?;
        let preset = preset(&name).unwrap_or_else(|| {
            ctx.warn(
                pos,
                format!("cloth: no preset named \"{name}\"; using \"denim\""),
            );
            &PRESETS[0]
        });
        let mut color = |n: &str| ctx.color_param(params, n, DEFAULT_COLOR, true);
        Ok(Self {
            preset,
            warp: [color("warp_Kd")?, color("warp_Ks")?],
            weft: [color("weft_Kd")?, color("weft_Ks")?],
            repeat: Vec2::new(
                params.float("repeat_u", DEFAULT_REPEAT)?,
                params.float("repeat_v", DEFAULT_REPEAT)?,
            ),
        })
    }
}

impl MaterialKind for Cloth {
    fn textures(&self) -> Vec<TextureId> {
        texture_ids(&[&self.warp[0], &self.warp[1], &self.weft[0], &self.weft[1]])
    }

    fn bxdf(&self, eval: &HitTextures, _u: f32) -> Bxdf {
        let highlight = self.preset.highlight(eval.at.uv, self.repeat);
        let [kd, ks] = match highlight.yarn.kind {
            YarnKind::Warp => self.warp,
            YarnKind::Weft => self.weft,
        };
        Bxdf::Cloth(ClothLobe::new(eval.color(kd), eval.color(ks), highlight))
    }
}
