//! File → diagram: IES LM-63 and EULUMDAT readers, symmetry expansion, and writers.

/// A photometric file could not be read: what is wrong, and where (1-based line and column).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{line}:{column}: {message}")]
pub struct ParseError {
    /// 1-based line of the offending token (0 when the problem is the file as a whole).
    pub line: usize,
    /// 1-based column of the offending token (0 when unknown).
    pub column: usize,
    /// What is wrong.
    pub message: String,
}
