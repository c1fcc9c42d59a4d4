//! Bump and normal mapping: the `"texture bumpmap"` every material except `mix` and `null`
//! takes (as in LuxRender 1.x), turned into the shading normal at a hit.
//!
//! ```text
//! Texture "bumps" "float" "fbm" "vector scale" [0.1 0.1 0.1]
//! Texture "height" "float" "scale" "texture tex1" "bumps" "float tex2" 0.002
//! Material "matte" "color Kd" [0.5 0.5 0.5] "texture bumpmap" "height"
//! ```
//!
//! | parameter                     | default | notes |
//! |-------------------------------|---------|-------|
//! | `texture bumpmap`             | none    | a float texture: the height in world units along the shading normal; a `normalmap` texture gives the normal directly |
//! | `float bumpmapsampledistance` | 0.001   | the finite-difference step, in world units along the surface |
//!
//! LuxRender's convention (core/material.cpp, `Material::Bump`, and the textures'
//! `GetDuv`): the height h is sampled at the hit and at points moved by the sample distance
//! along dp/du and dp/dv (the uv coordinates moving with them), giving dh/du and dh/dv by
//! forward differences. The bumped tangents are dp/du + dh/du n and dp/dv + dh/dv n (without
//! pbrt's h dn/du term, which LuxRender drops) and the new normal is their cross product,
//! turned into the hemisphere of the old one. The exporters' bump "strength" is a scale
//! texture around the height, so a height is in scene units.
//!
//! A normal map's texel (2c - 1) is a normal in the tangent frame (normalised dp/du, the
//! normal's cross product with it signed along dp/dv, the shading normal).
//!
//! Neither can make light leak through a surface: the BSDF keeps refusing a pair of directions
//! that the geometric normal sees on the other side ([`crate::bxdf::bsdf::Bsdf`]).

use glam::{Affine3A, Vec2, Vec3};

use super::eval::TextureEval;
use crate::geometry::SurfaceHit;
use crate::param::{Tex, TextureId};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::texture::TexturePoint;

/// LuxRender's finite-difference step, in world units.
pub const DEFAULT_SAMPLE_DISTANCE: f32 = 0.001;

#[derive(Clone, Debug, PartialEq)]
pub struct Bump {
    /// The height (or normal map) texture.
    pub map: TextureId,
    /// The step along the surface, world units, > 0.
    pub sample_distance: f32,
}

impl Bump {
    /// The material's bump map, if it names a texture (a constant height bumps nothing).
    pub fn read(params: &ParamList, ctx: &mut dyn ParseContext) -> Result<Option<Self>, ParseError> {
        let distance = params.float("bumpmapsampledistance", DEFAULT_SAMPLE_DISTANCE)?;
        let sample_distance = if distance > 0.0 && distance.is_finite() {
            distance
        } else {
            DEFAULT_SAMPLE_DISTANCE
        };
        let map = params.tex_float("bumpmap", 0.0)?;
        Ok(match ctx.tex(map, false, Vec3::ZERO) {
            Tex::Texture(map) => Some(Self {
                map,
                sample_distance,
            }),
            Tex::Const(_) => None,
        })
    }

    /// The bumped shading normal at `hit` (unit, in the hemisphere of `hit.ns`; `hit.ns` when
    /// the result would be degenerate). `world_to_object` moves the object-space texture point
    /// along with the world one.
    pub fn normal(&self, hit: &SurfaceHit, eval: &TextureEval, world_to_object: &Affine3A) -> Vec3 {
        let n = hit.ns;
        let dpdu = hit.dpdu;
        // A usable v tangent: LuxRender's coordinate system when the uvs give none.
        let dpdv = if dpdu.cross(hit.dpdv).length_squared() > 0.0 && hit.dpdv.is_finite() {
            hit.dpdv
        } else {
            n.cross(dpdu)
        };
        let bumped = match eval.textures.normal_map(Tex::Texture(self.map), &eval.at) {
            Some(tangent_space) => {
                let t = (dpdu - n * n.dot(dpdu)).normalize_or_zero();
                let b = n.cross(t);
                let b = if b.dot(dpdv) < 0.0 { -b } else { b };
                tangent_space.x * t + tangent_space.y * b + tangent_space.z * n
            }
            None => {
                let height = |at: &TexturePoint| eval.float_at(Tex::Texture(self.map), at);
                let base = height(&eval.at);
                let moved = |tangent: Vec3, duv: Vec2| {
                    let step = self.sample_distance / tangent.length();
                    let offset = step * tangent;
                    let at = TexturePoint {
                        p: eval.at.p + world_to_object.transform_vector3(offset),
                        p_world: eval.at.p_world + offset,
                        uv: eval.at.uv + step * duv,
                        ..eval.at
                    };
                    (height(&at) - base) / step
                };
                let dhdu = moved(dpdu, Vec2::X);
                let dhdv = moved(dpdv, Vec2::Y);
                (dpdu + dhdu * n).cross(dpdv + dhdv * n)
            }
        };
        let bumped = bumped.normalize_or_zero();
        if !bumped.is_finite() || bumped == Vec3::ZERO {
            return n;
        }
        if bumped.dot(n) < 0.0 {
            -bumped
        } else {
            bumped
        }
    }
}
