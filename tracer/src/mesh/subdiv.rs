//! Loop subdivision of triangle meshes, as LuxRender 1.x applies it to `Shape "loopsubdiv"`
//! and to any `"mesh"`, `"trianglemesh"` or `"plymesh"` given subdivision levels:
//!
//! ```text
//! Shape "loopsubdiv" "integer nlevels" [3] "bool dmnormalsmooth" ["true"]
//!     "string displacementmap" ["height"] "float dmscale" [0.2]
//!     "point P" [...] "integer indices" [...] "float uv" [...]
//! ```
//!
//! | parameter | default | meaning |
//! |---|---|---|
//! | `nsubdivlevels`, or `nlevels` | 0 | subdivision levels; each splits every triangle in four |
//! | `subdivscheme` | `"loop"` | `"microdisplacement"` is not modelled (a warning; loop is used) |
//! | `dmnormalsmooth` | true | smooth vertex normals from the limit surface (false: flat triangles) |
//! | `dmsharpboundary` | false | boundary vertices stay where they are instead of following the boundary curve |
//! | `displacementmap` | none | a float texture (by name, `string` or `texture`) moving each vertex along its normal |
//! | `dmscale` | 0.1 | displacement = dmscale x texture + dmoffset, in world units |
//! | `dmoffset` | 0 | |
//! | `dmnormalsplit` | false | not modelled (a warning) |
//!
//! LuxRender's defaults are those of its `Mesh` shape, which `loopsubdiv` is registered as in
//! 1.x: zero levels unless the file says (pbrt-v1's loopsubdiv defaulted to 3).
//!
//! What LuxRender does, and so what this does: the connectivity comes from positions (vertices
//! a file duplicates along a texture seam are one vertex of the surface), each level moves the
//! old vertices by the one-ring rule (Warren's weights: beta = 3/16 at valence 3, else
//! 3/(8n)) and places a new vertex on every edge (3/8, 3/8, 1/8, 1/8; the midpoint on a
//! boundary), boundary vertices follow the cubic B-spline of the boundary (1/8, 3/4, 1/8),
//! and the last level is pushed to the limit surface. Texture coordinates are subdivided over
//! the file's own vertices, so a seam is a boundary for them and stays put. Normals are the
//! limit surface's (the cross product of its two tangents from the one-ring). The optional
//! displacement then moves each vertex along its normal by dmscale times the mean of the
//! texture over the vertex's corners plus dmoffset, and the normals are made again.
//!
//! A mesh whose connectivity is not a manifold (an edge in three triangles, two triangles that
//! wind an edge the same way, two fans meeting at a vertex) is not subdivided: LuxRender aborts
//! its subdivision on inconsistent winding too.

use std::ops::{Add, Mul};
use std::sync::Arc;

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::diag::SourcePos;
use crate::mesh::TriangleMesh;
use crate::parse::context::{BoundTexture, ParseContext};
use crate::parse::error::ParseError;
use crate::parse::params::{ConstOrTextureName, ParamList, ParamType};
use crate::refs::ConstOrTexture;

/// Subdivision levels when the file gives neither `nsubdivlevels` nor `nlevels`.
pub const DEFAULT_LEVELS: i32 = 0;
/// `dmscale` when the file does not say.
pub const DEFAULT_DM_SCALE: f32 = 0.1;
/// `dmoffset` when the file does not say.
pub const DEFAULT_DM_OFFSET: f32 = 0.0;
/// `dmnormalsmooth` when the file does not say.
pub const DEFAULT_NORMAL_SMOOTH: bool = true;
/// `dmsharpboundary` when the file does not say.
pub const DEFAULT_SHARP_BOUNDARY: bool = false;
/// Levels past this are refused before anything is counted: 4^16 triangles per control
/// triangle is already far over any budget, and the count must not overflow.
pub const MAX_LEVELS: u32 = 16;

/// What the file asks of a mesh's subdivision.
#[derive(Clone, Debug, PartialEq)]
pub struct SubdivParams {
    pub levels: u32,
    pub normal_smooth: bool,
    pub sharp_boundary: bool,
    /// The displacement texture's name as written (resolved by the shape reader).
    pub displacement_map: Option<String>,
    pub dm_scale: f32,
    pub dm_offset: f32,
}

/// A parameter LuxRender reads that this does not model, with its position, for a warning.
pub struct Unmodelled {
    pub pos: SourcePos,
    pub message: String,
}

