//! The `gonio` binary on environment maps (tiny generated `.hdr`, `.pfm` and `.exr` images):
//! info, sample with radiance columns, pdf, check, convert --to pbrt-v4, and the black-map error.

use gonio::image::{write_hdr, write_pfm, Image};

mod common;
use common::*;

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
    let hdr = file_in(
        &dir,
        "const.hdr",
        write_hdr(&Image::constant(16, 8, [0.5, 1.0, 2.0]).unwrap()),
    );
    let exr = dir.join("const.exr");
    // `gonio convert HDR EXR --to pbrt-v4 --resolution N`: what it prints and the image.
    let to_pbrt = |n: usize| {
        let (from, to, n) = (hdr.to_str().unwrap(), exr.to_str().unwrap(), n.to_string());
        let out = ok(&["convert", from, to, "--to", "pbrt-v4", "--resolution", &n]);
        (out, Image::read(&exr).unwrap())
    };
    let (out, img) = to_pbrt(12);
    assert!(out.contains("LightSource \"infinite\""), "{out}");
    assert_eq!((img.width(), img.height()), (12, 12));
    assert!(img.rgb().chunks(3).all(|p| p == [0.5, 1.0, 2.0]));
    // A bright pixel at the zenith row lands in the centre of the octahedral square (+z).
    let mut top = Image::constant(16, 8, [0.0; 3]).unwrap();
    for x in 0..16 {
        top.set_pixel(x, 0, [1.0, 1.0, 1.0]);
    }
    std::fs::write(&hdr, write_hdr(&top)).unwrap();
    let (_, img) = to_pbrt(16);
    assert!(img.pixel(8, 8)[0] > 0.9 && img.pixel(0, 0)[0] == 0.0);
    // pbrt-v4 reads direction w (light space) at pixel ⌊EqualAreaSphereToSquare(w)·N⌋, y from the
    // top row: a lit cap round an asymmetric direction must come back there, not mirrored or
    // transposed. The cap: every pixel whose centre is within 25° of d0.
    let d0 = {
        let v = [0.6f64, -0.3, 0.45];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / n)
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (w, h) = (64, 32);
    let mut cap = Image::constant(w, h, [0.0; 3]).unwrap();
    for y in 0..h {
        for x in 0..w {
            let d = gonio::envmap::image_direction(
                (x as f64 + 0.5) / w as f64,
                (y as f64 + 0.5) / h as f64,
            );
            if dot(d, d0) > 25f64.to_radians().cos() {
                cap.set_pixel(x, y, [1.0, 2.0, 3.0]);
            }
        }
    }
    std::fs::write(&hdr, write_hdr(&cap)).unwrap();
    let n = 48;
    let (_, img) = to_pbrt(n);
    let pbrt_pixel = |d: [f64; 3]| {
        let uv = gonio::baselines::equal_area::equal_area_sphere_to_square(d);
        let x = ((uv[0] * n as f64) as usize).min(n - 1);
        let y = ((uv[1] * n as f64) as usize).min(n - 1);
        img.pixel(x, y)
    };
    assert_eq!(pbrt_pixel(d0), [1.0, 2.0, 3.0]);
    // Well inside and well outside the cap (clear of its ragged edge of pixels).
    let mut inside = 0;
    for i in 0..2000 {
        let (a, b) = ((i as f64 * 0.618_034) % 1.0, (i as f64 + 0.5) / 2000.0);
        let d = gonio::baselines::equal_area::equal_area_square_to_sphere([a, b]);
        let c = dot(d, d0);
        if c > 18f64.to_radians().cos() {
            assert_eq!(pbrt_pixel(d), [1.0, 2.0, 3.0], "{d:?} inside the cap");
            inside += 1;
        } else if c < 33f64.to_radians().cos() {
            assert_eq!(pbrt_pixel(d), [0.0; 3], "{d:?} outside the cap");
        }
    }
    assert!(inside > 20, "{inside}");
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

