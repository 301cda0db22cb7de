//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

/// The photometric test corpus: `$GONIO_CORPUS` if set, else `<workspace>/../shared/data/photometry`.
/// Prints a clear message and returns `None` when neither exists, so corpus tests skip.
pub fn corpus_dir() -> Option<PathBuf> {
    let candidates: Vec<PathBuf> = std::env::var_os("GONIO_CORPUS")
        .map(PathBuf::from)
        .into_iter()
        .chain(std::iter::once(
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/photometry"),
        ))
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