impl SubdivParams {
    /// The subdivision parameters of a mesh shape; `None` when it asks for no levels (the
    /// mesh is used as given, as LuxRender does). Unmodelled options are returned for the
    /// caller to warn about.
    pub fn read(params: &ParamList) -> Result<(Option<Self>, Vec<Unmodelled>), ParseError> {
        let mut unmodelled = Vec::new();
        let levels_name = if params.count("nsubdivlevels").is_some() {
            "nsubdivlevels"
        } else {
            "nlevels"
        };
        let levels = params.int(levels_name, DEFAULT_LEVELS)?;
        let scheme = params.string_or("subdivscheme", "loop")?;
        let normal_smooth = params.bool("dmnormalsmooth", DEFAULT_NORMAL_SMOOTH)?;
        let sharp_boundary = params.bool("dmsharpboundary", DEFAULT_SHARP_BOUNDARY)?;
        let dm_scale = params.float("dmscale", DEFAULT_DM_SCALE)?;
        let dm_offset = params.float("dmoffset", DEFAULT_DM_OFFSET)?;
        let displacement_map = match params.find("displacementmap") {
            None => None,
            Some(p) if p.ty == ParamType::String => params.string("displacementmap")?,
            Some(_) => match params.tex_float("displacementmap", 0.0)? {
                ConstOrTextureName::Named { name, .. } => Some(name),
                ConstOrTextureName::Const(_) => {
                    let p = params.find("displacementmap").expect("found above");
                    return Err(params.error(p, "expected the name of a float texture"));
                }
            },
        };
        if params.bool("dmnormalsplit", false)? {
            let p = params.find("dmnormalsplit").expect("read above");
            unmodelled.push(Unmodelled {
                pos: p.pos.clone(),
                message: format!(
                    "{}: \"bool dmnormalsplit\" is not supported; the normals are smooth across \
                     the given ones",
                    params.statement
                ),
            });
        }
        if scheme != "loop" {
            let p = params.find("subdivscheme").expect("read above");
            unmodelled.push(Unmodelled {
                pos: p.pos.clone(),
                message: format!(
                    "{}: subdivision scheme \"{scheme}\" is not supported; using \"loop\"",
                    params.statement
                ),
            });
        }
        if levels <= 0 {
            return Ok((None, unmodelled));
        }
        let levels = levels as u32;
        if levels > MAX_LEVELS {
            let p = params.find(levels_name).expect("a level count was given");
            return Err(params.error(
                p,
                format!("{levels} subdivision levels: at most {MAX_LEVELS} are allowed"),
            ));
        }
        Ok((
            Some(Self {
                levels,
                normal_smooth,
                sharp_boundary,
                displacement_map,
                dm_scale,
                dm_offset,
            }),
            unmodelled,
        ))
    }
}

/// `mesh` as the shape's parameters ask: subdivided (and displaced) when they give levels,
/// else itself. The subdivided size is checked against the build budget before anything is
/// made; a mesh Loop's rules do not apply to is a warning and stays as it is.
pub fn apply(
    ctx: &mut dyn ParseContext,
    params: &ParamList,
    mesh: Arc<TriangleMesh>,
    pos: &SourcePos,
) -> Result<Arc<TriangleMesh>, ParseError> {
    let (sub, unmodelled) = SubdivParams::read(params)?;
    for u in unmodelled {
        ctx.warn(&u.pos, u.message);
    }
    let Some(sub) = sub else {
        return Ok(mesh);
    };
    let triangles = subdivided_triangle_count(mesh.indices.len(), sub.levels);
    ctx.check_primitives(triangles, pos)?;
    let texture = match &sub.displacement_map {
        Some(name) => match ctx.find_texture(name, false) {
            Some(BoundTexture::Texture(id)) => Some(ConstOrTexture::Texture(id)),
            _ => {
                ctx.warn(
                    pos,
                    format!(
                        "{}: no float texture named \"{name}\"; the mesh is not displaced",
                        params.statement
                    ),
                );
                None
            }
        },
        None => None,
    };
    let object_to_world = ctx.ctm();
    let mut failed = None;
    let mut lookup = |points: &[(Vec3, Vec2)]| -> Vec<f32> {
        let tex = texture.expect("looked up only with a texture");
        ctx.eval_float_texture(tex, points, pos)
            .unwrap_or_else(|e| {
                failed = Some(e);
                Vec::new()
            })
    };
    let displacement = texture.map(|_| Displacement {
        texture: &mut lookup,
        scale: sub.dm_scale,
        offset: sub.dm_offset,
        object_to_world,
    });
    let result = subdivide(
        &mesh,
        sub.levels,
        sub.sharp_boundary,
        sub.normal_smooth,
        displacement,
    );
    if let Some(e) = failed {
        return Err(e);
    }
    match result {
        Ok(m) => Ok(Arc::new(m)),
        Err(e) => {
            ctx.warn(
                pos,
                format!("{}: {e}; the mesh is not subdivided", params.statement),
            );
            Ok(mesh)
        }
    }
}

/// The triangles `levels` levels of subdivision make of `triangles`, saturating.
pub fn subdivided_triangle_count(triangles: usize, levels: u32) -> u64 {
    (triangles as u64).saturating_mul(4u64.saturating_pow(levels))
}

/// Why a mesh cannot be subdivided.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TopologyError {
    #[error("an edge is shared by more than two triangles")]
    NonManifoldEdge,
    #[error("two triangles sharing an edge wind it the same way (inconsistent winding)")]
    InconsistentWinding,
    #[error("a vertex joins triangle fans that share no edge")]
    NonManifoldVertex,
}

/// A float texture's values at (object-space position, uv) points, in order.
pub type TextureLookup<'a> = dyn FnMut(&[(Vec3, Vec2)]) -> Vec<f32> + 'a;

/// The displacement of [`subdivide`]: a float texture's values at points, and its scale.
pub struct Displacement<'a> {
    pub texture: &'a mut TextureLookup<'a>,
    pub scale: f32,
    pub offset: f32,
    /// Displacements are world lengths along the world normal, as LuxRender's meshes live in
    /// world space.
    pub object_to_world: Mat4,
}

