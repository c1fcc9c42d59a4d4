//! The noise bases of the blender_* textures (Blender's noise library, as LuxRender 1.x
//! carries it), and the sums built on them: `g_noise` and `g_turbulence` (clouds, wood,
//! marble, stucci) and Musgrave's fractals (fbm, multifractal, hetero terrain, hybrid and
//! ridged multifractal) and the distorted noise of musgrave and distortednoise.
//!
//! | basis (`string noisebasis`) | unsigned value |
//! |------------------|-------|
//! | blender_original (default) | 0.5 + 0.5 x Perlin noise (see below) |
//! | original_perlin, improved_perlin | 0.5 + 0.5 x Perlin noise |
//! | voronoi_f1 .. voronoi_f4 | distance to the 1st .. 4th nearest feature point |
//! | voronoi_f2_f1 | F2 - F1 |
//! | voronoi_crackle | min(1, 10 (F2 - F1)) |
//! | cell_noise | Blender's integer hash of the cell, exactly |
//!
//! Where YAT departs from LuxRender, on purpose: Blender's own gradient noises and its voronoi
//! feature points come from about 4000 tabulated random numbers, which YAT does not copy.
//! The Perlin bases use YAT's Perlin noise ([`super::super::noise`], the same lattice and
//! range); the feature points are one per unit cell, placed by Blender's cell-noise integer
//! hash. Patterns therefore have Blender's character, scale, range and parameters, but their
//! features do not sit at the same places; `yat check` says so for every blender_* texture
//! that uses a noise.

use glam::Vec3;

use super::super::noise::noise;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_BASIS: &str = "blender_original";
/// How many octaves a sum may take: Blender asserts at most 25, and a hostile file must not
/// stall every lookup.
pub const MAX_OCTAVES: f32 = 25.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoiseBasis {
    BlenderOriginal,
    OriginalPerlin,
    ImprovedPerlin,
    VoronoiF1,
    VoronoiF2,
    VoronoiF3,
    VoronoiF4,
    VoronoiF2F1,
    VoronoiCrackle,
    CellNoise,
}

/// Blender's cell-noise hash of an integer cell, in [0, 1).
fn cell_hash(x: i32, y: i32, z: i32) -> f32 {
    let mut n = (x as u32)
        .wrapping_add((y as u32).wrapping_mul(1301))
        .wrapping_add((z as u32).wrapping_mul(314_159));
    n ^= n << 13;
    let h = n
        .wrapping_mul(n.wrapping_mul(n).wrapping_mul(15731).wrapping_add(789_221))
        .wrapping_add(1_376_312_589);
    h as f32 / 4_294_967_296.0
}

fn cell_of(p: Vec3) -> (i32, i32, i32) {
    // `as` saturates: a huge coordinate lands in the last cell instead of wrapping.
    (p.x.floor() as i32, p.y.floor() as i32, p.z.floor() as i32)
}

/// The feature point of a cell, in [0, 1)^3 relative to its corner (also the cell colour of
/// the voronoi texture's colour modes).
pub fn cell_point(x: i32, y: i32, z: i32) -> Vec3 {
    Vec3::new(
        cell_hash(x, y, z),
        cell_hash(x.wrapping_add(7919), y, z.wrapping_sub(104_729)),
        cell_hash(x, y.wrapping_add(15_485_863), z.wrapping_add(32_452_843)),
    )
}

/// How the voronoi texture measures distance (`string distmetric`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Metric {
    Actual,
    Squared,
    Manhattan,
    Chebychev,
    MinkowskiHalf,
    MinkowskiFour,
    /// With the exponent.
    Minkowski(f32),
}

impl Metric {
    fn distance(self, d: Vec3) -> f32 {
        let a = d.abs();
        match self {
            Metric::Actual => d.length(),
            Metric::Squared => d.length_squared(),
            Metric::Manhattan => a.element_sum(),
            Metric::Chebychev => a.max_element(),
            Metric::MinkowskiHalf => {
                let s = a.x.sqrt() + a.y.sqrt() + a.z.sqrt();
                s * s
            }
            Metric::MinkowskiFour => {
                let q = a * a;
                (q * q).element_sum().sqrt().sqrt()
            }
            Metric::Minkowski(e) => libm::powf(a.powf(e).element_sum(), 1.0 / e),
        }
    }
}

