//! Texture-coordinate generation: [`Mapping2D`] (LuxRender's TextureMapping2D: (s, t) from the
//! surface uv or from the position in texture space, for imagemap, checkerboard 2D, dots,
//! bilerp, uv, normalmap) and [`Mapping3D`] (LuxRender's TextureMapping3D: a point in texture
//! space, for checkerboard 3D, fbm, wrinkled, windy, marble, brick and the blender_* family).
//!
//! ```text
//! Texture "name" "color" "imagemap" "string mapping" "planar" "vector v1" [1 0 0] ...
//! Texture "name" "float" "fbm" "string coordinates" "local" "vector scale" [2 2 2] ...
//! ```
//!
//! | parameter        | mappings                  | default  |
//! |------------------|---------------------------|----------|
//! | `string mapping` | uv, spherical, cylindrical, planar | uv (an unknown name warns) |
//! | `float uscale`   | uv, spherical, cylindrical | 1 (planar ignores it) |
//! | `float vscale`   | uv, spherical, cylindrical | 1 (planar ignores it) |
//! | `float udelta`   | all                       | 0        |
//! | `float vdelta`   | all                       | 0        |
//! | `vector v1`      | planar                    | (1, 0, 0) |
//! | `vector v2`      | planar                    | (0, 1, 0) |
//! | `string coordinates` | 3D: global (world position), local (object position), uv ((u, v, 0)) | global (an unknown name warns) |
//! | `vector scale`   | 3D                        | (1, 1, 1): the pattern is stretched by it |
//! | `vector rotate`  | 3D                        | (0, 0, 0): degrees about x, then y, then z |
//! | `vector translate` | 3D                      | (0, 0, 0): the pattern is moved by it |
//!
//! Spherical, cylindrical and planar mappings work in texture space: the inverse of the
//! transform current at the `Texture` statement, applied to the shaded point's object-space
//! position. 3D mappings start from that transform itself, not its inverse (LuxRender 1.x's
//! `TextureMapping3D::Create` stores the CTM as its world-to-texture matrix, unlike its 2D
//! mappings), then compose (as LuxRender does) the inverse scale, the rotations and the
//! negated translation: texture point = CTM x S^-1 x Rx x Ry x Rz x T(-translate) x point.

use std::f32::consts::{PI, TAU};

use glam::{Mat4, Vec2, Vec3};

use super::common::LookupPoint;
use crate::diag::SourcePos;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

pub const DEFAULT_MAPPING: &str = "uv";
pub const DEFAULT_SCALE: f32 = 1.0;
pub const DEFAULT_DELTA: f32 = 0.0;
pub const DEFAULT_V1: Vec3 = Vec3::X;
pub const DEFAULT_V2: Vec3 = Vec3::Y;
pub const DEFAULT_COORDINATES: &str = "global";
pub const DEFAULT_SCALE_3D: Vec3 = Vec3::ONE;
pub const DEFAULT_ROTATE_3D: Vec3 = Vec3::ZERO;
pub const DEFAULT_TRANSLATE_3D: Vec3 = Vec3::ZERO;

/// 2D texture-coordinate generation. `world_to_texture` is the inverse of the transform current
/// at the `Texture` statement.
#[derive(Clone, Debug, PartialEq)]
pub enum Mapping2D {
    /// s = uscale x u + udelta, t = vscale x v + vdelta.
    Uv {
        uscale: f32,
        vscale: f32,
        udelta: f32,
        vdelta: f32,
    },
    /// s = uscale x phi / 2pi + udelta, t = vscale x theta / pi + vdelta.
    Spherical {
        world_to_texture: Mat4,
        uscale: f32,
        vscale: f32,
        udelta: f32,
        vdelta: f32,
    },
    /// s = uscale x phi / 2pi + udelta, t = vscale x (1 - z) / 2 + vdelta.
    Cylindrical {
        world_to_texture: Mat4,
        uscale: f32,
        vscale: f32,
        udelta: f32,
        vdelta: f32,
    },
    /// s = dot(p, v1) + udelta, t = dot(p, v2) + vdelta with p in texture space.
    Planar {
        world_to_texture: Mat4,
        v1: Vec3,
        v2: Vec3,
        udelta: f32,
        vdelta: f32,
    },
}

/// Azimuth of `p` around z in [0, 2pi) (LuxRender's SphericalPhi).
fn spherical_phi(p: Vec3) -> f32 {
    let phi = libm::atan2f(p.y, p.x);
    if phi < 0.0 {
        phi + TAU
    } else {
        phi
    }
}

