//! `Shape "sphere" "float radius" [1] ...`: the shape descriptions (plain data), LuxRender's
//! defaults, their reading, and the world-space area area lights are normalised by. Shapes are
//! placed by the transform current at the statement; the renderer's geometry is built from
//! these in [`crate::geometry`]. One file per kind, each with its syntax, parameters and
//! defaults:
//!
//! | type | kind |
//! |---|---|
//! | `trianglemesh`, `mesh`, `loopsubdiv`, `plymesh`, `heightfield`, `cone`, `paraboloid`, `hyperboloid` | [`mesh`]: triangles |
//! | `sphere` | [`sphere`]: exact |
//! | `disk` | [`disk`]: exact |
//! | `cylinder` | [`cylinder`]: exact |
//! | `plane` (the course's) | [`plane`]: unbounded |
//!
//! Every shape also takes `name`. Other types are a warning and the shape is skipped. The
//! shapes YAT has no exact intersection for (subdivision surfaces, heightfields, the quadrics
//! other than spheres, disks and cylinders) are triangle meshes from the start.
//!
//! A new shape is one new file (its struct, its reader, its [`ShapeKind`] impl and, when it is
//! intersected exactly, its [`ExactSurface`]) plus one line in the kind list below, which
//! generates the rest.

pub mod kind;
pub mod revolved;

use glam::{Mat4, Vec2, Vec3, Vec3A};

pub use kind::{ExactSurface, Placement, ShapeKind, SurfaceFrame};

use crate::diag::SourcePos;
use crate::medium::common::ShapeMedia;
use crate::mesh::TriangleMesh;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, MaterialId};

/// Generates the shape family from its kind list (see [`shapes!`]'s invocation below): each
/// kind's module and re-export, the [`Geometry`] variant of each kind, the name table from LuxRender's shape types to the kind's
/// readers, [`AnalyticSurface`] (a variant per kind, uninhabited for the kinds that are not
/// exact), and every dispatch `match`, each arm a call of the kind's [`ShapeKind`] or
/// [`ExactSurface`] method.
macro_rules! shapes {
    ($($module:ident::$kind:ident { $name:literal => $read:ident $(, $alias:literal => $read_alias:ident)* },)+) => {
        $(pub mod $module;)+
        $(pub use $module::$kind;)+

        /// A shape's geometry as the scene describes it, in object space.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Geometry {
            $($kind($kind),)+
        }

        /// The object-space surface of an exactly intersected shape, ready to intersect.
        #[derive(Clone, Copy, Debug)]
        pub enum AnalyticSurface {
            $($kind(<$kind as ShapeKind>::Surface),)+
        }

        impl Geometry {
            /// The reader of LuxRender shape type `ty`; None for a type this renderer does not
            /// know.
            fn reader(ty: &str) -> Option<GeometryReader> {
                Some(match ty {
                    $(
                        $name => |ctx, ty, params, pos| Ok(Self::$kind($module::$read(ctx, ty, params, pos)?)),
                        $($alias => |ctx, ty, params, pos| Ok(Self::$kind($module::$read_alias(ctx, ty, params, pos)?)),)*
                    )+
                    _ => return None,
                })
            }

            /// The kind's LuxRender name: the first of the types read into it ("mesh" for
            /// every triangle mesh).
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$kind(_) => $name,)+
                }
            }

            /// How the scene geometry places the shape.
            pub fn placement(&self) -> Placement<'_, AnalyticSurface> {
                match self {
                    $(Self::$kind(k) => k.placement().map(AnalyticSurface::$kind),)+
                }
            }

            /// The world-space area under `object_to_world`.
            fn world_area(&self, object_to_world: &Mat4) -> f32 {
                match self {
                    $(Self::$kind(k) => k.world_area(object_to_world),)+
                }
            }

            /// Object-space triangles of a shape that is not triangles already
            /// ([`ShapeKind::tessellate`]); None for meshes and unbounded shapes.
            pub fn tessellate(&self, segments: u32) -> Option<TriangleMesh> {
                match self {
                    $(Self::$kind(k) => k.tessellate(segments),)+
                }
            }
        }

        impl ExactSurface for AnalyticSurface {
            #[inline(always)]
            fn bounds(&self) -> (Vec3, Vec3) {
                match self {
                    $(Self::$kind(s) => s.bounds(),)+
                }
            }
            #[inline(always)]
            fn intersect(&self, o: Vec3A, d: Vec3A, tmax: f32) -> Option<f32> {
                match self {
                    $(Self::$kind(s) => s.intersect(o, d, tmax),)+
                }
            }
            #[inline(always)]
            fn surface_point(&self, o: Vec3A, d: Vec3A, t: f32) -> Vec3A {
                match self {
                    $(Self::$kind(s) => s.surface_point(o, d, t),)+
                }
            }
            #[inline(always)]
            fn shading(&self, p: Vec3A) -> SurfaceFrame {
                match self {
                    $(Self::$kind(s) => s.shading(p),)+
                }
            }
            fn area(&self) -> f32 {
                match self {
                    $(Self::$kind(s) => s.area(),)+
                }
            }
            fn sample(&self, u: Vec2) -> (Vec3A, Vec3A) {
                match self {
                    $(Self::$kind(s) => s.sample(u),)+
                }
            }
            fn whole_sphere_radius(&self) -> Option<f32> {
                match self {
                    $(Self::$kind(s) => s.whole_sphere_radius(),)+
                }
            }
        }
    };
}