/// `mesh` subdivided `levels` times and pushed to the limit surface, with limit normals
/// when `normals`, then displaced. Errors (with the mesh unusable for subdivision) leave the
/// choice to the caller: LuxRender renders the control mesh.
pub fn subdivide(
    mesh: &TriangleMesh,
    levels: u32,
    sharp_boundary: bool,
    normals: bool,
    displacement: Option<Displacement>,
) -> Result<TriangleMesh, TopologyError> {
    let rule = Rule::Smooth { sharp_boundary };
    // Positions: connectivity from positions, degenerate triangles left out.
    let (weld, welded_positions) = weld_positions(&mesh.positions);
    let kept: Vec<[u32; 3]> = mesh
        .indices
        .iter()
        .copied()
        .filter(|t| {
            let w = t.map(|i| weld[i as usize]);
            w[0] != w[1] && w[1] != w[2] && w[2] != w[0]
        })
        .collect();
    let welded_faces: Vec<[u32; 3]> = kept.iter().map(|t| t.map(|i| weld[i as usize])).collect();
    let (mut faces, mut positions) = compact(&welded_faces, &welded_positions);
    check_manifold(&faces, positions.len())?;
    for _ in 0..levels {
        (faces, positions) = refine(&faces, &positions, rule)?;
    }
    positions = limit(&faces, &positions, rule)?;

    // Texture coordinates over the file's own vertices (a seam is a boundary for them).
    let uv_channel = match &mesh.uvs {
        Some(uvs) => {
            let uvs: Vec<Vec2> = uvs.iter().map(|&[u, v]| Vec2::new(u, v)).collect();
            let (mut uv_faces, mut uv_values) = compact(&kept, &uvs);
            let uv_rule = match check_manifold(&uv_faces, uv_values.len()) {
                Ok(()) => rule,
                Err(_) => Rule::Linear,
            };
            for _ in 0..levels {
                (uv_faces, uv_values) = refine(&uv_faces, &uv_values, uv_rule)?;
            }
            let uv_values = limit(&uv_faces, &uv_values, uv_rule)?;
            Some((uv_faces, uv_values))
        }
        None => None,
    };

    let rings = Rings::new(&faces, positions.len())?;
    let needs_normals = normals || displacement.is_some();
    let mut vertex_normals = if needs_normals {
        rings.normals(&faces, &positions)
    } else {
        Vec::new()
    };
    if let Some(d) = displacement {
        displace(
            &faces,
            &mut positions,
            &vertex_normals,
            uv_channel.as_ref(),
            d,
        );
        if normals {
            vertex_normals = rings.normals(&faces, &positions);
        }
    }

    Ok(match uv_channel {
        // The output's vertices are the texture channel's: each has one position.
        Some((uv_faces, uv_values)) => {
            let mut position_of = vec![0u32; uv_values.len()];
            for (tp, tu) in faces.iter().zip(&uv_faces) {
                for k in 0..3 {
                    position_of[tu[k] as usize] = tp[k];
                }
            }
            TriangleMesh {
                positions: position_of.iter().map(|&p| positions[p as usize]).collect(),
                normals: normals.then(|| {
                    position_of
                        .iter()
                        .map(|&p| vertex_normals[p as usize])
                        .collect()
                }),
                uvs: Some(uv_values.iter().map(|uv| [uv.x, uv.y]).collect()),
                indices: uv_faces,
            }
        }
        None => TriangleMesh {
            positions,
            normals: normals.then_some(vertex_normals),
            uvs: None,
            indices: faces,
        },
    })
}

/// Moves every vertex along its normal by scale x (mean of the texture over its corners) +
/// offset, a world length.
fn displace(
    faces: &[[u32; 3]],
    positions: &mut [Vec3],
    normals: &[Vec3],
    uv_channel: Option<&(Vec<[u32; 3]>, Vec<Vec2>)>,
    d: Displacement,
) {
    // One lookup per distinct (position, uv) corner; LuxRender looks up once per face corner
    // with the same arguments.
    let (corner_point, points): (Vec<[u32; 3]>, Vec<(Vec3, Vec2)>) = match uv_channel {
        Some((uv_faces, uvs)) => {
            let mut points = vec![(Vec3::ZERO, Vec2::ZERO); uvs.len()];
            for (tp, tu) in faces.iter().zip(uv_faces) {
                for k in 0..3 {
                    points[tu[k] as usize] = (positions[tp[k] as usize], uvs[tu[k] as usize]);
                }
            }
            (uv_faces.clone(), points)
        }
        None => (
            faces.to_vec(),
            positions.iter().map(|&p| (p, Vec2::ZERO)).collect(),
        ),
    };
    let values = (d.texture)(&points);
    let mut sum = vec![0.0f32; positions.len()];
    let mut count = vec![0u32; positions.len()];
    for (tp, tc) in faces.iter().zip(&corner_point) {
        for k in 0..3 {
            sum[tp[k] as usize] += values.get(tc[k] as usize).copied().unwrap_or(0.0);
            count[tp[k] as usize] += 1;
        }
    }
    let linear = Mat3::from_mat4(d.object_to_world);
    let inverse = linear.inverse();
    let normal_matrix = inverse.transpose();
    for (i, p) in positions.iter_mut().enumerate() {
        if count[i] == 0 {
            continue;
        }
        let length = d.scale * sum[i] / count[i] as f32 + d.offset;
        let world_normal = (normal_matrix * normals[i]).normalize_or_zero();
        let step = inverse * (world_normal * length);
        if step.is_finite() {
            *p += step;
        }
    }
}

/// Values that subdivision averages: positions, texture coordinates.
trait Attr: Copy + Add<Output = Self> + Mul<f32, Output = Self> {
    const ZERO: Self;
}
impl Attr for Vec3 {
    const ZERO: Self = Vec3::ZERO;
}
impl Attr for Vec2 {
    const ZERO: Self = Vec2::ZERO;
}

/// How vertices move.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Rule {
    /// Loop's rules; with `sharp_boundary` boundary vertices stay put.
    Smooth { sharp_boundary: bool },
    /// New vertices at edge midpoints, old ones unmoved (texture coordinates of a mesh whose
    /// own vertices are not a manifold).
    Linear,
}

