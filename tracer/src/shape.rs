//! `Shape "sphere" "float radius" [1] ...`: the shape descriptions (plain data), LuxRender's
//! defaults, their reading, and the world-space area area lights are normalised by. Shapes are
//! placed by the transform current at the statement; the renderer's geometry is built from
//! these in [`crate::geometry`].
//!
//! | type | parameters (defaults) |
//! |---|---|
//! | `trianglemesh`, `mesh`, `loopsubdiv` | see [`crate::mesh::inline`]; subdivision and displacement: [`crate::mesh::subdiv`] |
//! | `plymesh` | `filename` (required; the file is read once and shared), `smooth` (ignored); subdivision as above |
//! | `heightfield` | see [`crate::mesh::heightfield`] |
//! | `cone`, `paraboloid`, `hyperboloid` | see [`crate::mesh::quadric`] (tessellated) |
//! | `sphere` | `radius` (1), `zmin` (-radius), `zmax` (radius), `phimax` (360) |
//! | `disk` | `height` (0), `radius` (1), `innerradius` (0), `phimax` (360) |
//! | `cylinder` | `radius` (1), `zmin` (-1), `zmax` (1), `phimax` (360) |
//! | `plane` (the course's) | `n` or `N` (0 0 1), the infinite plane's normal |
//!
//! Every shape also takes `name`. Other types are a warning and the shape is skipped. The
//! shapes YAT has no exact intersection for (subdivision surfaces, heightfields, the quadrics
//! other than spheres, disks and cylinders) become triangle meshes here, so everything after
//! the parser sees meshes.

use std::sync::Arc;

use glam::{Mat3, Mat4, Vec3};

use crate::diag::SourcePos;
use crate::medium::common::ShapeMedia;
use crate::mesh::quadric::Quadric;
use crate::mesh::{heightfield, inline, subdiv, TriangleMesh};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;
use crate::refs::{ConstOrTexture, MaterialId};

/// Radius of spheres, disks and cylinders when the file does not say.
pub const DEFAULT_RADIUS: f32 = 1.0;
/// Sweep of spheres, disks and cylinders in degrees when the file does not say.
pub const DEFAULT_PHIMAX: f32 = 360.0;
/// Height of a disk above the object-space origin when the file does not say.
pub const DEFAULT_DISK_HEIGHT: f32 = 0.0;
/// Inner radius of a disk when the file does not say.
pub const DEFAULT_DISK_INNER_RADIUS: f32 = 0.0;
/// The z range of a cylinder when the file does not say (a sphere's is -radius..radius).
pub const DEFAULT_CYLINDER_ZMIN: f32 = -1.0;
pub const DEFAULT_CYLINDER_ZMAX: f32 = 1.0;
/// Normal of the course's plane when the file does not say.
pub const DEFAULT_PLANE_NORMAL: Vec3 = Vec3::Z;

