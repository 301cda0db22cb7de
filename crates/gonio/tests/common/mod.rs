//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// The photometric test corpus: `$GONIO_CORPUS` if set, else `<workspace>/../shared/data/photometry`
/// (or `<workspace>/../../shared/…` for a worktree).
/// Prints a clear message and returns `None` when neither exists, so corpus tests skip.
pub fn corpus_dir() -> Option<PathBuf> {
    let candidates: Vec<PathBuf> = std::env::var_os("GONIO_CORPUS")
        .map(PathBuf::from)
        .into_iter()
        .chain(
            // <workspace>/../shared (main checkout) and <workspace>/../../shared (a worktree
            // under wt/).
            [
                "../../../shared/data/photometry",
                "../../../../shared/data/photometry",
            ]
            .iter()
            .map(|rel| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)),
        )
        .collect();
    for c in &candidates {
        if c.join("ies").is_dir() || c.join("ldt").is_dir() {
            return Some(c.clone());
        }
    }
    eprintln!(
        "skipping: corpus not found (set GONIO_CORPUS; tried {})",
        candidates
            .iter()
            .map(|c| c.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    None
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
