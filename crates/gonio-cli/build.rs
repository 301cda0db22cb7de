//! Finds the photometric test corpus at build time so that the corpus tests are marked
//! `#[ignore]` — and say so in the test summary — when it is absent.
//!
//! The places looked at are those of the workspace's one corpus helper (`../gonio/tests/common/corpus.rs`):
//! `$GONIO_CORPUS` if set, else `shared/data/photometry` beside the workspace. When found, the
//! build sets `--cfg gonio_corpus` and `GONIO_CORPUS_DIR` (its path) for the tests. The script
//! reruns when `GONIO_CORPUS` changes or the directory found changes; a corpus that appears later
//! at a default place needs `GONIO_CORPUS` set (as `.ci/run` does) or `cargo clean -p gonio-cli`.

// `corpus_helper.rs` links to the workspace helper, so that the packaged crate carries it.
#[path = "corpus_helper.rs"]
mod corpus;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(gonio_corpus)");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=../gonio/tests/common/corpus.rs");
    let found = corpus::find_corpus();
    corpus::announce("GONIO_CORPUS", "gonio_corpus", "GONIO_CORPUS_DIR", found);
}
