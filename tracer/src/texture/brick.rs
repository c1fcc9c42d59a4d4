//! Bricks and mortar in 3D texture space, in LuxRender's masonry bonds.
//!
//! ```text
//! Texture "name" "color" "brick" "string brickbond" "flemish" "texture bricktex" "b"
//!     "color mortartex" [0.8 0.8 0.8] "float brickwidth" 0.3 ...
//! ```
//!
//! | parameter           | default | notes |
//! |---------------------|---------|-------|
//! | `string brickbond`  | running | running, stacked, flemish, english, herringbone, basket, chain link (an unknown name is running) |
//! | `bricktex`          | 1       | texture or constant of the declared kind: the bricks |
//! | `mortartex`         | 0.2     | the mortar |
//! | `brickmodtex`       | 1       | multiplies the bricks; evaluated at the brick's index (so one value per brick) |
//! | `float brickwidth`  | 0.3     | along x |
//! | `float brickheight` | 0.1     | along z |
//! | `float brickdepth`  | 0.15    | along y |
//! | `float mortarsize`  | 0.01    | |
//! | `float brickrun`    | 0.75    | offset of successive courses, in bricks (stacked: 0, english: 0.25, chain link: 1.25) |
//! | `float brickbevel`  | 0       | accepted and ignored, as LuxRender 1.x does |
//! | 3D mapping          | global  | see [`super::mapping`] |
//!
//! Courses are stacked along z. Herringbone and basket use square cells of `brickwidth`, cut
//! into floor(brickwidth / brickheight) bricks.

use glam::Vec3;

use super::common::{Declared, ReferencedTextures, LookupPoint};
use super::mapping::Mapping3D;
use crate::diag::SourcePos;
use crate::refs::ConstOrTexture;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use super::kind::TextureType;

