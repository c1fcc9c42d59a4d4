//! Inline triangle meshes: `Shape "trianglemesh" "point P" [...] "integer indices" [...]`
//! (also `"mesh"`), with counts and index ranges validated and errors naming the parameter.
//!
//! | parameter | type | default |
//! |---|---|---|
//! | `P` | points | required |
//! | `indices` or `triindices` | integers, 3 per triangle | required unless the mesh has 3 vertices |
//! | `quadindices` | integers, 4 per quad (split into 2 triangles) | none |
//! | `N` | normals, one per vertex | none |
//! | `uv` or `st` | floats, 2 per vertex | none |

use crate::diag::SourcePos;
use crate::mesh::TriangleMesh;
use crate::parse::error::ParseError;
use crate::parse::params::{Param, ParamList};

/// Reads the mesh of an inline mesh shape.
pub fn read_inline(params: &ParamList, pos: &SourcePos) -> Result<TriangleMesh, ParseError> {
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
    p: &Param,
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
