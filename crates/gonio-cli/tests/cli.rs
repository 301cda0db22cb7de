//! The `gonio` binary, run end to end: every command with good and bad input.

use gonio::Batches;
use gonio::{Diagram, HemisphereMap, Sampler};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod common;
use common::*;

/// A hemisphere diagram with positive values everywhere, in the native JSON form.
const HEMI_JSON: &str = r#"{
  "theta_deg": [0, 30, 60, 90],
  "phi_deg": [0, 90, 180, 270],
  "values": [[10, 8, 4, 1], [10, 6, 3, 2], [10, 9, 5, 1], [10, 7, 2, 0.5]]
}"#;

fn hemi(dir: &Path) -> (PathBuf, HemisphereMap) {
    let p = dir.join("hemi.json");
    std::fs::write(&p, HEMI_JSON).unwrap();
    let map = HemisphereMap::new(&Diagram::from_json_str(HEMI_JSON).unwrap()).unwrap();
    (p, map)
}

/// Parses CSV text with a header into (header, rows of numbers).
fn csv(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("a header")
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

#[path = "../../gonio/tests/common/corpus.rs"]
mod corpus;

/// The photometric corpus as the build script found it; tests that need it are ignored (and say
/// so in the summary) when it is absent.
fn corpus() -> PathBuf {
    corpus::built_corpus_dir()
}

#[test]
fn sample_csv_matches_the_library_exactly() {
    let dir = temp_dir("sample");
    let (json, map) = hemi(&dir);
    let out = dir.join("s.csv");
    ok(&["sample", s(&json), "-n", "1000", "-o", s(&out)]);
    let (header, rows) = csv(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(header, ["u", "v", "x", "y", "z", "pdf"]);
    assert_eq!(rows.len(), 1000);
    for r in &rows {
        let d = [r[2], r[3], r[4]];
        assert!(((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - 1.0).abs() < 1e-12);
        assert!(r[5] > 0.0 && d[2] >= 0.0);
        // Shortest round-trip printing: u, v, direction and pdf are the library's exact f64s
        // from its batch path (SIMD; equal to the scalar `sample` within 1e-15 in the direction
        // and 1e-12 relative in the pdf, see tests/batch.rs of the library).
        let mut lib = [gonio::Sample::default()];
        map.sample_batch(&[[r[0], r[1]]], &mut lib);
        assert_eq!(lib[0].direction, d);
        assert_eq!(lib[0].pdf, r[5]);
        let scalar = map.sample([r[0], r[1]]);
        assert!((scalar.pdf - r[5]).abs() <= 1e-12 * r[5]);
        assert!((0..3).all(|k| (scalar.direction[k] - d[k]).abs() <= 1e-15));
        assert!((map.pdf(d) - r[5]).abs() <= 1e-6 * r[5]);
    }
    // Standard output gives the same bytes as the file.
    let stdout = ok(&["sample", s(&json), "-n", "1000"]);
    assert_eq!(stdout, std::fs::read_to_string(&out).unwrap());
}

#[test]
fn invert_and_pdf_agree_with_sample() {
    let dir = temp_dir("roundtrip");
    let (json, _) = hemi(&dir);
    let samples = dir.join("s.csv");
    ok(&[
        "sample",
        s(&json),
        "-n",
        "500",
        "--sequence",
        "sobol",
        "--seed",
        "7",
        "-o",
        s(&samples),
    ]);
    let (_, srows) = csv(&std::fs::read_to_string(&samples).unwrap());
    // The sample file has columns x,y,z among others: it serves directly as --directions input.
    let (h, inv) = csv(&ok(&["invert", s(&json), "--directions", s(&samples)]));
    assert_eq!(h, ["x", "y", "z", "u", "v"]);
    assert_eq!(inv.len(), srows.len());
    for (a, b) in srows.iter().zip(&inv) {
        assert!(
            (a[0] - b[3]).abs() < 1e-8 && (a[1] - b[4]).abs() < 1e-8,
            "{a:?} {b:?}"
        );
    }
    let (h, pdf) = csv(&ok(&["pdf", s(&json), "--directions", s(&samples)]));
    assert_eq!(h, ["x", "y", "z", "pdf"]);
    for (a, b) in srows.iter().zip(&pdf) {
        assert!((a[5] - b[3]).abs() <= 1e-9 * a[5], "{a:?} {b:?}");
    }
}

#[test]
fn pdf_normalises_and_refuses_zero_directions() {
    let dir = temp_dir("pdf");
    let (json, map) = hemi(&dir);
    let dirs = dir.join("d.csv");
    std::fs::write(&dirs, "id,z,y,x\n1,2,0,0\n2,1,1,1\n").unwrap();
    let (_, rows) = csv(&ok(&["pdf", s(&json), "--directions", s(&dirs)]));
    assert_eq!(rows[0][..3], [0.0, 0.0, 1.0]);
    assert_eq!(rows[0][3], map.pdf([0.0, 0.0, 1.0]));
    let k = 1.0 / 3f64.sqrt();
    assert!((rows[1][0] - k).abs() < 1e-15);
    std::fs::write(&dirs, "x,y,z\n0,0,1\n\n0,0,0\n").unwrap();
    let out = dir.join("p.csv");
    let err = fails(&["pdf", s(&json), "--directions", s(&dirs), "-o", s(&out)]);
    assert!(err.contains(":4: row 2:") && err.contains("zero"), "{err}");
    assert!(!out.exists());
    std::fs::write(&dirs, "x,y\n0,0\n").unwrap();
    let err = fails(&["pdf", s(&json), "--directions", s(&dirs)]);
    assert!(err.contains("no column `z`"), "{err}");
}

#[test]
fn points_on_the_boundary_are_accepted() {
    let dir = temp_dir("points");
    let (json, map) = hemi(&dir);
    let pts = dir.join("uv.csv");
    let corners =
        "v,u,extra\n0,0,a\n0,1,b\n1,0,c\n1,1,d\n0.5,0,e\n0,0.5,f\n1,0.5,g\n0.5,1,h\n0.5,0.5,i\n";
    std::fs::write(&pts, corners).unwrap();
    let (_, rows) = csv(&ok(&["sample", s(&json), "--points", s(&pts)]));
    assert_eq!(rows.len(), 9);
    assert_eq!(rows[1][..2], [1.0, 0.0]); // u = 1, v = 0: columns found by name
    for r in &rows {
        let d = [r[2], r[3], r[4]];
        assert!(((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - 1.0).abs() < 1e-12);
        // The CLI's batch path reads the density at its own direction (within 1e-15 of the
        // scalar one): 1e-12 relative.
        assert!((map.sample([r[0], r[1]]).pdf - r[5]).abs() <= 1e-12 * r[5]);
    }
}

#[test]
fn bad_points_are_refused_with_their_row_and_no_file() {
    let dir = temp_dir("badpoints");
    let (json, _) = hemi(&dir);
    let pts = dir.join("uv.csv");
    let out = dir.join("out.csv");
    for (text, row, line) in [
        ("u,v\n0.1,0.2\n0.3,0.4\nNaN,0.5\n", 3, 4),
        ("u,v\n0.1,0.2\n# comment\n0.3,1.0000001\n", 2, 4),
        ("u,v\n-1e-300,0.2\n", 1, 2),
        ("u,v\n0.1,inf\n", 1, 2),
        ("u,v\n0.1,abc\n", 1, 2),
    ] {
        std::fs::write(&pts, text).unwrap();
        let err = fails(&["sample", s(&json), "--points", s(&pts), "-o", s(&out)]);
        assert!(
            err.contains(&format!(":{line}: row {row}:")),
            "{text:?}: {err}"
        );
        assert!(!out.exists(), "no partial output for {text:?}");
        assert_eq!(
            std::fs::read_dir(&dir).unwrap().count(),
            2,
            "no temp files left"
        );
    }
    std::fs::write(&pts, "a,b\n1,2\n").unwrap();
    let err = fails(&["sample", s(&json), "--points", s(&pts)]);
    assert!(err.contains("no column `u`"), "{err}");
}

#[test]
fn binary_formats_have_the_right_size_and_values() {
    let dir = temp_dir("binary");
    let (json, _) = hemi(&dir);
    let (c, b32, b64) = (dir.join("s.csv"), dir.join("s.f32"), dir.join("s.f64"));
    ok(&["sample", s(&json), "-n", "100", "-o", s(&c)]);
    ok(&[
        "sample",
        s(&json),
        "-n",
        "100",
        "--format",
        "f32",
        "-o",
        s(&b32),
    ]);
    ok(&[
        "sample",
        s(&json),
        "-n",
        "100",
        "--format",
        "f64",
        "-o",
        s(&b64),
    ]);
    let f32s = std::fs::read(&b32).unwrap();
    let f64s = std::fs::read(&b64).unwrap();
    assert_eq!(f32s.len(), 100 * 6 * 4);
    assert_eq!(f64s.len(), 100 * 6 * 8);
    let (_, rows) = csv(&std::fs::read_to_string(&c).unwrap());
    for (k, r) in rows.iter().enumerate() {
        for (j, v) in r.iter().enumerate() {
            let o = (k * 6 + j) * 8;
            assert_eq!(f64::from_le_bytes(f64s[o..o + 8].try_into().unwrap()), *v);
            let o = (k * 6 + j) * 4;
            assert_eq!(
                f32::from_le_bytes(f32s[o..o + 4].try_into().unwrap()),
                *v as f32
            );
        }
    }
}

#[test]
fn zero_samples_give_the_header_only_and_large_runs_stream() {
    assert_eq!(ok(&["sample", "example", "-n", "0"]), "u,v,x,y,z,pdf\n");
    // More than one batch, from every sequence.
    for seq in ["halton", "sobol", "random"] {
        let out = ok(&[
            "sample",
            "example",
            "-n",
            "70000",
            "--sequence",
            seq,
            "--seed",
            "3",
        ]);
        assert_eq!(out.lines().count(), 70001);
    }
}

#[test]
fn broken_pipe_exits_quietly() {
    use std::io::Read;
    let mut child = Command::new(BIN)
        .args(["sample", "example", "-n", "100000000", "-q"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut buf = [0u8; 64];
    child.stdout.take().unwrap().read_exact(&mut buf).unwrap();
    // The read end is dropped here; the next write fails with EPIPE.
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{:?}", out.status);
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn every_method_samples_and_rejection_cannot_invert() {
    let dir = temp_dir("methods");
    let (json, _) = hemi(&dir);
    for m in [
        "hds",
        "piecewise-constant",
        "bilinear",
        "rejection",
        "uniform",
    ] {
        let (_, rows) = csv(&ok(&["sample", s(&json), "-n", "50", "--method", m]));
        assert_eq!(rows.len(), 50);
        assert!(rows.iter().all(|r| r[5] > 0.0 && r[4] >= 0.0), "{m}");
    }
    let dirs = dir.join("d.csv");
    std::fs::write(&dirs, "x,y,z\n0,0,1\n").unwrap();
    let err = fails(&[
        "invert",
        s(&json),
        "--directions",
        s(&dirs),
        "--method",
        "rejection",
    ]);
    assert!(err.contains("no inverse"), "{err}");
    let err = fails(&["sample", s(&json), "-n", "5", "--method", "magic"]);
    assert!(err.contains("magic"), "{err}");
    // A direction below the horizon has no preimage on the hemisphere: an empty u,v row, the
    // count on standard error, exit status 0 (issue 16).
    std::fs::write(&dirs, "x,y,z\n0,0,1\n0,0,-1\n").unwrap();
    let o = run(&["invert", s(&json), "--directions", s(&dirs)]);
    assert!(o.status.success());
    let out = String::from_utf8(o.stdout).unwrap();
    assert_eq!(out.lines().count(), 3, "{out}");
    assert!(out.lines().nth(2).unwrap().ends_with(",,"), "{out}");
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("1 of 2 directions have no preimage")
            && err.contains("outside the sampler's domain (Hemisphere)")
            && err.contains(":3, row 2"),
        "{err}"
    );
}

#[test]
fn info_json_has_the_documented_keys() {
    let dir = temp_dir("info");
    let (json, map) = hemi(&dir);
    let v: serde_json::Value = serde_json::from_str(&ok(&["info", s(&json), "--json"])).unwrap();
    assert_eq!(v["format"], "json");
    assert_eq!(v["grid"]["theta"]["count"], 4);
    assert_eq!(v["grid"]["phi"]["count"], 4);
    assert_eq!(v["grid"]["theta"]["max_deg"], 90.0);
    assert_eq!(v["map"]["domain"], "hemisphere");
    assert_eq!(v["map"]["target_power"], map.target_power());
    assert_eq!(v["map"]["memory_bytes"], map.memory_bytes());
    assert_eq!(v["map"]["paper_table_floats"], map.paper_table_floats());
    assert!(v["map"]["build_time_ms"].as_f64().unwrap() >= 0.0);
    let (lo, hi) = map.ratio_bound();
    // serde_json's default parser may be 1 ulp off; the printed text is exact.
    let rb = v["map"]["ratio_bound"].as_array().unwrap();
    assert!((rb[0].as_f64().unwrap() - lo).abs() <= 1e-15 * lo);
    assert!((rb[1].as_f64().unwrap() - hi).abs() <= 1e-15 * hi);
    assert!(v.get("photometry").is_none());
    let v: serde_json::Value = serde_json::from_str(&ok(&["info", "example", "--json"])).unwrap();
    assert_eq!(v["map"]["domain"], "sphere");
    assert_eq!(v["unit"], "cd");
    let text = ok(&["info", "example"]);
    assert!(text.contains("pdf/target") && text.contains("build time"));
}

#[test]
fn check_passes_on_a_good_diagram() {
    let dir = temp_dir("check");
    let (json, _) = hemi(&dir);
    let text = ok(&["check", s(&json), "--quick"]);
    assert!(text.contains("PASS"), "{text}");
    let v: serde_json::Value = serde_json::from_str(&ok(&[
        "check", "example", "--quick", "--json", "--seed", "5",
    ]))
    .unwrap();
    assert_eq!(v["passed"], true);
    assert!(v["options"]["ratio"]["claimed_bound"].is_array());
    let o = run(&["check", s(&json), "--quick", "--method", "bilinear"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
}

/// Issue 9: a diagram without data for θ < 30° — the map puts no light there (≤ 1e-6), says so as
/// a warning (stderr of `sample`, `info`), its power is the data's integral, and `check` compares
/// the map with the data and passes.
#[test]
fn partial_ranges_are_warned_and_conserve_light() {
    let dir = temp_dir("partial");
    let json = file_in(
        &dir,
        "cap.json",
        r#"{"theta_deg":[30,60,90],"phi_deg":[0,180],"values":[[3,2,1],[1,2,3]]}"#,
    );
    let o = run(&["sample", s(&json), "-n", "5"]);
    assert!(o.status.success());
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("warning") && err.contains("no data for θ in [0°, 30°]"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_str(&ok(&["info", s(&json), "--json"])).unwrap();
    let outside = v["map"]["probability_outside_measured"].as_f64().unwrap();
    assert!((0.0..=1e-6).contains(&outside), "{outside}");
    assert!((v["map"]["power_ratio"].as_f64().unwrap() - 1.0).abs() <= 1e-6);
    assert_eq!(v["map"]["completions"].as_array().unwrap().len(), 1);
    let data = Diagram::from_json_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["map"]["target_power"], data.integral());
    let text = ok(&["info", s(&json)]);
    assert!(
        text.contains("warning: no data for θ in [0°, 30°]"),
        "{text}"
    );
    let text = ok(&["check", s(&json), "--quick"]);
    assert!(text.contains("PASS"), "{text}");
}

#[test]
fn bad_input_files_give_located_one_line_errors() {
    let dir = temp_dir("badjson");
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\n  \"theta_deg\": [0, 90],\n  \"colour\": 1\n}").unwrap();
    let err = fails(&["info", s(&bad)]);
    assert!(
        err.starts_with(&format!("gonio: error: {}:3:", s(&bad))),
        "{err}"
    );
    assert!(err.contains("colour"), "{err}");
    // Valid JSON, invalid diagram: named, no location.
    std::fs::write(
        &bad,
        r#"{"theta_deg": [0, 90], "phi_deg": [0], "values": [[0, 0]]}"#,
    )
    .unwrap();
    let err = fails(&["sample", s(&bad), "-n", "3"]);
    assert!(
        err.starts_with("gonio: error:") && err.contains("bad.json"),
        "{err}"
    );
    let txt = dir.join("diagram.txt");
    std::fs::write(&txt, "not a diagram\n").unwrap();
    let err = fails(&["info", s(&txt)]);
    assert!(err.contains("unknown input format"), "{err}");
    assert!(err.contains("not recognisable"), "{err}");
    let err = fails(&["info", s(&dir.join("missing.JSON"))]);
    assert!(err.contains("cannot read"), "{err}");
    let bad_ies = dir.join("bad.IES");
    std::fs::write(&bad_ies, "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 x\n").unwrap();
    let err = fails(&["info", s(&bad_ies)]);
    assert!(
        err.starts_with(&format!("gonio: error: {}:3:", s(&bad_ies))),
        "{err}"
    );
    // Usage errors: exit code 2, one line.
    let o = run(&["sample", "example"]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr)
            .trim_end()
            .lines()
            .count(),
        1
    );
}

#[test]
fn convert_round_trips_through_ies_and_ldt() {
    let dir = temp_dir("convert");
    let j = dir.join("ex.json");
    ok(&["convert", "example", s(&j)]);
    let d0 = Diagram::from_json_str(&std::fs::read_to_string(&j).unwrap()).unwrap();
    let ex = gonio::synthetic::example_luminaire();
    assert_eq!(d0.values(), ex.values());
    // Degrees → radians is not always exact to the last bit.
    for (a, b) in d0
        .theta()
        .iter()
        .chain(d0.phi())
        .zip(ex.theta().iter().chain(ex.phi()))
    {
        assert!((a - b).abs() < 1e-14);
    }
    for ext in ["ies", "ldt"] {
        let f = dir.join(format!("ex.{ext}"));
        ok(&["convert", s(&j), s(&f)]);
        let back = dir.join(format!("back-{ext}.json"));
        ok(&["convert", s(&f), s(&back)]);
        let d1 = Diagram::from_json_str(&std::fs::read_to_string(&back).unwrap()).unwrap();
        assert!((d1.integral() / d0.integral() - 1.0).abs() < 1e-9, "{ext}");
        let v: serde_json::Value = serde_json::from_str(&ok(&["info", s(&f), "--json"])).unwrap();
        assert!(v["photometry"]["flux_lm"].as_f64().unwrap() > 0.0);
    }
    let err = fails(&["convert", "example", s(&dir.join("x.png"))]);
    assert!(err.contains("unknown output format"), "{err}");
    assert!(!dir.join("x.png").exists());
}

#[test]
fn tilt_files_are_read_next_to_the_ies_file() {
    let dir = temp_dir("tilt");
    let ies = dir.join("lamp.ies");
    ok(&["convert", "example", s(&ies)]);
    let text = std::fs::read_to_string(&ies).unwrap();
    assert!(text.contains("TILT=NONE"));
    std::fs::write(&ies, text.replace("TILT=NONE", "TILT=lamp.tlt")).unwrap();
    let err = fails(&["info", s(&ies)]);
    assert!(err.contains("lamp.tlt"), "{err}");
    std::fs::write(dir.join("lamp.tlt"), "1\n3\n0 45 90\n0.5 0.6 0.7\n").unwrap();
    let v: serde_json::Value = serde_json::from_str(&ok(&["info", s(&ies), "--json"])).unwrap();
    assert!(v["photometry"]["tilt"]
        .as_str()
        .unwrap()
        .contains("lamp.tlt"));
    assert_eq!(v["photometry"]["intensity_scale"], 0.5);
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn corpus_files_load_sample_and_report() {
    let corpus = corpus();
    for sub in ["ies", "ldt"] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(corpus.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(sub)))
            .collect();
        files.sort();
        for f in files.iter().take(3) {
            let o = run(&["info", s(f), "--json"]);
            if !o.status.success() {
                // Files the reader refuses on purpose must still fail cleanly.
                let err = String::from_utf8_lossy(&o.stderr);
                assert_eq!(err.trim_end().lines().count(), 1, "{err}");
                continue;
            }
            let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            let p = &v["photometry"];
            for key in [
                "format",
                "version",
                "photometric_type",
                "lamps",
                "multiplier",
                "tilt",
                "stored_vertical",
                "stored_horizontal",
                "symmetry",
                "max_intensity_cd",
                "flux_lm",
                "warnings",
            ] {
                assert!(p.get(key).is_some(), "{key} in {}", f.display());
            }
            assert_eq!(v["map"]["domain"], "sphere");
            let (_, rows) = csv(&ok(&["sample", s(f), "-n", "200"]));
            assert_eq!(rows.len(), 200);
            assert!(rows.iter().all(|r| r[5] >= 0.0));
        }
    }
}

/// `.ci/run` sets `GONIO_REQUIRE_CORPUS=1` when the corpus exists: then the corpus tests must
/// have been built to run, not ignored.
#[test]
fn corpus_tests_run_when_required() {
    corpus::assert_corpus_when_required(cfg!(gonio_corpus));
}

/// Issue 16: a direction with no preimage (zero density) gets empty u,v fields, the count goes
/// to standard error, the exit status is 0; a malformed row still stops the run.
#[test]
fn invert_keeps_one_row_per_input_row() {
    let dir = temp_dir("invert-rows");
    // Light only in the upper hemisphere, on the sphere (θ up to 180°).
    let json = file_in(
        &dir,
        "up.json",
        r#"{"theta_deg": [0, 90, 180], "phi_deg": [0], "values": [[1, 0, 0]]}"#,
    );
    let dirs = dir.join("d.csv");
    std::fs::write(&dirs, "x,y,z\n0,0,1\n0,0,-1\n1,0,0.2\n0,0.1,-1\n").unwrap();
    let o = run(&["invert", s(&json), "--directions", s(&dirs)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 5, "{text}");
    assert_eq!(lines[0], "x,y,z,u,v");
    assert!(
        lines[2].ends_with(",,") && lines[4].ends_with(",,"),
        "{text}"
    );
    assert!(
        !lines[1].ends_with(',') && !lines[3].ends_with(','),
        "{text}"
    );
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("2 of 4 directions have no preimage") && err.contains("density is 0"),
        "{err}"
    );
    // The mirror case (the issue's downlight): light only below, straight up has no preimage.
    let down = file_in(
        &dir,
        "down.json",
        r#"{"theta_deg": [0, 90, 180], "phi_deg": [0], "values": [[0, 0, 1]]}"#,
    );
    let o = run(&["invert", s(&down), "--directions", s(&dirs)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 5, "{text}");
    assert!(
        lines[1].ends_with(",,") && lines[3].ends_with(",,"),
        "{text}"
    );
    assert!(
        !lines[2].ends_with(',') && !lines[4].ends_with(','),
        "{text}"
    );
    // pdf: one row per input row too, 0 there.
    let pdf = ok(&["pdf", s(&json), "--directions", s(&dirs)]);
    let (_, rows) = csv(&pdf);
    assert_eq!(rows.len(), 4);
    assert_eq!(rows[1][3], 0.0);
    // The library says why: a distinct error kind.
    let d = Diagram::from_json_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let map = gonio::SphereMap::new(&d).unwrap();
    assert_eq!(
        map.invert([0.0, 0.0, -1.0]),
        Err(gonio::InvertError::ZeroDensity)
    );
    // A malformed row stops the run.
    std::fs::write(&dirs, "x,y,z\n0,0,1\n0,0,0\n").unwrap();
    let err = fails(&["invert", s(&json), "--directions", s(&dirs)]);
    assert!(err.contains(":3: row 2"), "{err}");
}

/// Issue 16: the format comes from the content, the extension is a hint; every error has the
/// `gonio: error:` prefix; JSON errors carry line:column; a UTF-8 BOM is accepted in JSON; UTF-16
/// is named.
#[test]
fn formats_from_content_and_located_errors() {
    let dir = temp_dir("formats");
    // An EULUMDAT file named .ies: read as EULUMDAT, with a warning.
    let ldt = dir.join("ex.ldt");
    ok(&["convert", "example", s(&ldt)]);
    let misnamed = dir.join("really-ldt.ies");
    std::fs::copy(&ldt, &misnamed).unwrap();
    let o = run(&["info", s(&misnamed), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("gonio: warning:") && err.contains("the content is EULUMDAT, not IES"),
        "{err}"
    );
    // No extension at all: the content decides, silently.
    let bare = dir.join("lamp");
    std::fs::copy(&ldt, &bare).unwrap();
    let o = run(&["info", s(&bare)]);
    assert!(o.status.success() && o.stderr.is_empty());
    // JSON with a UTF-8 byte-order mark.
    let bom = dir.join("bom.json");
    std::fs::write(&bom, format!("\u{feff}{HEMI_JSON}")).unwrap();
    ok(&["info", s(&bom)]);
    // A JSON value error names line and column of the value.
    let bad = file_in(
        &dir,
        "bad.json",
        "{\n  \"theta_deg\": [0, 45, 90],\n  \"phi_deg\": [0],\n  \"values\": [[1, -2, 0]]\n}\n",
    );
    let err = fails(&["info", s(&bad)]);
    assert!(
        err.starts_with(&format!("gonio: error: {}:4:18:", s(&bad))),
        "{err}"
    );
    std::fs::write(
        &bad,
        "{\"theta_deg\": [0, 90, 45],\n \"phi_deg\": [0], \"values\": [[1, 1, 1]]}",
    )
    .unwrap();
    let err = fails(&["info", s(&bad)]);
    assert!(
        err.starts_with(&format!("gonio: error: {}:1:23:", s(&bad))),
        "{err}"
    );
    // UTF-16 is named, for photometric files and JSON.
    let text = std::fs::read_to_string(&ldt).unwrap();
    let mut utf16 = vec![0xff, 0xfe];
    utf16.extend(text.encode_utf16().flat_map(|c| c.to_le_bytes()));
    let u16ldt = dir.join("u16.ldt");
    std::fs::write(&u16ldt, &utf16).unwrap();
    let err = fails(&["info", s(&u16ldt)]);
    assert!(
        err.starts_with("gonio: error:") && err.contains("UTF-16"),
        "{err}"
    );
    let mut utf16 = vec![0xff, 0xfe];
    utf16.extend(HEMI_JSON.encode_utf16().flat_map(|c| c.to_le_bytes()));
    let u16json = dir.join("u16.json");
    std::fs::write(&u16json, &utf16).unwrap();
    let err = fails(&["info", s(&u16json)]);
    assert!(err.contains("UTF-16"), "{err}");
    // IES parse errors carry the prefix and the location.
    let ies = dir.join("bad.ies");
    std::fs::write(&ies, "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 x\n").unwrap();
    let err = fails(&["info", s(&ies)]);
    assert!(
        err.starts_with(&format!("gonio: error: {}:3:", s(&ies))),
        "{err}"
    );
}

/// Issue 16: angles are written as the shortest decimal that reads back to the same radians.
#[test]
fn converted_files_have_short_angles() {
    let dir = temp_dir("short-angles");
    for ext in ["ies", "ldt", "json"] {
        let f = dir.join(format!("ex.{ext}"));
        ok(&["convert", "example", s(&f)]);
        let text = std::fs::read_to_string(&f).unwrap();
        for bad in ["99999999", "00000000"] {
            assert!(!text.contains(bad), "{ext}: {bad} in\n{text}");
        }
        // And they read back to the same diagram, bit for bit.
        let back = dir.join(format!("back-{ext}.json"));
        ok(&["convert", s(&f), s(&back)]);
        let d = Diagram::from_json_str(&std::fs::read_to_string(&back).unwrap()).unwrap();
        let ex = gonio::synthetic::example_luminaire();
        assert_eq!(d.theta(), ex.theta(), "{ext}");
        assert_eq!(d.phi(), ex.phi(), "{ext}");
        assert_eq!(d.values(), ex.values(), "{ext}");
    }
}

/// Issue 16: CSV input — a quoted field is one field; numbers out of the double range are
/// refused, not read as infinity.
#[test]
fn csv_quoted_fields_and_out_of_range_numbers() {
    let dir = temp_dir("csv-quotes");
    let pts = dir.join("p.csv");
    std::fs::write(&pts, "\"u\",\"v\"\n\"0.1\",\"0.2\"\n\"0.1,0.2\",0.3\n").unwrap();
    let err = fails(&["sample", "example", "--points", s(&pts)]);
    assert!(
        err.contains(":3: row 2: u = `0.1,0.2` is not a number"),
        "{err}"
    );
    std::fs::write(&pts, "u,v\n1e400,0.5\n").unwrap();
    let err = fails(&["sample", "example", "--points", s(&pts)]);
    assert!(err.contains("out of the range"), "{err}");
}

/// Issue 16: the main job's first sample is representative (Halton from index 1, not the corner
/// u = (0, 0)), and deterministic.
#[test]
fn first_sample_is_not_the_corner() {
    let out = ok(&["sample", "example", "-n", "3"]);
    let (_, rows) = csv(&out);
    assert_eq!((rows[0][0], rows[0][1]), (0.5, 1.0 / 3.0));
    assert!(rows[0][5] > 1e-3, "pdf {}", rows[0][5]);
    assert_eq!(out, ok(&["sample", "example", "-n", "3"]));
}

/// Issue 16: `bench --help` shows no unrendered rustdoc; `info` says `1 meridian`.
#[test]
fn help_and_info_wording() {
    let help = ok(&["bench", "--help"]);
    assert!(!help.contains("[`"), "{help}");
    let dir = temp_dir("wording");
    let (json, _) = hemi(&dir);
    let one = file_in(
        &dir,
        "one.json",
        r#"{"theta_deg": [0, 45, 90], "phi_deg": [0], "values": [[1, 0.7, 0]]}"#,
    );
    let info = ok(&["info", s(&one)]);
    assert!(info.contains("3 parallels × 1 meridian;"), "{info}");
    let info = ok(&["info", s(&json)]);
    assert!(info.contains("4 parallels × 4 meridians;"), "{info}");
    let ies = dir.join("ex.ies");
    ok(&["convert", "example", s(&ies)]);
    let info = ok(&["info", s(&ies)]);
    assert!(info.contains("format           IES LM-63-2019\n"), "{info}");
}

/// `gonio tables`: a photometric file, a JSON diagram and the example in both precisions; the
/// blob reads back with the library's reader and samples as the map the CLI's `sample` uses.
#[test]
fn tables_writes_a_blob_that_samples_as_the_map() {
    use gonio::mapping::blob::{self, Frame, Precision};
    let dir = temp_dir("tables");
    let json = dir.join("hemi.json");
    std::fs::write(&json, HEMI_JSON).unwrap();
    for (input, frame) in [("example", Frame::Photometric), (s(&json), Frame::Generic)] {
        for (p, want) in [("f32", Precision::F32), ("f64", Precision::F64)] {
            let out = dir.join(format!("t-{p}.bin"));
            let o = run(&["tables", input, "-o", s(&out), "--precision", p]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let bytes = std::fs::read(&out).unwrap();
            let t = blob::read(&bytes).unwrap();
            assert_eq!((t.precision, t.frame), (want, frame));
            // The blob's map samples as the CLI's own map (f64: to the printed digits).
            if want == Precision::F64 {
                let csv = ok(&["sample", input, "-n", "5", "--seed", "3"]);
                for line in csv.lines().skip(1) {
                    let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
                    let s = t.sample([v[0], v[1]]);
                    for c in 0..3 {
                        assert!((s.direction[c] - v[2 + c]).abs() < 1e-9, "{line} vs {s:?}");
                    }
                    assert!((s.pdf - v[5]).abs() <= 1e-9 * v[5], "{line} vs {s:?}");
                }
            }
        }
    }
    // A bad precision is a usage error; a directory as output is refused; nothing left behind.
    let e = fails(&[
        "tables",
        "example",
        "-o",
        s(&dir.join("x.bin")),
        "--precision",
        "f16",
    ]);
    assert!(e.contains("f16"), "{e}");
    fails(&["tables", "example", "-o", s(&dir)]);
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(names.len(), 3, "{names:?}");
}

/// `gonio tables BRDF`: the whole family of incident slices (no `--incident`), equal to the
/// library's family of the same table; a broken BRDF file gets its reader's message.
#[test]
fn tables_of_a_brdf_file_is_its_family() {
    use gonio::brdf::{self, BrdfSampler, SamplerOptions};
    use gonio::mapping::blob::Precision;
    let dir = temp_dir("tables-brdf");
    let (_, path) = ggx_file(&dir);
    let out = dir.join("ggx.bin");
    let o = run(&["tables", s(&path), "-o", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&out).unwrap();
    let (back, fam) = brdf::from_tables(&bytes).unwrap();
    assert_eq!(fam.slices.len(), 7);
    let want = BrdfSampler::new(back, &SamplerOptions::default())
        .unwrap()
        .tables(Precision::F32)
        .unwrap();
    assert!(want == bytes, "the CLI's family differs from the library's");
    std::fs::write(&path, "{\"format\": \"gonio-brdf\", \"version\": 1}").unwrap();
    let e = fails(&["tables", s(&path), "-o", s(&out)]);
    assert!(e.contains("ggx.json"), "{e}");
}

/// `gonio sample BRDF --incident`: the options of `gonio sample` work for a BRDF too (issue 36
/// item 6): `--sequence`, `--seed`, `--points` (a user's own points of the square, checked before
/// anything is written) and `-o`; each row is the library's sample of its point.
#[test]
fn brdf_sample_takes_sequences_points_and_an_output() {
    use gonio::brdf::{BrdfSampler, SamplerOptions};
    let dir = temp_dir("brdf-sample-points");
    let (table, path) = ggx_file(&dir);
    let sampler = BrdfSampler::new(table, &SamplerOptions::default()).unwrap();
    let wi = gonio::sampler::direction(30f64.to_radians(), 0.0);
    let check_rows = |csv: &str, n: usize| {
        let rows: Vec<Vec<f64>> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), n, "{csv}");
        for r in &rows {
            let s = sampler.sample(wi, [r[0], r[1]]);
            for c in 0..3 {
                assert!((s.direction[c] - r[2 + c]).abs() < 1e-12, "{r:?} vs {s:?}");
            }
            assert!((s.pdf - r[5]).abs() <= 1e-12 * s.pdf, "{r:?} vs {s:?}");
        }
        rows
    };
    let p = s(&path);
    for seq in ["halton", "sobol", "random"] {
        let csv = ok(&[
            "sample",
            p,
            "--incident",
            "30,0",
            "--sequence",
            seq,
            "--seed",
            "4",
            "-n",
            "6",
        ]);
        check_rows(&csv, 6);
    }
    // Halton skips the corner (0, 0), as `gonio sample` does.
    let h = ok(&[
        "sample",
        p,
        "--incident",
        "30,0",
        "--sequence",
        "halton",
        "-n",
        "1",
    ]);
    assert!(h.lines().nth(1).unwrap().starts_with("0.5,0.333"), "{h}");
    // The user's own points, to a file.
    let uv = dir.join("uv.csv");
    std::fs::write(&uv, "u,v\n0.1,0.2\n0.9,0.95\n0.5,0.5\n").unwrap();
    let out = dir.join("out.csv");
    ok(&[
        "sample",
        p,
        "--incident",
        "30,0",
        "--points",
        s(&uv),
        "-o",
        s(&out),
    ]);
    let rows = check_rows(&std::fs::read_to_string(&out).unwrap(), 3);
    assert_eq!((rows[1][0], rows[1][1]), (0.9, 0.95));
    // A point outside the square is refused with its row, and nothing is written.
    std::fs::write(&uv, "u,v\n0.1,0.2\n1.5,0.5\n").unwrap();
    let bad = dir.join("bad.csv");
    let e = fails(&[
        "sample",
        p,
        "--incident",
        "30,0",
        "--points",
        s(&uv),
        "-o",
        s(&bad),
    ]);
    assert!(
        e.contains("row 2") && e.contains("outside the unit square"),
        "{e}"
    );
    assert!(!bad.exists());
}
