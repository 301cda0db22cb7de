//! The one corpus-finding helper of the workspace, shared by the library's tests, the CLI's tests
//! and the examples (each includes this file with `#[path = ...] mod corpus;`).
//!
//! The photometric test corpus is `$GONIO_CORPUS` if set, else `shared/data/photometry` beside the
//! workspace (`<workspace>/shared`, `<workspace>/../shared`, or `<workspace>/../../shared` for a
//! worktree one level deeper), recognised by its `ies/` or `ldt/` folder. The files are never copied into the repo.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The places the corpus is looked for, in order.
pub fn corpus_candidates() -> Vec<PathBuf> {
    let ws = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::env::var_os("GONIO_CORPUS")
        .map(PathBuf::from)
        .into_iter()
        .chain(
            [
                "shared/data/photometry",
                "../shared/data/photometry",
                "../../shared/data/photometry",
            ]
            .iter()
            .map(|rel| ws.join(rel)),
        )
        .collect()
}

/// The corpus directory, or `None` (after printing which places were tried, so that a test or
/// example that skips says so visibly).
pub fn corpus_dir() -> Option<PathBuf> {
    let candidates = corpus_candidates();
    let found = candidates
        .iter()
        .find(|c| c.join("ies").is_dir() || c.join("ldt").is_dir())
        .cloned();
    if found.is_none() {
        eprintln!(
            "skipping: photometric corpus not found (set GONIO_CORPUS; tried {})",
            candidates
                .iter()
                .map(|c| c.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    found
}

/// Every valid photometric file of the corpus (`ies/*.ies`, `ldt/*.ldt` in any letter case,
/// without the deliberately broken `invalid_*` files), sorted.
pub fn corpus_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for sub in ["ies", "ldt"] {
        if let Ok(rd) = std::fs::read_dir(dir.join(sub)) {
            for e in rd.flatten() {
                let p = e.path();
                let name = p
                    .file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .to_string();
                let ext = p
                    .extension()
                    .map(|e| e.to_string_lossy().to_ascii_lowercase());
                if !name.starts_with("invalid_") && matches!(ext.as_deref(), Some("ies" | "ldt")) {
                    files.push(p);
                }
            }
        }
    }
    files.sort();
    files
}