#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// Shared between instances of the same object.
    Mesh(Arc<TriangleMesh>),
    Sphere {
        radius: f32,
        zmin: f32,
        zmax: f32,
        /// Degrees.
        phimax: f32,
    },
    Disk {
        height: f32,
        radius: f32,
        inner_radius: f32,
        phimax: f32,
    },
    Cylinder {
        radius: f32,
        zmin: f32,
        zmax: f32,
        phimax: f32,
    },
    /// The course's infinite plane through the object-space origin with this normal.
    Plane { normal: Vec3 },
}

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
    /// The LuxRender shape type ("mesh" for every triangle mesh, inline or PLY).
    pub fn name(&self) -> &'static str {
        match self {
            Geometry::Mesh(_) => "mesh",
            Geometry::Sphere { .. } => "sphere",
            Geometry::Disk { .. } => "disk",
            Geometry::Cylinder { .. } => "cylinder",
            Geometry::Plane { .. } => "plane",
        }
    }

    /// The primitives the shape places in the world, what the build budget counts: its
    /// triangles, or one.
    pub fn primitive_count(&self) -> u64 {
        match self {
            Geometry::Mesh(mesh) => mesh.indices.len() as u64,
            _ => 1,
        }
    }

    /// A sphere's z range: zmin and zmax in order, clamped to [-|radius|, |radius|]. None for
    /// other shapes. The renderer, the area of an emitting sphere and the tessellation
    /// ([`crate::mesh::tessellate`]) all use this range.
    pub fn sphere_z_range(&self) -> Option<(f32, f32)> {
        let Geometry::Sphere {
            radius, zmin, zmax, ..
        } = *self
        else {
            return None;
        };
        let r = radius.abs();
        Some((zmin.min(zmax).clamp(-r, r), zmin.max(zmax).clamp(-r, r)))
    }

    /// The geometry of `Shape "ty"`, or `None` (with a warning) for unsupported shapes.
    pub fn read(
        ctx: &mut dyn ParseContext,
        ty: &str,
        params: &ParamList,
        pos: &SourcePos,
    ) -> Result<Option<Geometry>, ParseError> {
        Ok(Some(match ty {
            "trianglemesh" | "mesh" | "loopsubdiv" => {
                let mesh = Arc::new(inline::read_inline(params, pos)?);
                Geometry::Mesh(subdiv::apply(ctx, params, mesh, pos)?)
            }
            "plymesh" => {
                let Some(filename) = params.string("filename")? else {
                    return Err(ParseError::Invalid {
                        pos: pos.clone(),
                        message: "Shape \"plymesh\" needs \"string filename\"".into(),
                    });
                };
                let mesh = ctx.ply_mesh(&filename, pos)?;
                // LuxRender computes vertex normals for a smooth mesh whose file has none.
                if params.bool("smooth", false)? && mesh.normals.is_none() {
                    ctx.warn(
                        pos,
                        "Shape \"plymesh\": \"smooth\" normals for a file without normals are not computed; the mesh is shaded flat".into(),
                    );
                }
                Geometry::Mesh(subdiv::apply(ctx, params, mesh, pos)?)
            }
            "sphere" => {
                let radius = params.float("radius", DEFAULT_RADIUS)?;
                Geometry::Sphere {
                    radius,
                    zmin: params.float("zmin", -radius)?,
                    zmax: params.float("zmax", radius)?,
                    phimax: params.float("phimax", DEFAULT_PHIMAX)?,
                }
            }
            "disk" => Geometry::Disk {
                height: params.float("height", DEFAULT_DISK_HEIGHT)?,
                radius: params.float("radius", DEFAULT_RADIUS)?,
                inner_radius: params.float("innerradius", DEFAULT_DISK_INNER_RADIUS)?,
                phimax: params.float("phimax", DEFAULT_PHIMAX)?,
            },
            "cylinder" => Geometry::Cylinder {
                radius: params.float("radius", DEFAULT_RADIUS)?,
                zmin: params.float("zmin", DEFAULT_CYLINDER_ZMIN)?,
                zmax: params.float("zmax", DEFAULT_CYLINDER_ZMAX)?,
                phimax: params.float("phimax", DEFAULT_PHIMAX)?,
            },
            "heightfield" => Geometry::Mesh(Arc::new(heightfield::read_heightfield(params, pos)?)),
            "cone" | "paraboloid" | "hyperboloid" => {
                let quadric = Quadric::read(ty, params)?.expect("a quadric's name");
                Geometry::Mesh(Arc::new(quadric.tessellate()))
            }
            "plane" => {
                let name = if params.count("n").is_some() {
                    "n"
                } else {
                    "N"
                };
                let n = params.vec3(name, DEFAULT_PLANE_NORMAL)?;
                let Some(normal) = n.try_normalize() else {
                    let p = params.find(name).expect("a zero normal was given");
                    return Err(params.error(p, "the plane normal must be non-zero"));
                };
                Geometry::Plane { normal }
            }
            other => {
                for p in &params.params {
                    params.ignore(&p.name);
                }
                ctx.warn(
                    pos,
                    format!("Shape \"{other}\" is not supported; the shape is skipped"),
                );
                return Ok(None);
            }
        }))
    }
}

impl ShapeDesc {
    /// The world-space area of a shape (infinite for the plane), for area-light normalisation.
    /// Quadrics under a non-uniform scale use the mean area scale |det|^(2/3).
    pub fn world_area(&self) -> f32 {
        let shape = self;
        let m = shape.object_to_world;
        let area_scale = libm::powf(Mat3::from_mat4(m).determinant().abs(), 2.0 / 3.0);
        let phi = |deg: f32| deg.clamp(0.0, 360.0).to_radians();
        match &shape.geometry {
            Geometry::Mesh(mesh) => mesh
                .indices
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| m.transform_point3(mesh.positions[i as usize]));
                    0.5 * (b - a).cross(c - a).length()
                })
                .sum(),
            Geometry::Sphere { radius, phimax, .. } => {
                let r = radius.abs();
                let (z0, z1) = shape.geometry.sphere_z_range().expect("a sphere");
                phi(*phimax) * r * (z1 - z0) * area_scale
            }
            Geometry::Disk {
                radius,
                inner_radius,
                phimax,
                ..
            } => {
                0.5 * phi(*phimax)
                    * (radius * radius - inner_radius * inner_radius).abs()
                    * area_scale
            }
            Geometry::Cylinder {
                radius,
                zmin,
                zmax,
                phimax,
            } => phi(*phimax) * radius.abs() * (zmax - zmin).abs() * area_scale,
            Geometry::Plane { .. } => f32::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
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
        let sphere = Geometry::Sphere {
            radius: 0.5,
            zmin: -0.5,
            zmax: 0.5,
            phimax: 360.0,
        };
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
        let disk = Geometry::Disk {
            height: 0.0,
            radius: 1.0,
            inner_radius: 0.0,
            phimax: 180.0,
        };
        let a = shape(disk, Mat4::IDENTITY).world_area();
        assert!((a - std::f32::consts::FRAC_PI_2).abs() < 1e-5);
    }
}
