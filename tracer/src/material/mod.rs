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
//! A new material is one new file (its struct, its reader, its [`MaterialKind`] impl) plus
//! one line in the kind list below, which generates the rest.
//!
//! Every material but `mix` and `null` may carry a bump or normal map ([`bump`]): read here
//! for all of them, kept as a [`MaterialDesc::Bumped`] wrapper, applied to the shading normal
//! in [`Materials::bsdf`].

pub mod bump;
pub mod eval;
pub mod film;
pub mod kind;
pub mod nk;

#[cfg(test)]
mod cloth_tests;
#[cfg(test)]
mod tests;

use glam::Affine3A;

pub use crate::bxdf::bsdf::{Bsdf, BsdfSample};
pub use bump::Bump;
pub use kind::MaterialKind;

use crate::bxdf::coat_over_base::Coating;
use crate::bxdf::{ggx_albedo, Bxdf};
use crate::diag::SourcePos;
use crate::geometry::SurfaceHit;
use crate::math::Frame;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, MaterialId, TextureId};
use crate::texture::{LookupPoint, Textures};
use eval::HitTextures;

/// Generates the material family from its kind list (see [`materials!`]'s invocation below):
/// each kind's module and re-export, the [`MaterialDesc`] variant, the name table from
/// LuxRender's material names to the kind's readers, and every dispatch `match`, each arm a
/// call of the kind's [`MaterialKind`] method.
macro_rules! materials {
    ($($module:ident::$kind:ident { $name:literal => $read:ident $(, $alias:literal => $read_alias:ident)* },)+) => {
        $(pub mod $module;)+
        $(pub use $module::$kind;)+

        /// A material's description: plain data with LuxRender's defaults applied, indexed by
        /// [`MaterialId`].
        #[derive(Clone, Debug, PartialEq)]
        pub enum MaterialDesc {
            $($kind($kind),)+
            /// A material with a bump or normal map (never a mix or null: LuxRender's take none).
            Bumped(Box<MaterialDesc>, Bump),
        }

        impl MaterialDesc {
            /// The reader of LuxRender material type `ty` (the material without its bump map);
            /// None for a type this renderer does not know.
            fn reader(ty: &str) -> Option<MaterialReader> {
                Some(match ty {
                    $(
                        $name => |params, pos, ctx| Ok(Self::$kind($kind::$read(params, pos, ctx)?)),
                        $($alias => |params, pos, ctx| Ok(Self::$kind($kind::$read_alias(params, pos, ctx)?)),)*
                    )+
                    _ => return None,
                })
            }

            /// The kind's LuxRender name: the first of the names read into it.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$kind(_) => $name,)+
                    Self::Bumped(m, _) => m.name(),
                }
            }

            /// The textures the material reads directly, in parameter order.
            pub fn textures(&self) -> Vec<TextureId> {
                match self {
                    $(Self::$kind(m) => m.textures(),)+
                    Self::Bumped(m, bump) => m.textures().into_iter().chain([bump.map]).collect(),
                }
            }

            /// The materials it refers to (those a `mix` or `layered` chooses between, a
            /// glossycoating's base).
            pub fn materials(&self) -> Vec<MaterialId> {
                match self {
                    $(Self::$kind(m) => m.materials(),)+
                    Self::Bumped(m, _) => m.materials(),
                }
            }

            /// The lobe of a leaf material at a hit, under its coat if it has one (`mix`,
            /// `layered` and glossycoating resolved by [`Materials`] first; an unresolved one
            /// shows the default matte). `u` in [0, 1) chooses shinymetal's lobe.
            fn bxdf(&self, eval: &HitTextures, u: f32) -> Bxdf {
                match self {
                    $(Self::$kind(m) => m.bxdf(eval, u),)+
                    Self::Bumped(m, _) => m.bxdf(eval, u),
                }
            }

            /// The coat over [`MaterialDesc::bxdf`], for the materials that have one.
            fn coating(&self, eval: &HitTextures) -> Option<Coating> {
                match self {
                    $(Self::$kind(m) => m.coating(eval),)+
                    Self::Bumped(m, _) => m.coating(eval),
                }
            }

            /// Whether the material needs the multibounce albedo tables.
            fn multibounce(&self) -> bool {
                match self {
                    $(Self::$kind(m) => m.multibounce(),)+
                    Self::Bumped(m, _) => m.multibounce(),
                }
            }
        }
    };
}