/// One vertex per distinct position (exact comparison, -0 = +0): the index of each vertex's
/// representative and the representatives' positions.
fn weld_positions(positions: &[Vec3]) -> (Vec<u32>, Vec<Vec3>) {
    let mut first = std::collections::HashMap::with_capacity(positions.len());
    let mut welded = Vec::new();
    let map = positions
        .iter()
        .map(|&p| {
            let key = (p + Vec3::ZERO).to_array().map(f32::to_bits);
            *first.entry(key).or_insert_with(|| {
                welded.push(p);
                welded.len() as u32 - 1
            })
        })
        .collect();
    (map, welded)
}

/// The vertices the faces use, renumbered in order of first use.
fn compact<T: Attr>(faces: &[[u32; 3]], values: &[T]) -> (Vec<[u32; 3]>, Vec<T>) {
    let mut new_index = vec![u32::MAX; values.len()];
    let mut out = Vec::new();
    let faces = faces
        .iter()
        .map(|t| {
            t.map(|i| {
                let slot = &mut new_index[i as usize];
                if *slot == u32::MAX {
                    out.push(values[i as usize]);
                    *slot = out.len() as u32 - 1;
                }
                *slot
            })
        })
        .collect();
    (faces, out)
}

const NO_TWIN: u32 = u32::MAX;

/// The edge structure of a triangle list: for each directed edge (slot 3f + k, from corner k
/// of face f to corner k + 1) the opposite slot of the neighbouring face, or [`NO_TWIN`] on a
/// boundary; and for each slot the undirected edge it belongs to.
struct Edges {
    twin: Vec<u32>,
    edge_of_slot: Vec<u32>,
    edge_count: u32,
}

impl Edges {
    /// `strict`: an edge in more than two faces, or wound the same way by both, is an error;
    /// otherwise every slot with the same two vertices shares one edge.
    fn new(faces: &[[u32; 3]], strict: bool) -> Result<Self, TopologyError> {
        let slots = faces.len() * 3;
        let mut keyed: Vec<(u64, u32)> = (0..slots)
            .map(|s| {
                let t = faces[s / 3];
                let (a, b) = (t[s % 3], t[(s + 1) % 3]);
                ((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), s as u32)
            })
            .collect();
        keyed.sort_unstable();
        let mut twin = vec![NO_TWIN; slots];
        // Each slot's edge is first named by the lowest slot along it, so the numbering (and
        // so a level's new vertices) follows the faces' order, not the sort's.
        let mut lowest_slot = vec![0u32; slots];
        for run in keyed.chunk_by(|x, y| x.0 == y.0) {
            if strict {
                if run.len() > 2 {
                    return Err(TopologyError::NonManifoldEdge);
                }
                if let [(_, s0), (_, s1)] = *run {
                    let from = |s: u32| faces[s as usize / 3][s as usize % 3];
                    if from(s0) == from(s1) {
                        return Err(TopologyError::InconsistentWinding);
                    }
                    twin[s0 as usize] = s1;
                    twin[s1 as usize] = s0;
                }
            }
            let lowest = run
                .iter()
                .map(|&(_, s)| s)
                .min()
                .expect("a run is not empty");
            for &(_, s) in run {
                lowest_slot[s as usize] = lowest;
            }
        }
        let mut edge_of_slot = vec![u32::MAX; slots];
        let mut edge_count = 0u32;
        for s in 0..slots {
            let lowest = lowest_slot[s] as usize;
            if edge_of_slot[lowest] == u32::MAX {
                edge_of_slot[lowest] = edge_count;
                edge_count += 1;
            }
            edge_of_slot[s] = edge_of_slot[lowest];
        }
        Ok(Self {
            twin,
            edge_of_slot,
            edge_count,
        })
    }
}

/// Every vertex's corners in order around it (a manifold is assumed; checked by
/// [`check_manifold`]): the one-ring LuxRender walks.
struct Rings {
    /// Corners (3f + k) of each vertex, ordered around it; a boundary vertex's start at the
    /// fan's end whose outgoing edge is a boundary.
    corners: Vec<u32>,
    start: Vec<u32>,
    boundary: Vec<bool>,
}

impl Rings {
    fn new(faces: &[[u32; 3]], vertex_count: usize) -> Result<Self, TopologyError> {
        let edges = Edges::new(faces, true)?;
        let mut count = vec![0u32; vertex_count + 1];
        for t in faces {
            for &v in t {
                count[v as usize + 1] += 1;
            }
        }
        for i in 0..vertex_count {
            count[i + 1] += count[i];
        }
        let start = count;
        let mut fill = start.clone();
        let mut unordered = vec![0u32; faces.len() * 3];
        for (f, t) in faces.iter().enumerate() {
            for (k, &v) in t.iter().enumerate() {
                unordered[fill[v as usize] as usize] = (3 * f + k) as u32;
                fill[v as usize] += 1;
            }
        }
        let mut corners = vec![0u32; faces.len() * 3];
        let mut boundary = vec![false; vertex_count];
        let prev = |c: u32| 3 * (c / 3) + (c % 3 + 2) % 3;
        for v in 0..vertex_count {
            let mine = &unordered[start[v] as usize..start[v + 1] as usize];
            if mine.is_empty() {
                continue;
            }
            // A fan's first corner: one whose outgoing edge is a boundary, else any.
            let first = mine
                .iter()
                .copied()
                .find(|&c| edges.twin[c as usize] == NO_TWIN);
            boundary[v] = first.is_some();
            let mut c = first.unwrap_or(mine[0]);
            let out = &mut corners[start[v] as usize..start[v + 1] as usize];
            let mut n = 0;
            loop {
                if n == out.len() {
                    return Err(TopologyError::NonManifoldVertex);
                }
                out[n] = c;
                n += 1;
                // Across the incoming edge to the next face around the vertex.
                let across = edges.twin[prev(c) as usize];
                if across == NO_TWIN || across == out[0] {
                    break;
                }
                c = across;
            }
            let closed = edges.twin[prev(c) as usize] != NO_TWIN;
            if n != out.len() || closed == boundary[v] {
                return Err(TopologyError::NonManifoldVertex);
            }
        }
        Ok(Self {
            corners,
            start,
            boundary,
        })
    }

