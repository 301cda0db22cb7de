//! The spelling `gonio info|sample|pdf|invert|check|plot|bench FILE --incident THETA,PHI`
//! on BRDF files the test writes (a gonio BRDF JSON told apart from a diagram JSON by its content,
//! a MERL file named `.binary`, a UTIA `.bin`), the alias `gonio brdf …`, the usage error without
//! `--incident`, and the slice picture.

use gonio::brdf::{write_json, write_merl, write_utia_dirs, Analytic};

mod common;
use common::*;

fn with_small(mut a: Vec<&str>) -> Vec<&str> {
    a.extend(SMALL_BRDF);
    a
}

#[test]
fn top_level_commands_on_every_format() {
    let dir = temp_dir("all");
    let mix = Analytic::families()[4];
    let json = dir.join("mix.json");
    std::fs::write(&json, write_json(&mix.table(7, 12).unwrap())).unwrap();
    let merl = dir.join("mix.binary");
    std::fs::write(&merl, write_merl(|wi, wo| mix.eval(wi, wo))).unwrap();
    let aniso = Analytic::families()[2];
    let utia = dir.join("aniso.bin");
    std::fs::write(&utia, write_utia_dirs(|wi, wo| aniso.eval(wi, wo))).unwrap();
    for (file, format) in [
        (&json, "gonio BRDF JSON"),
        (&merl, "MERL binary"),
        (&utia, "UTIA raw"),
    ] {
        let f = s(file);
        let (code, out, err) = gonio(&with_small(vec!["info", f, "--incident", "35,20"]));
        assert_eq!(code, Some(0), "{err}");
        assert!(out.contains(&format!("format: {format}")), "{out}");
        let (code, out, err) = gonio(&with_small(vec![
            "sample",
            f,
            "--incident",
            "35,20",
            "--samples",
            "30",
        ]));
        assert_eq!(code, Some(0), "{err}");
        assert!(out.starts_with("u,v,x,y,z,pdf,w_r,w_g,w_b\n"), "{out}");
        let samples = rows(&out);
        assert_eq!(samples.len(), 30);
        assert!(samples.iter().all(|r| r.len() == 9));
        let kept: Vec<&Vec<f64>> = samples.iter().filter(|r| r[5] > 1e-6).collect();
        assert!(
            kept.len() > 20,
            "{format}: {} samples of density > 1e-6",
            kept.len()
        );
        let csv = dir.join("dirs.csv");
        let text: String = std::iter::once("x,y,z\n".to_string())
            .chain(kept.iter().map(|r| format!("{},{},{}\n", r[2], r[3], r[4])))
            .collect();
        std::fs::write(&csv, text).unwrap();
        let (code, out, err) = gonio(&with_small(vec![
            "pdf",
            f,
            "--incident",
            "35,20",
            "--directions",
            s(&csv),
        ]));
        assert_eq!(code, Some(0), "{err}");
        assert!(out.starts_with("x,y,z,pdf\n"), "{out}");
        for (g, r) in rows(&out).iter().zip(&kept) {
            assert!(
                (g[3] - r[5]).abs() <= 1e-9 * r[5],
                "{format}: pdf {} vs {}",
                g[3],
                r[5]
            );
        }
        let (code, out, err) = gonio(&with_small(vec![
            "invert",
            f,
            "--incident",
            "35,20",
            "--directions",
            s(&csv),
        ]));
        assert_eq!(code, Some(0), "{err}");
        assert!(out.starts_with("x,y,z,u,v\n"), "{out}");
        let inv = rows(&out);
        assert_eq!(inv.len(), kept.len());
        for (g, r) in inv.iter().zip(&kept) {
            assert!(
                (g[3] - r[0]).abs() < 1e-8 && (g[4] - r[1]).abs() < 1e-8,
                "{format}: {g:?} vs {r:?}"
            );
        }
    }
    // `bench` times every method (a few samples: the test checks the table, not the speed).
    let (code, out, err) = gonio(&with_small(vec![
        "bench",
        s(&json),
        "--incident",
        "35,20",
        "-n",
        "200",
    ]));
    assert_eq!(code, Some(0), "{err}");
    assert!(out.starts_with("method,ns_per_sample"), "{out}");
    for m in ["hds,", "cosine,", "ggx-fit,", "piecewise-constant,"] {
        assert!(out.contains(m), "{m}: {out}");
    }
    // The alias still works, and agrees with the top-level spelling.
    let a = gonio(&with_small(vec![
        "sample",
        s(&json),
        "--incident",
        "10,0",
        "-n",
        "5",
    ]));
    let b = gonio(&with_small(vec![
        "brdf",
        "sample",
        s(&json),
        "--incident",
        "10,0",
        "-n",
        "5",
    ]));
    assert_eq!(a.0, Some(0));
    assert_eq!(a, b);
    // `check --quick` runs the cheaper battery at the incident direction (exit 0: every item
    // passes; the battery's own fixed seed and stated error rates).
    let (code, out, err) = gonio(&with_small(vec![
        "check",
        s(&json),
        "--incident",
        "50,0",
        "--quick",
    ]));
    assert_eq!(code, Some(0), "{out}{err}");
    assert!(out.contains("incident (50.0, 0.0)"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn usage_errors_and_diagram_json_untouched() {
    let dir = temp_dir("usage");
    let lambert = Analytic::families()[0];
    // Named like a diagram: the content decides.
    let json = dir.join("diagram.json");
    std::fs::write(&json, write_json(&lambert.table(5, 8).unwrap())).unwrap();
    // Each command with the arguments it requires of every input (parsed first), then the
    // input's kind: a BRDF file without --incident is a usage error naming the file's format.
    let dirs = dir.join("dirs.csv");
    std::fs::write(&dirs, "x,y,z\n0,0,1\n").unwrap();
    let png = dir.join("never.png");
    for cmd in ["info", "sample", "pdf", "invert", "check", "plot", "bench"] {
        let mut a = vec![cmd, s(&json)];
        match cmd {
            "sample" => a.extend(["-n", "3"]),
            "pdf" | "invert" => a.extend(["--directions", s(&dirs)]),
            "plot" => a.extend(["-o", s(&png)]),
            _ => {}
        }
        let (code, _, err) = gonio(&a);
        assert_eq!(code, Some(2), "{cmd}: {err}");
        assert!(
            err.contains("is a BRDF file (gonio BRDF JSON)")
                && err.contains("--incident THETA,PHI"),
            "{cmd}: {err}"
        );
    }
    let (code, _, err) = gonio(&["brdf", "info", s(&json)]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--incident"), "{err}");
    // A diagram JSON still goes to the diagram commands.
    let diagram = dir.join("lamp.json");
    let (code, _, err) = gonio(&["convert", "example", s(&diagram)]);
    assert_eq!(code, Some(0), "{err}");
    let (code, out, err) = gonio(&["info", s(&diagram)]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!out.contains("gonio BRDF JSON"), "{out}");
    // A broken BRDF JSON is still recognised (by its format name) and its reader says where.
    let text = std::fs::read_to_string(&json).unwrap();
    let cut = dir.join("cut.json");
    std::fs::write(&cut, &text[..text.len() / 2]).unwrap();
    let (code, _, err) = gonio(&["info", s(&cut), "--incident", "0,0"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("json "), "{err}");
    // A garbage file that happens to start like a huge MERL header: an error, not a crash.
    let junk = file_in(
        &dir,
        "junk.binary",
        b"\xff\xff\xff\x7f\xff\xff\xff\x7f\xff\xff\xff\x7fxyz",
    );
    let (code, _, err) = gonio(&["brdf", "info", s(&junk), "--incident", "0,0"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("not a BRDF file"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn plot_draws_the_slice() {
    let dir = temp_dir("plot");
    let ggx = Analytic::families()[1];
    let json = dir.join("ggx.json");
    std::fs::write(&json, write_json(&ggx.table(7, 12).unwrap())).unwrap();
    for (out, magic) in [("slice.png", &b"\x89PNG"[..]), ("slice.svg", &b"<svg"[..])] {
        let path = dir.join(out);
        let (code, _, err) = gonio(&with_small(vec![
            "plot",
            s(&json),
            "--incident",
            "45,30",
            "-o",
            s(&path),
            "--samples",
            "300",
        ]));
        assert_eq!(code, Some(0), "{err}");
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(magic), "{out}");
        assert!(bytes.len() > 5000, "{out}: {} bytes", bytes.len());
    }
    let (code, _, err) = gonio(&with_small(vec![
        "plot",
        s(&json),
        "--incident",
        "45,30",
        "-o",
        s(&dir.join("slice.gif")),
    ]));
    assert_eq!(code, Some(1));
    assert!(err.contains(".png or .svg"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 36: a BRDF file is one more input kind of the one command tree, so its options are
/// ordinary options: refused (exit 2, by name) for another input, a BRDF method is refused for a
/// diagram and a diagram's method for a BRDF, and the options every input has work on a BRDF
/// (`--format f64` binary rows, `-o`, `--json`).
#[test]
fn brdf_options_are_ordinary_options() {
    let dir = temp_dir("options");
    let json = file_in(
        &dir,
        "ggx.json",
        write_json(&Analytic::families()[1].table(7, 12).unwrap()),
    );
    // BRDF options on a luminaire: a usage error naming the option.
    for opt in [
        vec!["--incident", "30,0"],
        vec!["--theta-o", "7"],
        vec!["--merl-phi", "12"],
    ] {
        let mut a = vec!["sample", "example", "-n", "3"];
        a.extend(opt.iter().copied());
        let (code, _, err) = gonio(&a);
        assert_eq!(code, Some(2), "{opt:?}: {err}");
        assert!(
            err.contains(opt[0]) && err.contains("applies to BRDF files"),
            "{opt:?}: {err}"
        );
    }
    // A BRDF method on a diagram, a diagram's method on a BRDF.
    let (code, _, err) = gonio(&["sample", "example", "-n", "3", "--method", "cosine"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--method cosine"), "{err}");
    let (code, _, err) = gonio(&with_small(vec![
        "sample",
        s(&json),
        "--incident",
        "30,0",
        "-n",
        "3",
        "--method",
        "bilinear",
    ]));
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("--method bilinear"), "{err}");
    // Binary rows of nine f64 values, to a file; the same values as the CSV.
    let bin = dir.join("rows.bin");
    let (code, _, err) = gonio(&with_small(vec![
        "sample",
        s(&json),
        "--incident",
        "30,0",
        "-n",
        "17",
        "--format",
        "f64",
        "-o",
        s(&bin),
    ]));
    assert_eq!(code, Some(0), "{err}");
    let bytes = std::fs::read(&bin).unwrap();
    assert_eq!(bytes.len(), 17 * 9 * 8);
    let (code, out, err) = gonio(&with_small(vec![
        "sample",
        s(&json),
        "--incident",
        "30,0",
        "-n",
        "17",
    ]));
    assert_eq!(code, Some(0), "{err}");
    let csv: Vec<f64> = rows(&out).into_iter().flatten().collect();
    let binv: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(csv, binv);
    // `info --json` and `check --json` on a BRDF.
    let (code, out, err) = gonio(&with_small(vec![
        "info",
        s(&json),
        "--incident",
        "30,0",
        "--json",
    ]));
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["format"], "gonio BRDF JSON");
    assert!(v["albedo"].as_f64().unwrap() > 0.0);
    let (code, out, err) = gonio(&with_small(vec![
        "check",
        s(&json),
        "--incident",
        "30,0",
        "--quick",
        "--json",
    ]));
    assert_eq!(code, Some(0), "{out}{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["incident_deg"][0], 30.0);
    assert_eq!(v["passed"], true);
    std::fs::remove_dir_all(&dir).ok();
}
