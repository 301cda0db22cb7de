use super::*;
use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
use gonio::{Diagram, HemisphereMap, MapRef, Method, Sampler, SphereMap};
use std::path::PathBuf;

/// A fresh directory under the system temp dir for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gonio-plot-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn hemisphere() -> (Diagram, HemisphereMap) {
    let d = random_hemisphere(Family::Lobes, 7, 6, false, 3);
    let m = HemisphereMap::new(&d).unwrap();
    (d, m)
}

fn input<'a>(
    title: &str,
    d: &'a Diagram,
    s: &'a dyn Sampler,
    map: Option<MapRef<'a>>,
    photometric: bool,
) -> PlotInput<'a> {
    PlotInput {
        title: title.to_string(),
        diagram: d,
        sampler: s,
        map,
        samples: 3000,
        seed: 1,
        photometric,
        hv_photometry: None,
    }
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.len() > 24, "PNG too short");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "not a PNG");
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

/// Renders every kind of `input` as PNG and SVG in a fresh directory named after `tag`, checks
/// the files, and removes the directory.
fn check_all_kinds(tag: &str, input: &PlotInput) {
    let dir = temp_dir(tag);
    for kind in PlotKind::ALL {
        let (w, h) = (640, 480);
        let png = dir.join(format!("{tag}-{kind}.png"));
        render(kind, input, &png, w, h).unwrap_or_else(|e| panic!("{kind} png: {e:#}"));
        let bytes = std::fs::read(&png).unwrap();
        assert_eq!(png_size(&bytes), (w, h), "{kind}");
        let svg = dir.join(format!("{tag}-{kind}.svg"));
        render(kind, input, &svg, w, h).unwrap_or_else(|e| panic!("{kind} svg: {e:#}"));
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.starts_with("<svg"), "{kind}: not an SVG");
        assert!(
            text.contains(&input.title),
            "{kind}: title missing from the SVG"
        );
        assert!(text.contains("</svg>"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_kind_renders_a_hemisphere_map() {
    let (d, m) = hemisphere();
    let inp = input("tiny-hemi", &d, &m, Some(MapRef::Hemisphere(&m)), false);
    check_all_kinds("hemi", &inp);
}

#[test]
fn every_kind_renders_a_sphere_map_photometric() {
    let d = example_luminaire();
    let m = SphereMap::new(&d).unwrap();
    let inp = input("tiny-sphere", &d, &m, Some(MapRef::Sphere(&m)), true);
    check_all_kinds("sphere", &inp);
}

#[test]
fn every_kind_renders_a_baseline() {
    let (d, _) = hemisphere();
    let b = gonio::Method::Bilinear
        .build(&d, gonio::Domain::Hemisphere)
        .unwrap();
    let inp = input("tiny-bilinear", &d, b.as_ref(), None, false);
    check_all_kinds("baseline", &inp);
}

#[test]
fn unsupported_extension_is_an_error() {
    let dir = temp_dir("ext");
    let (d, m) = hemisphere();
    let inp = input("x", &d, &m, Some(MapRef::Hemisphere(&m)), false);
    for name in ["out.jpg", "out", "out.pdf"] {
        let err = render(PlotKind::Polar, &inp, &dir.join(name), 400, 300).unwrap_err();
        assert!(err.to_string().contains(".png or .svg"), "{err}");
        assert!(!dir.join(name).exists());
    }
    // Upper-case extensions are fine.
    render(PlotKind::Polar, &inp, &dir.join("OUT.PNG"), 400, 300).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_size_and_zero_samples_are_errors() {
    let dir = temp_dir("size");
    let (d, m) = hemisphere();
    let inp = input("x", &d, &m, Some(MapRef::Hemisphere(&m)), false);
    assert!(render(PlotKind::Polar, &inp, &dir.join("a.png"), 10, 10).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn kinds_parse_and_print() {
    for k in PlotKind::ALL {
        assert_eq!(k.as_str().parse::<PlotKind>().unwrap(), k);
        assert_eq!(k.to_string(), k.as_str());
    }
    assert_eq!("Density".parse::<PlotKind>().unwrap(), PlotKind::Density);
    let e = "histogram".parse::<PlotKind>().unwrap_err();
    assert!(e.to_string().contains("polar, warp, density, ratio"));
}

#[test]
fn histogram_of_the_hds_map_matches_its_pdf() {
    let (d, m) = hemisphere();
    let inp = input("x", &d, &m, Some(MapRef::Hemisphere(&m)), false);
    let n = 200_000;
    let h = density::histogram(&inp, n, 24, 8);
    assert_eq!(h.outside, 0);
    assert_eq!(h.counts.iter().sum::<u64>(), n as u64);
    // The cell averages of the pdf integrate to ≈ 1 over the hemisphere.
    let total: f64 = h.pdf.iter().sum::<f64>() * h.grid.cell_solid_angle();
    assert!((total - 1.0).abs() < 0.02, "∫pdf = {total}");
    // χ² per cell near 1.
    let (mut chi2, mut dof) = (0.0, 0);
    for k in 0..h.grid.len() {
        let e = h.expected(k);
        if e >= 5.0 {
            chi2 += (h.counts[k] as f64 - e).powi(2) / e;
            dof += 1;
        }
    }
    assert!(chi2 / (dof as f64) < 2.0, "χ²/dof = {}", chi2 / dof as f64);
}

#[test]
fn ratio_of_the_hds_map_lies_within_its_bound() {
    let (d, m) = hemisphere();
    let inp = input("x", &d, &m, Some(MapRef::Hemisphere(&m)), false);
    let grid = grid::Grid::new(gonio::Domain::Hemisphere, 60, 20);
    let (lo, hi) = m.ratio_bound();
    for r in ratio::ratio_grid(&inp, &grid) {
        if r.is_finite() {
            assert!(
                r >= lo * (1.0 - 1e-9) && r <= hi * (1.0 + 1e-9),
                "{r} ∉ [{lo}, {hi}]"
            );
        } else {
            assert!(r.is_nan(), "pdf > 0 where the target is 0");
        }
    }
}

#[test]
fn numbers_format_briefly() {
    assert_eq!(fmt_num(1200.0), "1200");
    assert_eq!(fmt_num(0.25), "0.25");
    assert_eq!(fmt_num(1.0), "1");
    assert_eq!(fmt_num(0.123456), "0.123");
    assert_eq!(nice_step(230.0), 250.0);
    assert_eq!(nice_step(0.9), 1.0);
}

/// Writes the README gallery into `docs/gallery/` through [`run`], exactly as the commands in
/// `docs/GALLERY.md` do (run with `cargo test -p gonio-cli --release write_gallery -- --ignored`).
#[test]
#[ignore]
fn write_gallery() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = root.join("docs/gallery");
    std::fs::create_dir_all(&out).unwrap();
    // The hemisphere example: a synthetic diagram of lobes, stored next to the pictures.
    let hemi = random_hemisphere(Family::Lobes, 10, 12, false, 7);
    let json = out.join("lobes.json");
    std::fs::write(
        &json,
        serde_json::to_string_pretty(&hemi.to_json()).unwrap() + "\n",
    )
    .unwrap();
    for (input, tag) in [
        ("example".to_string(), "example"),
        (json.to_str().unwrap().to_string(), "lobes"),
    ] {
        for kind in PlotKind::ALL {
            let (width, height) = kind.default_size();
            let path = out.join(format!("{tag}-{kind}.png"));
            let args = PlotArgs {
                input: input.clone(),
                output: path.clone(),
                kind: match kind {
                    PlotKind::Polar => crate::args::PlotKind::Polar,
                    PlotKind::Warp => crate::args::PlotKind::Warp,
                    PlotKind::Density => crate::args::PlotKind::Density,
                    PlotKind::Ratio => crate::args::PlotKind::Ratio,
                },
                samples: Some(kind.default_samples()),
                seed: 0,
                method: crate::args::MethodName::Hds,
                brdf: Default::default(),
                width: Some(width),
                height: Some(height),
            };
            let t = std::time::Instant::now();
            run(&args, &Default::default()).unwrap();
            let size = std::fs::metadata(&path).unwrap().len();
            eprintln!(
                "{} {} bytes in {:.2} s",
                path.display(),
                size,
                t.elapsed().as_secs_f64()
            );
            assert!(
                size < 300_000,
                "{} is too large for the README",
                path.display()
            );
        }
    }
}

#[test]
fn run_draws_the_example_and_a_json_hemisphere() {
    let dir = temp_dir("run");
    let json = dir.join("lobe.json");
    std::fs::write(
        &json,
        r#"{"theta_deg":[0,30,60,90],"phi_deg":[0,90,180,270],
            "values":[[4,3,1,0],[4,2,1,0],[4,1,0.5,0],[4,2,1,0]]}"#,
    )
    .unwrap();
    for (input, method, kind, out) in [
        (
            "example",
            Method::Hds,
            crate::args::PlotKind::Ratio,
            "ex.png",
        ),
        (
            "example",
            Method::Uniform,
            crate::args::PlotKind::Warp,
            "ex.svg",
        ),
        (
            json.to_str().unwrap(),
            Method::Hds,
            crate::args::PlotKind::Warp,
            "j.png",
        ),
        (
            json.to_str().unwrap(),
            Method::Bilinear,
            crate::args::PlotKind::Density,
            "j.svg",
        ),
    ] {
        let args = PlotArgs {
            input: input.to_string(),
            output: dir.join(out),
            kind,
            samples: Some(2000),
            seed: 3,
            method: match method {
                Method::Bilinear => crate::args::MethodName::Bilinear,
                _ => crate::args::MethodName::Hds,
            },
            brdf: Default::default(),
            width: Some(800),
            height: Some(500),
        };
        run(&args, &Default::default())
            .unwrap_or_else(|e| panic!("{input} {method} {kind:?}: {e:#}"));
        assert!(std::fs::metadata(dir.join(out)).unwrap().len() > 1000);
    }
    // Nothing but the outputs (and the input) is left behind: no temporary files.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 5);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 16: a type B file is drawn in its own H = 0° and V = 0° planes, from the measured
/// (H, V) table, not as C-plane cuts of the resampled diagram.
#[test]
fn polar_draws_type_b_in_its_h_and_v_planes() {
    use gonio::photometry::{read, FileFormat, NoTiltFiles, PhotometricType};
    // Type B (photometric type 2), H in [-90, 90], V in [-90, 90]; I = 200 − |V| − 0.5 |H| + 0.1 V.
    let v = [-90.0, -45.0, 0.0, 45.0, 90.0];
    let h = [-90.0, -30.0, 0.0, 30.0, 90.0];
    let mut values = String::new();
    for hh in h {
        for vv in v {
            values += &format!("{} ", 200.0 - f64::abs(vv) - 0.5 * f64::abs(hh) + 0.1 * vv);
        }
        values.push('\n');
    }
    let text = format!(
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 5 5 2 2 0 0 0\n1 1 10\n-90 -45 0 45 90\n-90 -30 0 30 90\n{values}"
    );
    let p = read(text.as_bytes(), FileFormat::Ies, &NoTiltFiles).unwrap();
    assert_eq!(p.photometric_type, PhotometricType::B);
    let d = p.to_diagram().unwrap();
    let map = SphereMap::new(&d).unwrap();
    let mut inp = input("type B", &d, &map, Some(MapRef::Sphere(&map)), true);
    inp.hv_photometry = Some(&p);
    let thetas: Vec<f64> = (90..=180)
        .step_by(5)
        .map(|t| (t as f64).to_radians())
        .collect();
    let [vplane, hplane] = polar::curves(&inp, &thetas);
    for (k, &t) in thetas.iter().enumerate() {
        let a = 180.0 - t.to_degrees();
        assert_eq!(vplane.0[k], p.intensity_hv(0.0, a));
        assert_eq!(vplane.1[k], p.intensity_hv(0.0, -a));
        assert_eq!(hplane.0[k], p.intensity_hv(a, 0.0));
        assert_eq!(hplane.1[k], p.intensity_hv(-a, 0.0));
    }
    // The measured nodes appear exactly: V = 45° on the right of the H = 0° plane (θ = 135°).
    let k = thetas
        .iter()
        .position(|&t| (t.to_degrees() - 135.0).abs() < 1e-9)
        .unwrap();
    assert!(
        (vplane.0[k] - (200.0 - 45.0 + 4.5)).abs() < 1e-9,
        "{}",
        vplane.0[k]
    );
    assert!(
        (vplane.1[k] - (200.0 - 45.0 - 4.5)).abs() < 1e-9,
        "{}",
        vplane.1[k]
    );
    // The picture says which planes it shows.
    let dir = temp_dir("polar-b");
    let svg = dir.join("b.svg");
    render(PlotKind::Polar, &inp, &svg, 800, 700).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("H = 0°") && text.contains("V = 0°"), "legend");
    // Without the photometry the same diagram is drawn in its C planes.
    inp.hv_photometry = None;
    let [c0, _] = polar::curves(&inp, &thetas);
    assert_eq!(c0.0[k], d.interpolate(thetas[k], 0.0));
}
