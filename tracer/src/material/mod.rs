//! Materials: what a `Material` / `MakeNamedMaterial` statement describes, and the BSDF it
//! makes at a hit. One file per material, each with its `.lxs` syntax, parameters and
//! defaults, its reading and its evaluation: [`matte`], [`glossy`] (glossy, glossy2),
//! [`mirror`], [`glass`] (glass, roughglass, glass2), [`metal`] (metal, metal2),
//! [`mattetranslucent`], [`null`], [`mix`], [`carpaint`], [`velvet`], [`shinymetal`],
//! [`glossycoating`], [`glossytranslucent`], [`layered`], [`scatter`], [`cloth`]. They compose the lobes
//! of [`crate::bxdf`]; [`eval`] is what they see of the textures at a hit.
//!
//! A material is resolved per hit into a [`Bsdf`]: textures are evaluated at the hit, `mix`
//! and `layered` materials (and shinymetal's two lobes) are resolved stochastically, a
//! glossycoating's base is resolved under its coat, and the result is a plain value.
//!
//! A new material is one new file plus one line in [`MaterialDesc::read`]'s name table (and
//! one line in each `match` below).
//!
//! Every material but `mix` and `null` may carry a bump or normal map ([`bump`]): read here
//! for all of them, kept as a [`MaterialDesc::Bumped`] wrapper, applied to the shading normal
//! in [`Materials::bsdf`].

pub mod bump;
pub mod carpaint;
pub mod cloth;
pub mod eval;
pub mod glass;
pub mod glossy;
pub mod glossycoating;
pub mod glossytranslucent;
pub mod layered;
pub mod matte;
pub mod mattetranslucent;
pub mod metal;
pub mod mirror;
pub mod mix;
pub mod nk;
pub mod null;
pub mod scatter;
pub mod shinymetal;
pub mod velvet;

#[cfg(test)]
mod cloth_tests;
#[cfg(test)]
mod tests;

use glam::Affine3A;

pub use crate::bxdf::bsdf::{Bsdf, BsdfSample};
pub use bump::Bump;
pub use carpaint::CarPaint;
pub use cloth::Cloth;
pub use glass::Glass;
pub use glossy::Glossy;
pub use glossycoating::GlossyCoating;
pub use glossytranslucent::GlossyTranslucent;
pub use layered::Layered;
pub use matte::Matte;
pub use mattetranslucent::MatteTranslucent;
pub use metal::Metal;
pub use mirror::Mirror;
pub use mix::Mix;
pub use null::Null;
pub use scatter::Scatter;
pub use shinymetal::ShinyMetal;
pub use velvet::Velvet;

use crate::bxdf::coating::Coating;
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
    CarPaint(CarPaint),
    Velvet(Velvet),
    ShinyMetal(ShinyMetal),
    GlossyCoating(GlossyCoating),
    GlossyTranslucent(GlossyTranslucent),
    Layered(Layered),
    Scatter(Scatter),
    Cloth(Cloth),
    /// A material with a bump or normal map (never a mix or null: LuxRender's take none).
    Bumped(Box<MaterialDesc>, Bump),
}

