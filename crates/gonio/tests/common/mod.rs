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
