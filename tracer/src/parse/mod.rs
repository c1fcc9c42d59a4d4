//! The LuxRender 1.x scene parser: `.lxs` text -> statements with positions -> [`SceneDesc`]
//! with LuxRender's defaults applied.
//!
//! Module map: `lexer` (bytes -> tokens), `reader` (tokens -> statement arguments and
//! parameter lists), `params` (typed parameter access), `builder` (the graphics state
//! machine: transforms, attribute blocks, includes, objects), and one module per kind of thing
//! described: `options` (the camera, film, filter, integrator and sampler statements, read by
//! their concepts). Materials, textures, lights and shapes read themselves ([`crate::material`],
//! [`crate::texture`], [`crate::lights`], [`crate::shape`], meshes by [`crate::mesh`]); metal
//! presets and blackbody colours are in [`crate::spectra`].
//!
//! Choices where LuxRender leaves room (each is pinned by a test):
//! - An empty file, or one without `Camera`/`WorldBegin`, loads with LuxRender's defaults and a
//!   warning; it renders an empty (black) scene.
//! - `AttributeEnd`/`TransformEnd` without a matching begin is a warning and is ignored (pbrt's
//!   and LuxRender's behaviour); blocks still open at the end of the file are a warning.
//! - References to undefined names (`NamedMaterial`, textures, `ObjectInstance`) are warnings,
//!   as in LuxRender; the statement falls back to the default.
//! - `Camera "environment"` and `"realistic"` give a warning and render as perspective.
//! - Statements after `WorldEnd` are ignored with one warning.

mod builder;
pub(crate) mod context;
pub(crate) mod error;
mod lexer;
pub(crate) mod luxrender_params;
mod options;
pub(crate) mod params;
mod reader;

use crate::assets::AssetSource;
use crate::budget::{BuildGuard, Limit};
use crate::desc::SceneDesc;
use crate::diag::SourcePos;

pub use builder::MAX_INCLUDE_DEPTH;
pub use error::ParseError;

pub use crate::spectra::{blackbody_rgb, metal_preset};

/// Parses the main scene file `main` (its name as given to `source`) and every file it
/// includes, and builds the scene description, under the default build budget. Warnings go
/// into `SceneDesc::warnings`.
pub fn parse_scene(main: &str, source: &dyn AssetSource) -> Result<SceneDesc, ParseError> {
    parse_scene_guarded(main, source, BuildGuard::default())
}

/// [`parse_scene`] under `guard`: its budget is checked as the scene is read, its cancel flag
/// at every statement.
pub fn parse_scene_guarded(
    main: &str,
    source: &dyn AssetSource,
    guard: BuildGuard,
) -> Result<SceneDesc, ParseError> {
    let bytes = source.read(main).map_err(|error| ParseError::Asset {
        pos: SourcePos::new(main, 0, 0),
        error,
    })?;
    let mut b = builder::Builder::new(source, guard);
    let start = SourcePos::new(main, 0, 0);
    b.spend(Limit::ParsedBytes, bytes.len() as u64, &start)?;
    // Held while it is parsed, and on a worker until its build ends.
    b.spend(Limit::MemoryBytes, bytes.len() as u64, &start)?;
    b.run_file(main, &bytes)?;
    b.finish()
}
