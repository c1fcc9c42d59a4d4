//! What the bidirectional integrator needs of the scene beyond the path tracer's view, its
//! bounds, and the light it hands back besides a sample's radiance. A leaf of `bdpt/`.

use glam::{Vec2, Vec3};

use crate::camera::Camera;
use crate::integrator::scene::PathScene;

/// The most scattering vertices a subpath has, whatever the scene asks: what bounds a
/// sample's memory and work.
pub const MAX_DEPTH: u32 = 64;

/// Vertices of a subpath at most: its start and [`MAX_DEPTH`] scattering vertices.
pub(crate) const MAX_VERTICES: usize = MAX_DEPTH as usize + 1;

/// What the bidirectional integrator needs beyond the path tracer's view of the scene.
pub trait BidirectionalScene: PathScene {
    fn camera(&self) -> &Camera;
    /// Scattering vertices of a light subpath at most.
    fn light_depth(&self) -> u32;
    /// The one strategy (light vertices s, camera vertices t) whose paths count, at full
    /// weight, instead of all strategies weighed by MIS: what tests compare strategies with
    /// (each alone renders the image of its paths). None renders.
    fn only_strategy(&self) -> Option<(usize, usize)> {
        None
    }
}

/// Light a light subpath's vertex sends into the camera: `radiance` at film position
/// `raster`, to be added through the pixel filter as a splat (not as a camera sample).
#[derive(Clone, Copy, Debug)]
pub struct LightSplat {
    pub raster: Vec2,
    pub radiance: Vec3,
    /// None: the splat of the image's light; Some(g): light group `g`'s share of one (a render
    /// that keeps its light groups apart makes both).
    pub group: Option<u8>,
}
