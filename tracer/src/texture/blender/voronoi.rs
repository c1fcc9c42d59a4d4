//! `blender_voronoi`: Blender's Voronoi (Worley) texture, a weighted sum of the distances to
//! the four nearest feature points, or cell colours.
//!
//! ```text
//! Texture "v" "float" "blender_voronoi" "string distmetric" "manhattan" "float w1" 1 "float w2" -1
//! ```
//!
//! | parameter              | default | notes |
//! |------------------------|---------|-------|
//! | `string distmetric`    | actual_distance | actual_distance, distance_squared, manhattan, chebychev, minkovsky_half, minkovsky_four, minkovsky |
//! | `float minkovsky_exp`  | 2.5     | minkovsky's exponent |
//! | `integer coltype`      | 0       | 0 intensity; 1 the cells' colours; 2 those shaded by F2 - F1; 3 those times the intensity |
//! | `float w1` .. `w4`     | 1, 0, 0, 0 | weights of F1 .. F4 |
//! | `float outscale`       | 1       | |
//! | `float noisesize`      | 0.25    | the point is divided by it |
//! | `float nabla`          | 0.025   | accepted and ignored (Blender's normal step) |
//! | common                 |         | see [`super::common`] |

use glam::Vec3;

use super::common::{read_choice, Pattern, DEFAULT_NOISESIZE};
use super::noise_basis::{cell_point, voronoi, Metric};
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const METRICS: [&str; 7] = [
    "actual_distance",
    "distance_squared",
    "manhattan",
    "chebychev",
    "minkovsky_half",
    "minkovsky_four",
    "minkovsky",
];

#[derive(Clone, Debug, PartialEq)]
pub struct Voronoi {
    pub metric: Metric,
    pub coltype: i32,
    pub weights: [f32; 4],
    pub outscale: f32,
    pub size: f32,
}

impl Voronoi {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let exponent = params.float("minkovsky_exp", 2.5)?;
        let metric = match read_choice(params, "distmetric", &METRICS, pos, ctx)? {
            0 => Metric::Actual,
            1 => Metric::Squared,
            2 => Metric::Manhattan,
            3 => Metric::Chebychev,
            4 => Metric::MinkowskiHalf,
            5 => Metric::MinkowskiFour,
            _ => Metric::Minkowski(exponent),
        };
        params.ignore("nabla");
        Ok(Self {
            metric,
            coltype: params.int("coltype", 0)?.clamp(0, 3),
            weights: [
                params.float("w1", 1.0)?,
                params.float("w2", 0.0)?,
                params.float("w3", 0.0)?,
                params.float("w4", 0.0)?,
            ],
            outscale: params.float("outscale", 1.0)?,
            size: params.float("noisesize", DEFAULT_NOISESIZE)?,
        })
    }

    pub fn pattern(&self, p: Vec3) -> Pattern {
        let p = if self.size != 0.0 { p / self.size } else { p };
        let (da, pa) = voronoi(p, self.metric);
        let aw = self.weights.map(f32::abs);
        let total: f32 = aw.iter().sum();
        let sc = if total != 0.0 {
            self.outscale / total
        } else {
            0.0
        };
        let w = self.weights;
        let intensity = sc * (w[0] * da[0] + w[1] * da[1] + w[2] * da[2] + w[3] * da[3]).abs();
        if self.coltype == 0 {
            return Pattern::Intensity(intensity);
        }
        let mut colour = Vec3::ZERO;
        for (weight, point) in aw.iter().zip(pa) {
            let cell = point.floor();
            colour += *weight * cell_point(cell.x as i32, cell.y as i32, cell.z as i32);
        }
        let shade = if self.coltype >= 2 {
            let t = ((da[1] - da[0]) * 10.0).min(1.0);
            if self.coltype == 3 {
                t * intensity
            } else {
                t * sc
            }
        } else {
            sc
        };
        Pattern::Rgb(colour * shade)
    }
}
