//! `gonio brdf …` end to end on files the test writes (JSON, MERL named without its extension,
//! UTIA): formats recognised from the content, the CSV columns, sample → pdf → invert agreeing.

use gonio::brdf::{write_json, write_merl, write_utia_dirs, Analytic};

mod common;
use common::*;

#[test]
fn brdf_commands_on_every_format() {
    let dir = std::env::temp_dir().join(format!("gonio-brdf-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mix = Analytic::families()[4];
    let json = dir.join("mix.json");
    std::fs::write(&json, write_json(&mix.table(7, 12).unwrap())).unwrap();
    let merl = dir.join("mix.dat");
    std::fs::write(&merl, write_merl(|wi, wo| mix.eval(wi, wo))).unwrap();
    let utia = dir.join("aniso.bin");
    let g = Analytic::families()[2];
    std::fs::write(&utia, write_utia_dirs(|wi, wo| g.eval(wi, wo))).unwrap();
    let small = SMALL_BRDF;
    for (file, format) in [
        (&json, "gonio BRDF JSON"),
        (&merl, "MERL binary"),
        (&utia, "UTIA raw"),
    ] {
        let f = file.to_str().unwrap();
        let mut a = vec!["brdf", "info", f, "--incident", "40,10"];
        a.extend(small);
        let (status, out, err) = gonio(&a);
        assert_eq!(status, Some(0), "{err}");
        assert!(out.contains(&format!("format: {format}")), "{out}");
        let mut a = vec!["brdf", "sample", f, "--incident", "40,10", "-n", "20"];
        a.extend(small);
        let (status, out, err) = gonio(&a);
        assert_eq!(status, Some(0), "{err}");
        assert!(out.starts_with("u,v,x,y,z,pdf,w_r,w_g,w_b\n"));
        let samples = rows(&out);
        assert_eq!(samples.len(), 20);
        // The same directions file as for every input: a header names the columns.
        let dirs: String = std::iter::once("x,y,z\n".to_string())
            .chain(
                samples
                    .iter()
                    .filter(|r| r[5] > 1e-6)
                    .map(|r| format!("{},{},{}\n", r[2], r[3], r[4])),
            )
            .collect();
        let csv = dir.join("dirs.csv");
        std::fs::write(&csv, &dirs).unwrap();
        let c = csv.to_str().unwrap();
        for cmd in ["pdf", "invert"] {
            let mut a = vec!["brdf", cmd, f, "--incident", "40,10", "--directions", c];
            a.extend(small);
            let (status, out, err) = gonio(&a);
            assert_eq!(status, Some(0), "{err}");
            let got = rows(&out);
            let want: Vec<&Vec<f64>> = samples.iter().filter(|r| r[5] > 1e-6).collect();
            assert_eq!(got.len(), want.len());
            for (g, s) in got.iter().zip(want) {
                if cmd == "pdf" {
                    assert!(
                        (g[3] - s[5]).abs() <= 1e-6 * s[5],
                        "{format}: pdf {} vs {}",
                        g[3],
                        s[5]
                    );
                } else {
                    assert!(
                        (g[3] - s[0]).abs() < 1e-6 && (g[4] - s[1]).abs() < 1e-6,
                        "{format}: {g:?} vs {s:?}"
                    );
                }
            }
        }
    }
    // A truncated MERL file: one line, located.
    let bytes = std::fs::read(&merl).unwrap();
    let cut = dir.join("cut.binary");
    std::fs::write(&cut, &bytes[..bytes.len() - 5]).unwrap();
    let (status, _, err) = gonio(&["brdf", "info", cut.to_str().unwrap(), "--incident", "0,0"]);
    assert!(
        status != Some(0) && err.contains("merl") && err.contains("bytes"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 40: a BRDF JSON with a UTF-8 byte order mark was refused everywhere; values of 1.7e308
/// gave albedo `inf`. The BOM file reads (as JSON, at the top level too); the huge values are
/// refused with the value's line and column.
#[test]
fn bom_json_reads_and_huge_values_are_refused_located() {
    let dir = std::env::temp_dir().join(format!("gonio-brdf-cli-bom-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = write_json(&Analytic::families()[0].table(4, 6).unwrap());
    let bom = dir.join("bom.json");
    let mut bytes = b"\xEF\xBB\xBF".to_vec();
    bytes.extend(text.as_bytes());
    std::fs::write(&bom, &bytes).unwrap();
    let b = bom.to_str().unwrap();
    for args in [
        &["brdf", "info", b, "--incident", "30,0"][..],
        &["info", b, "--incident", "30,0"][..],
    ] {
        let (status, out, err) = gonio(args);
        assert_eq!(status, Some(0), "{args:?}: {err}");
        assert!(out.contains("gonio BRDF JSON"), "{args:?}: {out}");
        assert!(!out.contains("inf"), "{args:?}: {out}");
    }
    let values = vec!["1.7e308"; 36].join(", ");
    let huge = format!(
        "{{\"format\": \"gonio-brdf\", \"version\": 1, \"symmetry\": \"isotropic\", \"channels\": 1,\n\"theta_i_deg\": [0, 45, 90], \"phi_i_deg\": [0],\n\"theta_o_deg\": [0, 45, 90], \"phi_o_deg\": [0, 90, 180, 270],\n\"values\": [{values}]}}"
    );
    let hp = dir.join("huge.json");
    std::fs::write(&hp, huge).unwrap();
    let (status, _, err) = gonio(&["brdf", "info", hp.to_str().unwrap(), "--incident", "30,0"]);
    assert_ne!(status, Some(0));
    assert!(
        err.contains("json 4:12") && err.contains("1.7e308"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 40, item 6: a broken BRDF file named at the top level with `--incident` gets the BRDF
/// reader's own message (not "unexpected argument '--incident'"), as `gonio brdf info` gives it.
#[test]
fn broken_brdf_files_with_incident_get_the_reader_s_message() {
    let dir = std::env::temp_dir().join(format!("gonio-cli-brdf-broken-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let empty = dir.join("empty.binary");
    std::fs::write(&empty, b"").unwrap();
    // A MERL header whose dimensions are 10^9 × 1 × 1 with 24 bytes after it.
    let lying = dir.join("lying.binary");
    let mut b = Vec::new();
    for d in [1_000_000_000i32, 1, 1] {
        b.extend_from_slice(&d.to_le_bytes());
    }
    b.extend_from_slice(&[0u8; 24]);
    std::fs::write(&lying, &b).unwrap();
    let missing = dir.join("missing.binary");
    for f in [&empty, &lying, &missing] {
        let f = f.to_str().unwrap();
        let (status, _, top) = gonio(&["info", f, "--incident", "30,0"]);
        assert_ne!(status, Some(0), "{f}");
        assert!(!top.contains("unexpected argument"), "{f}: {top}");
        let (_, _, sub) = gonio(&["brdf", "info", f, "--incident", "30,0"]);
        assert_eq!(top, sub, "{f}: the top level and `gonio brdf info` differ");
        assert!(top.contains(f), "{f}: {top}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
