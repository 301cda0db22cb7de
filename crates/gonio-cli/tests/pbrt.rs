//! `gonio convert FILE OUT --to pbrt-v4`, proved by an independent decode.
//!
//! For every readable corpus file the test runs the binary, reads the written image back (EXR with
//! the `exr` crate, PFM by hand) and evaluates it the way pbrt-v4's `GoniometricLight` does — the
//! light-space direction goes through pbrt's y↔z swap, Clarberg's `EqualAreaSphereToSquare`
//! (written here from the paper's formulas, with an exact `atan2`) and a nearest-pixel lookup with
//! clamping — and compares with the file's intensity (the library's reading of the file,
//! `Diagram::interpolate`), placed in pbrt's light frame by the documented convention (zenith +y,
//! C0 along +x, C90 along +z):
//!
//! * at random directions the decoded value equals the mean intensity over the pixel, computed
//!   here with a different quadrature (16 × 16 midpoints), within twice the quadrature error the
//!   command reports (plus f32 rounding) — so it lies within the pixel-averaging error of the
//!   file's intensity in that direction;
//! * the image's power 4π·mean(pixels) (pbrt's own formula) equals the file's flux to 0.5 %;
//! * the brightest pixel lies where the file is that bright (the largest intensity over the pixel
//!   is at least the pixel's value), and the pixel holding the file's brightest node holds a
//!   value within the file's range over that pixel.

use gonio::photometry::{read, DirTiltResolver, FileFormat, PhotometricType};
use gonio::sampler::spherical;
use gonio::Diagram;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_gonio");
/// Pixels per side of the test images (the command's default is 512; 128 keeps the test fast).
const RES: usize = 128;
/// Random directions per file.
const DIRECTIONS: usize = 300;

#[path = "../../gonio/tests/common/corpus.rs"]
mod corpus;

// ---- pbrt-v4's evaluation, written independently --------------------------------------------

/// Clarberg's octahedral equal-area map, sphere → square (pbrt's `EqualAreaSphereToSquare`).
fn sphere_to_square(d: [f64; 3]) -> [f64; 2] {
    let (x, y, z) = (d[0].abs(), d[1].abs(), d[2].abs());
    let r = (1.0 - z).max(0.0).sqrt();
    // Fraction of the quadrant's right angle, measured from the x axis.
    let a = y.atan2(x) / FRAC_PI_2;
    let (mut u, mut v) = (r * (1.0 - a), r * a);
    if d[2] < 0.0 {
        // Lower hemisphere: mirror across the diamond's edge.
        (u, v) = (1.0 - v, 1.0 - u);
    }
    let u = if d[0] < 0.0 { -u } else { u };
    let v = if d[1] < 0.0 { -v } else { v };
    [0.5 * (u + 1.0), 0.5 * (v + 1.0)]
}

/// Clarberg's map, square → sphere (pbrt's `EqualAreaSquareToSphere`).
fn square_to_sphere(p: [f64; 2]) -> [f64; 3] {
    let (u, v) = (2.0 * p[0] - 1.0, 2.0 * p[1] - 1.0);
    let (au, av) = (u.abs(), v.abs());
    let sd = 1.0 - (au + av);
    let r = 1.0 - sd.abs();
    let phi = if r == 0.0 { 1.0 } else { (av - au) / r + 1.0 } * FRAC_PI_4;
    let z = (1.0 - r * r).copysign(sd);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    [phi.cos().copysign(u) * s, phi.sin().copysign(v) * s, z]
}

/// A decoded single-channel square image, `pixels[y * n + x]`, y from the top (pbrt's order).
struct Img {
    n: usize,
    pixels: Vec<f32>,
}

impl Img {
    /// pbrt's `LookupNearestChannel`: pixel (⌊u·n⌋, ⌊v·n⌋), clamped.
    fn pixel_of(&self, uv: [f64; 2]) -> (usize, usize) {
        let c = |t: f64| ((t * self.n as f64) as i64).clamp(0, self.n as i64 - 1) as usize;
        (c(uv[0]), c(uv[1]))
    }
    fn at(&self, (x, y): (usize, usize)) -> f64 {
        f64::from(self.pixels[y * self.n + x])
    }
    /// pbrt-v4's intensity in a direction of the light's frame (before its y↔z swap).
    fn pbrt_intensity(&self, w_light: [f64; 3]) -> f64 {
        // GoniometricLight::Create appends a y↔z swap: the image sees (x, z, y).
        let w_image = [w_light[0], w_light[2], w_light[1]];
        self.at(self.pixel_of(sphere_to_square(w_image)))
    }
}

