//! A mutation fuzzer on stable Rust for what YAT reads from outside: scene files (the parser,
//! the PLY reader, image decoding and the build step, [`parser_target`]) and messages from the
//! network (the protobuf messages of `render.proto` and the checks and conversions each end
//! runs on them, [`wire_target`]).
//!
//! No coverage instrumentation (that needs nightly): inputs grow from seeds by byte, token and
//! protobuf-field mutations ([`mutate`]), and an input is kept when it makes the code say
//! something new (an error or warning never seen). [`campaign`] runs the loop, catches panics,
//! minimizes and saves each distinct one.

pub mod campaign;
pub mod mutate;
#[cfg(test)]
mod parser_regressions;
pub mod parser_target;
pub mod stand_ins;
pub mod wire_target;

#[path = "../../tests/fixtures/workspace.rs"]
pub mod workspace;
