//! The parser's error: what is wrong and where, file:line:column first.

use crate::assets::AssetError;
use crate::budget::{Cancelled, OverBudget};
use crate::diag::SourcePos;

#[derive(Debug, thiserror::Error)]
pub enum ParseError {
    /// The text is not a well-formed statement sequence.
    #[error("{pos}: syntax error: {message}")]
    Syntax { pos: SourcePos, message: String },
    /// A parameter has the wrong type, count or value.
    #[error("{pos}: {statement}: parameter \"{param}\": {message}")]
    Parameter {
        pos: SourcePos,
        statement: String,
        param: String,
        message: String,
    },
    /// Well-formed but unusable input: bad mesh data, include cycles, a missing required value.
    #[error("{pos}: {message}")]
    Invalid { pos: SourcePos, message: String },
    /// A referenced file (Include, PLY, image) cannot be read.
    #[error("{pos}: {error}")]
    Asset { pos: SourcePos, error: AssetError },
    /// A referenced image exists but its header does not decode.
    #[error("{pos}: image \"{path}\" does not decode: {message}")]
    Image {
        pos: SourcePos,
        path: String,
        message: String,
    },
    /// The statement at `pos` took the scene over its build budget.
    #[error("{pos}: {exceeded}")]
    OverBudget {
        pos: SourcePos,
        exceeded: OverBudget,
    },
    /// The parse was abandoned through its cancel flag (at the statement at `pos`).
    #[error("{pos}: {}", Cancelled)]
    Cancelled { pos: SourcePos },
    /// A PLY file is malformed.
    #[error("{pos}: PLY file \"{path}\": {message}")]
    Ply {
        pos: SourcePos,
        path: String,
        message: String,
    },
}

impl ParseError {
    /// Where in the scene files the problem is.
    pub fn pos(&self) -> &SourcePos {
        match self {
            ParseError::Syntax { pos, .. }
            | ParseError::Parameter { pos, .. }
            | ParseError::Invalid { pos, .. }
            | ParseError::Asset { pos, .. }
            | ParseError::Image { pos, .. }
            | ParseError::OverBudget { pos, .. }
            | ParseError::Cancelled { pos, .. }
            | ParseError::Ply { pos, .. } => pos,
        }
    }
}
