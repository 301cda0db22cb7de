//! What every end-to-end test of the `gonio` binary needs: the binary, a fresh folder, a run that
//! cannot hang, its success or its one-line error, and the CSV it writes.
// Each test file uses its own part of this module.
#![allow(dead_code)]

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_gonio");

/// A run that takes longer than this is taken to be blocked (on a FIFO or a device).
pub const HANG: Duration = Duration::from_secs(60);

/// A fresh, empty folder for one test (unique to the process and the call).
pub fn temp_dir(name: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let d = std::env::temp_dir().join(format!(
        "gonio-cli-{}-{}-{name}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `contents` to the file `name` in `dir` and gives its path.
pub fn file_in(dir: &Path, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, contents).unwrap();
    p
}

/// The path as the `&str` argument the binary takes.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Starts gonio with `args` (no standard input, output captured).
pub fn spawn_plain(args: &[&str]) -> Child {
    Command::new(BIN)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the gonio binary runs")
}

/// Starts gonio with `args` and `--quiet`.
pub fn spawn(args: &[&str]) -> Child {
    let mut all = args.to_vec();
    all.push("--quiet");
    spawn_plain(&all)
}

/// Waits for `child`, reading its output as it comes (a large output cannot fill the pipe and
/// stall it); one still going after [`HANG`] is killed and the test fails (it blocked).
pub fn finish(mut child: Child, args: &[&str]) -> Output {
    fn drain(r: Option<impl Read + Send + 'static>) -> std::thread::JoinHandle<Vec<u8>> {
        std::thread::spawn(move || {
            let mut v = Vec::new();
            if let Some(mut r) = r {
                r.read_to_end(&mut v).unwrap();
            }
            v
        })
    }
    let (out, err) = (drain(child.stdout.take()), drain(child.stderr.take()));
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > HANG {
            let _ = child.kill();
            let _ = child.wait();
            panic!("gonio {args:?} blocked for {HANG:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Output {
        status,
        stdout: out.join().unwrap(),
        stderr: err.join().unwrap(),
    }
}

/// Runs gonio with `args` and `--quiet`.
pub fn run(args: &[&str]) -> Output {
    finish(spawn(args), args)
}

/// Runs gonio with `args` as given: (exit status, standard output, standard error).
pub fn gonio(args: &[&str]) -> (Option<i32>, String, String) {
    let out = finish(spawn_plain(args), args);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs and expects success; returns standard output.
pub fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "gonio {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// Runs and expects failure with exit status `code` (1: an error, 2: a usage error) and a
/// one-line message, no panic; returns the message.
pub fn fails_with(code: i32, args: &[&str]) -> String {
    refusal(args, &[code])
}

/// [`fails_with`] either exit status of a refusal (1 or 2).
pub fn fails(args: &[&str]) -> String {
    refusal(args, &[1, 2])
}

fn refusal(args: &[&str], codes: &[i32]) -> String {
    let o = run(args);
    let err = String::from_utf8(o.stderr).unwrap();
    let code = o.status.code();
    assert!(
        code.is_some_and(|c| codes.contains(&c)),
        "gonio {args:?}: exit status {code:?}, not one of {codes:?}: {err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "one-line error: {err:?}");
    assert!(!err.contains("panicked"), "no panic: {err}");
    err
}

/// The numeric rows of a CSV the binary wrote (header and `#` lines skipped).
pub fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .skip(1)
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').map(|f| f.parse().unwrap()).collect())
        .collect()
}

/// A GGX table (α = 0.3, F0 = (0.9, 0.6, 0.3); 7 incident θ × 12 outgoing φ) written as gonio
/// BRDF JSON to `ggx.json` in `dir`: the table and the file.
pub fn ggx_file(dir: &Path) -> (gonio::brdf::TabulatedBrdf, PathBuf) {
    let table = gonio::brdf::Analytic::Ggx {
        alpha_x: 0.3,
        alpha_y: 0.3,
        f0: [0.9, 0.6, 0.3],
    }
    .table(7, 12)
    .unwrap();
    let path = dir.join("ggx.json");
    std::fs::write(&path, gonio::brdf::write_json(&table)).unwrap();
    (table, path)
}

/// The small grids that keep the MERL resampling and the slices quick.
pub const SMALL_BRDF: [&str; 8] = [
    "--merl-theta",
    "7",
    "--merl-phi",
    "12",
    "--theta-o",
    "7",
    "--phi-o",
    "12",
];
