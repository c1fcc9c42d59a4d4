//! Materials: what a `Material` / `MakeNamedMaterial` statement describes, and the BSDF it
//! makes at a hit. One file per material, each with its `.lxs` syntax, parameters and
//! defaults, its reading and its evaluation: [`matte`], [`glossy`] (glossy, glossy2),
//! [`mirror`], [`glass`] (glass, roughglass, glass2), [`metal`] (metal, metal2),
//! [`mattetranslucent`], [`null`], [`mix`]. They compose the lobes of [`crate::bxdf`];
//! [`eval`] is what they see of the textures at a hit.
//!
//! A material is resolved per hit into a [`Bsdf`]: textures are evaluated at the hit, `mix`
//! materials are resolved stochastically, and the result is a plain value.
//!
//! A new material is one new file plus one line in [`MaterialDesc::read`]'s name table (and
//! one line in each `match` below).
//!
//! Every material but `mix` and `null` may carry a bump or normal map ([`bump`]): read here
//! for all of them, kept as a [`MaterialDesc::Bumped`] wrapper, applied to the shading normal
//! in [`Materials::bsdf`].

pub mod bump;
pub mod eval;
pub mod glass;
pub mod glossy;
pub mod matte;
pub mod mattetranslucent;
pub mod metal;
pub mod mirror;
pub mod mix;
pub mod null;

#[cfg(test)]
mod tests;

use glam::Affine3A;

pub use crate::bxdf::bsdf::{Bsdf, BsdfSample};
pub use bump::Bump;
pub use glass::Glass;
pub use glossy::Glossy;
pub use matte::Matte;
pub use mattetranslucent::MatteTranslucent;
pub use metal::Metal;
pub use mirror::Mirror;
pub use mix::Mix;
pub use null::Null;

use crate::bxdf::{ggx_albedo, Bxdf};
use crate::diag::SourcePos;
use crate::geometry::SurfaceHit;
use crate::math::Frame;
use crate::param::{MaterialId, Tex, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::texture::{TexturePoint, Textures};
use eval::TextureEval;

/// A material's description: plain data with LuxRender's defaults applied, indexed by
/// [`MaterialId`].
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialDesc {
    Matte(Matte),
    Glossy(Glossy),
    Mirror(Mirror),
    Glass(Glass),
    Metal(Metal),
    MatteTranslucent(MatteTranslucent),
    Null(Null),
    Mix(Mix),
    /// A material with a bump or normal map (never a mix or null: LuxRender's take none).
    Bumped(Box<MaterialDesc>, Bump),
}

impl MaterialDesc {
    /// Reads `Material "ty"` (or `MakeNamedMaterial` with `"string type" ["ty"]`): the table
    /// from LuxRender's material names to kinds. An unsupported type warns and becomes a matte
    /// (with its Kd when given).
    pub fn read(
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let material = Self::read_kind(ty, params, pos, ctx)?;
        if matches!(material, Self::Mix(_) | Self::Null(_)) {
            return Ok(material);
        }
        Ok(match Bump::read(params, ctx)? {
            Some(bump) => Self::Bumped(Box::new(material), bump),
            None => material,
        })
    }

    /// The material of LuxRender type `ty`, without its bump map.
    fn read_kind(
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        Ok(match ty {
            "matte" => Self::Matte(Matte::read(params, pos, ctx)?),
            "glossy" => Self::Glossy(Glossy::read(params, pos, ctx)?),
            "glossy2" => Self::Glossy(Glossy::read(params, pos, ctx)?),
            "mirror" => Self::Mirror(Mirror::read(params, pos, ctx)?),
            "glass" => Self::Glass(Glass::read(params, pos, ctx)?),
            "roughglass" => Self::Glass(Glass::read_rough(params, pos, ctx)?),
            "glass2" => Self::Glass(Glass::read_glass2(params, pos, ctx)?),
            "metal" => Self::Metal(Metal::read(params, pos, ctx)?),
            "metal2" => Self::Metal(Metal::read_metal2(params, pos, ctx)?),
            "mattetranslucent" => Self::MatteTranslucent(MatteTranslucent::read(params, pos, ctx)?),
            "null" => Self::Null(Null),
            "mix" => Self::Mix(Mix::read(params, pos, ctx)?),
            other => {
                ctx.warn(pos, format!("material \"{other}\" is not supported; using matte (with its Kd when given)"));
                let kd = ctx.color_param(params, "Kd", matte::DEFAULT_KD, true)?;
                for p in &params.params {
                    params.ignore(&p.name);
                }
                Self::Matte(Matte {
                    kd,
                    sigma: Tex::float(matte::DEFAULT_SIGMA),
                })
            }
        })
    }

    /// The kind's LuxRender name (glossy2, roughglass, glass2 and metal2 are read into the
    /// glossy, glass and metal kinds).
    pub fn name(&self) -> &'static str {
        match self {
            Self::Matte(_) => "matte",
            Self::Glossy(_) => "glossy",
            Self::Mirror(_) => "mirror",
            Self::Glass(_) => "glass",
            Self::Metal(_) => "metal",
            Self::MatteTranslucent(_) => "mattetranslucent",
            Self::Null(_) => "null",
            Self::Mix(_) => "mix",
            Self::Bumped(m, _) => m.name(),
        }
    }

    /// The textures the material reads directly, in parameter order.
    pub fn textures(&self) -> Vec<TextureId> {
        match self {
            Self::Matte(m) => m.textures(),
            Self::Glossy(m) => m.textures(),
            Self::Mirror(m) => m.textures(),
            Self::Glass(m) => m.textures(),
            Self::Metal(m) => m.textures(),
            Self::MatteTranslucent(m) => m.textures(),
            Self::Null(m) => m.textures(),
            Self::Mix(m) => m.textures(),
            Self::Bumped(m, bump) => m.textures().into_iter().chain([bump.map]).collect(),
        }
    }

    /// The materials it refers to (those a `mix` chooses between).
    pub fn materials(&self) -> Vec<MaterialId> {
        match self {
            Self::Mix(m) => m.materials(),
            Self::Bumped(m, _) => m.materials(),
            _ => Vec::new(),
        }
    }

    /// The lobe of a leaf material at a hit (a `mix` resolved by [`Materials`] first; an
    /// unresolved one shows the default matte).
    fn bxdf(&self, eval: &TextureEval) -> Bxdf {
        match self {
            Self::Matte(m) => m.bxdf(eval),
            Self::Glossy(m) => m.bxdf(eval),
            Self::Mirror(m) => m.bxdf(eval),
            Self::Glass(m) => m.bxdf(eval),
            Self::Metal(m) => m.bxdf(eval),
            Self::MatteTranslucent(m) => m.bxdf(eval),
            Self::Null(m) => m.bxdf(),
            Self::Mix(_) => Matte::default_bxdf(),
            Self::Bumped(m, _) => m.bxdf(eval),
        }
    }
}

