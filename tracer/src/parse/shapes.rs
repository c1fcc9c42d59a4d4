//! `Shape` geometry: triangle meshes (inline and PLY), quadrics and the course's plane, with
//! mesh data validated (counts, index ranges) and errors naming the parameter.

use std::sync::Arc;

use glam::{Mat3, Vec3};

use super::builder::Builder;
use super::context::ParseContext;
use super::params::ParamList;
use super::{ParseError, Pos};
use crate::assets::AssetKind;
use crate::desc::{Geometry, ShapeDesc};
use crate::mesh::ply;
use crate::mesh::TriangleMesh;

impl Builder<'_> {
    /// The geometry of `Shape "ty"`, or `None` (with a warning) for unsupported shapes.
    pub(super) fn geometry(
        &mut self,
        ty: &str,
        params: &ParamList,
        pos: &Pos,
    ) -> Result<Option<Geometry>, ParseError> {
        Ok(Some(match ty {
            "trianglemesh" | "mesh" => Geometry::Mesh(Arc::new(inline_mesh(params, pos)?)),
            "plymesh" => {
                let Some(filename) = params.string("filename")? else {
                    return Err(ParseError::Invalid {
                        pos: pos.clone(),
                        message: "Shape \"plymesh\" needs \"string filename\"".into(),
                    });
                };
                params.ignore("smooth");
                Geometry::Mesh(self.ply_mesh(&filename, pos)?)
            }
            "sphere" => {
                let radius = params.float("radius", 1.0)?;
                Geometry::Sphere {
                    radius,
                    zmin: params.float("zmin", -radius)?,
                    zmax: params.float("zmax", radius)?,
                    phimax: params.float("phimax", 360.0)?,
                }
            }
            "disk" => Geometry::Disk {
                height: params.float("height", 0.0)?,
                radius: params.float("radius", 1.0)?,
                inner_radius: params.float("innerradius", 0.0)?,
                phimax: params.float("phimax", 360.0)?,
            },
            "cylinder" => Geometry::Cylinder {
                radius: params.float("radius", 1.0)?,
                zmin: params.float("zmin", -1.0)?,
                zmax: params.float("zmax", 1.0)?,
                phimax: params.float("phimax", 360.0)?,
            },
            "plane" => {
                let name = if params.count("n").is_some() {
                    "n"
                } else {
                    "N"
                };
                let n = params.vec3(name, Vec3::Z)?;
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
                self.warn(
                    pos,
                    format!("Shape \"{other}\" is not supported; the shape is skipped"),
                );
                return Ok(None);
            }
        }))
    }

    fn ply_mesh(&mut self, filename: &str, pos: &Pos) -> Result<Arc<TriangleMesh>, ParseError> {
        if let Some(m) = self.ply_meshes.get(filename) {
            return Ok(m.clone());
        }
        let bytes = self.read_asset(filename, AssetKind::Ply, pos)?;
        let ply_error = |message: String| ParseError::Ply {
            pos: pos.clone(),
            path: filename.to_string(),
            message,
        };
        let mesh = ply::read_mesh(&bytes).map_err(ply_error)?;
        validate_mesh(&mesh).map_err(ply_error)?;
        let mesh = Arc::new(mesh);
        self.ply_meshes.insert(filename.to_string(), mesh.clone());
        Ok(mesh)
    }
}

fn inline_mesh(params: &ParamList, pos: &Pos) -> Result<TriangleMesh, ParseError> {
    let Some((positions, _)) = params.vec3s("P")? else {
        return Err(ParseError::Invalid {
            pos: pos.clone(),
            message: format!("{}: missing \"point P\"", params.statement),
        });
    };
    let n = positions.len();
    let mut indices = Vec::new();
    let mut any_indices = false;
    for name in ["indices", "triindices"] {
        if let Some((v, p)) = params.ints(name)? {
            if any_indices {
                return Err(params.error(
                    p,
                    "give the triangles once, as \"indices\" or \"triindices\"",
                ));
            }
            any_indices = true;
            if v.len() % 3 != 0 {
                return Err(params.error(
                    p,
                    format!("expected a multiple of 3 indices, got {}", v.len()),
                ));
            }
            let v = checked_indices(params, p, &v, n)?;
            indices.extend(v.chunks_exact(3).map(|t| [t[0], t[1], t[2]]));
        }
    }
    if let Some((v, p)) = params.ints("quadindices")? {
        any_indices = true;
        if v.len() % 4 != 0 {
            return Err(params.error(
                p,
                format!("expected a multiple of 4 indices, got {}", v.len()),
            ));
        }
        let v = checked_indices(params, p, &v, n)?;
        for q in v.chunks_exact(4) {
            indices.push([q[0], q[1], q[2]]);
            indices.push([q[0], q[2], q[3]]);
        }
    }
    if !any_indices {
        if n != 3 {
            return Err(ParseError::Invalid {
                pos: pos.clone(),
                message: format!(
                    "{}: missing \"integer indices\" (only a 3-vertex mesh may omit them)",
                    params.statement
                ),
            });
        }
        indices.push([0, 1, 2]);
    }
    let normals = match params.vec3s("N")? {
        Some((v, p)) if v.len() != n => {
            return Err(params.error(
                p,
                format!("expected one normal per vertex ({n}), got {}", v.len()),
            ))
        }
        Some((v, _)) => Some(v),
        None => None,
    };
    let uv_name = if params.count("uv").is_some() {
        "uv"
    } else {
        "st"
    };
    let uvs = match params.floats(uv_name)? {
        Some((v, p)) if v.len() != 2 * n => {
            return Err(params.error(
                p,
                format!("expected 2 values per vertex ({}), got {}", 2 * n, v.len()),
            ))
        }
        Some((v, _)) => Some(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect()),
        None => None,
    };
    Ok(TriangleMesh {
        positions,
        normals,
        uvs,
        indices,
    })
}

