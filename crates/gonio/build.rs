//! Finds the photometric test corpus at build time so that the corpus tests are marked
//! `#[ignore]` — and say so in the test summary — when it is absent.
//!
//! The places looked at are those of the workspace's one corpus helper (`tests/common/corpus.rs`):
//! `$GONIO_CORPUS` if set, else `shared/data/photometry` beside the workspace. When found, the
//! build sets `--cfg gonio_corpus` and `GONIO_CORPUS_DIR` (its path) for the tests. The script
//! reruns when `GONIO_CORPUS` changes or the directory found changes; a corpus that appears later
//! at a default place needs `GONIO_CORPUS` set (as `.ci/run` does) or `cargo clean -p gonio`.

#[path = "tests/common/corpus.rs"]
mod corpus;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(gonio_corpus)");
    println!("cargo::rustc-check-cfg=cfg(gonio_envmaps)");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=tests/common/corpus.rs");
    let found = corpus::find_envmaps();
    corpus::announce("GONIO_ENVMAPS", "gonio_envmaps", "GONIO_ENVMAPS_DIR", found);
    let found = corpus::find_corpus();
    corpus::announce("GONIO_CORPUS", "gonio_corpus", "GONIO_CORPUS_DIR", found);
}
