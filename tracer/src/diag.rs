//! Where a scene statement came from, and the warnings the parser gives about what it read.

use std::fmt;

/// A position in the scene files: file name as written, 1-based line and column (0 for the
/// file as a whole).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourcePos {
    pub file: String,
    pub line: u32,
    pub column: u32,
}

impl SourcePos {
    pub fn new(file: &str, line: u32, column: u32) -> Self {
        Self {
            file: file.to_string(),
            line,
            column,
        }
    }
}

impl fmt::Display for SourcePos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

/// How a warning bears on the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Severity {
    /// The statement or parameter is not rendered as LuxRender would render it: an
    /// unsupported feature, an approximation, a fallback where LuxRender does something else.
    Differs,
    /// A difference from LuxRender's image that is documented and accepted (it has a reason
    /// that a fix would not outweigh): listed apart from [`Severity::Differs`], not counted.
    Accepted,
    /// A parameter LuxRender reads that changes nothing in its image (a sampler's, an
    /// accelerator's or a renderer's choice, which files are written, how often): YAT's image
    /// is the same without it.
    NoEffect,
    /// Something about the file that does not change the image compared with LuxRender's: a
    /// parameter LuxRender ignores too, a dangling name both replace by the same default.
    Note,
}

/// Later occurrences of a warning are kept as positions up to this many; beyond, only counted.
pub const MAX_REPEAT_POSITIONS: usize = 32;

/// A warning at its first occurrence, with where it occurs again (a warning of one kind is
/// given once, so a scene repeating it thousands of times prints it once).
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    pub pos: SourcePos,
    pub message: String,
    pub severity: Severity,
    /// Later occurrences, at most [`MAX_REPEAT_POSITIONS`].
    pub also_at: Vec<SourcePos>,
    /// Later occurrences beyond those in `also_at`.
    pub unlisted: u64,
}

impl Warning {
    pub fn new(severity: Severity, pos: SourcePos, message: String) -> Self {
        Self {
            pos,
            message,
            severity,
            also_at: Vec::new(),
            unlisted: 0,
        }
    }

    /// One more occurrence at `pos`.
    pub fn repeat(&mut self, pos: &SourcePos) {
        if self.also_at.len() < MAX_REPEAT_POSITIONS {
            self.also_at.push(pos.clone());
        } else {
            self.unlisted += 1;
        }
    }

    /// How many times the warning occurs.
    pub fn occurrences(&self) -> u64 {
        1 + self.also_at.len() as u64 + self.unlisted
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let label = match self.severity {
            Severity::Differs => "warning",
            Severity::Accepted => "accepted difference",
            Severity::NoEffect => "note",
            Severity::Note => "note",
        };
        write!(f, "{}: {label}: {}", self.pos, self.message)?;
        match self.occurrences() {
            1 => Ok(()),
            n => write!(f, " ({n} times)"),
        }
    }
}