    /// The neighbours of vertex `v` in order (a boundary vertex: from one boundary neighbour
    /// to the other).
    fn ring(&self, faces: &[[u32; 3]], v: usize, out: &mut Vec<u32>) {
        out.clear();
        let corner = |c: u32, step: usize| faces[c as usize / 3][(c as usize % 3 + step) % 3];
        let mine = &self.corners[self.start[v] as usize..self.start[v + 1] as usize];
        for &c in mine {
            out.push(corner(c, 1));
        }
        if self.boundary[v] {
            if let Some(&last) = mine.last() {
                out.push(corner(last, 2));
            }
        }
    }

    /// Unit normals from the tangents of the limit surface at each vertex (LuxRender's
    /// formulas), facing the side the triangles' winding makes the front.
    fn normals(&self, faces: &[[u32; 3]], positions: &[Vec3]) -> Vec<Vec3> {
        let mut facing = vec![Vec3::ZERO; positions.len()];
        for t in faces {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                facing[i as usize] += n;
            }
        }
        let mut ring = Vec::new();
        (0..positions.len())
            .map(|v| {
                self.ring(faces, v, &mut ring);
                let n = ring.len();
                if n < 2 {
                    return facing[v].normalize_or_zero();
                }
                let p = |i: usize| positions[ring[i] as usize];
                let centre = positions[v];
                let (s, t) = if !self.boundary[v] {
                    let mut s = Vec3::ZERO;
                    let mut t = Vec3::ZERO;
                    for k in 0..n {
                        let angle = std::f32::consts::TAU * k as f32 / n as f32;
                        s += libm::cosf(angle) * p(k);
                        t += libm::sinf(angle) * p(k);
                    }
                    (s, t)
                } else {
                    let s = p(n - 1) - p(0);
                    let t = match n {
                        2 => p(0) + p(1) - 2.0 * centre,
                        3 => p(1) - centre,
                        4 => -p(0) + 2.0 * p(1) + 2.0 * p(2) - p(3) - 2.0 * centre,
                        _ => {
                            let theta = std::f32::consts::PI / (n - 1) as f32;
                            let mut t = libm::sinf(theta) * (p(0) + p(n - 1));
                            for k in 1..n - 1 {
                                t += (2.0 * libm::cosf(theta) - 2.0)
                                    * libm::sinf(k as f32 * theta)
                                    * p(k);
                            }
                            -t
                        }
                    };
                    (s, t)
                };
                let normal = t.cross(s).normalize_or_zero();
                if normal == Vec3::ZERO {
                    facing[v].normalize_or_zero()
                } else if normal.dot(facing[v]) < 0.0 {
                    -normal
                } else {
                    normal
                }
            })
            .collect()
    }
}

/// Whether the faces form a manifold (with or without boundary) that Loop's rules apply to.
fn check_manifold(faces: &[[u32; 3]], vertex_count: usize) -> Result<(), TopologyError> {
    Rings::new(faces, vertex_count).map(|_| ())
}

/// Loop's even-vertex weight for valence `n` (Warren's).
fn beta(n: usize) -> f32 {
    if n == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * n as f32)
    }
}

/// Per vertex: the sum of its neighbours, their number, and its two boundary neighbours
/// when it is on a boundary.
struct Neighbours<T> {
    sum: Vec<T>,
    valence: Vec<u32>,
    boundary: Vec<Option<[u32; 2]>>,
}

impl<T: Attr> Neighbours<T> {
    fn new(faces: &[[u32; 3]], values: &[T], edges: &Edges) -> Self {
        let n = values.len();
        let mut sum = vec![T::ZERO; n];
        let mut valence = vec![0u32; n];
        let mut boundary: Vec<Option<[u32; 2]>> = vec![None; n];
        let mut add_boundary = |v: u32, other: u32| {
            let b = &mut boundary[v as usize];
            *b = Some(match *b {
                None => [other, u32::MAX],
                Some([first, _]) => [first, other],
            });
        };
        for (s, &twin) in edges.twin.iter().enumerate() {
            let t = faces[s / 3];
            let (a, b) = (t[s % 3], t[(s + 1) % 3]);
            sum[a as usize] = sum[a as usize] + values[b as usize];
            valence[a as usize] += 1;
            if twin == NO_TWIN {
                sum[b as usize] = sum[b as usize] + values[a as usize];
                valence[b as usize] += 1;
                add_boundary(a, b);
                add_boundary(b, a);
            }
        }
        Self {
            sum,
            valence,
            boundary,
        }
    }