/// The distances to the four nearest feature points (nearest first) and those points.
pub fn voronoi(p: Vec3, metric: Metric) -> ([f32; 4], [Vec3; 4]) {
    let mut da = [1e10f32; 4];
    let mut pa = [Vec3::ZERO; 4];
    let (xi, yi, zi) = cell_of(p);
    for dx in -1..=1 {
        for dy in -1..=1 {
            for dz in -1..=1 {
                let (x, y, z) = (
                    xi.saturating_add(dx),
                    yi.saturating_add(dy),
                    zi.saturating_add(dz),
                );
                let point = cell_point(x, y, z) + Vec3::new(x as f32, y as f32, z as f32);
                let d = metric.distance(p - point);
                if let Some(k) = da.iter().position(|&e| d < e) {
                    da.copy_within(k..3, k + 1);
                    pa.copy_within(k..3, k + 1);
                    da[k] = d;
                    pa[k] = point;
                }
            }
        }
    }
    (da, pa)
}

fn perlin_unsigned(p: Vec3) -> f32 {
    0.5 + 0.5 * noise(p)
}

impl NoiseBasis {
    /// The basis named by parameter `name` (an unknown name warns and is blender_original).
    pub fn read(
        params: &ParamList,
        name: &str,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(match params.string_or(name, DEFAULT_BASIS)?.as_str() {
            "blender_original" => Self::BlenderOriginal,
            "original_perlin" => Self::OriginalPerlin,
            "improved_perlin" => Self::ImprovedPerlin,
            "voronoi_f1" => Self::VoronoiF1,
            "voronoi_f2" => Self::VoronoiF2,
            "voronoi_f3" => Self::VoronoiF3,
            "voronoi_f4" => Self::VoronoiF4,
            "voronoi_f2_f1" => Self::VoronoiF2F1,
            "voronoi_crackle" => Self::VoronoiCrackle,
            "cell_noise" => Self::CellNoise,
            other => {
                ctx.warn(
                    pos,
                    format!("unknown noise basis \"{other}\"; using blender_original"),
                );
                Self::BlenderOriginal
            }
        })
    }

    /// The basis in [0, 1] (roughly, for the gradient noises).
    pub fn unsigned(self, p: Vec3) -> f32 {
        let f = |k: usize| voronoi(p, Metric::Actual).0[k];
        match self {
            Self::BlenderOriginal | Self::OriginalPerlin | Self::ImprovedPerlin => {
                perlin_unsigned(p)
            }
            Self::VoronoiF1 => f(0),
            Self::VoronoiF2 => f(1),
            Self::VoronoiF3 => f(2),
            Self::VoronoiF4 => f(3),
            Self::VoronoiF2F1 => {
                let (da, _) = voronoi(p, Metric::Actual);
                da[1] - da[0]
            }
            Self::VoronoiCrackle => (10.0 * Self::VoronoiF2F1.unsigned(p)).min(1.0),
            Self::CellNoise => {
                let (x, y, z) = cell_of(p);
                cell_hash(x, y, z)
            }
        }
    }

    /// The basis centred on 0 (2 x unsigned - 1; the Perlin bases are their signed noise):
    /// what Musgrave's fractals and the distorted noise sum.
    pub fn signed(self, p: Vec3) -> f32 {
        match self {
            Self::OriginalPerlin | Self::ImprovedPerlin => noise(p),
            _ => 2.0 * self.unsigned(p) - 1.0,
        }
    }

    /// Blender's BLI_gNoise: the unsigned basis at p / size ("hard" folds it to |2n - 1|).
    pub fn g_noise(self, size: f32, p: Vec3, hard: bool) -> f32 {
        let t = self.unsigned(self.scaled(size, p));
        if hard {
            (2.0 * t - 1.0).abs()
        } else {
            t
        }
    }

    /// Blender's BLI_gTurbulence: octaves 0..=depth of the basis at doubling frequency and
    /// halving amplitude, normalised so the weights sum to 1. The Perlin bases enter signed,
    /// as in Blender.
    pub fn g_turbulence(self, size: f32, p: Vec3, depth: u32, hard: bool) -> f32 {
        let p = self.scaled(size, p);
        let depth = depth.min(MAX_OCTAVES as u32);
        let (mut sum, mut amp, mut scale) = (0.0, 1.0, 1.0);
        for _ in 0..=depth {
            let mut t = match self {
                Self::OriginalPerlin | Self::ImprovedPerlin => noise(scale * p),
                _ => self.unsigned(scale * p),
            };
            if hard {
                t = (2.0 * t - 1.0).abs();
            }
            sum += t * amp;
            amp *= 0.5;
            scale *= 2.0;
        }
        sum * (1u32 << depth) as f32 / ((1u32 << (depth + 1)) - 1) as f32
    }

