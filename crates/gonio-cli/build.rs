//! Finds the photometric test corpus at build time so that the corpus tests are marked
//! `#[ignore]` — and say so in the test summary — when it is absent.
//!
//! The corpus is `$GONIO_CORPUS` if set, else `<workspace>/../shared/data/photometry` (or one
//! level further up, for a worktree under a sub-directory). When found, the build sets
//! `--cfg gonio_corpus` and `GONIO_CORPUS_DIR` (its path) for the tests. The script reruns when
//! `GONIO_CORPUS` changes or the directory found changes; a corpus that appears later at the
//! default place needs `GONIO_CORPUS` set (as `.ci/run` does) or `cargo clean -p gonio-cli`.

use std::path::PathBuf;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(gonio_corpus)");
    println!("cargo:rerun-if-env-changed=GONIO_CORPUS");
    println!("cargo:rerun-if-changed=build.rs");
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let candidates: Vec<PathBuf> = match std::env::var_os("GONIO_CORPUS") {
        Some(p) if !p.is_empty() => vec![PathBuf::from(p)],
        _ => vec![
            manifest.join("../../../shared/data/photometry"),
            manifest.join("../../../../shared/data/photometry"),
        ],
    };
    for c in candidates {
        if c.join("ies").is_dir() || c.join("ldt").is_dir() {
            let c = c.canonicalize().unwrap_or(c);
            println!("cargo:rerun-if-changed={}", c.display());
            println!("cargo:rustc-cfg=gonio_corpus");
            println!("cargo:rustc-env=GONIO_CORPUS_DIR={}", c.display());
            return;
        }
    }
}