impl Mapping2D {
    /// The mapping parameters of a texture statement.
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let mapping = params.string_or("mapping", DEFAULT_MAPPING)?;
        Ok(match mapping.as_str() {
            "spherical" | "cylindrical" => {
                let world_to_texture = crate::math::inverse(&ctx.ctm());
                let uscale = params.float("uscale", DEFAULT_SCALE)?;
                let vscale = params.float("vscale", DEFAULT_SCALE)?;
                let udelta = params.float("udelta", DEFAULT_DELTA)?;
                let vdelta = params.float("vdelta", DEFAULT_DELTA)?;
                if mapping == "spherical" {
                    Mapping2D::Spherical {
                        world_to_texture,
                        uscale,
                        vscale,
                        udelta,
                        vdelta,
                    }
                } else {
                    Mapping2D::Cylindrical {
                        world_to_texture,
                        uscale,
                        vscale,
                        udelta,
                        vdelta,
                    }
                }
            }
            "planar" => {
                // LuxRender's planar mapping has no scale; exporters write one anyway.
                params.ignore("uscale");
                params.ignore("vscale");
                Mapping2D::Planar {
                    world_to_texture: crate::math::inverse(&ctx.ctm()),
                    v1: params.vec3("v1", DEFAULT_V1)?,
                    v2: params.vec3("v2", DEFAULT_V2)?,
                    udelta: params.float("udelta", DEFAULT_DELTA)?,
                    vdelta: params.float("vdelta", DEFAULT_DELTA)?,
                }
            }
            other => {
                if other != "uv" {
                    ctx.warn(
                        pos,
                        format!("unknown texture mapping \"{other}\"; using uv"),
                    );
                }
                Mapping2D::Uv {
                    uscale: params.float("uscale", DEFAULT_SCALE)?,
                    vscale: params.float("vscale", DEFAULT_SCALE)?,
                    udelta: params.float("udelta", DEFAULT_DELTA)?,
                    vdelta: params.float("vdelta", DEFAULT_DELTA)?,
                }
            }
        })
    }

    /// Texture coordinates (s, t) of a surface point.
    pub fn map(&self, at: &LookupPoint) -> Vec2 {
        match *self {
            Mapping2D::Uv {
                uscale,
                vscale,
                udelta,
                vdelta,
            } => Vec2::new(uscale, vscale) * at.uv + Vec2::new(udelta, vdelta),
            Mapping2D::Spherical {
                world_to_texture,
                uscale,
                vscale,
                udelta,
                vdelta,
            } => {
                let p = world_to_texture.transform_point3(at.p).normalize_or_zero();
                let theta = libm::acosf(p.z.clamp(-1.0, 1.0));
                Vec2::new(uscale, vscale) * Vec2::new(spherical_phi(p) / TAU, theta / PI)
                    + Vec2::new(udelta, vdelta)
            }
            Mapping2D::Cylindrical {
                world_to_texture,
                uscale,
                vscale,
                udelta,
                vdelta,
            } => {
                let p = world_to_texture.transform_point3(at.p);
                Vec2::new(uscale, vscale) * Vec2::new(spherical_phi(p) / TAU, 0.5 - 0.5 * p.z)
                    + Vec2::new(udelta, vdelta)
            }
            Mapping2D::Planar {
                world_to_texture,
                v1,
                v2,
                udelta,
                vdelta,
            } => {
                let p = world_to_texture.transform_point3(at.p);
                Vec2::new(p.dot(v1), p.dot(v2)) + Vec2::new(udelta, vdelta)
            }
        }
    }
}

/// Which position a 3D mapping starts from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coordinates {
    /// The world-space position.
    Global,
    /// The position in the shaded shape's object space.
    Local,
    /// (u, v, 0).
    Uv,
}

/// A point in 3D texture space.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapping3D {
    pub coordinates: Coordinates,
    /// The CTM at the `Texture` statement, composed with the scale, rotate and translate options.
    pub world_to_texture: Mat4,
}

