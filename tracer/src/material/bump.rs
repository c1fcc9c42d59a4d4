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

use super::eval::HitTextures;
use crate::geometry::SurfaceHit;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, TextureId};
use crate::texture::LookupPoint;

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
    pub fn read(
        params: &ParamList,
        ctx: &mut dyn ParseContext,
    ) -> Result<Option<Self>, ParseError> {
        let distance = params.float("bumpmapsampledistance", DEFAULT_SAMPLE_DISTANCE)?;
        let sample_distance = if distance > 0.0 && distance.is_finite() {
            distance
        } else {
            DEFAULT_SAMPLE_DISTANCE
        };
        Ok(match ctx.float_param(params, "bumpmap", 0.0)? {
            ConstOrTexture::Texture(map) => Some(Self {
                map,
                sample_distance,
            }),
            ConstOrTexture::Const(_) => None,
        })
    }

    /// The bumped shading normal at `hit` (unit, in the hemisphere of `hit.ns`; `hit.ns` when
    /// the result would be degenerate). `world_to_object` moves the object-space texture point
    /// along with the world one.
    pub fn normal(&self, hit: &SurfaceHit, eval: &HitTextures, world_to_object: &Affine3A) -> Vec3 {
        let n = hit.ns;
        let dpdu = hit.dpdu;
        // A usable v tangent: LuxRender's coordinate system when the uvs give none.
        let dpdv = if dpdu.cross(hit.dpdv).length_squared() > 0.0 && hit.dpdv.is_finite() {
            hit.dpdv
        } else {
            n.cross(dpdu)
        };
        let bumped = match eval
            .textures
            .normal_map(ConstOrTexture::Texture(self.map), &eval.at)
        {
            Some(tangent_space) => {
                let t = (dpdu - n * n.dot(dpdu)).normalize_or_zero();
                let b = n.cross(t);
                let b = if b.dot(dpdv) < 0.0 { -b } else { b };
                tangent_space.x * t + tangent_space.y * b + tangent_space.z * n
            }
            None => {
                let height =
                    |at: &LookupPoint| eval.float_at(ConstOrTexture::Texture(self.map), at);
                let base = height(&eval.at);
                let moved = |tangent: Vec3, duv: Vec2| {
                    let step = self.sample_distance / tangent.length();
                    let offset = step * tangent;
                    let at = LookupPoint {
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

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::{Affine3A, Vec2, Vec3};

    use super::*;
    use crate::assets::MemorySource;
    use crate::desc::MaterialDesc;
    use crate::material::Materials;
    use crate::parse::parse_scene;
    use crate::refs::MaterialId;
    use crate::texture::Textures;

    /// The scene's textures and its first material's bump map.
    fn bumped(statements: &str, files: &[(&str, Arc<[u8]>)]) -> (Textures, Bump, MaterialDesc) {
        let mut source = MemorySource::new();
        let text = format!("Camera \"perspective\"\nWorldBegin\n{statements}\nWorldEnd\n");
        source.insert("main.lxs", text.as_bytes().into());
        for (name, bytes) in files {
            source.insert(*name, bytes.clone());
        }
        let desc = parse_scene("main.lxs", &source).unwrap_or_else(|e| panic!("{e}"));
        let material = desc.materials[0].clone();
        let MaterialDesc::Bumped(_, bump) = &material else {
            panic!("a bumped material: {material:?}")
        };
        let bump = bump.clone();
        (
            Textures::new(&desc.textures, &source).unwrap(),
            bump,
            material,
        )
    }

    fn plane_hit(uv: Vec2, dpdu: Vec3, dpdv: Vec3) -> SurfaceHit {
        SurfaceHit {
            t: 1.0,
            p: Vec3::new(uv.x, uv.y, 0.0),
            ng: Vec3::Z,
            ns: Vec3::Z,
            uv,
            dpdu,
            dpdv,
            shape: 0,
            prim: 0,
        }
    }

    fn normal_at(textures: &Textures, bump: &Bump, hit: &SurfaceHit) -> Vec3 {
        let eval = HitTextures {
            textures,
            at: LookupPoint {
                p: hit.p,
                p_world: hit.p,
                uv: hit.uv,
                prim: 0,
            },
        };
        bump.normal(hit, &eval, &Affine3A::IDENTITY)
    }

    /// A height of 0.3 (u + v) / 3 (the uv texture read as a float is the mean of frac(u),
    /// frac(v) and 0) has dh/du = dh/dv = 0.1 per unit of uv.
    const LINEAR_HEIGHT: &str = "Texture \"uv\" \"float\" \"uv\"\n\
        Texture \"h\" \"float\" \"scale\" \"texture tex1\" \"uv\" \"float tex2\" 0.3\n\
        Material \"matte\" \"texture bumpmap\" \"h\"";

    #[test]
    fn a_linear_height_tilts_the_normal_by_its_slope_in_world_units() {
        let (textures, bump, _) = bumped(LINEAR_HEIGHT, &[]);
        assert_eq!(bump.sample_distance, DEFAULT_SAMPLE_DISTANCE);
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-3;
        // uv in world units: n = normalise(-0.1, -0.1, 1).
        let n = normal_at(
            &textures,
            &bump,
            &plane_hit(Vec2::splat(0.25), Vec3::X, Vec3::Y),
        );
        let expected = Vec3::new(-0.1, -0.1, 1.0).normalize();
        assert!(close(n, expected), "{n} vs {expected}");
        // u runs half as fast over the surface (|dp/du| = 2): the slope along x halves, as
        // LuxRender's differences along dp/du give (dp/du + dh/du n) x (dp/dv + dh/dv n).
        let n = normal_at(
            &textures,
            &bump,
            &plane_hit(Vec2::splat(0.25), 2.0 * Vec3::X, Vec3::Y),
        );
        let expected = Vec3::new(-0.05, -0.1, 1.0).normalize();
        assert!(close(n, expected), "{n} vs {expected}");
        // Mirrored uv (dp/dv along -y): still in the hemisphere of the shading normal, and
        // tilted against the height's gradient in world space (+y is -v).
        let n = normal_at(
            &textures,
            &bump,
            &plane_hit(Vec2::splat(0.25), Vec3::X, -Vec3::Y),
        );
        let expected = Vec3::new(-0.1, 0.1, 1.0).normalize();
        assert!(close(n, expected), "{n} vs {expected}");
    }

    #[test]
    fn a_normal_map_gives_the_normal_in_the_tangent_frame() {
        // One texel (0.8, 0.5, 0.9) = tangent-space (0.6, 0, 0.8) (g = 128/255, about 0).
        let img = ::image::RgbImage::from_pixel(1, 1, ::image::Rgb([204, 128, 230]));
        let mut png = std::io::Cursor::new(Vec::new());
        img.write_to(&mut png, ::image::ImageFormat::Png).unwrap();
        let png: Arc<[u8]> = png.into_inner().into();
        let (textures, bump, _) = bumped(
            "Texture \"n\" \"float\" \"normalmap\" \"string filename\" \"n.png\"\n\
             Material \"matte\" \"texture bumpmap\" \"n\"",
            &[("n.png", png)],
        );
        let close = |a: Vec3, b: Vec3| (a - b).length() < 0.01;
        // Tangent frame (x, y, z): the normal leans towards +x.
        let n = normal_at(
            &textures,
            &bump,
            &plane_hit(Vec2::splat(0.5), Vec3::X, Vec3::Y),
        );
        assert!(close(n, Vec3::new(0.6, 0.0, 0.8)), "{n}");
        // With u along +y the map leans towards +y.
        let n = normal_at(
            &textures,
            &bump,
            &plane_hit(Vec2::splat(0.5), Vec3::Y, -Vec3::X),
        );
        assert!(close(n, Vec3::new(0.0, 0.6, 0.8)), "{n}");
        // Read as a plain float texture a normal map is 0 (no height).
        let eval = HitTextures {
            textures: &textures,
            at: LookupPoint::new(Vec3::ZERO, Vec2::splat(0.5)),
        };
        assert_eq!(eval.float(ConstOrTexture::Texture(bump.map)), 0.0);
    }

    #[test]
    fn shading_normals_never_let_light_through_the_surface() {
        // A steep bump (slope 30 per unit of uv): the shading normal lies almost in the
        // surface. For every pair of directions on opposite sides of the geometric normal the
        // matte BSDF is exactly 0, and so is every pair the bumped normal sees on opposite
        // sides; the bump does change the shading of the others.
        let scene = "Texture \"uv\" \"float\" \"uv\"\n\
            Texture \"h\" \"float\" \"scale\" \"texture tex1\" \"uv\" \"float tex2\" 90\n\
            Material \"matte\" \"color Kd\" [0.8 0.8 0.8] \"texture bumpmap\" \"h\"\n\
            Material \"matte\" \"color Kd\" [0.8 0.8 0.8]";
        let mut source = MemorySource::new();
        let text = format!("Camera \"perspective\"\nWorldBegin\n{scene}\nWorldEnd\n");
        source.insert("main.lxs", text.as_bytes().into());
        let desc = parse_scene("main.lxs", &source).unwrap();
        let textures = Textures::new(&desc.textures, &source).unwrap();
        let materials = Materials::new(desc.materials.clone());
        let hit = plane_hit(Vec2::splat(0.25), Vec3::X, Vec3::Y);
        let bsdf = materials.bsdf(MaterialId(0), &hit, &Affine3A::IDENTITY, &textures, 0.5);
        let flat = materials.bsdf(MaterialId(1), &hit, &Affine3A::IDENTITY, &textures, 0.5);
        let (_, bump, _) = bumped(scene, &[]);
        let ns = normal_at(&textures, &bump, &hit);
        assert!(ns.z < 0.1, "steep: {ns}");
        let dirs: Vec<Vec3> = (0..400)
            .map(|i| {
                let (a, b) = (
                    (i as f32 * 0.618_034).fract(),
                    (i as f32 * 0.754_877_7).fract(),
                );
                let z = 2.0 * a - 1.0;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * b;
                Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z)
            })
            .collect();
        let (mut through, mut differs) = (0, 0);
        for &wo in &dirs {
            for &wi in &dirs {
                let f = bsdf.eval(wo, wi);
                let opposite = wo.z * wi.z <= 0.0 || wo.dot(ns) * wi.dot(ns) <= 0.0;
                if opposite && f != Vec3::ZERO {
                    through += 1;
                }
                if (f - flat.eval(wo, wi)).abs().max_element() > 1e-3 {
                    differs += 1;
                }
                if let Some(s) = bsdf.sample(wo, 0.5, Vec2::new(0.3, 0.7)) {
                    assert!(s.wi.z * wo.z > 0.0, "sampled through: {wo} -> {}", s.wi);
                }
            }
        }
        assert_eq!(through, 0);
        assert!(
            differs > 10_000,
            "the bump changes the shading of {differs} pairs"
        );
    }

    #[test]
    fn mix_and_null_take_no_bump_and_a_constant_height_is_none() {
        let mut source = MemorySource::new();
        let text = "Camera \"perspective\"\nWorldBegin\n\
            Texture \"h\" \"float\" \"fbm\"\n\
            MakeNamedMaterial \"a\" \"string type\" \"matte\" \"texture bumpmap\" \"h\"\n\
            MakeNamedMaterial \"b\" \"string type\" \"matte\" \"float bumpmap\" 0.5\n\
            MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string namedmaterial1\" \"a\" \
              \"string namedmaterial2\" \"b\" \"texture bumpmap\" \"h\"\n\
            WorldEnd\n";
        source.insert("main.lxs", text.as_bytes().into());
        let desc = parse_scene("main.lxs", &source).unwrap();
        assert!(matches!(desc.materials[0], MaterialDesc::Bumped(..)));
        assert_eq!(desc.materials[0].name(), "matte");
        assert_eq!(desc.materials[0].textures(), vec![TextureId(0)]);
        assert!(matches!(desc.materials[1], MaterialDesc::Matte(_)));
        assert!(matches!(desc.materials[2], MaterialDesc::Mix(_)));
        // The mix's bumpmap is reported as unused (LuxRender ignores it too).
        assert!(
            desc.warnings.iter().any(|w| w.message.contains("bumpmap")),
            "{:?}",
            desc.warnings
        );
    }
}