/// What a ray that no layer of a `layered` material catches meets.
static PASS_THROUGH: MaterialDesc = MaterialDesc::Null(Null);

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
            "mattetranslucent" => Self::MatteTranslucent(MatteTranslucent::read(params, ctx)?),
            "null" => Self::Null(Null),
            "mix" => Self::Mix(Mix::read(params, pos, ctx)?),
            "carpaint" => Self::CarPaint(CarPaint::read(params, pos, ctx)?),
            "velvet" => Self::Velvet(Velvet::read(params, pos, ctx)?),
            "shinymetal" => Self::ShinyMetal(ShinyMetal::read(params, pos, ctx)?),
            "glossycoating" => Self::GlossyCoating(GlossyCoating::read(params, pos, ctx)?),
            "glossytranslucent" => {
                Self::GlossyTranslucent(GlossyTranslucent::read(params, pos, ctx)?)
            }
            "layered" => Self::Layered(Layered::read(params, pos, ctx)?),
            "scatter" => Self::Scatter(Scatter::read(params, pos, ctx)?),
            "cloth" => Self::Cloth(Cloth::read(params, pos, ctx)?),
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
            Self::CarPaint(_) => "carpaint",
            Self::Velvet(_) => "velvet",
            Self::ShinyMetal(_) => "shinymetal",
            Self::GlossyCoating(_) => "glossycoating",
            Self::GlossyTranslucent(_) => "glossytranslucent",
            Self::Layered(_) => "layered",
            Self::Scatter(_) => "scatter",
            Self::Cloth(_) => "cloth",
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
            Self::CarPaint(m) => m.textures(),
            Self::Velvet(m) => m.textures(),
            Self::ShinyMetal(m) => m.textures(),
            Self::GlossyCoating(m) => m.textures(),
            Self::GlossyTranslucent(m) => m.textures(),
            Self::Layered(m) => m.textures(),
            Self::Scatter(m) => m.textures(),
            Self::Cloth(m) => m.textures(),
            Self::Bumped(m, bump) => m.textures().into_iter().chain([bump.map]).collect(),
        }
    }

    /// The materials it refers to (those a `mix` or `layered` chooses between, a
    /// glossycoating's base).
    pub fn materials(&self) -> Vec<MaterialId> {
        match self {
            Self::Mix(m) => m.materials(),
            Self::Layered(m) => m.materials(),
            Self::GlossyCoating(m) => vec![m.base],
            Self::Bumped(m, _) => m.materials(),
            _ => Vec::new(),
        }
    }

    /// The lobe of a leaf material at a hit, under its coat if it has one (`mix`, `layered`
    /// and glossycoating resolved by [`Materials`] first; an unresolved one shows the default
    /// matte). `u` in [0, 1) chooses shinymetal's lobe.
    fn bxdf(&self, eval: &TextureEval, u: f32) -> Bxdf {
        match self {
            Self::Matte(m) => m.bxdf(eval),
            Self::Glossy(m) => m.bxdf(eval),
            Self::Mirror(m) => m.bxdf(eval),
            Self::Glass(m) => m.bxdf(eval),
            Self::Metal(m) => m.bxdf(eval),
            Self::MatteTranslucent(m) => m.bxdf(eval),
            Self::Null(m) => m.bxdf(),
            Self::CarPaint(m) => m.bxdf(eval),
            Self::Velvet(m) => m.bxdf(eval),
            Self::ShinyMetal(m) => m.bxdf(eval, u),
            Self::GlossyTranslucent(m) => m.bxdf(eval),
            Self::Scatter(m) => m.bxdf(eval),
            Self::Cloth(m) => m.bxdf(eval),
            Self::Mix(_) | Self::Layered(_) | Self::GlossyCoating(_) => Matte::default_bxdf(),
            Self::Bumped(m, _) => m.bxdf(eval, u),
        }
    }

    /// The coat over [`MaterialDesc::bxdf`], for the materials that have one.
    fn coating(&self, eval: &TextureEval) -> Option<Coating> {
        match self {
            Self::Glossy(m) => Some(m.coating(eval)),
            Self::CarPaint(m) => Some(m.coating(eval)),
            Self::GlossyTranslucent(m) => Some(m.coating(eval)),
            Self::Bumped(m, _) => m.coating(eval),
            _ => None,
        }
    }

    /// Whether the material needs the multibounce albedo tables.
    fn multibounce(&self) -> bool {
        match self {
            Self::Glossy(m) => m.coat.multibounce,
            Self::GlossyCoating(m) => m.coat.multibounce,
            Self::GlossyTranslucent(m) => {
                m.front.multibounce || m.back.as_ref().is_some_and(|b| b.multibounce)
            }
            Self::Bumped(m, _) => m.multibounce(),
            _ => false,
        }
    }
}

