//! The surface integrator: its settings as the scene file gives them ([`options`]) and the path
//! tracer that uses them ([`path`]), which [`packet`] runs for several samples of a pixel at
//! once, to the same bits. The settings are a leaf (the scene description holds them); the path
//! tracer sees the scene through the [`PathScene`] interface it defines.

pub mod options;
pub mod packet;
pub mod path;

pub use options::{IntegratorDesc, RussianRoulette};
pub use path::{trace_path, PathResult, PathScene, GLOSSY_SPLIT};
