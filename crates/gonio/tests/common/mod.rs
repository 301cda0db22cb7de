//! Helpers shared by the integration tests.
#![allow(dead_code)]

#[path = "corpus.rs"]
mod corpus;
/// The corpus as the build found it (see `corpus.rs`): tests that call it are marked
/// `#[cfg_attr(not(gonio_corpus), ignore = "…")]`.
#[allow(unused_imports)]
pub use corpus::{built_corpus_dir as corpus_dir, corpus_files};

/// The azimuths (C angles, degrees) at which a stored plane at `c` appears after the symmetry
/// expansion: itself and its mirror images (for a rotationally symmetric file, a few arbitrary
/// azimuths, all equal to the single plane).
pub fn images(sym: gonio::photometry::Symmetry, c: f64) -> Vec<f64> {
    use gonio::photometry::Symmetry;
    match sym {
        Symmetry::Quadrant => vec![c, 180.0 - c, 180.0 + c, 360.0 - c],
        Symmetry::BilateralC0C180 => vec![c, 360.0 - c],
        Symmetry::BilateralC90C270 => vec![c, 180.0 - c],
        Symmetry::Rotational => vec![c, 37.0, 123.4, 301.0],
        _ => vec![c],
    }
}