impl Mapping3D {
    pub fn read(
        params: &ParamList,
        pos: &SourcePos,
        ctx: &mut dyn ParseContext,
    ) -> Result<Self, ParseError> {
        let coordinates = match params
            .string_or("coordinates", DEFAULT_COORDINATES)?
            .as_str()
        {
            "global" => Coordinates::Global,
            "local" => Coordinates::Local,
            "uv" => Coordinates::Uv,
            other => {
                ctx.warn(
                    pos,
                    format!("3D texture coordinates \"{other}\" are not supported; using global"),
                );
                Coordinates::Global
            }
        };
        // Typed lookups: marble also has a "float scale".
        let scale = params.vec3_typed("scale", DEFAULT_SCALE_3D)?;
        let rotate = params.vec3_typed("rotate", DEFAULT_ROTATE_3D)?;
        let translate = params.vec3_typed("translate", DEFAULT_TRANSLATE_3D)?;
        // A zero scale would put every point at infinity; LuxRender divides anyway, we keep
        // the axis unscaled instead.
        let inv_scale = Vec3::select(scale.cmpeq(Vec3::ZERO), Vec3::ONE, scale.recip());
        // The CTM uninverted, as LuxRender 1.x uses it (see the module notes).
        let world_to_texture = ctx.ctm()
            * Mat4::from_scale(inv_scale)
            * Mat4::from_rotation_x(rotate.x.to_radians())
            * Mat4::from_rotation_y(rotate.y.to_radians())
            * Mat4::from_rotation_z(rotate.z.to_radians())
            * Mat4::from_translation(-translate);
        Ok(Self {
            coordinates,
            world_to_texture,
        })
    }

    /// The identity mapping of world positions (tests).
    pub fn global(world_to_texture: Mat4) -> Self {
        Self {
            coordinates: Coordinates::Global,
            world_to_texture,
        }
    }

    /// The texture-space point of a surface point.
    pub fn map(&self, at: &LookupPoint) -> Vec3 {
        let p = match self.coordinates {
            Coordinates::Global => at.p_world,
            Coordinates::Local => at.p,
            Coordinates::Uv => at.uv.extend(0.0),
        };
        self.world_to_texture.transform_point3(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(p: Vec3, uv: Vec2) -> LookupPoint {
        LookupPoint::new(p, uv)
    }

    #[test]
    fn uv_mapping_scales_then_offsets() {
        // Blender's export: vscale -1, vdelta 1 turns v upside down.
        let m = Mapping2D::Uv {
            uscale: 2.0,
            vscale: -1.0,
            udelta: 0.25,
            vdelta: 1.0,
        };
        let st = m.map(&at(Vec3::ZERO, Vec2::new(0.5, 0.2)));
        assert!((st - Vec2::new(1.25, 0.8)).length() < 1e-6, "{st}");
    }

    #[test]
    fn spherical_mapping_angles() {
        let spherical = |vscale: f32, vdelta: f32| Mapping2D::Spherical {
            world_to_texture: Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0)),
            uscale: 1.0,
            vscale,
            udelta: 0.0,
            vdelta,
        };
        let m = spherical(1.0, 0.0);
        // A point above the texture-space origin is at theta 0; one on -y at phi 3pi/2.
        let top = m.map(&at(Vec3::new(0.0, 0.0, 3.0), Vec2::ZERO));
        assert!(top.y.abs() < 1e-6, "{top}");
        let side = m.map(&at(Vec3::new(0.0, -2.0, 1.0), Vec2::ZERO));
        assert!((side - Vec2::new(0.75, 0.5)).length() < 1e-6, "{side}");
        // Blender's vscale -1, vdelta 1 turns the map upside down: the top reads t = 1.
        let flipped = spherical(-1.0, 1.0).map(&at(Vec3::new(0.0, 0.0, 3.0), Vec2::ZERO));
        assert!((flipped.y - 1.0).abs() < 1e-6, "{flipped}");
    }

    #[test]
    fn cylindrical_mapping_angles_and_height() {
        let m = Mapping2D::Cylindrical {
            world_to_texture: Mat4::IDENTITY,
            uscale: 2.0,
            vscale: 1.0,
            udelta: -0.5,
            vdelta: 0.0,
        };
        // phi = pi gives s = 2 x 0.5 - 0.5.
        let st = m.map(&at(Vec3::new(-1.0, 0.0, 0.5), Vec2::ZERO));
        assert!((st - Vec2::new(0.5, 0.25)).length() < 1e-6, "{st}");
    }

    #[test]
    fn planar_mapping_projects_texture_space_position() {
        let m = Mapping2D::Planar {
            world_to_texture: Mat4::from_scale(Vec3::splat(2.0)),
            v1: Vec3::X,
            v2: Vec3::Y,
            udelta: 0.5,
            vdelta: 1.0,
        };
        let st = m.map(&at(Vec3::new(1.0, -1.0, 7.0), Vec2::ZERO));
        assert!((st - Vec2::new(2.5, -1.0)).length() < 1e-6, "{st}");
    }
}