fn read_exr(path: &Path) -> Img {
    use exr::prelude::*;
    let image = read_first_flat_layer_from_file(path).expect("the EXR file reads back");
    let layer = image.layer_data;
    assert_eq!(layer.size.width(), layer.size.height(), "a square image");
    assert_eq!(layer.channel_data.list.len(), 1, "one channel");
    let ch = &layer.channel_data.list[0];
    assert_eq!(ch.name.to_string(), "Y", "pbrt reads a Y channel");
    let pixels = match &ch.sample_data {
        FlatSamples::F32(v) => v.clone(),
        _ => panic!("f32 samples expected"),
    };
    Img {
        n: layer.size.width(),
        pixels,
    }
}

fn read_pfm(path: &Path) -> Img {
    let bytes = std::fs::read(path).unwrap();
    // Header: "Pf", width, height, scale — whitespace-separated, then one whitespace byte.
    let mut fields = Vec::new();
    let mut k = 0;
    while fields.len() < 4 {
        while bytes[k].is_ascii_whitespace() {
            k += 1;
        }
        let start = k;
        while !bytes[k].is_ascii_whitespace() {
            k += 1;
        }
        fields.push(std::str::from_utf8(&bytes[start..k]).unwrap().to_string());
    }
    k += 1;
    assert_eq!(fields[0], "Pf", "greyscale PFM");
    let (w, h): (usize, usize) = (fields[1].parse().unwrap(), fields[2].parse().unwrap());
    let scale: f64 = fields[3].parse().unwrap();
    assert_eq!(w, h);
    assert!(scale < 0.0, "little-endian");
    let data = &bytes[k..];
    assert_eq!(data.len(), 4 * w * h);
    // PFM rows run from the bottom up; pbrt flips them so that y = 0 is the top.
    let mut pixels = vec![0f32; w * h];
    for file_row in 0..h {
        let y = h - 1 - file_row;
        for x in 0..w {
            let o = 4 * (file_row * w + x);
            pixels[y * w + x] =
                f32::from_le_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]])
                    * scale.abs() as f32;
        }
    }
    Img { n: w, pixels }
}

// ---- the file's side ---------------------------------------------------------------------------

/// The file's intensity in a direction of pbrt's light frame: the luminaire's zenith is +y, C0 is
/// +x and C90 is +z, i.e. gonio's (x, y, z) = (x_l, z_l, y_l).
fn file_intensity(d: &Diagram, w_light: [f64; 3]) -> f64 {
    let (theta, phi) = spherical([w_light[0], w_light[2], w_light[1]]);
    d.interpolate(theta, phi)
}

/// The pixel (x, y) of an n×n image as points of the square (s × s midpoints, or an (s+1)² grid
/// with the edges), mapped to pbrt's light frame.
fn pixel_points(n: usize, (x, y): (usize, usize), s: usize, edges: bool) -> Vec<[f64; 3]> {
    let mut pts = Vec::new();
    let (m, off) = if edges { (s + 1, 0.0) } else { (s, 0.5) };
    for j in 0..m {
        for i in 0..m {
            let u = (x as f64 + (i as f64 + off) / s as f64) / n as f64;
            let v = (y as f64 + (j as f64 + off) / s as f64) / n as f64;
            let w = square_to_sphere([u.min(1.0), v.min(1.0)]);
            pts.push([w[0], w[2], w[1]]); // image → light frame (undo pbrt's swap)
        }
    }
    pts
}

struct Report {
    worst_mean_error: f64,
    power_ratio: f64,
    brightest_angle_deg: f64,
}

