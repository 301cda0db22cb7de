//! Helpers shared by the integration tests.
#![allow(dead_code)]

#[path = "corpus.rs"]
mod corpus;
/// The corpus as the build found it (see `corpus.rs`): tests that call it are marked
/// `#[cfg_attr(not(gonio_corpus), ignore = "…")]`.
#[allow(unused_imports)]
pub use corpus::{assert_corpus_when_required, built_corpus_dir as corpus_dir, corpus_files};

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

/// The hemisphere diagrams every batch test runs (`synthetic::random_hemisphere`'s arguments:
/// family, parallels, meridians, irregular meridians, seed): uniform and irregular meridians,
/// zero-heavy values, one meridian.
pub const MAP_CASES: [(gonio::synthetic::Family, usize, usize, bool, u64); 5] = {
    use gonio::synthetic::Family;
    [
        (Family::Lobes, 19, 36, false, 1),
        (Family::Lobes, 181, 361, false, 2),
        (Family::Spiky, 13, 17, true, 3),
        (Family::ZeroHeavy, 9, 12, true, 4),
        (Family::Rotational, 30, 1, false, 5),
    ]
};