pub const DEFAULT_BOND: &str = "running";
pub const DEFAULT_BRICKTEX: f32 = 1.0;
pub const DEFAULT_MORTARTEX: f32 = 0.2;
pub const DEFAULT_BRICKMODTEX: f32 = 1.0;
pub const DEFAULT_WIDTH: f32 = 0.3;
pub const DEFAULT_HEIGHT: f32 = 0.1;
pub const DEFAULT_DEPTH: f32 = 0.15;
pub const DEFAULT_MORTAR: f32 = 0.01;
pub const DEFAULT_RUN: f32 = 0.75;
/// LuxRender shifts the pattern by this plus the mortar size so that the origin is in mortar.
const EPSILON: f32 = 1e-3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bond {
    Running,
    Flemish,
    English,
    Herringbone,
    Basket,
    /// "chain link".
    ChainLink,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Brick {
    pub bond: Bond,
    pub brick: ConstOrTexture,
    pub mortar: ConstOrTexture,
    pub modulation: ConstOrTexture,
    /// Brick size along x, y, z (width, depth, height) after the bond's adjustments.
    pub size: Vec3,
    pub mortar_size: f32,
    pub run: f32,
    /// Added to the normalised point (running: half a brick in y, chain link: its own).
    pub offset: Vec3,
    /// floor(width / height): bricks per cell of herringbone and basket.
    pub proportion: f32,
    pub mapping: Mapping3D,
}

impl Brick {
    pub fn read(
        decl: &Declared,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let positive = |name: &str, default: f32| -> Result<f32, ParseError> {
            let v = params.float(name, default)?;
            if v > 0.0 && v.is_finite() {
                Ok(v)
            } else {
                let p = params.find(name).expect("read above");
                Err(params.error(p, format!("{v} is not a positive size")))
            }
        };
        let width = positive("brickwidth", DEFAULT_WIDTH)?;
        let height = positive("brickheight", DEFAULT_HEIGHT)?;
        let depth = positive("brickdepth", DEFAULT_DEPTH)?;
        let mortar_size = params.float("mortarsize", DEFAULT_MORTAR)?;
        let mut run = params.float("brickrun", DEFAULT_RUN)?;
        params.ignore("brickbevel");
        let mut offset = Vec3::ZERO;
        let bond = match params.string_or("brickbond", DEFAULT_BOND)?.as_str() {
            "stacked" => {
                run = 0.0;
                Bond::Running
            }
            "flemish" => Bond::Flemish,
            "english" => {
                run = 0.25;
                Bond::English
            }
            "herringbone" => Bond::Herringbone,
            "basket" => Bond::Basket,
            "chain link" => {
                run = 1.25;
                offset = Vec3::new(0.25, -1.0, 0.0);
                Bond::ChainLink
            }
            _ => {
                offset = Vec3::new(0.0, -0.5, 0.0);
                Bond::Running
            }
        };
        let (size, proportion) = match bond {
            // Square cells, at least one brick each.
            Bond::Herringbone | Bond::Basket => {
                (Vec3::splat(width), (width / height).floor().max(1.0))
            }
            _ => (Vec3::new(width, depth, height), 1.0),
        };
        Ok(Self {
            bond,
            brick: decl.tex(ctx, params, "bricktex", DEFAULT_BRICKTEX)?,
            mortar: decl.tex(ctx, params, "mortartex", DEFAULT_MORTARTEX)?,
            modulation: decl.tex(ctx, params, "brickmodtex", DEFAULT_BRICKMODTEX)?,
            size,
            mortar_size,
            run,
            offset,
            proportion,
            mapping: Mapping3D::read(params, pos, ctx)?,
        })
    }

    /// The brick index of texture-space point `p`, or `None` in mortar.
    pub fn brick_at(&self, p: Vec3) -> Option<Vec3> {
        let shift = EPSILON + self.mortar_size;
        let bp = (p + Vec3::splat(shift)) / self.size + self.offset;
        // Mortar thickness relative to the brick size along each axis.
        let mortar = Vec3::splat(self.mortar_size) / self.size;
        match self.bond {
            Bond::Running => self.running(bp, mortar),
            Bond::English => self.english(bp, mortar),
            Bond::Flemish => self.running_alternate(bp, mortar, 1.0),
            Bond::ChainLink => self.running_alternate(bp, mortar, 2.0),
            Bond::Herringbone => self.herringbone(bp, mortar),
            Bond::Basket => self.basket(bp, mortar),
        }
    }

    fn inside(b: Vec3, mortar: Vec3) -> bool {
        b.z > mortar.z && b.y > mortar.y && b.x > mortar.x
    }

    fn running(&self, p: Vec3, mortar: Vec3) -> Option<Vec3> {
        let iz = p.z.floor();
        let bx = p.x + iz * self.run;
        let by = p.y - iz * self.run;
        let index = Vec3::new(bx.floor(), by.floor(), iz);
        let b = Vec3::new(bx - index.x, by - index.y, p.z - iz);
        Self::inside(b, mortar).then_some(index)
    }

    fn english(&self, p: Vec3, mortar: Vec3) -> Option<Vec3> {
        let iz = p.z.floor();
        let bx = p.x + iz * self.run;
        let by = p.y - iz * self.run;
        let index = Vec3::new(bx.floor(), by.floor(), iz);
        // Every other course is cut into half bricks (headers).
        let divider = (iz.abs() % 2.0).floor() + 1.0;
        let b = Vec3::new(
            (divider * bx - (divider * bx).floor()) / divider,
            (divider * by - (divider * by).floor()) / divider,
            p.z - iz,
        );
        Self::inside(b, mortar).then_some(index)
    }

    /// Flemish (one whole brick and a half per unit) and chain link (two and a half).
    fn running_alternate(&self, p: Vec3, mortar: Vec3, whole: f32) -> Option<Vec3> {
        let sub = whole + 0.5;
        let rsub = sub.ceil();
        let iz = p.z.floor();
        let bx = (p.x + iz * self.run) / sub;
        let by = (p.y + iz * self.run) / sub;
        let (ix, iy) = (bx.floor(), by.floor());
        let (bx, by) = ((bx - ix) * sub, (by - iy) * sub);
        let index = Vec3::new(ix + bx.floor() / rsub, iy + by.floor() / rsub, iz);
        let b = Vec3::new(bx - bx.floor(), by - by.floor(), (p.z - iz) * sub);
        Self::inside(b, mortar).then_some(index)
    }

    fn basket(&self, p: Vec3, mortar: Vec3) -> Option<Vec3> {
        let inv = 1.0 / self.proportion;
        let (mut ix, mut iy) = (p.x.floor(), p.y.floor());
        let (mut bx, mut by) = (p.x - ix, p.y - iy);
        ix += iy - 2.0 * (0.5 * iy).floor();
        // Alternate cells are cut across x or across y.
        if ix - 2.0 * (0.5 * ix).floor() < 1.0 {
            bx %= inv;
            ix = (self.proportion * p.x).floor() * inv;
        } else {
            by %= inv;
            iy = (self.proportion * p.y).floor() * inv;
        }
        (by > mortar.y && bx > mortar.x).then_some(Vec3::new(ix, iy, 0.0))
    }

    fn herringbone(&self, p: Vec3, mortar: Vec3) -> Option<Vec3> {
        let (prop, inv) = (self.proportion, 1.0 / self.proportion);
        let mut iy = (prop * p.y).floor();
        let px = p.x + iy * inv;
        let ix = px.floor();
        let mut bx = 2.0 * (0.5 * px - (0.5 * px).floor());
        let mut by = (prop * p.y - (prop * p.y).floor()) * inv;
        if bx > 1.0 {
            let past_end = bx > 1.0 + inv;
            bx = prop * (bx - 1.0);
            iy -= (bx - 1.0).floor();
            bx = (bx - bx.floor()) * inv;
            if past_end {
                by = 1.0;
            }
        }
        (by > mortar.z && bx > mortar.x).then_some(Vec3::new(ix, iy, 0.0))
    }
}

impl TextureType for Brick {
    fn name(&self) -> &'static str {
        "brick"
    }

    fn references(&self) -> Vec<ConstOrTexture> {
        vec![self.brick, self.mortar, self.modulation]
    }

    fn eval(&self, at: &LookupPoint, textures: &impl ReferencedTextures) -> Vec3 {
        match self.brick_at(self.mapping.map(at)) {
            Some(index) => {
                let brick = LookupPoint {
                    p: index,
                    p_world: index,
                    ..*at
                };
                textures.eval(self.brick, at) * textures.eval(self.modulation, &brick)
            }
            None => textures.eval(self.mortar, at),
        }
    }
}
