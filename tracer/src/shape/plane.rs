//! `Shape "plane"`: the course's infinite plane through the object-space origin.
//!
//! | parameter | default |
//! |---|---|
//! | `n` or `N` | 0 0 1, the normal (non-zero) |

use glam::{Mat4, Vec3};

use super::kind::{NotExact, Placement, ShapeKind};
use crate::diag::SourcePos;
use crate::mesh::TriangleMesh;
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// Normal of the course's plane when the file does not say.
pub const DEFAULT_NORMAL: Vec3 = Vec3::Z;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit length.
    pub normal: Vec3,
}

/// `Shape "plane"` with LuxRender's defaults.
pub fn read(
    _ctx: &mut dyn ParseContext,
    _ty: &str,
    params: &ParamList,
    _pos: &SourcePos,
) -> Result<Plane, ParseError> {
    let name = if params.count("n").is_some() {
        "n"
    } else {
        "N"
    };
    let n = params.vec3(name, DEFAULT_NORMAL)?;
    let Some(normal) = n.try_normalize() else {
        let p = params.find(name).expect("a zero normal was given");
        return Err(params.error(p, "the plane normal must be non-zero"));
    };
    Ok(Plane { normal })
}

impl Plane {
    /// A square of side 2 x `half_size` through the object-space origin, front towards the
    /// normal; uvs are the in-plane object coordinates (YAT's plane uv). For consumers that
    /// take only triangles.
    pub fn quad(&self, half_size: f32) -> TriangleMesh {
        let n = self.normal.normalize_or_zero();
        let s = n.any_orthonormal_vector();
        let t = n.cross(s);
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(a, b)| (s * a + t * b) * half_size);
        TriangleMesh {
            positions: corners.to_vec(),
            normals: None,
            uvs: Some(corners.map(|p| [p.dot(s), p.dot(t)]).to_vec()),
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }
}

impl ShapeKind for Plane {
    type Surface = NotExact;

    fn placement(&self) -> Placement<'_, NotExact> {
        Placement::Unbounded(self.normal)
    }

    fn world_area(&self, _object_to_world: &Mat4) -> f32 {
        f32::INFINITY
    }
}
