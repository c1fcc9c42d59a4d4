//! What a path carries from vertex to vertex, and what it returns.

use glam::Vec3;

use super::scene::PathScene;
use crate::geometry::SurfaceHit;
use crate::material::Bsdf;
use crate::math::Ray;
use crate::medium::{MediumId, ShapeMedia};
use crate::wavelength::Wavelength;

/// Null surfaces crossed in a row before a path gives up (guards against stacked coplanar
/// null faces).
pub const MAX_PASS_THROUGH: u32 = 64;

/// Radiance along a camera ray, the number of rays traced for it, and whether it escaped.
#[derive(Clone, Copy, Debug, Default)]
pub struct PathResult {
    pub radiance: Vec3,
    pub rays: u32,
    /// The camera ray escaped (to the environment, or lost among more than
    /// [`MAX_PASS_THROUGH`] null surfaces) before any vertex, having met only surfaces it
    /// crosses straight on: LuxRender's alpha 0 (its path integrator's `vertexIndex == 0` at
    /// the escape).
    pub escaped: bool,
}

/// A path between two vertices: the ray to the next one and what the path carries.
pub(super) struct PathState {
    pub(super) ray: Ray,
    /// What `ray` hits (`Some(None)`: nothing), when the caller has traced it already: a path
    /// leaving a packet at a vertex the packet does not shade is not traced twice.
    pub(super) traced: Option<Option<SurfaceHit>>,
    pub(super) throughput: Vec3,
    /// The light the path has gathered so far (a path traced in lanes up to here goes on one
    /// at a time with its sum, which it adds to in the same order).
    pub(super) radiance: Vec3,
    pub(super) medium: Option<MediumId>,
    pub(super) depth: u32,
    /// Null surfaces crossed since the last vertex.
    pub(super) pass_through: u32,
    /// Whether the path may still split at a glossy vertex (once, at its first that may see a
    /// lamp).
    pub(super) may_split: bool,
    /// The continuations its next broad vertex sends on, while every vertex so far was
    /// specular (1 after that).
    pub(super) branches: usize,
    pub(super) prev: PrevScatter,
    /// The wavelength the path took at its first dispersive vertex (its weight is in the
    /// throughput from there on).
    pub(super) wavelength: Option<Wavelength>,
}

impl PathState {
    pub(super) fn camera<S: PathScene>(scene: &S, ray: Ray, branches: usize) -> Self {
        Self {
            ray,
            traced: None,
            throughput: Vec3::ONE,
            radiance: Vec3::ZERO,
            medium: scene.volumes().camera,
            depth: 0,
            pass_through: 0,
            may_split: scene.glossy_split(),
            branches,
            // The camera ray counts as specular: emitters it sees are taken at full weight.
            prev: PrevScatter::plain(ray.origin, 0.0, true),
            wavelength: None,
        }
    }
}

/// Where the ray that reached the current vertex was sampled, for MIS on emitters it hits.
pub(super) struct PrevScatter {
    pub(super) p: Vec3,
    pub(super) pdf: f32,
    pub(super) specular: bool,
    /// The share of the light samples at `p` that went to lamp images (0 where it sees none):
    /// the lights' own share is what is left.
    pub(super) image_share: f32,
    /// Set when the ray just reflected in a flat mirror straight after a non-specular vertex:
    /// a lamp it reaches is one a lamp-image sample at that vertex could have found.
    pub(super) before_mirror: Option<BeforeMirror>,
    /// Set when `p` split ([`GLOSSY_SPLIT`](super::glossy_split::GLOSSY_SPLIT)): its own BSDF samples took the light of the lamps
    /// it sees directly, so a lamp this ray finds (through null surfaces too) is not counted.
    /// An environment map it escapes to is, as after any vertex.
    pub(super) lamps_counted: bool,
    /// The side `p`'s light sample sampled environment maps for ([`Bsdf::gathers_from`](crate::material::Bsdf::gathers_from)):
    /// the density an escaping ray is weighed by.
    pub(super) facing: Option<Vec3>,
}

impl PrevScatter {
    /// A vertex that sampled no lamp images.
    pub(super) fn plain(p: Vec3, pdf: f32, specular: bool) -> Self {
        Self {
            p,
            pdf,
            specular,
            image_share: 0.0,
            before_mirror: None,
            lamps_counted: false,
            facing: None,
        }
    }
}

/// The non-specular vertex before a flat mirror (one that sampled lamp images, with
/// [`IMAGE_SHARE`](crate::lights::IMAGE_SHARE) of its light samples), and the mirror's plane.
#[derive(Clone, Copy)]
pub(super) struct BeforeMirror {
    pub(super) p: Vec3,
    pub(super) pdf: f32,
    pub(super) plane: u16,
}

/// A camera path's first broad vertex where it branches ([`MAX_BRANCHES`]): what its
/// continuations start from.
///
/// [`MAX_BRANCHES`]: super::branch::MAX_BRANCHES
pub(super) struct BranchPoint {
    pub(super) hit: SurfaceHit,
    pub(super) wo: Vec3,
    pub(super) bsdf: Bsdf,
    /// The side the BSDF gathers light from ([`Bsdf::gathers_from`]).
    pub(super) facing: Option<Vec3>,
    pub(super) sides: ShapeMedia,
    pub(super) image_share: f32,
    pub(super) throughput: Vec3,
    pub(super) depth: u32,
    pub(super) may_split: bool,
    /// The vertex's own roulette number: the first continuation's.
    pub(super) roulette: f32,
    /// The continuations it sends on.
    pub(super) count: usize,
    /// The light and rays of the path up to here: added to the sums after its
    /// continuations', as a packet adds its lanes' (the order of float sums is in the bits).
    pub(super) radiance: Vec3,
    pub(super) rays: u32,
    pub(super) wavelength: Option<Wavelength>,
}