    /// p / size, after Blender's shift by 1 for its original noise.
    fn scaled(self, size: f32, p: Vec3) -> Vec3 {
        let p = if self == Self::BlenderOriginal {
            p + Vec3::ONE
        } else {
            p
        };
        if size != 0.0 {
            p / size
        } else {
            p
        }
    }
}

/// Musgrave's fractal sums over a signed basis (`h` the fractal increment, `lacunarity` the
/// frequency ratio, `octaves` possibly fractional).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fractal {
    pub basis: NoiseBasis,
    pub h: f32,
    pub lacunarity: f32,
    pub octaves: f32,
}

impl Fractal {
    fn octaves(&self) -> (u32, f32) {
        let o = self.octaves.clamp(0.0, MAX_OCTAVES);
        (o as u32, o - o.floor())
    }

    pub fn fbm(&self, mut p: Vec3) -> f32 {
        let (n, rmd) = self.octaves();
        let step = libm::powf(self.lacunarity, -self.h);
        let (mut value, mut pwr) = (0.0, 1.0);
        for _ in 0..n {
            value += self.basis.signed(p) * pwr;
            pwr *= step;
            p *= self.lacunarity;
        }
        if rmd != 0.0 {
            value += rmd * self.basis.signed(p) * pwr;
        }
        value
    }

    pub fn multifractal(&self, mut p: Vec3) -> f32 {
        let (n, rmd) = self.octaves();
        let step = libm::powf(self.lacunarity, -self.h);
        let (mut value, mut pwr) = (1.0, 1.0);
        for _ in 0..n {
            value *= pwr * self.basis.signed(p) + 1.0;
            pwr *= step;
            p *= self.lacunarity;
        }
        if rmd != 0.0 {
            value *= rmd * self.basis.signed(p) * pwr + 1.0;
        }
        value
    }

    pub fn hetero_terrain(&self, mut p: Vec3, offset: f32) -> f32 {
        let (n, rmd) = self.octaves();
        let step = libm::powf(self.lacunarity, -self.h);
        let mut pwr = step;
        let mut value = offset + self.basis.signed(p);
        p *= self.lacunarity;
        for _ in 1..n {
            value += (self.basis.signed(p) + offset) * pwr * value;
            pwr *= step;
            p *= self.lacunarity;
        }
        if rmd != 0.0 {
            value += rmd * (self.basis.signed(p) + offset) * pwr * value;
        }
        value
    }

    pub fn hybrid_multifractal(&self, mut p: Vec3, offset: f32, gain: f32) -> f32 {
        let (n, rmd) = self.octaves();
        let step = libm::powf(self.lacunarity, -self.h);
        let mut pwr = step;
        let mut result = self.basis.signed(p) + offset;
        let mut weight = gain * result;
        p *= self.lacunarity;
        let mut i = 1;
        while weight > 0.001 && i < n {
            weight = weight.min(1.0);
            let signal = (self.basis.signed(p) + offset) * pwr;
            pwr *= step;
            result += weight * signal;
            weight *= gain * signal;
            p *= self.lacunarity;
            i += 1;
        }
        if rmd != 0.0 {
            result += rmd * (self.basis.signed(p) + offset) * pwr;
        }
        result
    }

    pub fn ridged_multifractal(&self, mut p: Vec3, offset: f32, gain: f32) -> f32 {
        let (n, _) = self.octaves();
        let step = libm::powf(self.lacunarity, -self.h);
        let mut pwr = step;
        let mut signal = offset - self.basis.signed(p).abs();
        signal *= signal;
        let mut result = signal;
        for _ in 1..n {
            p *= self.lacunarity;
            let weight = (signal * gain).clamp(0.0, 1.0);
            let s = offset - self.basis.signed(p).abs();
            signal = s * s * weight;
            result += signal * pwr;
            pwr *= step;
        }
        result
    }
}

/// Blender's distorted-domain noise: `basis2` at p moved by `basis1` at three shifted points
/// times `distortion`.
pub fn distorted_noise(p: Vec3, distortion: f32, basis1: NoiseBasis, basis2: NoiseBasis) -> f32 {
    let shift = Vec3::splat(13.5);
    let offset = Vec3::new(
        basis1.signed(p + shift),
        basis1.signed(p),
        basis1.signed(p - shift),
    ) * distortion;
    basis2.signed(p + offset)
}
