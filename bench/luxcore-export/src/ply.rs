//! The binary PLY files LuxCore reads the meshes from.

use glam::{Vec2, Vec3};
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
    ScalarType,
};
use ply_rs_bw::writer::Writer;

/// Binary little-endian PLY of a world-space mesh.
pub fn ply_bytes(
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    uvs: Option<&[Vec2]>,
    indices: &[[u32; 3]],
) -> std::io::Result<Vec<u8>> {
    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = Encoding::BinaryLittleEndian;
    let float = || PropertyType::Scalar(ScalarType::Float);
    let mut vertex = ElementDef::new("vertex".into());
    let mut names = vec!["x", "y", "z"];
    if normals.is_some() {
        names.extend(["nx", "ny", "nz"]);
    }
    if uvs.is_some() {
        // LuxCore's PLY reader takes uvs as s and t.
        names.extend(["s", "t"]);
    }
    for n in &names {
        vertex
            .properties
            .add(PropertyDef::new((*n).into(), float()));
    }
    ply.header.elements.add(vertex);
    let mut face = ElementDef::new("face".into());
    face.properties.add(PropertyDef::new(
        "vertex_indices".into(),
        PropertyType::List(ScalarType::UChar, ScalarType::UInt),
    ));
    ply.header.elements.add(face);

    let vertices = (0..positions.len())
        .map(|i| {
            let mut values = positions[i].to_array().to_vec();
            if let Some(n) = normals {
                values.extend(n[i].to_array());
            }
            if let Some(uv) = uvs {
                values.extend(uv[i].to_array());
            }
            let mut e = DefaultElement::new();
            for (name, value) in names.iter().zip(values) {
                e.insert((*name).into(), Property::Float(value));
            }
            e
        })
        .collect();
    let faces = indices
        .iter()
        .map(|tri| {
            let mut e = DefaultElement::new();
            e.insert("vertex_indices".into(), Property::ListUInt(tri.to_vec()));
            e
        })
        .collect();
    ply.payload.insert("vertex".into(), vertices);
    ply.payload.insert("face".into(), faces);
    let mut out = Vec::new();
    Writer::new()
        .write_ply(&mut out, &mut ply)
        .map_err(std::io::Error::other)?;
    Ok(out)
}