#[test]
fn weight_lookup_and_mis_options() {
    let dir = temp_dir("options");
    // A blue source at pixel (7, 3) and a red one at (24, 10) on a dim grey sky.
    let mut img = Image::constant(32, 16, [0.25, 0.25, 0.25]).unwrap();
    img.set_pixel(7, 3, [1.0, 1.0, 4000.0]);
    img.set_pixel(24, 10, [4000.0, 1.0, 1.0]);
    let pfm = dir.join("two.pfm");
    std::fs::write(&pfm, write_pfm(&img, false, false)).unwrap();
    let f = pfm.to_str().unwrap();
    let on = |rows: &[Vec<f64>], rgb: [f64; 3]| rows.iter().filter(|r| r[6..9] == rgb[..]).count();
    // --weight red / blue send the samples to the red / blue source.
    let red = rows(&ok(&["sample", f, "-n", "400", "--weight", "red"]));
    let blue = rows(&ok(&["sample", f, "-n", "400", "--weight", "blue"]));
    // (The other source's pixel has weight 1 against the sky's 0.25: it gets a few samples.)
    let (r_on_red, r_on_blue) = (on(&red, [4000.0, 1.0, 1.0]), on(&red, [1.0, 1.0, 4000.0]));
    let (b_on_red, b_on_blue) = (on(&blue, [4000.0, 1.0, 1.0]), on(&blue, [1.0, 1.0, 4000.0]));
    assert!(
        r_on_red > 120 && r_on_red > 20 * r_on_blue,
        "{r_on_red} {r_on_blue}"
    );
    assert!(
        b_on_blue > 120 && b_on_blue > 20 * b_on_red,
        "{b_on_blue} {b_on_red}"
    );
    // The same points, another weight: other directions and densities.
    let lum = rows(&ok(&["sample", f, "-n", "400"]));
    assert!(lum.iter().zip(&red).any(|(a, b)| a[5] != b[5]));
    // --lookup bilinear: the same directions and densities, radiance between pixel centres (not
    // only the image's three pixel colours).
    let bil = rows(&ok(&["sample", f, "-n", "400", "--lookup", "bilinear"]));
    assert!(lum.iter().zip(&bil).all(|(a, b)| a[..6] == b[..6]));
    let colours = |r: &Vec<f64>| {
        [[0.25; 3], [1.0, 1.0, 4000.0], [4000.0, 1.0, 1.0]]
            .iter()
            .any(|c| r[6..9] == c[..])
    };
    assert!(lum.iter().all(colours));
    assert!(bil.iter().filter(|r| !colours(r)).count() > 100);
    // info says what was chosen, as text and as JSON.
    let info = ok(&[
        "info",
        f,
        "--weight",
        "green",
        "--lookup",
        "bilinear",
        "--mis-compensation",
    ]);
    assert!(
        info.contains("weight: green channel, MIS compensation")
            && info.contains("radiance lookup: bilinear"),
        "{info}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["info", f, "--json", "--weight", "blue"])).unwrap();
    assert_eq!(json["envmap"]["weight"], "blue");
    assert_eq!(json["envmap"]["lookup"], "nearest");
    assert_eq!(json["envmap"]["width"], 32);
    assert!(json["envmap"]["weight_power"].as_f64().unwrap() > 0.0);
    let (m64, m32) = (
        json["envmap"]["memory_bytes_beyond_image"]
            .as_u64()
            .unwrap(),
        json["envmap"]["float32_memory_bytes_beyond_image"]
            .as_u64()
            .unwrap(),
    );
    assert!(m32 > 0 && m32 < m64, "{m32} {m64}");
    // MIS compensation moves mass off the dim sky: fewer samples on the grey pixels.
    let mis = rows(&ok(&["sample", f, "-n", "400", "--mis-compensation"]));
    assert!(on(&mis, [0.25; 3]) < on(&lum, [0.25; 3]));
    // The options on other inputs are refused, not ignored.
    for opt in [
        &["--weight", "red"][..],
        &["--lookup", "bilinear"],
        &["--mis-compensation"],
    ] {
        let mut args = vec!["info", "example"];
        args.extend_from_slice(opt);
        let o = run(&args);
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("environment maps"), "{err}");
    }
    // Commands that never read an environment map refuse them too (usage error).
    for args in [
        &[
            "brdf",
            "info",
            "x.json",
            "--incident",
            "30,0",
            "--weight",
            "red",
        ][..],
        &["uv", "mesh.obj", "-o", "out.obj", "--lookup", "bilinear"],
    ] {
        let o = run(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("environment maps"));
    }
    // A channel that is black everywhere is the clear black-map error.
    let mut green0 = Image::constant(16, 8, [1.0, 0.0, 1.0]).unwrap();
    green0.set_pixel(3, 3, [2.0, 0.0, 2.0]);
    let g = dir.join("nogreen.pfm");
    std::fs::write(&g, write_pfm(&green0, false, false)).unwrap();
    let o = run(&["info", g.to_str().unwrap(), "--weight", "green"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("black"));
    let _ = std::fs::remove_dir_all(&dir);
}
