//! 2D texture-coordinate generation (LuxRender's TextureMapping2D): (s, t) from the surface
//! uv or from the position in texture space.

use std::f32::consts::{PI, TAU};

use glam::{Mat4, Vec2, Vec3};

use super::TexturePoint;
use crate::desc::Mapping2D;

/// Azimuth of `p` around z in [0, 2pi) (LuxRender's SphericalPhi).
fn spherical_phi(p: Vec3) -> f32 {
    let phi = p.y.atan2(p.x);
    if phi < 0.0 {
        phi + TAU
    } else {
        phi
    }
}

#[derive(Clone, Debug)]
pub enum Mapping {
    Uv {
        scale: Vec2,
        delta: Vec2,
    },
    /// s = phi / 2pi, t = theta / pi of the direction from the texture-space origin.
    Spherical {
        world_to_texture: Mat4,
        scale: Vec2,
        delta: Vec2,
    },
    /// s = phi / 2pi around the texture-space z axis, t = (1 - z) / 2.
    Cylindrical {
        world_to_texture: Mat4,
        scale: Vec2,
        delta: Vec2,
    },
    /// s = dot(p, v1) + udelta, t = dot(p, v2) + vdelta with p in texture space.
    Planar {
        world_to_texture: Mat4,
        v1: Vec3,
        v2: Vec3,
        delta: Vec2,
    },
}

impl Mapping {
    pub fn new(desc: &Mapping2D) -> Self {
        match *desc {
            Mapping2D::Uv {
                uscale,
                vscale,
                udelta,
                vdelta,
            } => Mapping::Uv {
                scale: Vec2::new(uscale, vscale),
                delta: Vec2::new(udelta, vdelta),
            },
            Mapping2D::Spherical {
                world_to_texture,
                uscale,
                vscale,
                udelta,
                vdelta,
            } => Mapping::Spherical {
                world_to_texture,
                scale: Vec2::new(uscale, vscale),
                delta: Vec2::new(udelta, vdelta),
            },
            Mapping2D::Cylindrical {
                world_to_texture,
                uscale,
                vscale,
                udelta,
                vdelta,
            } => Mapping::Cylindrical {
                world_to_texture,
                scale: Vec2::new(uscale, vscale),
                delta: Vec2::new(udelta, vdelta),
            },
            Mapping2D::Planar {
                world_to_texture,
                v1,
                v2,
                udelta,
                vdelta,
            } => Mapping::Planar {
                world_to_texture,
                v1,
                v2,
                delta: Vec2::new(udelta, vdelta),
            },
        }
    }

    /// Texture coordinates (s, t) of a surface point.
    pub fn map(&self, at: &TexturePoint) -> Vec2 {
        match self {
            Mapping::Uv { scale, delta } => *scale * at.uv + *delta,
            Mapping::Spherical {
                world_to_texture,
                scale,
                delta,
            } => {
                let p = world_to_texture.transform_point3(at.p).normalize_or_zero();
                let theta = p.z.clamp(-1.0, 1.0).acos();
                *scale * Vec2::new(spherical_phi(p) / TAU, theta / PI) + *delta
            }
            Mapping::Cylindrical {
                world_to_texture,
                scale,
                delta,
            } => {
                let p = world_to_texture.transform_point3(at.p);
                *scale * Vec2::new(spherical_phi(p) / TAU, 0.5 - 0.5 * p.z) + *delta
            }
            Mapping::Planar {
                world_to_texture,
                v1,
                v2,
                delta,
            } => {
                let p = world_to_texture.transform_point3(at.p);
                Vec2::new(p.dot(*v1), p.dot(*v2)) + *delta
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(p: Vec3, uv: Vec2) -> TexturePoint {
        TexturePoint { p, uv }
    }

    #[test]
    fn uv_mapping_scales_then_offsets() {
        // Blender's export: vscale -1, vdelta 1 turns v upside down.
        let m = Mapping::new(&Mapping2D::Uv {
            uscale: 2.0,
            vscale: -1.0,
            udelta: 0.25,
            vdelta: 1.0,
        });
        let st = m.map(&at(Vec3::ZERO, Vec2::new(0.5, 0.2)));
        assert!((st - Vec2::new(1.25, 0.8)).length() < 1e-6, "{st}");
    }

    #[test]
    fn spherical_mapping_angles() {
        let spherical = |vscale: f32, vdelta: f32| {
            Mapping::new(&Mapping2D::Spherical {
                world_to_texture: Mat4::from_translation(Vec3::new(0.0, 0.0, -1.0)),
                uscale: 1.0,
                vscale,
                udelta: 0.0,
                vdelta,
            })
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
        let m = Mapping::new(&Mapping2D::Cylindrical {
            world_to_texture: Mat4::IDENTITY,
            uscale: 2.0,
            vscale: 1.0,
            udelta: -0.5,
            vdelta: 0.0,
        });
        // phi = pi gives s = 2 x 0.5 - 0.5.
        let st = m.map(&at(Vec3::new(-1.0, 0.0, 0.5), Vec2::ZERO));
        assert!((st - Vec2::new(0.5, 0.25)).length() < 1e-6, "{st}");
    }

    #[test]
    fn planar_mapping_projects_texture_space_position() {
        let m = Mapping::new(&Mapping2D::Planar {
            world_to_texture: Mat4::from_scale(Vec3::splat(2.0)),
            v1: Vec3::X,
            v2: Vec3::Y,
            udelta: 0.5,
            vdelta: 1.0,
        });
        let st = m.map(&at(Vec3::new(1.0, -1.0, 7.0), Vec2::ZERO));
        assert!((st - Vec2::new(2.5, -1.0)).length() < 1e-6, "{st}");
    }
}
