//! `Shape "heightfield"`: heights over the unit square, as pbrt-v1 and LuxRender read them.
//!
//! ```text
//! Shape "heightfield" "integer nu" [3] "integer nv" [2] "float Pz" [0 0.5 0  0 1 0]
//! ```
//!
//! | parameter | default | meaning |
//! |---|---|---|
//! | `nu`, `nv` | required, at least 2 | samples along x and along y |
//! | `Pz` | required, nu x nv values | the height of sample (i, j) is `Pz[i + j nu]` |
//!
//! Sample (i, j) sits at (i / (nu - 1), j / (nv - 1), Pz) in object space with that (u, v);
//! each grid cell is two triangles facing +z (for rising heights, up the slope), without vertex
//! normals (LuxRender gives none: the triangles are shaded flat).

use glam::Vec3;

use crate::diag::SourcePos;
use crate::mesh::TriangleMesh;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// The triangle mesh of a heightfield statement.
pub fn read_heightfield(params: &ParamList, pos: &SourcePos) -> Result<TriangleMesh, ParseError> {
    let missing = |what: &str| ParseError::Invalid {
        pos: pos.clone(),
        message: format!("{}: missing \"{what}\"", params.statement),
    };
    let count = |name: &str| -> Result<u32, ParseError> {
        let Some(p) = params.find(name) else {
            return Err(missing(&format!("integer {name}")));
        };
        let n = params.int(name, 0)?;
        if n < 2 {
            return Err(params.error(p, format!("needs at least 2 samples, got {n}")));
        }
        Ok(n as u32)
    };
    let (nu, nv) = (count("nu")?, count("nv")?);
    let Some((z, p)) = params.floats("Pz")? else {
        return Err(missing("float Pz"));
    };
    // In 64 bits: nu x nv of two 32-bit counts cannot overflow, and the list bounds it.
    let expected = u64::from(nu) * u64::from(nv);
    if z.len() as u64 != expected {
        return Err(params.error(
            p,
            format!(
                "expected nu x nv = {nu} x {nv} = {expected} heights, got {}",
                z.len()
            ),
        ));
    }
    Ok(heightfield_mesh(nu, nv, &z))
}

/// The triangles of `nu` x `nv` heights (`z.len()` = nu x nv, both at least 2).
pub fn heightfield_mesh(nu: u32, nv: u32, z: &[f32]) -> TriangleMesh {
    let mut positions = Vec::with_capacity(z.len());
    let mut uvs = Vec::with_capacity(z.len());
    for j in 0..nv {
        for i in 0..nu {
            let (u, v) = (i as f32 / (nu - 1) as f32, j as f32 / (nv - 1) as f32);
            positions.push(Vec3::new(u, v, z[(i + j * nu) as usize]));
            uvs.push([u, v]);
        }
    }
    let at = |i: u32, j: u32| i + j * nu;
    let mut indices = Vec::with_capacity(2 * (nu as usize - 1) * (nv as usize - 1));
    for j in 0..nv - 1 {
        for i in 0..nu - 1 {
            indices.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            indices.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TriangleMesh {
        positions,
        normals: None,
        uvs: Some(uvs),
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_and_normals(m: &TriangleMesh) -> (f32, Vec<Vec3>) {
        let mut area = 0.0;
        let mut normals = Vec::new();
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let n = (b - a).cross(c - a);
            area += 0.5 * n.length();
            normals.push(n.normalize());
        }
        (area, normals)
    }

    #[test]
    fn a_constant_height_is_a_flat_unit_square_facing_up() {
        let m = heightfield_mesh(5, 4, &[0.75; 20]);
        assert_eq!(m.positions.len(), 20);
        assert_eq!(m.indices.len(), 2 * 4 * 3);
        assert!(m.positions.iter().all(|p| p.z == 0.75));
        let (area, normals) = area_and_normals(&m);
        assert!((area - 1.0).abs() < 1e-6, "area {area}");
        assert!(normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
        let (lo, hi) = m
            .positions
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        assert_eq!(
            (lo, hi),
            (Vec3::new(0.0, 0.0, 0.75), Vec3::new(1.0, 1.0, 0.75))
        );
        assert_eq!(m.uvs.as_ref().unwrap()[19], [1.0, 1.0]);
    }

    #[test]
    fn a_ramp_tilts_every_normal_against_the_slope() {
        // z = 2x: every triangle's normal is (-2, 0, 1) / sqrt(5), its area sqrt(5) x 1.
        let (nu, nv) = (4u32, 3u32);
        let z: Vec<f32> = (0..nv)
            .flat_map(|_| (0..nu).map(move |i| 2.0 * i as f32 / (nu - 1) as f32))
            .collect();
        let m = heightfield_mesh(nu, nv, &z);
        let (area, normals) = area_and_normals(&m);
        let expected = Vec3::new(-2.0, 0.0, 1.0).normalize();
        for n in normals {
            assert!((n - expected).length() < 1e-5, "{n} vs {expected}");
        }
        assert!((area - 5f32.sqrt()).abs() < 1e-5, "area {area}");
    }
}
