//! The error of reading a diagram from its JSON text. Every error from outside input says what is
//! wrong and where.

use crate::diagram::DiagramError;

/// What [`crate::Diagram::from_json_str`] returns: the JSON text could not be read, or the diagram
/// it holds is not valid. (Photometric files have their own error,
/// [`crate::photometry::ParseError`]; building a sampler has [`crate::BuildError`].)
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The diagram is not valid (see [`DiagramError`]).
    #[error(transparent)]
    Diagram(#[from] DiagramError),
    /// The JSON text could not be read (1-based line and column).
    #[error("{line}:{column}: {message}")]
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What serde_json said.
        message: String,
    },
}
