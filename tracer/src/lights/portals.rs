//! Portals (`PortalShape`): the openings through which light from a direction (a distant light,
//! the sun, the sky, an environment map) enters an interior, as LuxRender 1.x reads them.
//!
//! ```text
//! AttributeBegin
//!   LightSource "sunsky" "vector sundir" [0.78 0.25 0.57]
//!   PortalShape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point P" [...]
//! AttributeEnd
//! ```
//!
//! A `PortalShape` is read as a `Shape` is (any shape type, under the current transform and
//! `ReverseOrientation`) but is not part of the scene: it belongs to the lights of the last
//! `LightSource` of its attribute block (LuxRender's `currentLight`), and light passes through
//! it along its front normal (the side an area light on it would light): the normal points
//! into the interior. Light subpaths (bidirectional transport) of those lights start behind a
//! point of a portal instead of a disc as wide as the scene, so they enter the room instead of
//! mostly lighting its outside. The path tracer samples these lights as it would without
//! portals.
//!
//! Portals change no image, only its noise: a light subpath's density is exactly the portals'
//! ([`Portals::pdf_reaching`]), zero for light that crosses none, and multiple importance
//! sampling then gives such light wholly to the camera subpath's strategies, which do not
//! depend on portals. A portal that misses a window, or faces the wrong way, costs samples,
//! never light.
//!
//! Bounded: every density evaluation visits every portal triangle, so a scene's portals hold
//! at most [`MAX_PORTAL_TRIANGLES`] (the parser skips, with a warning, a portal beyond it);
//! exact shapes are tessellated in [`PORTAL_SEGMENTS`].

use std::ops::Range;

use glam::{Mat4, Vec2, Vec3};

use super::sample::SceneSphere;
use crate::geometry::TriangleSurface;
use crate::shape::{Geometry, Placement};

/// The most triangles a scene's portals hold: each density of light from a direction visits
/// all of them.
pub const MAX_PORTAL_TRIANGLES: u64 = 1024;
/// The segments an exact shape (sphere, disk, cylinder) used as a portal is tessellated in.
pub const PORTAL_SEGMENTS: u32 = 8;

/// A `PortalShape`: its shape as the statement placed it, and the lights it lets in.
#[derive(Clone, Debug, PartialEq)]
pub struct PortalDesc {
    pub geometry: Geometry,
    pub object_to_world: Mat4,
    pub reverse_orientation: bool,
    /// The lights (indices into [`SceneDesc::lights`](crate::desc::SceneDesc::lights)) of the
    /// `LightSource` statement the portal follows.
    pub lights: Range<u32>,
}

impl PortalDesc {
    /// The portal's world-space triangles, front sides facing where its light goes.
    pub fn triangles(&self) -> Vec<TriangleSurface> {
        crate::geometry::world_triangles(
            &self.geometry,
            &self.object_to_world,
            self.reverse_orientation,
            PORTAL_SEGMENTS,
        )
    }

    /// The triangles [`Self::triangles`] gives, counted before placing them (what the parser
    /// checks against [`MAX_PORTAL_TRIANGLES`]).
    pub fn triangle_count(&self) -> u64 {
        match self.geometry.placement() {
            Placement::Triangles(mesh) => mesh.indices.len() as u64,
            Placement::Exact(_) => self
                .geometry
                .tessellate(PORTAL_SEGMENTS)
                .map_or(0, |m| m.indices.len() as u64),
            Placement::Unbounded(_) => 0,
        }
    }
}

/// The portals of one light (or of the lights at infinity together), world-space triangles.
#[derive(Clone, Debug, Default)]
pub struct Portals {
    triangles: Vec<TriangleSurface>,
}

