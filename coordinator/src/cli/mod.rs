//! The `yat` subcommands: each maps its flags onto the library's plain types and runs.

pub mod worker;
