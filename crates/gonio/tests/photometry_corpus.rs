//! The photometric corpus (`shared/data/photometry`, see its SOURCES.md): every file is read with
//! per-file expectations, its flux is checked against an independent quadrature and against
//! uniform random sampling, the node property holds for every type C file, the invalid file fails
//! on its line, and the ERCO Trion IES/LDT twins agree.
//!
//! Run with `GONIO_CORPUS=/path/to/shared/data/photometry cargo test -p gonio --test photometry_corpus`;
//! the tests print "skipping" and pass when the corpus is absent.

mod common;

use gonio::photometry::{read, FileFormat, NoTiltFiles, PhotometricType, Photometry, Symmetry};
use gonio::Diagram;
use rand::{Rng, SeedableRng};
use std::f64::consts::{PI, TAU};
use std::path::Path;

/// (file, stored vertical angles, stored horizontal planes, symmetry, expanded meridians,
/// maximum intensity in cd, flux in lm of the interpolated distribution).
#[rustfmt::skip]
const EXPECT: &[(&str, usize, usize, Symmetry, usize, f64, f64)] = &[
    ("ies/iesna91_amd_rpr_near_duplicate_angles.ies", 269, 2, Symmetry::None, 1, 48.28, 18.221),
    ("ies/iesna91_lithonia_bollard_sideways_peak.ies", 29, 1, Symmetry::Rotational, 1, 573.0, 1848.746),
    ("ies/iesna91_lithonia_commas_wrapped_header.ies", 37, 5, Symmetry::Quadrant, 16, 166.0, 33.149),
    ("ies/iesna91_mdl_type_b_minimal_2x5.ies", 2, 5, Symmetry::TypeAB { horizontal: false, vertical: false }, 360, 1.0, 3.456),
    ("ies/iesna91_nvidia_mdl_rimlight_no_final_eol.ies", 16, 1, Symmetry::Rotational, 1, 10.0, 18.845),
    ("ies/iesna95_ledalite_direct_indirect_two_lamps.ies", 73, 5, Symmetry::Quadrant, 16, 1065.2, 5296.655),
    ("ies/lm63_1986_erco_one_value_per_line_ctrlz.ies", 19, 1, Symmetry::Rotational, 1, 1500.5526, 1305.151),
    ("ies/lm63_1986_erco_par38_narrow_two_planes.ies", 73, 2, Symmetry::Quadrant, 4, 56580.0, 4055.805),
    ("ies/lm63_1986_itl_report_header_three_lamps.ies", 37, 5, Symmetry::Quadrant, 16, 1738.0, 5771.641),
    ("ies/lm63_1995_constant_half_candela_2x2.ies", 2, 2, Symmetry::BilateralC0C180, 2, 0.5, PI),
    ("ies/lm63_1995_erco_hipar_spot_latin1_header.ies", 19, 1, Symmetry::Rotational, 1, 68000.0, 4302.164),
    ("ies/lm63_1995_erco_trion_washlight_uplight.ies", 37, 13, Symmetry::BilateralC0C180, 24, 1271.94, 1778.192),
    ("ies/lm63_1995_erco_uplight_only_v0_180.ies", 37, 7, Symmetry::Quadrant, 24, 1057.8, 3197.532),
    ("ies/lm63_1995_qssi_roadway_irregular_grid.ies", 35, 35, Symmetry::BilateralC0C180, 68, 15059.66, 28338.148),
    ("ies/lm63_1995_spec_example_tilt_include.ies", 5, 3, Symmetry::Quadrant, 8, 50000.0, 84173.176),
    ("ies/lm63_2002_ael_asa_roadway_h0_180.ies", 37, 73, Symmetry::BilateralC0C180, 144, 6019.0, 9560.828),
    ("ies/lm63_2002_erco_tab_separated_spot.ies", 19, 7, Symmetry::Quadrant, 24, 11501.82, 3259.786),
    ("ies/lm63_2002_lithonia_area_full_h0_360.ies", 73, 145, Symmetry::None, 144, 5828.9767, 8654.241),
    ("ies/lm63_2002_lithonia_indx_spot_0p5deg.ies", 361, 1, Symmetry::Rotational, 1, 4616.0, 185.192),
    ("ies/lm63_2002_lithonia_par_mixed_crlf_lf.ies", 73, 5, Symmetry::Quadrant, 16, 10671.0, 5297.463),
    ("ies/lm63_2002_lithonia_type_b_flood_quadrant.ies", 45, 23, Symmetry::TypeAB { horizontal: true, vertical: false }, 360, 1215.0, 1729.725),
    ("ies/lm63_2002_lithonia_type_b_full_hm90_90.ies", 45, 45, Symmetry::TypeAB { horizontal: false, vertical: false }, 360, 216.0, 79.073),
    ("ies/lm63_2002_lithonia_wallwash_h90_270.ies", 73, 9, Symmetry::BilateralC90C270, 16, 614.0, 804.683),
    ("ies/lm63_2002_rab_wallpack_fine_irregular.ies", 199, 38, Symmetry::BilateralC0C180, 74, 245.127, 828.339),
    ("ies/lm63_2002_rzero_uvc_0p5deg_mw_per_sr.ies", 361, 9, Symmetry::BilateralC0C180, 16, 33.25, 55.348),
    ("ies/lm63_2019_nvidia_ext_lights_ies_profile.ies", 10, 1, Symmetry::Rotational, 1, 8500.0, 8749.731),
    ("ies/lm63_2019_synthetic_tilt_include.ies", 5, 3, Symmetry::Quadrant, 8, 10000.0, 20826.253),
    ("ies/lm63_2019_synthetic_type_a.ies", 5, 5, Symmetry::TypeAB { horizontal: true, vertical: true }, 360, 15000.0, 40006.617),
    ("ldt/isym0_fine_1deg_360x181.ldt", 181, 360, Symmetry::None, 360, 1087.4694, 2445.499),
    ("ldt/isym0_ledil_strada_72x181.ldt", 181, 72, Symmetry::None, 72, 157.29, 354.515),
    ("ldt/isym0_ledvance_flood_10deg_crlf.ldt", 91, 16, Symmetry::None, 16, 2241610.0, 154944.330),
    ("ldt/isym1_erco_iku_utf8_bom.ldt", 91, 1, Symmetry::Rotational, 1, 471.3405, 611.930),
    ("ldt/isym1_three_lamp_sets_synthetic.ldt", 37, 1, Symmetry::Rotational, 1, 1100.0, 452.262),
    ("ldt/isym2_anonymized_24x37.ldt", 37, 13, Symmetry::BilateralC0C180, 24, 415.4841, 333.933),
    ("ldt/isym2_erco_trion_washlight_uplight.ldt", 37, 13, Symmetry::BilateralC0C180, 24, 1271.94, 1778.199),
    ("ldt/isym3_anonymized_24x37.ldt", 37, 13, Symmetry::BilateralC90C270, 24, 426.4979, 608.408),
    ("ldt/isym3_synthetic_no_final_eol.ldt", 37, 19, Symmetry::BilateralC90C270, 36, 2866.0, 3140.825),
    ("ldt/isym4_signify_bn126c_irregular_gamma.ldt", 55, 19, Symmetry::Quadrant, 72, 2861.5722, 10002.820),
    ("ldt/isym4_two_lamp_sets_144x73.ldt", 73, 37, Symmetry::Quadrant, 144, 702.5174, 1983.277),
];