impl Portals {
    /// None without a triangle.
    pub fn new(triangles: Vec<TriangleSurface>) -> Option<Self> {
        (!triangles.is_empty()).then_some(Self { triangles })
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The portals' area seen along `dir` (the way the light travels), front sides only: the
    /// sum of each triangle's area times the cosine of `dir` to its front normal, where that is
    /// positive.
    fn projected_area(&self, dir: Vec3) -> f32 {
        self.triangles
            .iter()
            .map(|t| t.area() * t.n.dot(dir).max(0.0))
            .sum()
    }

    /// The start of a ray along unit `dir` that crosses a portal at a point sampled by `u`, and
    /// its density per area across `dir`: a triangle is chosen by its projected area, a point
    /// uniformly on it, and the ray starts on the plane one radius of `sphere` behind its centre
    /// (or at the point, when that lies farther back), so it crosses everything between. None
    /// when no portal faces `dir`.
    pub fn sample(&self, dir: Vec3, u: Vec2, sphere: &SceneSphere) -> Option<(Vec3, f32)> {
        let total = self.projected_area(dir);
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut left = u.x * total;
        let mut chosen = None;
        for (i, t) in self.triangles.iter().enumerate() {
            let w = t.area() * t.n.dot(dir).max(0.0);
            if w <= 0.0 {
                continue;
            }
            chosen = Some((i, w));
            if left < w {
                break;
            }
            left -= w;
        }
        let (i, w) = chosen?;
        let ux = (left / w).clamp(0.0, 1.0 - f32::EPSILON);
        let x = self.triangles[i].sample(Vec2::new(ux, u.y)).p;
        let back = ((x - sphere.centre).dot(dir) + sphere.radius).max(0.0);
        // The chosen triangle is crossed by construction (rounding at its edges aside); the
        // others as the density from the other side finds them.
        let others = self
            .triangles
            .iter()
            .enumerate()
            .filter(|&(j, t)| j != i && t.n.dot(dir) > 0.0 && line_crosses(t, x, dir))
            .count();
        Some((x - dir * back, (1 + others) as f32 / total))
    }

    /// The density, per area across unit `dir`, with which [`Self::sample`]'s rays along `dir`
    /// pass `x`: the number of front-facing portal triangles the line through `x` crosses
    /// (anywhere along it: every ray crosses the whole scene) over the projected area.
    pub fn pdf_reaching(&self, dir: Vec3, x: Vec3) -> f32 {
        let crossed = self
            .triangles
            .iter()
            .filter(|t| t.n.dot(dir) > 0.0 && line_crosses(t, x, dir))
            .count();
        if crossed == 0 {
            return 0.0;
        }
        let total = self.projected_area(dir);
        if total > 0.0 {
            crossed as f32 / total
        } else {
            0.0
        }
    }
}

/// Whether the line through `x` along `dir` (both ways) crosses triangle `t`: Moller and
/// Trumbore's barycentric test without the range of the ray parameter.
fn line_crosses(t: &TriangleSurface, x: Vec3, dir: Vec3) -> bool {
    let [p0, p1, p2] = t.vertices;
    let (e1, e2) = (p1 - p0, p2 - p0);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return false;
    }
    let inv = 1.0 / det;
    let s = x - p0;
    let b1 = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return false;
    }
    let b2 = dir.dot(s.cross(e1)) * inv;
    b2 >= 0.0 && b1 + b2 <= 1.0
}

/// What light from a direction enters the scene through: the disc of the scene's sphere, or a
/// light's portals.
#[derive(Clone, Copy, Debug)]
pub enum Entry<'a> {
    Disc(&'a SceneSphere),
    Portals(&'a Portals, &'a SceneSphere),
}

impl Entry<'_> {
    /// A ray start for light travelling along unit `dir` and its density per area across
    /// `dir` ([`SceneSphere::entry_point`], [`Portals::sample`]).
    pub fn sample(self, dir: Vec3, u: Vec2) -> Option<(Vec3, f32)> {
        match self {
            Self::Disc(sphere) => Some((sphere.entry_point(dir, u), sphere.pdf_area())),
            Self::Portals(portals, sphere) => portals.sample(dir, u, sphere),
        }
    }

    /// The density [`Self::sample`] gave a ray along `dir` from `origin`: the disc's
    /// constant, or the portals' density along the ray's line.
    pub fn pdf_start(self, dir: Vec3, origin: Vec3) -> f32 {
        match self {
            Self::Disc(sphere) => sphere.pdf_area(),
            Self::Portals(portals, _) => portals.pdf_reaching(dir, origin),
        }
    }

    /// The density with which [`Self::sample`]'s rays along `dir` pass `x`.
    pub fn pdf_reaching(self, dir: Vec3, x: Vec3) -> f32 {
        match self {
            Self::Disc(sphere) => sphere.pdf_reaching(dir, x),
            Self::Portals(portals, _) => portals.pdf_reaching(dir, x),
        }
    }
}
