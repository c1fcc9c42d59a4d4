//! PLY meshes (ASCII and binary) through the `ply-rs-bw` crate: vertex positions, normals and
//! texture coordinates, faces of 3 or 4 vertices split into triangles.

use glam::Vec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

use crate::mesh::TriangleMesh;

/// One element of any kind: vertex fields, or a face's index list. Elements other than
/// vertices and faces are read and dropped.
#[derive(Default)]
struct Element {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    has_normal: bool,
    has_uv: bool,
    face: Option<Vec<u32>>,
    bad_face: bool,
}

impl PropertyAccess for Element {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if matches!(name, "vertex_indices" | "vertex_index") {
            match property.to_u32_list() {
                Some(v) => self.face = Some(v),
                None => self.bad_face = true,
            }
            return PropertyAccessResult::Set;
        }
        let Some(v) = property.to_f32_lossy() else {
            return PropertyAccessResult::Ignored;
        };
        match name {
            "x" => self.position[0] = v,
            "y" => self.position[1] = v,
            "z" => self.position[2] = v,
            "nx" | "ny" | "nz" => {
                self.has_normal = true;
                self.normal[usize::from(name.as_bytes()[1] - b'x')] = v;
            }
            "u" | "s" | "texture_u" | "texture_s" => {
                self.has_uv = true;
                self.uv[0] = v;
            }
            "v" | "t" | "texture_v" | "texture_t" => {
                self.has_uv = true;
                self.uv[1] = v;
            }
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }
}

/// Reads a PLY file into a mesh; the message says what is wrong with a malformed file.
pub fn read_mesh(bytes: &[u8]) -> Result<TriangleMesh, String> {
    let mut reader = Reader::new(bytes);
    let parser = Parser::<Element>::new();
    let header = parser.read_header(&mut reader).map_err(|e| e.to_string())?;
    let mut mesh = TriangleMesh::default();
    let (mut normals, mut uvs) = (Vec::new(), Vec::new());
    let (mut all_normals, mut all_uvs) = (true, true);
    let mut saw_vertices = false;
    for (name, def) in &header.elements {
        let elements = parser
            .read_payload_for_element(&mut reader, def, &header)
            .map_err(|e| format!("element \"{name}\": {e}"))?;
        match name.as_str() {
            "vertex" => {
                saw_vertices = true;
                mesh.positions.reserve(elements.len());
                for e in &elements {
                    mesh.positions.push(Vec3::from_array(e.position));
                    normals.push(Vec3::from_array(e.normal));
                    uvs.push(e.uv);
                    all_normals &= e.has_normal;
                    all_uvs &= e.has_uv;
                }
            }
            "face" => {
                for (i, e) in elements.iter().enumerate() {
                    match (e.bad_face, e.face.as_deref()) {
                        (false, Some([a, b, c])) => mesh.indices.push([*a, *b, *c]),
                        (false, Some([a, b, c, d])) => {
                            mesh.indices.push([*a, *b, *c]);
                            mesh.indices.push([*a, *c, *d]);
                        }
                        (false, Some(v)) => {
                            return Err(format!(
                                "face {} has {} vertices; only triangles and quads are supported",
                                i + 1,
                                v.len()
                            ))
                        }
                        _ => return Err(format!("face {} has no valid vertex index list", i + 1)),
                    }
                }
            }
            _ => {}
        }
    }
    if !saw_vertices {
        return Err("no \"vertex\" element".into());
    }
    if mesh.indices.is_empty() {
        return Err("no faces".into());
    }
    if all_normals && !normals.is_empty() {
        mesh.normals = Some(normals);
    }
    if all_uvs && !uvs.is_empty() {
        mesh.uvs = Some(uvs);
    }
    Ok(mesh)
}

/// Reads a PLY file into a mesh and checks it ([`validate`]): what a `plymesh` shape uses.
pub fn read_valid_mesh(bytes: &[u8]) -> Result<TriangleMesh, String> {
    let mesh = read_mesh(bytes)?;
    validate(&mesh)?;
    Ok(mesh)
}

/// Checks a mesh read from a file: indices in range, attribute counts, finite values.
pub fn validate(m: &TriangleMesh) -> Result<(), String> {
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

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII_QUAD: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad_becomes_two_triangles() {
        let m = read_mesh(ASCII_QUAD.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals.as_ref().unwrap()[2], Vec3::Z);
        assert_eq!(m.uvs.as_ref().unwrap()[2], [1.0, 1.0]);
    }

    #[test]
    fn binary_little_endian_triangle() {
        let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
        for p in [[0.0f32, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.5]] {
            for c in p {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        bytes.push(3);
        for i in [0u32, 1, 2] {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
        let m = read_mesh(&bytes).unwrap();
        assert_eq!(m.positions[2], Vec3::new(0.0, 3.0, 0.5));
        assert_eq!(m.indices, vec![[0, 1, 2]]);
        assert!(m.normals.is_none() && m.uvs.is_none());
    }

    #[test]
    fn malformed_files_are_errors() {
        assert!(read_mesh(b"").is_err());
        assert!(read_mesh(b"\x00\xff garbage").is_err());
        let truncated = &ASCII_QUAD[..ASCII_QUAD.len() - 12];
        assert!(read_mesh(truncated.as_bytes()).is_err());
        let pentagon = ASCII_QUAD
            .replace("element vertex 4", "element vertex 5")
            .replace("4 0 1 2 3", "0 1 1 0 0 1 0 1\n5 0 1 2 3 4");
        let e = read_mesh(pentagon.as_bytes()).unwrap_err();
        assert!(e.contains("5 vertices"), "{e}");
    }
}
