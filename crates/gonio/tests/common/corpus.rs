//! The one corpus-finding helper of the workspace, shared by the library's tests, the CLI's tests,
//! the examples (each includes this file with `#[path = ...] mod corpus;`) and the build scripts
//! of `gonio` and `gonio-cli`.
//!
//! The photometric test corpus is `$GONIO_CORPUS` if set, else `shared/data/photometry` beside the
//! workspace (`<workspace>/shared`, `<workspace>/../shared`, or `<workspace>/../../shared` for a
//! worktree one level deeper), recognised by its `ies/` or `ldt/` folder. The files are never copied into the repo.
//!
//! Tests that need the corpus are marked `#[cfg_attr(not(gonio_corpus), ignore = "…")]`: the build
//! script looks for it with [`find_corpus`] and sets `--cfg gonio_corpus` and `GONIO_CORPUS_DIR`
//! when found, so that without it they show as *ignored* in `cargo test`'s summary line; they read
//! the directory with [`built_corpus_dir`]. Examples look at run time with [`corpus_dir`].
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The places a shared data folder is looked for, in order: the variable `var`, else
/// `shared/data/NAME` beside the workspace (in it, beside it, or one level further up).
fn candidates(var: &str, name: &str) -> Vec<PathBuf> {
    let ws = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let beside = ["", "../", "../../"].map(|up| ws.join(format!("{up}shared/data/{name}")));
    std::env::var_os(var)
        .map(PathBuf::from)
        .into_iter()
        .chain(beside)
        .collect()
}

/// The places the corpus is looked for, in order: `$GONIO_CORPUS`, else
/// `shared/data/photometry` beside the workspace.
pub fn corpus_candidates() -> Vec<PathBuf> {
    candidates("GONIO_CORPUS", "photometry")
}

/// The first of [`corpus_candidates`] that holds an `ies/` or `ldt/` folder.
pub fn find_corpus() -> Option<PathBuf> {
    corpus_candidates()
        .into_iter()
        .find(|c| c.join("ies").is_dir() || c.join("ldt").is_dir())
}

/// The corpus as the build script found it (`GONIO_CORPUS_DIR`), for tests marked
/// `#[cfg_attr(not(gonio_corpus), ignore = "…")]`. When such a test does run, a corpus that has
/// gone missing since the build fails it rather than passing unseen.
pub fn built_corpus_dir() -> PathBuf {
    match option_env!("GONIO_CORPUS_DIR") {
        Some(p) if Path::new(p).is_dir() => PathBuf::from(p),
        other => panic!(
            "the photometric corpus is not available (the build found {other:?}); set \
             GONIO_CORPUS and rebuild"
        ),
    }
}

/// The corpus directory at run time, or `None` (after printing which places were tried, so that
/// an example that skips says so visibly).
pub fn corpus_dir() -> Option<PathBuf> {
    let candidates = corpus_candidates();
    let found = find_corpus();
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

/// The places the shared environment maps are looked for, in order: `$GONIO_ENVMAPS`, else
/// `shared/data/envmaps` beside the workspace (as for the photometric corpus).
pub fn envmap_candidates() -> Vec<PathBuf> {
    candidates("GONIO_ENVMAPS", "envmaps")
}

/// The first of [`envmap_candidates`] that holds a `.hdr` file.
pub fn find_envmaps() -> Option<PathBuf> {
    envmap_candidates().into_iter().find(|c| {
        std::fs::read_dir(c)
            .map(|rd| {
                rd.flatten()
                    .any(|e| e.path().extension().is_some_and(|x| x == "hdr"))
            })
            .unwrap_or(false)
    })
}

/// The environment maps as the build script found them (`GONIO_ENVMAPS_DIR`), for tests marked
/// `#[cfg_attr(not(gonio_envmaps), ignore = "…")]`: every `.hdr` there, sorted.
pub fn built_envmaps() -> Vec<PathBuf> {
    let dir = match option_env!("GONIO_ENVMAPS_DIR") {
        Some(p) if Path::new(p).is_dir() => PathBuf::from(p),
        other => panic!(
            "the shared environment maps are not available (the build found {other:?}); set \
             GONIO_ENVMAPS and rebuild"
        ),
    };
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|rd| rd.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    v.retain(|p| p.extension().is_some_and(|x| x == "hdr"));
    v.sort();
    v
}

/// The environment maps at run time (for examples), or `None` after saying where it looked.
pub fn envmaps_dir() -> Option<PathBuf> {
    let found = find_envmaps();
    if found.is_none() {
        eprintln!(
            "skipping: shared environment maps not found (set GONIO_ENVMAPS; tried {})",
            envmap_candidates()
                .iter()
                .map(|c| c.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    found
}

/// For a build script: tells cargo to rerun when `var` changes, and, when `found` holds a
/// folder, to rerun when it changes and to set `--cfg CFG` and the environment variable `env` to
/// its path for the crate's tests.
pub fn announce(var: &str, cfg: &str, env: &str, found: Option<PathBuf>) {
    println!("cargo:rerun-if-env-changed={var}");
    if let Some(d) = found {
        let d = d.canonicalize().unwrap_or(d);
        println!("cargo:rerun-if-changed={}", d.display());
        println!("cargo:rustc-cfg={cfg}");
        println!("cargo:rustc-env={env}={}", d.display());
    }
}

/// For a test: with `GONIO_REQUIRE_CORPUS=1` (set by `.ci/run`), the crate must have been built
/// with the corpus (`built_with_corpus`: `cfg!(gonio_corpus)` of the calling crate), so that its
/// corpus tests ran instead of being ignored.
pub fn assert_corpus_when_required(built_with_corpus: bool) {
    if std::env::var_os("GONIO_REQUIRE_CORPUS").is_some_and(|v| v == "1") {
        assert!(
            built_with_corpus,
            "GONIO_REQUIRE_CORPUS=1 but the corpus was not found at build time \
             (looked at {:?}); the corpus tests would be ignored",
            corpus_candidates()
        );
    }
}