/// Converts `file` and checks the image; returns what was measured.
fn check_file(file: &Path, out: &Path, rng: &mut u64) -> Report {
    let bytes = std::fs::read(file).unwrap();
    let format = FileFormat::from_path_extension(file).unwrap();
    let photometry = read(
        &bytes,
        format,
        &DirTiltResolver::new(file.parent().unwrap()),
    )
    .unwrap();
    let diagram = photometry.to_diagram().unwrap();
    let flux = diagram.integral();
    let i_max = diagram.max_value();

    let o = Command::new(BIN)
        .args(["convert", file.to_str().unwrap(), out.to_str().unwrap()])
        .args([
            "--to",
            "pbrt-v4",
            "--resolution",
            &RES.to_string(),
            "--quiet",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{}: {}",
        file.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    // The scene line names the image and the file's flux.
    let line = stdout
        .lines()
        .find(|l| l.starts_with("LightSource \"goniometric\""))
        .expect("a LightSource line");
    assert!(
        line.contains(&format!("\"string filename\" \"{}\"", out.display())),
        "{line}"
    );
    let power_text = line.rsplit(' ').next().unwrap();
    let printed_flux: f64 = power_text.parse().unwrap();
    assert_eq!(printed_flux, flux, "\"float power\" is the file's flux");
    // The quadrature error the command states.
    let err: f64 = stdout
        .split("quadrature error estimate ")
        .nth(1)
        .and_then(|t| t.split_whitespace().next())
        .and_then(|t| t.parse().ok())
        .expect("the command states its quadrature error");

    let img = if out.extension().unwrap() == "exr" {
        read_exr(out)
    } else {
        read_pfm(out)
    };
    assert_eq!(img.n, RES);
    assert!(img.pixels.iter().all(|p| p.is_finite() && *p >= 0.0));

    // Random directions (splitmix64; uniform on the sphere).
    let mut next = || {
        *rng = rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *rng;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut worst = 0.0f64;
    let tol_abs = 2.0 * err + 1e-6 * i_max;
    let mut check_direction = |w: [f64; 3]| {
        let decoded = img.pbrt_intensity(w);
        let pix = img.pixel_of(sphere_to_square([w[0], w[2], w[1]]));
        let pts = pixel_points(RES, pix, 16, false);
        let mean = pts
            .iter()
            .map(|&p| file_intensity(&diagram, p))
            .sum::<f64>()
            / pts.len() as f64;
        let e = (decoded - mean).abs();
        assert!(
            e <= tol_abs,
            "{}: direction {w:?}: decoded {decoded} but the pixel's mean intensity is {mean} \
             (allowed error {tol_abs})",
            file.display()
        );
        // Hence within the pixel-averaging error of the file's intensity in that direction.
        let grid = pixel_points(RES, pix, 8, true);
        let vals: Vec<f64> = grid.iter().map(|&p| file_intensity(&diagram, p)).collect();
        let (lo, hi) = vals
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        let here = file_intensity(&diagram, w);
        assert!(
            (decoded - here).abs() <= (hi - lo) + 0.25 * (hi - lo) + tol_abs,
            "{}: direction {w:?}: decoded {decoded}, file {here}, range over the pixel [{lo}, {hi}]",
            file.display()
        );
        worst = worst.max(e / i_max);
    };
    for _ in 0..DIRECTIONS {
        let z = 2.0 * next() - 1.0;
        let a = 2.0 * PI * next();
        let s = (1.0 - z * z).max(0.0).sqrt();
        check_direction([s * a.cos(), s * a.sin(), z]);
    }

    // The file's brightest node, placed in pbrt's light frame independently of gonio's frame:
    // type C, γ from nadir (−y), C from +x toward +z.
    if photometry.photometric_type == PhotometricType::C {
        let nv = photometry.vertical_angles_deg.len();
        let (k, _) =
            photometry
                .candela
                .iter()
                .enumerate()
                .fold(
                    (0, f64::MIN),
                    |(bk, bv), (k, &v)| if v > bv { (k, v) } else { (bk, bv) },
                );
        let (gamma, c) = (
            photometry.vertical_angles_deg[k % nv].to_radians(),
            photometry.horizontal_angles_deg[k / nv].to_radians(),
        );
        let w = [gamma.sin() * c.cos(), -gamma.cos(), gamma.sin() * c.sin()];
        check_direction(w);
    }

    // The brightest pixel lies where the file is at least that bright.
    let (bk, bval) =
        img.pixels.iter().enumerate().fold(
            (0, f32::MIN),
            |(bk, bv), (k, &v)| if v > bv { (k, v) } else { (bk, bv) },
        );
    let bpix = (bk % RES, bk / RES);
    let grid = pixel_points(RES, bpix, 16, true);
    let vals: Vec<f64> = grid.iter().map(|&p| file_intensity(&diagram, p)).collect();
    let (lo, hi) = vals
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    // The pixel's mean is at most the largest intensity over it; the grid may miss a peak between
    // its points, hence the same margin as above (a quarter of the range seen on the grid).
    assert!(
        f64::from(bval) <= hi + 0.25 * (hi - lo) + tol_abs,
        "{}: the brightest pixel ({bval}) lies where the file reaches only {hi}",
        file.display()
    );
    // Angle from the brightest pixel's centre to the file's brightest node (reported).
    let centre = pixel_points(RES, bpix, 1, false)[0];
    let node = {
        let (mut best, mut bv) = ([0.0; 3], f64::MIN);
        for (i, &phi) in diagram.phi().iter().enumerate() {
            for (j, &theta) in diagram.theta().iter().enumerate() {
                let v = diagram.value(i, j);
                if v > bv {
                    bv = v;
                    let g = gonio::sampler::direction(theta, phi);
                    best = [g[0], g[2], g[1]];
                }
            }
        }
        best
    };
    let cos = (centre[0] * node[0] + centre[1] * node[1] + centre[2] * node[2]).clamp(-1.0, 1.0);

    let power_ratio = {
        let sum: f64 = img.pixels.iter().map(|&p| f64::from(p)).sum();
        4.0 * PI * sum / (img.pixels.len() as f64) / flux
    };
    assert!(
        (power_ratio - 1.0).abs() <= 0.005,
        "{}: image power / flux = {power_ratio}",
        file.display()
    );
    Report {
        worst_mean_error: worst,
        power_ratio,
        brightest_angle_deg: cos.acos().to_degrees(),
    }
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn pbrt_images_decode_to_the_files_intensity_and_flux() {
    let corpus = corpus::built_corpus_dir();
    let tmp = std::env::temp_dir().join(format!("gonio-pbrt-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let mut files: Vec<PathBuf> = ["ies", "ldt"]
        .iter()
        .flat_map(|d| std::fs::read_dir(corpus.join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let mut rng = 0x5eed_u64;
    let (mut checked, mut type_b) = (0, 0);
    for (k, file) in files.iter().enumerate() {
        let name = file.file_name().unwrap().to_string_lossy().to_string();
        let format = FileFormat::from_path_extension(file).unwrap();
        let bytes = std::fs::read(file).unwrap();
        let Ok(p) = read(
            &bytes,
            format,
            &DirTiltResolver::new(file.parent().unwrap()),
        ) else {
            eprintln!("{name}: not a valid file (skipped: nothing to convert)");
            assert!(name.starts_with("invalid_"), "{name} should read");
            continue;
        };
        if p.photometric_type == PhotometricType::B {
            type_b += 1;
        }
        // Every third file goes through PFM, the others through EXR.
        let ext = if k % 3 == 0 { "pfm" } else { "exr" };
        let out = tmp.join(format!("{name}.{ext}"));
        let r = check_file(file, &out, &mut rng);
        println!(
            "{name} ({}, {ext}): max |decoded − pixel mean| = {:.2e}·I_max, power/flux = {:.5}, \
             brightest pixel {:.2}° from the brightest node",
            p.photometric_type, r.worst_mean_error, r.power_ratio, r.brightest_angle_deg
        );
        checked += 1;
    }
    let _ = std::fs::remove_dir_all(&tmp);
    assert!(checked >= 38, "only {checked} corpus files were checked");
    assert!(type_b >= 2, "the type B files were checked ({type_b})");
}

#[test]
fn exr_and_pfm_hold_the_same_pixels_and_bad_requests_fail() {
    let tmp = std::env::temp_dir().join(format!("gonio-pbrt2-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let run = |args: &[&str]| {
        Command::new(BIN)
            .args(args)
            .arg("--quiet")
            .output()
            .unwrap()
    };
    let (exr, pfm) = (tmp.join("a.exr"), tmp.join("a.pfm"));
    for out in [&exr, &pfm] {
        let o = run(&[
            "convert",
            "example",
            out.to_str().unwrap(),
            "--to",
            "pbrt-v4",
            "--resolution",
            "32",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (a, b) = (read_exr(&exr), read_pfm(&pfm));
    assert_eq!(a.n, 32);
    assert_eq!(a.pixels, b.pixels);
    // Not an image format, no --to for an image, a resolution out of range, --resolution alone.
    let bad = tmp.join("a.png");
    for args in [
        vec![
            "convert",
            "example",
            bad.to_str().unwrap(),
            "--to",
            "pbrt-v4",
        ],
        vec!["convert", "example", exr.to_str().unwrap()],
        vec![
            "convert",
            "example",
            exr.to_str().unwrap(),
            "--to",
            "pbrt-v4",
            "--resolution",
            "0",
        ],
        vec![
            "convert",
            "example",
            tmp.join("a.json").to_str().unwrap(),
            "--resolution",
            "8",
        ],
    ] {
        let o = run(&args);
        assert!(!o.status.success(), "{args:?} should fail");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    assert!(!bad.exists());
    let _ = std::fs::remove_dir_all(&tmp);
}