// The kinds: `module::Kind { "luxrender name" => reader, "another name" => reader, ... },`.
materials! {
    matte::Matte { "matte" => read },
    glossy::Glossy { "glossy" => read, "glossy2" => read },
    glossy_lossy::GlossyLossy { "glossy_lossy" => read, "substrate" => read, "plastic" => read },
    mirror::Mirror { "mirror" => read },
    glass::Glass { "glass" => read, "roughglass" => read_rough, "glass2" => read_glass2 },
    metal::Metal { "metal" => read, "metal2" => read_metal2 },
    mattetranslucent::MatteTranslucent { "mattetranslucent" => read },
    null::Null { "null" => read },
    mix::Mix { "mix" => read },
    carpaint::CarPaint { "carpaint" => read },
    velvet::Velvet { "velvet" => read },
    shinymetal::ShinyMetal { "shinymetal" => read },
    glossycoating::GlossyCoating { "glossycoating" => read },
    glossytranslucent::GlossyTranslucent { "glossytranslucent" => read },
    layered::Layered { "layered" => read },
    scatter::Scatter { "scatter" => read },
    cloth::Cloth { "cloth" => read },
}

impl MaterialDesc {
    /// Whether the material scatters light into one direction (a delta lobe: mirror, glass,
    /// metal or shinymetal with both roughnesses the constant 0), which no light sample finds.
    pub fn has_delta_lobe(&self) -> bool {
        let smooth = |u: &ConstOrTexture, v: &ConstOrTexture| {
            matches!((u, v), (ConstOrTexture::Const(u), ConstOrTexture::Const(v))
                if u.max_element() <= 0.0 && v.max_element() <= 0.0)
        };
        match self {
            Self::Mirror(_) => true,
            Self::Glass(g) => smooth(&g.uroughness, &g.vroughness),
            Self::Metal(m) => smooth(&m.uroughness, &m.vroughness),
            Self::ShinyMetal(m) => smooth(&m.uroughness, &m.vroughness),
            Self::Bumped(m, _) => m.has_delta_lobe(),
            _ => false,
        }
    }
}

/// Reads a material kind from a statement's parameters.
type MaterialReader =
    fn(&ParamList, &SourcePos, &mut dyn ParseContext) -> Result<MaterialDesc, ParseError>;

/// What a ray that no layer of a `layered` material catches meets.
static PASS_THROUGH: MaterialDesc = MaterialDesc::Null(Null);

impl MaterialDesc {
    /// Reads `Material "ty"` (or `MakeNamedMaterial` with `"string type" ["ty"]`) through the
    /// name table. An unsupported type warns and becomes a matte (with its Kd when given).
    pub fn read(
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let Some(read) = Self::reader(ty) else {
            ctx.warn(
                pos,
                format!("material \"{ty}\" is not supported; using matte (with its Kd when given)"),
            );
            let kd = ctx.color_param(params, "Kd", matte::DEFAULT_KD, true)?;
            params.ignore_all();
            return Ok(Self::Matte(Matte {
                kd,
                sigma: ConstOrTexture::float(matte::DEFAULT_SIGMA),
            }));
        };
        let material = read(params, pos, ctx)?;
        if matches!(material, Self::Mix(_) | Self::Null(_)) {
            return Ok(material);
        }
        Ok(match Bump::read(params, ctx)? {
            Some(bump) => Self::Bumped(Box::new(material), bump),
            None => material,
        })
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
        eval: &HitTextures,
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
    // Inlined into `bsdf`: a call away, its lobe and coat are returned through a temporary and
    // copied into the BSDF (memcpy on every hit).
    #[inline(always)]
    fn scattering(
        &self,
        id: MaterialId,
        eval: &HitTextures,
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
                return (bxdf, Some(coating.coat_over(eval, diffuse)), bump);
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
        let eval = HitTextures {
            textures,
            at: LookupPoint {
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