pub struct Materials {
    materials: Vec<MaterialDesc>,
}

impl Materials {
    /// The materials indexed by [`MaterialId`].
    pub fn new(materials: Vec<MaterialDesc>) -> Self {
        let multibounce = materials.iter().any(|m| {
            let leaf = match m {
                MaterialDesc::Bumped(leaf, _) => leaf,
                m => m,
            };
            matches!(
                leaf,
                MaterialDesc::Glossy(Glossy {
                    multibounce: true,
                    ..
                })
            )
        });
        if multibounce {
            ggx_albedo::prepare();
        }
        Self { materials }
    }

    /// Follows `mix` materials down to a leaf, and the leaf's bump map. At each level `u_mix`
    /// chooses a side against the amount and is rescaled to [0, 1) within the chosen side (see
    /// [`Mix::choose`]).
    fn resolve(
        &self,
        id: MaterialId,
        eval: &TextureEval,
        u_mix: f32,
    ) -> Option<(&MaterialDesc, Option<&Bump>)> {
        let mut material = self.materials.get(id.0 as usize)?;
        let mut u = u_mix;
        // A well-formed scene cannot nest deeper than it has materials; more means a cycle.
        for _ in 0..=self.materials.len() {
            match material {
                MaterialDesc::Mix(mix) => {
                    let next;
                    (next, u) = mix.choose(eval, u);
                    material = self.materials.get(next.0 as usize)?;
                }
                MaterialDesc::Bumped(leaf, bump) => return Some((leaf, Some(bump))),
                leaf => return Some((leaf, None)),
            }
        }
        Some((material, None))
    }

    /// The BSDF of material `id` at `hit` on a shape whose world-to-object transform is
    /// `world_to_object` (the object-space position is what planar and local 3D texture
    /// mappings see). `u_mix` resolves `mix` materials stochastically.
    pub fn bsdf(
        &self,
        id: MaterialId,
        hit: &SurfaceHit,
        world_to_object: &Affine3A,
        textures: &Textures,
        u_mix: f32,
    ) -> Bsdf {
        let eval = TextureEval {
            textures,
            at: TexturePoint {
                p: world_to_object.transform_point3(hit.p),
                p_world: hit.p,
                uv: hit.uv,
                prim: hit.prim,
            },
        };
        let (bxdf, ns) = match self.resolve(id, &eval, u_mix) {
            Some((material, bump)) => (
                material.bxdf(&eval),
                bump.map_or(hit.ns, |b| b.normal(hit, &eval, world_to_object)),
            ),
            // A dangling id or a mix cycle (resolve gives up on it).
            None => (Matte::default_bxdf(), hit.ns),
        };
        Bsdf::new(Frame::from_normal_tangent(ns, hit.dpdu), hit.ng, bxdf)
    }
}
