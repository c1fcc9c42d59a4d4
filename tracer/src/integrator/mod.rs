//! The surface integrator: its settings as the scene file gives them ([`options`]) and the path
//! tracer that uses them, which [`packet`] runs for several samples of a pixel at once, to the
//! same bits. The settings are a leaf (the scene description holds them); the path tracer sees
//! the scene through the [`PathScene`] interface ([`scene`]).
//!
//! The path tracer, a file a concept: [`path`] is the loop from vertex to vertex, [`state`]
//! what a path carries between them, [`vertex`] what it does at a surface (shared with the
//! packets' lanes shaded one at a time), [`direct`] and [`shadow`] its light sample and shadow
//! rays, [`light_draw`] the light sample's numbers and the BSDF samples it is weighed against,
//! [`mis`] and [`roulette`] the weights both loops use (written over lanes), [`media`] the
//! segments through volumes, [`glossy_split`], [`mirror_images`] and [`branch`] the vertices
//! that take more than one sample.

pub mod bdpt;
mod branch;
mod direct;
mod glossy_split;
mod groups;
mod light_draw;
mod media;
mod mirror_images;
mod mis;
pub mod options;
pub mod packet;
mod path;
mod roulette;
mod scene;
mod shadow;
mod state;
mod vertex;

use crate::math::Ray;
use crate::sampler::PixelSampler;

pub use branch::MAX_BRANCHES;
pub use glossy_split::GLOSSY_SPLIT;
pub use groups::{GroupRadiance, GroupSink};
pub use options::{IntegratorDesc, RussianRoulette, Transport};
pub use scene::{Crossing, PathScene};
pub use state::{PathResult, MAX_PASS_THROUGH};

/// Radiance along the camera ray `ray`, drawn from `sampler`.
// Inlined into the unit loop: a call away, it costs measurable speed (bench/RESULTS.md, "The
// integrator's inlining").
#[inline(always)]
pub fn trace_path<S: PathScene>(scene: &S, ray: Ray, sampler: &mut PixelSampler) -> PathResult {
    trace_branching_path(scene, ray, sampler, scene.first_vertex_branches())
}

/// [`trace_path`] with `branches` continuations at the first broad vertex (clamped to 1 ..=
/// [`MAX_BRANCHES`]) whatever the scene's own number: what `render::branching` measures with.
#[inline(always)]
pub fn trace_branching_path<S: PathScene>(
    scene: &S,
    ray: Ray,
    sampler: &mut PixelSampler,
    branches: usize,
) -> PathResult {
    let mut out = PathResult::default();
    let state = state::PathState::camera(scene, ray, branches.clamp(1, MAX_BRANCHES));
    branch::walk_to_the_end(scene, state, sampler, (&mut out, &mut ()));
    out
}

/// [`trace_path`] with the light of each light group apart too, for a scene whose film keeps
/// a layer per group: the path neither branches nor splits (the scene's
/// [`PathScene::first_vertex_branches`] and [`PathScene::glossy_split`] say so for such a
/// render), so every light term it adds comes from one light, or from the lights at infinity.
pub fn trace_path_by_group<S: PathScene>(
    scene: &S,
    ray: Ray,
    sampler: &mut PixelSampler,
) -> (PathResult, GroupRadiance) {
    let mut out = PathResult::default();
    let mut groups = GroupRadiance::default();
    let mut state = state::PathState::camera(scene, ray, 1);
    state.may_split = false;
    branch::walk_to_the_end(scene, state, sampler, (&mut out, &mut groups));
    (out, groups)
}
