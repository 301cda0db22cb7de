//! The `gonio` binary on environment maps (tiny generated `.hdr`, `.pfm` and `.exr` images):
//! info, sample with radiance columns, pdf, check, convert --to pbrt-v4, and the black-map error.

use gonio::image::{write_hdr, write_pfm, Image};
use std::path::PathBuf;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_gonio");

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gonio-envmap-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .arg("--quiet")
        .output()
        .expect("the gonio binary runs")
}

fn ok(args: &[&str]) -> String {
    let o = run(args);
    assert!(
        o.status.success(),
        "gonio {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// A 32 × 16 sky: 0.25 everywhere, a bright pixel at (7, 3).
fn sky() -> Image {
    let mut img = Image::constant(32, 16, [0.25, 0.25, 0.25]).unwrap();
    img.set_pixel(7, 3, [6400.0, 3200.0, 1600.0]);
    img
}

#[test]
fn every_command_reads_an_envmap() {
    let dir = temp_dir("all");
    let hdr = dir.join("sky.hdr");
    std::fs::write(&hdr, write_hdr(&sky())).unwrap();
    let pfm = dir.join("sky.pfm");
    std::fs::write(&pfm, write_pfm(&sky(), false, true)).unwrap();
    for f in [&hdr, &pfm] {
        let f = f.to_str().unwrap();
        let info = ok(&["info", f]);
        assert!(info.contains("32 × 16 pixels"), "{info}");
        let s = ok(&["sample", f, "-n", "200", "--seed", "3"]);
        let mut lines = s.lines();
        assert_eq!(lines.next(), Some("u,v,x,y,z,pdf,r,g,b"));
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 200);
        // Most samples land on the bright pixel (it holds most of the luminance).
        let bright = rows
            .iter()
            .filter(|r| r[6] == 6400.0 && r[7] == 3200.0)
            .count();
        // (The density is bilinear between pixel centres: about 56 % of the node's mass lies in its pixel.)
        assert!(bright > 60, "{bright} of 200 on the bright pixel");
        assert!(rows.iter().all(|r| r[6] == 6400.0 || r[6] == 0.25));
        // pdf of the sampled directions agrees with the sample's.
        let dirs = dir.join("dirs.csv");
        let text: String = std::iter::once("x,y,z\n".to_string())
            .chain(rows.iter().map(|r| format!("{},{},{}\n", r[2], r[3], r[4])))
            .collect();
        std::fs::write(&dirs, text).unwrap();
        let p = ok(&["pdf", f, "--directions", dirs.to_str().unwrap()]);
        for (line, r) in p.lines().skip(1).zip(&rows) {
            let pdf: f64 = line.rsplit(',').next().unwrap().parse().unwrap();
            assert!((pdf - r[5]).abs() <= 1e-9 * r[5], "{pdf} vs {}", r[5]);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn convert_writes_pbrt_v4s_equal_area_image() {
    let dir = temp_dir("convert");
    let hdr = dir.join("const.hdr");
    std::fs::write(
        &hdr,
        write_hdr(&Image::constant(16, 8, [0.5, 1.0, 2.0]).unwrap()),
    )
    .unwrap();
    let exr = dir.join("const.exr");
    let out = ok(&[
        "convert",
        hdr.to_str().unwrap(),
        exr.to_str().unwrap(),
        "--to",
        "pbrt-v4",
        "--resolution",
        "12",
    ]);
    assert!(out.contains("LightSource \"infinite\""), "{out}");
    let img = Image::read(&exr).unwrap();
    assert_eq!((img.width(), img.height()), (12, 12));
    assert!(img.rgb().chunks(3).all(|p| p == [0.5, 1.0, 2.0]));
    // A bright pixel at the zenith row lands in the centre of the octahedral square (+z).
    let mut top = Image::constant(16, 8, [0.0; 3]).unwrap();
    for x in 0..16 {
        top.set_pixel(x, 0, [1.0, 1.0, 1.0]);
    }
    std::fs::write(&hdr, write_hdr(&top)).unwrap();
    ok(&[
        "convert",
        hdr.to_str().unwrap(),
        exr.to_str().unwrap(),
        "--to",
        "pbrt-v4",
        "--resolution",
        "16",
    ]);
    let img = Image::read(&exr).unwrap();
    assert!(img.pixel(8, 8)[0] > 0.9 && img.pixel(0, 0)[0] == 0.0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_black_map_is_a_clear_error() {
    let dir = temp_dir("black");
    let hdr = dir.join("black.hdr");
    std::fs::write(&hdr, write_hdr(&Image::constant(16, 8, [0.0; 3]).unwrap())).unwrap();
    let o = run(&["info", hdr.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("black.hdr") && err.contains("black"), "{err}");
    let bad = dir.join("cut.hdr");
    std::fs::write(&bad, &write_hdr(&sky())[..60]).unwrap();
    let o = run(&["info", bad.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("scanline"));
    let _ = std::fs::remove_dir_all(&dir);
}
