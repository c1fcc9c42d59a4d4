//! Every shape YAT renders as triangles: `trianglemesh`, `mesh` and `loopsubdiv`
//! ([`crate::mesh::inline`]; subdivision and displacement: [`crate::mesh::subdiv`]),
//! `plymesh` (`filename`, required: the file is read once and shared; `smooth`, ignored;
//! subdivision as above), `heightfield` ([`crate::mesh::heightfield`]), and `cone`,
//! `paraboloid` and `hyperboloid`, tessellated ([`crate::mesh::quadric`]). The mesh is shared
//! between instances of the same object.

use std::sync::Arc;

use glam::Mat4;

use super::kind::{NotExact, Placement, ShapeKind};
use crate::diag::SourcePos;
use crate::mesh::quadric::Quadric;
use crate::mesh::{heightfield, inline, subdiv, TriangleMesh};
use crate::parse::context::ParseContext;
use crate::parse::error::ParseError;
use crate::parse::params::ParamList;

/// An object-space triangle mesh, shared between instances.
pub type Mesh = Arc<TriangleMesh>;

/// `trianglemesh`, `mesh`, `loopsubdiv`: the mesh in the statement, subdivided if it asks.
pub fn read_inline(
    ctx: &mut dyn ParseContext,
    _ty: &str,
    params: &ParamList,
    pos: &SourcePos,
) -> Result<Mesh, ParseError> {
    let mesh = Arc::new(inline::read_inline(params, pos)?);
    subdiv::apply(ctx, params, mesh, pos)
}

/// `plymesh`: the mesh of `filename`, subdivided if the statement asks.
pub fn read_ply(
    ctx: &mut dyn ParseContext,
    _ty: &str,
    params: &ParamList,
    pos: &SourcePos,
) -> Result<Mesh, ParseError> {
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
    subdiv::apply(ctx, params, mesh, pos)
}

/// `heightfield`: the grid of heights as triangles.
pub fn read_heightfield(
    _ctx: &mut dyn ParseContext,
    _ty: &str,
    params: &ParamList,
    pos: &SourcePos,
) -> Result<Mesh, ParseError> {
    Ok(Arc::new(heightfield::read_heightfield(params, pos)?))
}

/// `cone`, `paraboloid`, `hyperboloid`: the quadric tessellated.
pub fn read_quadric(
    _ctx: &mut dyn ParseContext,
    ty: &str,
    params: &ParamList,
    _pos: &SourcePos,
) -> Result<Mesh, ParseError> {
    let quadric = Quadric::read(ty, params)?.expect("a quadric's name");
    Ok(Arc::new(quadric.tessellate()))
}

impl ShapeKind for Mesh {
    type Surface = NotExact;

    fn placement(&self) -> Placement<'_, NotExact> {
        Placement::Triangles(self)
    }

    fn world_area(&self, m: &Mat4) -> f32 {
        self.indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.transform_point3(self.positions[i as usize]));
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }
}
