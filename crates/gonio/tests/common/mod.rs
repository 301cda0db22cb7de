//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// The photometric test corpus, as the build script found it (`$GONIO_CORPUS`, else
/// `<workspace>/../shared/data/photometry`). Tests that need it carry
/// `#[cfg_attr(not(gonio_corpus), ignore = "…")]`, so without the corpus they show as *ignored* in
/// the test summary; when they do run, a corpus that has gone missing since the build fails them.
pub fn corpus_dir() -> PathBuf {
    match option_env!("GONIO_CORPUS_DIR") {
        Some(p) if PathBuf::from(p).is_dir() => PathBuf::from(p),
        other => panic!(
            "the photometric corpus is not available (build found {other:?}); set GONIO_CORPUS \
             and rebuild"
        ),
    }
}

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