// The kinds: `module::Kind { "luxrender type" => reader, "another type" => reader, ... },`.
shapes! {
    mesh::Mesh {
        "mesh" => read_inline,
        "trianglemesh" => read_inline,
        "loopsubdiv" => read_inline,
        "plymesh" => read_ply,
        "heightfield" => read_heightfield,
        "cone" => read_quadric,
        "paraboloid" => read_quadric,
        "hyperboloid" => read_quadric
    },
    sphere::Sphere { "sphere" => read },
    disk::Disk { "disk" => read },
    cylinder::Cylinder { "cylinder" => read },
    plane::Plane { "plane" => read },
}

/// Reads a shape kind from a statement's type and parameters.
type GeometryReader =
    fn(&mut dyn ParseContext, &str, &ParamList, &SourcePos) -> Result<Geometry, ParseError>;

/// An area light on a shape, as LuxRender defines its radiance: `L` (a colour, or a texture
/// evaluated where the surface is seen or sampled) times `gain`, the gain scaled by power x
/// efficacy / (area x pi x mean luminance of `L`) when that is positive (lights/area.rs).
#[derive(Clone, Debug, PartialEq)]
pub struct AreaLightDesc {
    pub l: ConstOrTexture,
    pub gain: f32,
    pub power: f32,
    pub efficacy: f32,
    /// The shape's world-space area.
    pub area: f32,
    /// Its light group: an index into the film's light groups.
    pub group: u8,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    pub name: String,
    pub geometry: Geometry,
    pub object_to_world: Mat4,
    pub reverse_orientation: bool,
    pub material: MaterialId,
    pub area_light: Option<AreaLightDesc>,
    /// The `Interior` and `Exterior` volumes current when the shape was defined.
    pub media: ShapeMedia,
}

impl Geometry {
    /// The geometry of `Shape "ty"` through the name table, or `None` (with a warning) for
    /// unsupported shapes.
    pub fn read(
        ctx: &mut dyn ParseContext,
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
    ) -> Result<Option<Geometry>, ParseError> {
        let Some(read) = Self::reader(ty) else {
            params.ignore_all();
            ctx.warn(
                pos,
                format!("Shape \"{ty}\" is not supported; the shape is skipped"),
            );
            return Ok(None);
        };
        read(ctx, ty, params, pos).map(Some)
    }

    /// The primitives the shape places in the world, what the build budget counts: its
    /// triangles, or one.
    pub fn primitive_count(&self) -> u64 {
        match self.placement() {
            Placement::Triangles(mesh) => mesh.indices.len() as u64,
            Placement::Exact(_) | Placement::Unbounded(_) => 1,
        }
    }
}

impl ShapeDesc {
    /// The world-space area of a shape (infinite for the plane), for area-light normalisation.
    /// Exact shapes under a non-uniform scale use the mean area scale |det|^(2/3).
    pub fn world_area(&self) -> f32 {
        self.geometry.world_area(&self.object_to_world)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;

    fn shape(geometry: Geometry, m: Mat4) -> ShapeDesc {
        ShapeDesc {
            name: String::new(),
            geometry,
            object_to_world: m,
            reverse_orientation: false,
            material: MaterialId(0),
            area_light: None,
            media: Default::default(),
        }
    }

    #[test]
    fn world_areas() {
        let sphere = Geometry::Sphere(Sphere {
            radius: 0.5,
            zmin: -0.5,
            zmax: 0.5,
            phimax: 360.0,
        });
        let a = shape(sphere, Mat4::from_scale(Vec3::splat(2.0))).world_area();
        assert!((a - 4.0 * std::f32::consts::PI).abs() < 1e-4, "{a}");
        let quad = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        };
        let m = Mat4::from_translation(Vec3::ONE) * Mat4::from_scale(Vec3::new(3.0, 2.0, 1.0));
        let a = shape(Geometry::Mesh(Arc::new(quad)), m).world_area();
        assert!((a - 6.0).abs() < 1e-5, "{a}");
        let disk = Geometry::Disk(Disk {
            height: 0.0,
            radius: 1.0,
            inner_radius: 0.0,
            phimax: 180.0,
        });
        let a = shape(disk, Mat4::IDENTITY).world_area();
        assert!((a - std::f32::consts::FRAC_PI_2).abs() < 1e-5);
    }
}
