//! Shapes (`scene.shapes.shape<N>`, `scene.objects.object<N>`): every shape as a world-space
//! PLY mesh with its material; analytic shapes are tessellated, infinite planes become large
//! squares, and an emitting shape (or one with volumes) gets its own material carrying the
//! emission (and the volumes).

use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};
use yat_tracer::desc::{Geometry, MaterialDesc, SceneDesc, ShapeDesc, TriangleMesh};
use yat_tracer::material::Null;
use yat_tracer::texture::LookupPoint;

use crate::bake::material_bake;
use crate::error::ExportError;
use crate::materials::write_material;
use crate::options::ExportOptions;
use crate::ply::ply_bytes;
use crate::props::{mat_name, quoted, Props};
use crate::volumes::set_material_volumes;

/// Half the side of the quad an infinite plane becomes (scene units).
pub const PLANE_HALF_SIZE: f32 = 1.0e4;

/// Writes every shape and its object; returns the meshes as (relative path, PLY bytes).
pub fn write_shapes(
    desc: &SceneDesc,
    opts: &ExportOptions,
    p: &mut Props,
    notes: &mut Vec<String>,
) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    let mut meshes = Vec::new();
    for (i, shape) in desc.shapes.iter().enumerate() {
        let Some(bytes) = export_shape(desc, shape, opts, notes)? else {
            notes.push(format!("shape \"{}\": degenerate, left out", shape.name));
            continue;
        };
        let path = format!("meshes/shape{i}.ply");
        p.set(format!("scene.shapes.shape{i}.type"), quoted("mesh"));
        p.set(format!("scene.shapes.shape{i}.ply"), quoted(&path));
        let material = match &shape.area_light {
            Some(area) => {
                let name = format!("emitter{i}");
                let m = desc.materials.get(shape.material.0 as usize);
                write_material(p, &name, m.unwrap_or(&MaterialDesc::Null(Null)), Some(area));
                name
            }
            None if !shape.media.is_empty() => {
                // LuxCore keeps volumes on materials: this shape's own copy.
                let name = format!("{}_shape{i}", mat_name(shape.material));
                if let Some(m) = desc.materials.get(shape.material.0 as usize) {
                    write_material(p, &name, m, None);
                }
                name
            }
            None => mat_name(shape.material),
        };
        set_material_volumes(p, &material, shape.media);
        p.set(
            format!("scene.objects.object{i}.shape"),
            quoted(&format!("shape{i}")),
        );
        p.set(
            format!("scene.objects.object{i}.material"),
            quoted(&material),
        );
        meshes.push((path, bytes));
    }
    Ok(meshes)
}

/// The shape's mesh in world space, wound so LuxCore's front face (counter-clockwise, the
/// geometric normal cross(p1 - p0, p2 - p0)) is YAT's.
fn export_shape(
    desc: &SceneDesc,
    shape: &ShapeDesc,
    opts: &ExportOptions,
    notes: &mut Vec<String>,
) -> Result<Option<Vec<u8>>, ExportError> {
    let mesh: Arc<TriangleMesh> = match &shape.geometry {
        Geometry::Mesh(m) => m.clone(),
        Geometry::Plane(plane) => {
            notes.push(format!(
                "shape \"{}\": infinite plane as a {}-unit square",
                shape.name,
                2.0 * PLANE_HALF_SIZE
            ));
            Arc::new(plane.quad(PLANE_HALF_SIZE))
        }
        g => match g.tessellate(opts.segments) {
            Some(m) => {
                notes.push(format!(
                    "shape \"{}\": tessellated into {} triangles",
                    shape.name,
                    m.indices.len()
                ));
                Arc::new(m)
            }
            None => return Ok(None),
        },
    };
    if mesh.indices.is_empty() {
        return Ok(None);
    }
    let m = shape.object_to_world;
    let linear = Mat3::from_mat4(m);
    let det = linear.determinant();
    if det == 0.0 || !det.is_finite() {
        return Ok(None);
    }
    let positions: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|&p| m.transform_point3(p))
        .collect();
    let normal_matrix = linear.inverse().transpose();
    let normals: Option<Vec<Vec3>> = mesh
        .normals
        .as_ref()
        .filter(|n| n.len() == mesh.positions.len())
        .map(|n| {
            n.iter()
                .map(|&n| (normal_matrix * n).normalize_or_zero())
                .collect()
        });
    let object_uv = |i: usize| -> Vec2 {
        mesh.uvs
            .as_ref()
            .and_then(|uv| uv.get(i))
            .map_or(Vec2::ZERO, |&[u, v]| Vec2::new(u, v))
    };
    let uvs: Option<Vec<Vec2>> = match material_bake(desc, shape.material)? {
        Some(mapping) => Some(
            (0..mesh.positions.len())
                .map(|i| mapping.map(&LookupPoint::new(mesh.positions[i], object_uv(i))))
                .collect(),
        ),
        None => mesh
            .uvs
            .as_ref()
            .filter(|uv| uv.len() == mesh.positions.len())
            .map(|_| (0..mesh.positions.len()).map(object_uv).collect()),
    };
    let flip = shape.reverse_orientation ^ (det < 0.0);
    let indices: Vec<[u32; 3]> = mesh
        .indices
        .iter()
        .filter(|tri| tri.iter().all(|&i| (i as usize) < positions.len()))
        .map(|&[a, b, c]| if flip { [a, c, b] } else { [a, b, c] })
        .collect();
    ply_bytes(&positions, normals.as_deref(), uvs.as_deref(), &indices)
        .map(Some)
        .map_err(|error| ExportError::Ply {
            shape: shape.name.clone(),
            error,
        })
}