/// Real EULUMDAT measurements, whose flux must equal (first lamp set's flux) × LORL.
const LDT_FLUX_CONSISTENT: &[&str] = &[
    "ldt/isym0_fine_1deg_360x181.ldt",
    "ldt/isym0_ledil_strada_72x181.ldt",
    "ldt/isym0_ledvance_flood_10deg_crlf.ldt",
    "ldt/isym1_erco_iku_utf8_bom.ldt",
    "ldt/isym2_anonymized_24x37.ldt",
    "ldt/isym2_erco_trion_washlight_uplight.ldt",
    "ldt/isym3_anonymized_24x37.ldt",
    "ldt/isym4_signify_bn126c_irregular_gamma.ldt",
    "ldt/isym4_two_lamp_sets_144x73.ldt",
];

fn load(dir: &Path, rel: &str) -> Photometry {
    let path = dir.join(rel);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let format = FileFormat::from_path_extension(&path).unwrap();
    read(&bytes, format, &NoTiltFiles).unwrap_or_else(|e| panic!("{rel}:{e}"))
}

/// ∫ of the interpolated diagram dω by the midpoint rule on every cell split 16 × 8 (θ × φ),
/// independent of the closed form of `Diagram::integral`.
fn quadrature(d: &Diagram) -> f64 {
    let (th, ph) = (d.theta(), d.phi());
    let (kt, kp) = (16usize, 8usize);
    let mut phis = Vec::new(); // (φ, dφ)
    if ph.len() == 1 {
        phis.push((0.0, TAU));
    } else {
        for (i, &w) in d.sector_widths().iter().enumerate() {
            for q in 0..kp {
                phis.push((ph[i] + (q as f64 + 0.5) * w / kp as f64, w / kp as f64));
            }
        }
    }
    let mut total = 0.0;
    for j in 0..th.len() - 1 {
        let h = (th[j + 1] - th[j]) / kt as f64;
        for q in 0..kt {
            let t = th[j] + (q as f64 + 0.5) * h;
            let ring: f64 = phis.iter().map(|&(p, w)| d.interpolate(t, p) * w).sum();
            total += ring * t.sin() * h;
        }
    }
    total
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn every_file_meets_its_expectations() {
    let dir = common::corpus_dir();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
    for &(rel, nv, nh, sym, meridians, max_cd, flux) in EXPECT {
        let p = load(&dir, rel);
        assert_eq!(p.vertical_angles_deg.len(), nv, "{rel}");
        assert_eq!(p.horizontal_angles_deg.len(), nh, "{rel}");
        assert_eq!(p.symmetry, sym, "{rel}");
        assert!(
            (p.max_intensity_cd() / max_cd - 1.0).abs() < 1e-6,
            "{rel}: max {}",
            p.max_intensity_cd()
        );
        let d = p.to_diagram().unwrap();
        assert_eq!(d.n_meridians(), meridians, "{rel}");
        // the diagram covers a hemisphere or the sphere
        let (t0, t1) = (d.theta()[0], d.theta()[d.n_parallels() - 1]);
        assert!(
            [(0.0, PI / 2.0), (PI / 2.0, PI), (0.0, PI)]
                .iter()
                .any(|&(a, b)| (t0 - a).abs() < 1e-12 && (t1 - b).abs() < 1e-12),
            "{rel}: θ range {t0}..{t1}"
        );
        // flux: closed form vs regression value and vs an independent quadrature
        let f = p.flux_lm();
        assert!((f / flux - 1.0).abs() < 5e-4, "{rel}: flux {f} vs {flux}");
        let q = quadrature(&d);
        assert!(
            (f / q - 1.0).abs() < 0.01,
            "{rel}: closed form {f} vs quadrature {q}"
        );
        // sampled: uniform random directions estimate the same flux (5 standard errors)
        let n = 100_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let z: f64 = rng.gen_range(-1.0..1.0);
            let phi: f64 = rng.gen_range(0.0..TAU);
            let v = 4.0 * PI * d.interpolate(z.acos(), phi);
            s += v;
            s2 += v * v;
        }
        let mean = s / n as f64;
        let se = ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        assert!(
            (mean - f).abs() <= 5.0 * se + 1e-9 * f,
            "{rel}: sampled {mean} ± {se} vs {f}"
        );
    }
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn eulumdat_flux_is_lamp_flux_times_lorl() {
    let dir = common::corpus_dir();
    for rel in LDT_FLUX_CONSISTENT {
        let p = load(&dir, rel);
        let info = p.ldt.as_ref().unwrap();
        let want = p.lamp_sets[0].flux_lm * info.light_output_ratio_pct / 100.0;
        let got = p.flux_lm();
        assert!(
            (got / want - 1.0).abs() < 0.01,
            "{rel}: {got} lm vs {want} lm"
        );
    }
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn corpus_warnings_and_quirks() {
    let dir = common::corpus_dir();
    let warns = |rel: &str| load(&dir, rel).warnings;
    let has = |rel: &str, needle: &str| warns(rel).iter().any(|w| w.message.contains(needle));
    assert!(has(
        "ies/lm63_1986_erco_one_value_per_line_ctrlz.ies",
        "trailing"
    ));
    assert!(has(
        "ies/iesna95_ledalite_direct_indirect_two_lamps.ies",
        "IESNA95"
    ));
    assert!(has("ies/lm63_2002_lithonia_par_mixed_crlf_lf.ies", "POS."));
    assert!(has(
        "ldt/isym0_ledil_strada_72x181.ldt",
        "Ityp = 1 contradicts Isym = 0"
    ));
    assert!(has("ldt/isym4_two_lamp_sets_144x73.ldt", "first set"));
    let p = load(&dir, "ies/lm63_1995_spec_example_tilt_include.ies");
    let t = p.tilt.table().unwrap();
    assert_eq!((t.geometry, t.angles_deg.len()), (1, 13));
    assert_eq!(p.keyword("OTHER").unwrap().lines().count(), 3); // [MORE] ×2
    let p = load(&dir, "ies/lm63_2019_synthetic_tilt_include.ies");
    assert_eq!(p.tilt.table().unwrap().angles_deg.len(), 7);
    let p = load(&dir, "ies/lm63_1986_itl_report_header_three_lamps.ies");
    assert_eq!(p.lamp_sets[0].count, 3);
    assert_eq!(p.header.len(), 8);
    let p = load(&dir, "ldt/isym1_three_lamp_sets_synthetic.ldt");
    assert_eq!(p.lamp_sets.len(), 3);
    assert_eq!(p.intensity_scale, 0.5);
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn invalid_file_fails_with_its_line() {
    let dir = common::corpus_dir();
    let bytes = std::fs::read(dir.join("ies/invalid_iesna91_mdl_garbage_line.ies")).unwrap();
    let e = read(&bytes, FileFormat::Ies, &NoTiltFiles).unwrap_err();
    assert_eq!((e.line, e.column), (3, 1), "{e}");
    assert!(e.message.contains("file"), "{e}");
}

/// The images of stored plane angle `c` under a symmetry (independent of the library's rule).
#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn type_c_nodes_are_kept_exactly() {
    let dir = common::corpus_dir();
    let mut files = 0;
    for &(rel, ..) in EXPECT {
        let p = load(&dir, rel);
        if p.photometric_type != PhotometricType::C {
            continue;
        }
        files += 1;
        let d = p.to_diagram().unwrap();
        let nv = p.vertical_angles_deg.len();
        let nh = p.horizontal_angles_deg.len();
        let mut checked = 0;
        for (h, &c) in p.horizontal_angles_deg.iter().enumerate() {
            // a closing plane that differs from the first one is not kept (warned about)
            let closing =
                h == nh - 1 && nh > 1 && (c - p.horizontal_angles_deg[0] - 360.0).abs() < 1e-9;
            if closing && p.raw_values[..nv] != p.raw_values[h * nv..(h + 1) * nv] {
                continue;
            }
            for (k, &g) in p.vertical_angles_deg.iter().enumerate() {
                if g <= 0.0 || g >= 180.0 {
                    continue; // poles
                }
                let want = p.raw_values[h * nv + k] * p.intensity_scale;
                let theta = (180.0 - g).to_radians();
                for img in common::images(p.symmetry, c) {
                    let got = d.interpolate(theta, img.rem_euclid(360.0).to_radians());
                    assert!(
                        (got - want).abs() <= 1e-12 * want.abs(),
                        "{rel}: node γ = {g}°, C = {c}° (image {img}°): {got} vs {want}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 0, "{rel}");
    }
    assert_eq!(files, 35);
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn erco_trion_twins_agree() {
    let dir = common::corpus_dir();
    let a = load(&dir, "ies/lm63_1995_erco_trion_washlight_uplight.ies");
    let b = load(&dir, "ldt/isym2_erco_trion_washlight_uplight.ldt");
    let (da, db) = (a.to_diagram().unwrap(), b.to_diagram().unwrap());
    let (fa, fb) = (a.flux_lm(), b.flux_lm());
    let mut worst = 0.0f64;
    let mut peak = 0.0f64;
    for j in 0..=360 {
        let theta = (j as f64 * 0.5).to_radians();
        for i in 0..144 {
            let phi = (i as f64 * 2.5).to_radians();
            let (x, y) = (
                da.interpolate(theta, phi) / fa,
                db.interpolate(theta, phi) / fb,
            );
            worst = worst.max((x - y).abs());
            peak = peak.max(x);
        }
    }
    assert!(
        worst <= 1e-3 * peak,
        "normalised difference {worst} (peak {peak})"
    );
    assert!((fa / fb - 1.0).abs() < 1e-3);
}

/// ∫ I(H, V) dω over the whole (H, V) domain by the midpoint rule, in the file's own coordinates:
/// type B: H is a latitude (dω = cos H dH dV, H ∈ [−90°, 90°], V ∈ [−180°, 180°]); type A: V is a
/// latitude (dω = cos V dH dV, V ∈ [−90°, 90°], H ∈ [−180°, 180°]).
fn hv_flux(p: &Photometry) -> f64 {
    let n = 720usize; // 0.25° in the latitude, 0.5° in the longitude
    let (dl, dg) = (180.0 / n as f64, 360.0 / n as f64);
    let mut total = 0.0;
    for i in 0..n {
        let lat = -90.0 + (i as f64 + 0.5) * dl;
        let w = lat.to_radians().cos();
        for k in 0..n {
            let lon = -180.0 + (k as f64 + 0.5) * dg;
            let v = match p.photometric_type {
                PhotometricType::B => p.intensity_hv(lat, lon),
                _ => p.intensity_hv(lon, lat),
            };
            total += v * w;
        }
    }
    total * dl.to_radians() * dg.to_radians()
}

#[test]
#[cfg_attr(
    not(gonio_corpus),
    ignore = "photometric corpus not found: set GONIO_CORPUS (or put it at ../shared/data/photometry) and rebuild"
)]
fn type_b_and_a_resampling_preserves_flux_and_beam() {
    let dir = common::corpus_dir();
    let mut files = 0;
    for &(rel, ..) in EXPECT {
        let p = load(&dir, rel);
        if p.photometric_type == PhotometricType::C {
            continue;
        }
        files += 1;
        let (got, want) = (p.flux_lm(), hv_flux(&p));
        assert!(
            (got / want - 1.0).abs() < 0.01,
            "{rel}: resampled {got} lm vs (H, V) integral {want} lm"
        );
        // the brightest stored node away from the poles of the (H, V) system keeps its
        // direction and (nearly) its value
        let nv = p.vertical_angles_deg.len();
        let hv = |k: usize| {
            (
                p.horizontal_angles_deg[k / nv],
                p.vertical_angles_deg[k % nv],
            )
        };
        let pole = |k: usize| match p.photometric_type {
            PhotometricType::B => hv(k).0.abs() >= 90.0,
            _ => hv(k).1.abs() >= 90.0,
        };
        let k = (0..p.candela.len())
            .filter(|&k| !pole(k))
            .max_by(|&a, &b| p.candela[a].total_cmp(&p.candela[b]))
            .unwrap();
        let (h, v) = hv(k);
        let peak = p.candela[k];
        let dir_ = gonio::photometry::direction_of_hv(p.photometric_type, h, v);
        let (theta, phi) = gonio::sampler::spherical(dir_);
        let d = p.to_diagram().unwrap();
        let at = d.interpolate(theta, phi);
        assert!(
            (at / peak - 1.0).abs() < 0.02,
            "{rel}: at the peak (H {h}°, V {v}°) the diagram has {at} cd, the file {peak} cd"
        );
    }
    assert_eq!(files, 4);
}

/// `.ci/run` sets `GONIO_REQUIRE_CORPUS=1` when the corpus exists: then the corpus tests must
/// have been built to run, not ignored.
#[test]
fn corpus_tests_run_when_required() {
    common::assert_corpus_when_required(cfg!(gonio_corpus));
}