    /// Vertex `v` moved by the even-vertex rule (`limit`: pushed to the limit surface).
    fn moved(&self, values: &[T], v: usize, rule: Rule, limit: bool) -> T {
        let x = values[v];
        match (rule, self.boundary[v]) {
            (Rule::Linear, _)
            | (
                Rule::Smooth {
                    sharp_boundary: true,
                },
                Some(_),
            ) => x,
            (Rule::Smooth { .. }, Some([a, b])) => {
                let w = if limit { 1.0 / 5.0 } else { 1.0 / 8.0 };
                x * (1.0 - 2.0 * w) + (values[a as usize] + values[b as usize]) * w
            }
            (Rule::Smooth { .. }, None) => {
                let n = self.valence[v] as usize;
                if n == 0 {
                    return x;
                }
                let b = beta(n);
                let w = if limit {
                    1.0 / (n as f32 + 3.0 / (8.0 * b))
                } else {
                    b
                };
                x * (1.0 - n as f32 * w) + self.sum[v] * w
            }
        }
    }
}

/// One level: every triangle split in four (corner children first, in corner order, then the
/// middle one), new vertices numbered after the old in order of their edge's first slot.
fn refine<T: Attr>(
    faces: &[[u32; 3]],
    values: &[T],
    rule: Rule,
) -> Result<(Vec<[u32; 3]>, Vec<T>), TopologyError> {
    let edges = Edges::new(faces, rule != Rule::Linear)?;
    let neighbours = Neighbours::new(faces, values, &edges);
    let old = values.len() as u32;
    let mut out: Vec<T> = (0..values.len())
        .map(|v| neighbours.moved(values, v, rule, false))
        .collect();
    out.resize(values.len() + edges.edge_count as usize, T::ZERO);
    for (s, &twin) in edges.twin.iter().enumerate() {
        let t = faces[s / 3];
        let (a, b, c) = (t[s % 3], t[(s + 1) % 3], t[(s + 2) % 3]);
        let mid = (values[a as usize] + values[b as usize]) * 0.5;
        let value = match rule {
            Rule::Smooth { .. } if twin != NO_TWIN => {
                let t2 = faces[twin as usize / 3];
                let d = t2[(twin as usize + 2) % 3];
                (values[a as usize] + values[b as usize]) * (3.0 / 8.0)
                    + (values[c as usize] + values[d as usize]) * (1.0 / 8.0)
            }
            _ => mid,
        };
        out[(old + edges.edge_of_slot[s]) as usize] = value;
    }
    let mut children = Vec::with_capacity(faces.len() * 4);
    for (f, t) in faces.iter().enumerate() {
        let e = |k: usize| old + edges.edge_of_slot[3 * f + k];
        let (e0, e1, e2) = (e(0), e(1), e(2));
        children.push([t[0], e0, e2]);
        children.push([e0, t[1], e1]);
        children.push([e2, e1, t[2]]);
        children.push([e0, e1, e2]);
    }
    Ok((children, out))
}

