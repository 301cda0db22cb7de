//! No two modules of a crate of the workspace import each other (issue 24: "the four circles").
//!
//! Reads the sources of every crate under `crates/` (each `src/**.rs` file is a module), collects
//! the module paths each file names through `crate::…` and `super::…` (in `use` lines and inline
//! paths, brace groups included; comment lines are skipped), and fails on every pair of modules
//! that name each other. A module and its ancestors are not a circle: a parent declares and
//! re-exports its children, and children use what their parent defines (the module tree itself).
//! Paths that end at the crate root (`crate::InputError`) are such ancestor edges too.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module path inside one crate: `[]` is the root, `["mapping", "batch"]` is `mapping::batch`.
type Module = Vec<String>;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("a source folder is readable") {
        let p = e.expect("a folder entry").path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The module of a source file: `src/lib.rs` → root, `src/a/mod.rs` and `src/a.rs` → `a`.
fn module_of(src: &Path, file: &Path) -> Module {
    let rel = file.strip_prefix(src).expect("under src");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|s| s.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file name");
    let stem = last.trim_end_matches(".rs").to_string();
    if !(stem == "mod" || (parts.is_empty() && (stem == "lib" || stem == "main"))) {
        parts.push(stem);
    }
    parts
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The `::`-separated identifiers at the start of `s`, and the rest after them (which starts
/// with `{` for a brace group).
fn segments(s: &str) -> (Vec<String>, &str) {
    let mut segs = Vec::new();
    let mut rest = s;
    loop {
        let n = rest.find(|c: char| !is_ident(c)).unwrap_or(rest.len());
        if n == 0 {
            break;
        }
        segs.push(rest[..n].to_string());
        rest = &rest[n..];
        match rest.strip_prefix("::") {
            Some(r) if r.starts_with(|c: char| is_ident(c) || c == '{') => rest = r,
            _ => break,
        }
    }
    (segs, rest)
}

/// The first path of every top-level entry of the brace group at the start of `s` (`{a, b::c,
/// d::{e, f}}` → `a`, `b::c`, `d`).
fn group_entries(s: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut depth = 0;
    let mut start = 1;
    for (i, c) in s.char_indices() {
        match c {
            '{' => depth += 1,
            '}' | ',' if depth == 1 => {
                let (segs, _) = segments(s[start..i].trim_start());
                if !segs.is_empty() {
                    out.push(segs);
                }
                start = i + 1;
                if c == '}' {
                    break;
                }
            }
            '}' => depth -= 1,
            _ => {}
        }
    }
    out
}

/// The paths (relative to the crate root) that `code` names from module `m`.
fn named_paths(m: &Module, code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for (kw, is_super) in [("crate::", false), ("super::", true)] {
        let mut from = 0;
        while let Some(i) = code[from..].find(kw) {
            let at = from + i;
            from = at + kw.len();
            // Not the tail of a longer identifier (`$crate::`, `my_super::`).
            if code[..at].ends_with(|c: char| is_ident(c) || c == '$') || code[..at].ends_with("::")
            {
                continue;
            }
            let mut base: Vec<String> = Vec::new();
            let mut rest = &code[from..];
            if is_super {
                base = m.clone();
                base.pop();
                while let Some(r) = rest.strip_prefix("super::") {
                    base.pop();
                    rest = r;
                }
            }
            let (segs, after) = segments(rest);
            let mut prefix = base.clone();
            prefix.extend(segs);
            if after.starts_with('{') {
                for e in group_entries(after) {
                    let mut p = prefix.clone();
                    p.extend(e);
                    out.push(p);
                }
            } else {
                out.push(prefix);
            }
        }
    }
    out
}

/// The longest prefix of `path` that is a module of the crate.
fn resolve(modules: &BTreeSet<Module>, path: &[String]) -> Module {
    (0..=path.len())
        .rev()
        .map(|n| path[..n].to_vec())
        .find(|p| modules.contains(p))
        .unwrap_or_default()
}

/// Every module's imports of other modules (ancestors and descendants left out), per crate.
fn edges() -> BTreeMap<String, BTreeMap<Module, BTreeSet<Module>>> {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut all = BTreeMap::new();
    for e in std::fs::read_dir(&crates).expect("crates/ is readable") {
        let src = e.expect("an entry").path().join("src");
        if !src.is_dir() {
            continue;
        }
        let name = src
            .parent()
            .and_then(|p| p.file_name())
            .map(|s| s.to_string_lossy().into_owned())
            .expect("a crate folder");
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        let modules: BTreeSet<Module> = files.iter().map(|f| module_of(&src, f)).collect();
        let mut graph: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
        for f in &files {
            let m = module_of(&src, f);
            let text = std::fs::read_to_string(f).expect("a source file is readable");
            let code: String = text
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n");
            let targets = graph.entry(m.clone()).or_default();
            for p in named_paths(&m, &code) {
                let t = resolve(&modules, &p);
                if !t.starts_with(&m) && !m.starts_with(&t) {
                    targets.insert(t);
                }
            }
        }
        all.insert(name, graph);
    }
    all
}

fn show(m: &Module) -> String {
    if m.is_empty() {
        "(root)".into()
    } else {
        m.join("::")
    }
}

fn edge(g: &BTreeMap<Module, BTreeSet<Module>>, a: &str, b: &str) -> bool {
    let split = |s: &str| -> Module { s.split("::").map(String::from).collect() };
    g.get(&split(a)).is_some_and(|t| t.contains(&split(b)))
}

#[test]
fn no_two_modules_import_each_other() {
    let all = edges();
    let mut circles = Vec::new();
    for (krate, g) in &all {
        for (a, targets) in g {
            for b in targets {
                if a < b && g.get(b).is_some_and(|t| t.contains(a)) {
                    circles.push(format!("{krate}: {} <-> {}", show(a), show(b)));
                }
            }
        }
    }
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

#[test]
fn the_check_sees_the_modules_and_edges_of_the_four_named_circles() {
    let all = edges();
    let (lib, py, cli) = (&all["gonio"], &all["gonio-py"], &all["gonio-cli"]);
    // One direction of each former circle is still there (the check reads these modules), and
    // the other direction is gone.
    for (g, a, b) in [
        (lib, "mapping::sphere", "mapping::batch"),
        (lib, "method", "baselines"),
        (lib, "method", "sampler"),
        (py, "diagram", "sampler"),
        (py, "misc", "sampler"),
        (py, "misc", "diagram"),
        (cli, "plot::grid", "plot::colour"),
    ] {
        assert!(edge(g, a, b), "the check misses {a} -> {b}");
        assert!(!edge(g, b, a), "{b} -> {a} is back");
    }
}

#[test]
fn paths_are_read_as_rust_resolves_them() {
    let m: Module = vec!["a".into(), "b".into()];
    let got = named_paths(
        &m,
        "use crate::{x, y::z, w::{p, q}};\nlet v = super::c::D;\nsuper::super::e::f();\n$crate::no",
    );
    let want: Vec<Vec<&str>> = vec![
        vec!["x"],
        vec!["y", "z"],
        vec!["w"],
        vec!["a", "c", "D"],
        vec!["e", "f"],
    ];
    assert_eq!(got, want);
}

/// Issue 36: the sampler contract (`sampler.rs`) is the bottom of the library's layers: it names
/// nothing of the HDS mapping (no `crate::mapping` path, none of the map's types through the
/// crate root), and the `Sampler` trait has at most ten methods.
#[test]
fn the_sampler_contract_names_nothing_of_the_mapping_and_stays_narrow() {
    let all = edges();
    let g = &all["gonio"];
    let sampler = vec!["sampler".to_string()];
    let into_mapping: Vec<String> = g[&sampler]
        .iter()
        .filter(|t| t.first().is_some_and(|s| s == "mapping"))
        .map(show)
        .collect();
    assert!(into_mapping.is_empty(), "sampler imports {into_mapping:?}");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/sampler.rs");
    let text = std::fs::read_to_string(src).expect("sampler.rs is readable");
    let code: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect();
    for name in [
        "HemisphereMap",
        "SphereMap",
        "MapRef",
        "Refinement",
        "Completion",
        "Stages",
    ] {
        assert!(
            !code.iter().any(|l| l.contains(name)),
            "sampler.rs names {name}"
        );
    }
    // The trait's methods: the `fn` lines between `pub trait Sampler` and its closing brace.
    let start = code
        .iter()
        .position(|l| l.starts_with("pub trait Sampler"))
        .expect("the Sampler trait");
    let end = start
        + code[start..]
            .iter()
            .position(|l| *l == "}")
            .expect("the trait's end");
    let methods: Vec<&str> = code[start..end]
        .iter()
        .filter(|l| l.trim_start().starts_with("fn "))
        .copied()
        .collect();
    assert!(
        (7..=10).contains(&methods.len()),
        "{} methods: {methods:#?}",
        methods.len()
    );
}
