//! YAT's renderer as a library. It knows nothing of the network: the worker and coordinator
//! crates drive it through [`render`].
//!
//! Data flow: `.lxs` text -> [`parse`] (the statements; each concept reads its own parameters:
//! [`camera`], [`film`], [`filter`], [`sampler`], [`integrator::options`], [`shape`], ...) ->
//! [`desc::SceneDesc`] (plain data, defaults applied) -> [`render::RenderScene::build`]
//! (world-space geometry and BVH, decoded textures, light sampling tables) ->
//! [`render::RenderScene::render_unit`] (per sample: [`sampler`], [`filter`], [`camera`], then
//! [`integrator::trace_path`]) -> [`film::SampleBuffer`]s merged into a [`film::Film`].
//!
//! Parse and build are bounded by a [`budget::BuildBudget`] and can be abandoned through a
//! cancel flag ([`budget::BuildGuard`]).
//!
//! Leaves the layers above share: [`render::unit`] (work units, which the film's buffers are
//! keyed by), [`render::settings`], [`geometry::SurfaceHit`]; the path tracer sees the built
//! scene only through [`integrator::PathScene`].

// Lets test fixtures shared with the integration tests (tests/fixtures) name this crate
// `yat_tracer` from inside it too.
#[cfg(test)]
extern crate self as yat_tracer;

pub mod assets;
pub mod budget;
pub mod bxdf;
pub mod camera;
pub mod desc;
pub mod diag;
pub mod film;
pub mod filter;
pub mod geometry;
pub mod image_io;
pub mod integrator;
pub mod lanes;
pub mod lights;
pub mod material;
pub mod math;
pub mod medium;
pub mod mesh;
pub mod parse;
pub mod private_file;
pub mod refs;
pub mod render;
pub mod sampler;
pub mod shape;
pub mod spectra;
pub mod texture;
pub mod vec3_lanes;
pub mod wavelength;

/// This build of the renderer: a hash of its sources and of the workspace's manifest and locked
/// dependencies (tracer/build.rs). Builds with the same name render the same bits on any CPU
/// (docs/architecture.md, "Determinism rules"); a coordinator refuses workers of another.
pub const RENDERER_BUILD: &str = env!("YAT_RENDERER_BUILD");