/// Every vertex pushed to the limit surface.
fn limit<T: Attr>(faces: &[[u32; 3]], values: &[T], rule: Rule) -> Result<Vec<T>, TopologyError> {
    let edges = Edges::new(faces, rule != Rule::Linear)?;
    let neighbours = Neighbours::new(faces, values, &edges);
    Ok((0..values.len())
        .map(|v| neighbours.moved(values, v, rule, true))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 12 vertices (0, +-1, +-phi) and cyclic permutations; the 20 faces are the triples
    /// at mutual distance 2, wound outwards.
    fn icosahedron() -> TriangleMesh {
        let phi = (1.0 + 5f32.sqrt()) / 2.0;
        let mut positions = Vec::new();
        for a in [-1.0, 1.0] {
            for b in [-phi, phi] {
                positions.push(Vec3::new(0.0, a, b));
                positions.push(Vec3::new(a, b, 0.0));
                positions.push(Vec3::new(b, 0.0, a));
            }
        }
        let edge = |i: usize, j: usize| ((positions[i] - positions[j]).length() - 2.0).abs() < 1e-4;
        let mut indices = Vec::new();
        for i in 0..12 {
            for j in i + 1..12 {
                for k in j + 1..12 {
                    if edge(i, j) && edge(j, k) && edge(i, k) {
                        let [a, b, c] = [i, j, k].map(|x| positions[x]);
                        let t = [i as u32, j as u32, k as u32];
                        indices.push(if (b - a).cross(c - a).dot(a) > 0.0 {
                            t
                        } else {
                            [t[0], t[2], t[1]]
                        });
                    }
                }
            }
        }
        TriangleMesh {
            positions,
            indices,
            ..Default::default()
        }
    }

    /// The cube [-1, 1]^3: `seams` gives each face its own 4 vertices and uvs (24 vertices,
    /// as exporters write it), else 8 shared vertices.
    fn cube(seams: bool) -> TriangleMesh {
        let mut m = TriangleMesh::default();
        let mut uvs = Vec::new();
        let corner = |c: Vec3, m: &mut TriangleMesh| -> u32 {
            match m.positions.iter().position(|&p| p == c) {
                Some(i) if !seams => i as u32,
                _ => {
                    m.positions.push(c);
                    m.positions.len() as u32 - 1
                }
            }
        };
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let n = Vec3::AXES[axis] * sign;
                let (s, t) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
                let quad = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .map(|(a, b)| (n + s * a + t * b, [(a + 1.0) / 2.0, (b + 1.0) / 2.0]));
                let ids = quad.map(|(p, uv)| {
                    let i = corner(p, &mut m);
                    if uvs.len() <= i as usize {
                        uvs.push(uv);
                    }
                    i
                });
                for tri in [[ids[0], ids[1], ids[2]], [ids[0], ids[2], ids[3]]] {
                    let [a, b, c] = tri.map(|i| m.positions[i as usize]);
                    let outward = (b - a).cross(c - a).dot(n) > 0.0;
                    m.indices.push(if outward {
                        tri
                    } else {
                        [tri[0], tri[2], tri[1]]
                    });
                }
            }
        }
        if seams {
            m.uvs = Some(uvs);
        }
        m
    }

    /// A flat hexagon fan of radius 1 around a centre at height `lift`, with uv = (x, y).
    fn hexagon(lift: f32) -> TriangleMesh {
        let mut positions = vec![Vec3::new(0.0, 0.0, lift)];
        for k in 0..6 {
            let a = std::f32::consts::TAU * k as f32 / 6.0;
            positions.push(Vec3::new(libm::cosf(a), libm::sinf(a), 0.0));
        }
        let indices = (0..6u32).map(|k| [0, 1 + k, 1 + (k + 1) % 6]).collect();
        let uvs = positions.iter().map(|p| [p.x, p.y]).collect();
        TriangleMesh {
            positions,
            indices,
            uvs: Some(uvs),
            normals: None,
        }
    }

    fn plain(m: &TriangleMesh, levels: u32) -> TriangleMesh {
        subdivide(m, levels, false, true, None).unwrap()
    }

    fn area_volume(m: &TriangleMesh) -> (f64, f64) {
        m.indices.iter().fold((0.0, 0.0), |(area, volume), t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
            (
                area + 0.5 * (b - a).cross(c - a).length(),
                volume + a.dot(b.cross(c)) / 6.0,
            )
        })
    }

    fn radius_spread(m: &TriangleMesh) -> f32 {
        let r: Vec<f32> = m.positions.iter().map(|p| p.length()).collect();
        let (lo, hi) = r
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        (hi - lo) / (r.iter().sum::<f32>() / r.len() as f32)
    }

    #[test]
    fn a_closed_mesh_has_four_times_the_faces_per_level() {
        let ico = icosahedron();
        assert_eq!((ico.positions.len(), ico.indices.len()), (12, 20));
        for levels in 1..=4 {
            let m = plain(&ico, levels);
            let faces = 20 * 4usize.pow(levels);
            assert_eq!(m.indices.len(), faces);
            // Euler: V - E + F = 2 with E = 3F/2.
            assert_eq!(m.positions.len(), 2 + faces / 2);
            assert_eq!(
                subdivided_triangle_count(ico.indices.len(), levels),
                faces as u64
            );
        }
    }

    /// 36 pi V^2 / A^3: 1 for a sphere, less for any other shape.
    fn roundness(m: &TriangleMesh) -> f64 {
        let (a, v) = area_volume(m);
        36.0 * std::f64::consts::PI * v * v / (a * a * a)
    }

    #[test]
    fn a_subdivided_icosahedron_becomes_round() {
        let ico = icosahedron();
        let q: Vec<f64> = (0..=4).map(|l| roundness(&plain(&ico, l))).collect();
        // The icosahedron itself: 0.829.
        assert!((q[0] - 0.8288).abs() < 1e-3, "{q:?}");
        for w in q.windows(2) {
            assert!(w[1] > w[0], "roundness must grow with levels: {q:?}");
        }
        assert!(q[4] > 0.995, "{q:?}");
        // The vertices lie on the limit surface, whose radius varies by under 3.5%.
        let spreads: Vec<f32> = (1..=4).map(|l| radius_spread(&plain(&ico, l))).collect();
        assert!(spreads.iter().all(|&s| s < 0.035), "{spreads:?}");
        // Outward smooth normals, close to the radial direction.
        let m = plain(&ico, 3);
        let normals = m.normals.as_ref().unwrap();
        for (p, n) in m.positions.iter().zip(normals) {
            assert!(n.dot(p.normalize()) > 0.99, "{p} {n}");
        }
    }

    #[test]
    fn a_subdivided_cube_converges_to_its_limit_surface() {
        let cube = cube(false);
        let figures: Vec<(f64, f64)> = (1..=6).map(|l| area_volume(&plain(&cube, l))).collect();
        let (area, volume) = figures[5];
        // The limit lies well inside the control cube (volume 8, area 24): Loop's rules shrink
        // a coarse cube to a blob of volume 3.150 and area 10.52 (this code's figures at
        // level 6, pinned so a change of rule shows).
        assert!((volume - 3.150).abs() < 0.005, "{volume}");
        assert!((area - 10.52).abs() < 0.01, "{area}");
        // Level 4 is within 0.5% of level 6 in area and volume; level 1 is further off.
        let (a4, v4) = figures[3];
        assert!((a4 / area - 1.0).abs() < 0.005, "area {a4} vs {area}");
        assert!((v4 / volume - 1.0).abs() < 0.005, "volume {v4} vs {volume}");
        let (a1, _) = figures[0];
        assert!((a1 / area - 1.0).abs() > (a4 / area - 1.0).abs());
        // Every vertex stays inside the control hull.
        assert!(plain(&cube, 3)
            .positions
            .iter()
            .all(|p| p.abs().max_element() <= 1.0 + 1e-6));
    }

    #[test]
    fn seams_do_not_open_the_surface_and_uvs_stay_linear_per_face() {
        let welded = plain(&cube(false), 2);
        let seamed = plain(&cube(true), 2);
        assert_eq!(seamed.indices.len(), welded.indices.len());
        // The same surface: every position of the seamed result is one of the welded result.
        for p in &seamed.positions {
            assert!(
                welded.positions.iter().any(|q| (*p - *q).length() < 1e-5),
                "{p} is not on the welded surface"
            );
        }
        let (a, v) = area_volume(&welded);
        let (a2, v2) = area_volume(&seamed);
        assert!((a - a2).abs() < 1e-4 && (v - v2).abs() < 1e-4);
        // Each face's uvs stay in its own [0, 1]^2.
        let uvs = seamed.uvs.as_ref().unwrap();
        assert_eq!(uvs.len(), seamed.positions.len());
        assert!(uvs
            .iter()
            .all(|uv| (0.0..=1.0).contains(&uv[0]) && (0.0..=1.0).contains(&uv[1])));
    }

    /// The positions of the vertices on edges that only one triangle has.
    fn boundary_of(m: &TriangleMesh) -> Vec<Vec3> {
        let mut count = std::collections::HashMap::new();
        for t in &m.indices {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut on: Vec<u32> = count
            .into_iter()
            .filter(|&(_, n)| n == 1)
            .flat_map(|((a, b), _)| [a, b])
            .collect();
        on.sort_unstable();
        on.dedup();
        on.into_iter().map(|i| m.positions[i as usize]).collect()
    }

    #[test]
    fn boundary_vertices_follow_the_boundary_curve() {
        let flat = subdivide(&hexagon(0.0), 3, false, true, None).unwrap();
        let lifted = subdivide(&hexagon(0.7), 3, false, true, None).unwrap();
        let boundary = boundary_of(&flat);
        // 6 edges, 8 segments each after 3 levels.
        assert_eq!(boundary.len(), 48);
        // The boundary curve depends only on the boundary: lifting the centre moves none of
        // those vertices, and they stay in the plane of the boundary.
        for p in &boundary {
            assert!(
                lifted.positions.iter().any(|q| (*p - *q).length() < 1e-6),
                "{p} moved when the interior did"
            );
            // Inside the hexagon, outside the circle of radius 0.8.
            assert!(p.truncate().length() <= 1.0 && p.truncate().length() > 0.8);
        }
        // A flat mesh with uv = (x, y) keeps uv = (x, y): Loop reproduces linear functions.
        let uvs = flat.uvs.as_ref().unwrap();
        for (p, uv) in flat.positions.iter().zip(uvs) {
            assert!((p.x - uv[0]).abs() < 1e-5 && (p.y - uv[1]).abs() < 1e-5);
        }
        // With a sharp boundary the old corners stay and the new boundary vertices lie on the
        // hexagon's edges.
        let sharp = subdivide(&hexagon(0.0), 3, true, true, None).unwrap();
        let corners = &hexagon(0.0).positions[1..];
        for c in corners {
            assert!(sharp.positions.iter().any(|q| (*c - *q).length() < 1e-6));
        }
        let inradius = libm::cosf(std::f32::consts::PI / 6.0);
        let on_edge = |p: &Vec3| {
            (0..6).any(|k| {
                let angle = std::f32::consts::TAU * (k as f32 + 0.5) / 6.0;
                let n = Vec3::new(libm::cosf(angle), libm::sinf(angle), 0.0);
                (p.dot(n) - inradius).abs() < 1e-5
            })
        };
        let sharp_boundary = boundary_of(&sharp);
        assert_eq!(sharp_boundary.len(), 48);
        assert!(sharp_boundary.iter().all(on_edge));
    }

    #[test]
    fn displacement_moves_vertices_by_scale_times_texture_plus_offset_along_the_normal() {
        let ico = icosahedron();
        let base = plain(&ico, 2);
        let normals = base.normals.clone().unwrap();
        for (m, expected_world) in [
            (Mat4::IDENTITY, 1.0f32),
            (Mat4::from_scale(Vec3::splat(2.0)), 0.5),
        ] {
            // A texture worth 1 + z: the displacement is 0.3 (1 + z) - 0.1 world units.
            let mut texture = |points: &[(Vec3, Vec2)]| -> Vec<f32> {
                points.iter().map(|(p, _)| 1.0 + p.z).collect()
            };
            let d = Displacement {
                texture: &mut texture,
                scale: 0.3,
                offset: -0.1,
                object_to_world: m,
            };
            let moved = subdivide(&ico, 2, false, true, Some(d)).unwrap();
            assert_eq!(moved.positions.len(), base.positions.len());
            for ((p, q), n) in base.positions.iter().zip(&moved.positions).zip(&normals) {
                let length = (0.3 * (1.0 + p.z) - 0.1) * expected_world;
                assert!(
                    (*q - (*p + *n * length)).length() < 1e-5,
                    "{p} moved to {q}, expected {}",
                    *p + *n * length
                );
            }
        }
    }

    #[test]
    fn meshes_that_are_not_manifolds_are_refused() {
        let mut flipped = icosahedron();
        flipped.indices[0] = [
            flipped.indices[0][0],
            flipped.indices[0][2],
            flipped.indices[0][1],
        ];
        assert_eq!(
            subdivide(&flipped, 1, false, true, None).unwrap_err(),
            TopologyError::InconsistentWinding
        );
        let fin = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Y],
            indices: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
            ..Default::default()
        };
        assert_eq!(
            subdivide(&fin, 1, false, true, None).unwrap_err(),
            TopologyError::NonManifoldEdge
        );
        // Two fans meeting at one vertex.
        let bowtie = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::X, -Vec3::Y],
            indices: vec![[0, 1, 2], [0, 3, 4]],
            ..Default::default()
        };
        assert_eq!(
            subdivide(&bowtie, 1, false, true, None).unwrap_err(),
            TopologyError::NonManifoldVertex
        );
    }
}
