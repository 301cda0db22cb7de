//! The crate-wide error type. Every error from outside input says what is wrong and where.

use crate::diagram::DiagramError;

/// Anything that can go wrong when turning outside input into a sampler.
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
    /// A photometric file could not be read (see [`crate::photometry::ParseError`]).
    #[error(transparent)]
    Parse(#[from] crate::photometry::ParseError),
}