fn checked_indices(
    params: &ParamList,
    p: &super::params::Param,
    v: &[i64],
    vertex_count: usize,
) -> Result<Vec<u32>, ParseError> {
    v.iter()
        .enumerate()
        .map(|(i, &x)| {
            if x < 0 || x as usize >= vertex_count {
                Err(params.error(
                    p,
                    format!("index {} (value {x}) is out of range: the mesh has {vertex_count} vertices", i + 1),
                ))
            } else {
                Ok(x as u32)
            }
        })
        .collect()
}

/// Checks a mesh read from a file: indices in range, attribute counts, finite values.
fn validate_mesh(m: &TriangleMesh) -> Result<(), String> {
    let n = m.positions.len();
    if let Some((i, v)) = m
        .indices
        .iter()
        .flatten()
        .enumerate()
        .find(|(_, &v)| v as usize >= n)
    {
        return Err(format!(
            "face index {} (value {v}) is out of range: {n} vertices",
            i + 1
        ));
    }
    if let Some(i) = m.positions.iter().position(|p| !p.is_finite()) {
        return Err(format!("vertex {} has a non-finite position", i + 1));
    }
    if let Some(normals) = &m.normals {
        if let Some(i) = normals.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {} has a non-finite normal", i + 1));
        }
    }
    if let Some(uvs) = &m.uvs {
        if let Some(i) = uvs
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(format!(
                "vertex {} has a non-finite texture coordinate",
                i + 1
            ));
        }
    }
    Ok(())
}

/// The world-space area of a shape (infinite for the plane), for area-light normalisation.
/// Quadrics under a non-uniform scale use the mean area scale |det|^(2/3).
pub fn world_area(shape: &ShapeDesc) -> f32 {
    let m = shape.object_to_world;
    let area_scale = Mat3::from_mat4(m).determinant().abs().powf(2.0 / 3.0);
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
        Geometry::Sphere {
            radius,
            zmin,
            zmax,
            phimax,
        } => {
            let r = radius.abs();
            let h = zmax.clamp(-r, r) - zmin.clamp(-r, r);
            phi(*phimax) * r * h.abs() * area_scale
        }
        Geometry::Disk {
            radius,
            inner_radius,
            phimax,
            ..
        } => {
            0.5 * phi(*phimax) * (radius * radius - inner_radius * inner_radius).abs() * area_scale
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::param::MaterialId;
    use glam::Mat4;

    fn shape(geometry: Geometry, m: Mat4) -> ShapeDesc {
        ShapeDesc {
            name: String::new(),
            geometry,
            object_to_world: m,
            reverse_orientation: false,
            material: MaterialId(0),
            area_light: None,
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
        let a = world_area(&shape(sphere, Mat4::from_scale(Vec3::splat(2.0))));
        assert!((a - 4.0 * std::f32::consts::PI).abs() < 1e-4, "{a}");
        let quad = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        };
        let m = Mat4::from_translation(Vec3::ONE) * Mat4::from_scale(Vec3::new(3.0, 2.0, 1.0));
        let a = world_area(&shape(Geometry::Mesh(Arc::new(quad)), m));
        assert!((a - 6.0).abs() < 1e-5, "{a}");
        let disk = Geometry::Disk {
            height: 0.0,
            radius: 1.0,
            inner_radius: 0.0,
            phimax: 180.0,
        };
        let a = world_area(&shape(disk, Mat4::IDENTITY));
        assert!((a - std::f32::consts::FRAC_PI_2).abs() < 1e-5);
    }
}
