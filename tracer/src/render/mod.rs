//! The render API every node uses: settings, the unit plan, the built scene and rendering one
//! unit into a sample buffer.
//!
//! Files: [`settings`] (resolved settings and command-line overrides), [`unit`](mod@unit) (a
//! work unit and its counters: the leaf the film, the plan and the nodes share), [`plan`]
//! (cutting an image into units), [`adaptive`] (the rounds of an adaptive render and the
//! decision between them), [`convergence`] (rounds until the image stops changing, LuxRender's
//! `haltthreshold`) with [`perceptual_diff`] (Yee's metric it tests with), [`sampling`] (which
//! of those a render is, and where its rounds are), [`branching`] (how many continuations
//! camera paths take at their first broad vertex), [`layers`] (what units carry besides
//! radiance: alpha), [`scene`] (the built scene and rendering one unit).

pub mod adaptive;
pub mod branching;
pub mod convergence;
pub mod layers;
pub mod outliers;
pub mod perceptual_diff;
pub mod plan;
pub mod sampling;
pub mod scene;
pub mod settings;
pub mod unit;

pub use plan::{plan_units, PASSES, PLAN_VERSION, TILE_SIZE};
pub use scene::{BuildError, RenderScene};
pub use settings::{RenderOverrides, RenderSettings, SettingsError, DEFAULT_SPP};
pub use unit::{UnitStats, WorkUnit};