pub struct Materials {
    materials: Vec<MaterialDesc>,
}

impl Materials {
    /// The materials indexed by [`MaterialId`].
    pub fn new(materials: Vec<MaterialDesc>) -> Self {
        if materials.iter().any(MaterialDesc::multibounce) {
            ggx_albedo::prepare();
        }
        Self { materials }
    }

    /// Follows `mix` and `layered` materials down to a leaf, and the leaf's bump map. At each
    /// level `u` chooses a side (or layer) against the amounts and is rescaled to [0, 1) within
    /// the chosen one (see [`Mix::choose`]); the leaf gets what is left of it.
    fn resolve(
        &self,
        id: MaterialId,
        eval: &TextureEval,
        u_mix: f32,
    ) -> Option<(&MaterialDesc, f32, Option<&Bump>)> {
        let mut material = self.materials.get(id.0 as usize)?;
        let mut u = u_mix;
        let mut bump = None;
        // A well-formed scene cannot nest deeper than it has materials; more means a cycle.
        for _ in 0..=self.materials.len() {
            let next = match material {
                MaterialDesc::Mix(mix) => {
                    let next;
                    (next, u) = mix.choose(eval, u);
                    next
                }
                MaterialDesc::Layered(layered) => {
                    let next;
                    (next, u) = layered.choose(eval, u);
                    match next {
                        Some(next) => next,
                        None => return Some((&PASS_THROUGH, u, bump)),
                    }
                }
                MaterialDesc::Bumped(leaf, leaf_bump) => {
                    bump = Some(leaf_bump);
                    material = leaf;
                    continue;
                }
                _ => return Some((material, u, bump)),
            };
            material = self.materials.get(next.0 as usize)?;
        }
        None
    }

    /// The lobe, coat and bump map of material `id`: a glossycoating's coat over its base's
    /// lobe (whose own coat, if any, is dropped; its bump map applies when the coating has
    /// none).
    fn scattering(
        &self,
        id: MaterialId,
        eval: &TextureEval,
        u_mix: f32,
    ) -> (Bxdf, Option<Coating>, Option<&Bump>) {
        let Some((leaf, u, bump)) = self.resolve(id, eval, u_mix) else {
            return (Matte::default_bxdf(), None, None);
        };
        let MaterialDesc::GlossyCoating(coating) = leaf else {
            return (leaf.bxdf(eval, u), leaf.coating(eval), bump);
        };
        let (mut base, mut u, mut bump) = (leaf, u, bump);
        for _ in 0..=self.materials.len() {
            let MaterialDesc::GlossyCoating(g) = base else {
                let bxdf = base.bxdf(eval, u);
                let diffuse = matches!(bxdf, Bxdf::Diffuse(_) | Bxdf::Translucent(_));
                return (bxdf, Some(coating.coating(eval, diffuse)), bump);
            };
            let Some((next, next_u, next_bump)) = self.resolve(g.base, eval, u) else {
                break;
            };
            (base, u, bump) = (next, next_u, bump.or(next_bump));
        }
        (Matte::default_bxdf(), None, None)
    }

    /// The BSDF of material `id` at `hit` on a shape whose world-to-object transform is
    /// `world_to_object` (the object-space position is what planar and local 3D texture
    /// mappings see). `u_mix` resolves `mix` materials stochastically.
    // Inlined into the path loop, where it is hot; the mirror-image light sample calls it too,
    // and a second call site would otherwise leave it out of line.
    #[inline(always)]
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
        // A dangling id or a mix cycle shows the default matte.
        let (bxdf, coating, bump) = self.scattering(id, &eval, u_mix);
        let ns = bump.map_or(hit.ns, |b| b.normal(hit, &eval, world_to_object));
        Bsdf::new(
            Frame::from_normal_tangent(ns, hit.dpdu),
            hit.ng,
            bxdf,
            coating,
        )
    }
}
