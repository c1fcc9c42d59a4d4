//! What the path tracer needs of the scene it traces.

use super::options::IntegratorDesc;
use crate::geometry::{SceneGeometry, SurfaceHit};
use crate::lights::Lights;
use crate::material::Bsdf;
use crate::medium::{ShapeMedia, Volumes};

/// How a shadow ray meets a shape. Paths cross the same shapes the same way (a `null` always,
/// a pane when its lobe choice is the straight transmission), so light sampling and BSDF
/// sampling see the same light behind them and multiple importance sampling weighs them as one
/// strategy pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// It stops there.
    Blocks,
    /// `null`: it goes on unchanged (the geometry's occlusion test looks through it).
    Null,
    /// A pane of architectural glass (LuxRender's `architectural` glass): it goes on without
    /// bending, carrying the pane's straight transmittance
    /// ([`Bsdf::straight_transmittance`]).
    Pane,
}

/// What the path tracer needs from the scene. The renderer's built scene implements it, so the
/// integrator does not depend on how the scene is built.
pub trait PathScene {
    /// The scene's SurfaceIntegrator settings.
    fn integrator(&self) -> &IntegratorDesc;
    /// Bounces per path (the settings' max depth, which the command line may override).
    fn max_depth(&self) -> u32;
    fn geometry(&self) -> &SceneGeometry;
    fn lights(&self) -> &Lights;
    /// The BSDF at a hit; `u_mix` resolves mix materials.
    fn bsdf_at(&self, hit: &SurfaceHit, u_mix: f32) -> Bsdf;
    /// The scene's volumes and the camera's.
    fn volumes(&self) -> &Volumes;
    /// The volumes on the two sides of shape `shape`.
    fn shape_media(&self, shape: u32) -> ShapeMedia;
    /// How a shadow ray crosses shape `shape` (and a path that goes straight on through it).
    fn crossing(&self, shape: u32) -> Crossing;
    /// Whether some shape is a [`Crossing::Pane`]: shadow rays then walk from surface to
    /// surface, as in a scene with volumes.
    fn has_panes(&self) -> bool;
    /// Whether paths split at glossy vertices ([`GLOSSY_SPLIT`](super::glossy_split::GLOSSY_SPLIT)): the integrator allows it, the
    /// scene has lamps and metals, and no volumes or material that lets rays through at some
    /// hits only (a split sample crosses a surface only where [`Self::crossing`] says so).
    fn glossy_split(&self) -> bool;
    /// The continuations a camera path's first broad scattering vertex sends on (see
    /// [`MAX_BRANCHES`](super::branch::MAX_BRANCHES); 1: the path goes on alone).
    fn first_vertex_branches(&self) -> usize;
    /// Whether a path ends at the surface (or volume event) after its first non-specular
    /// vertex, with the light it finds there, as LuxRender's direct lighting does
    /// ([`Transport::DirectLighting`](super::Transport::DirectLighting)): that vertex's light
    /// sample and BSDF sample are all the light it gathers past its specular chain.
    fn direct_lighting(&self) -> bool;
}
