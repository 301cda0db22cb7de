//! Unit tests of the readers, the expansion and the writers, on small inline texts.

use super::*;
use std::f64::consts::PI;

fn ies(text: &str) -> Result<Photometry, ParseError> {
    read(text.as_bytes(), FileFormat::Ies, &NoTiltFiles)
}

fn ldt(text: &str) -> Result<Photometry, ParseError> {
    read(text.as_bytes(), FileFormat::Eulumdat, &NoTiltFiles)
}

/// A minimal LM-63-2002 type C file with the given angles and values.
fn ies_c(vert: &str, horiz: &str, values: &str) -> String {
    let nv = vert.split_whitespace().count();
    let nh = horiz.split_whitespace().count();
    format!(
        "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 1000 1 {nv} {nh} 1 2 0 0 0\n1 1 10\n{vert}\n{horiz}\n{values}\n"
    )
}

fn has_warning(p: &Photometry, needle: &str) -> bool {
    p.warnings.iter().any(|w| w.message.contains(needle))
}

// ---------------------------------------------------------------------------------------------
// IES: versions, header, tokens

#[test]
fn ies_versions_are_recognised() {
    let body = "TILT=NONE\n1 1000 1 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n5 1\n";
    let cases = [
        ("IESNA91\n", Version::Ies1991),
        ("IESNA:LM-63-1995\n", Version::Ies1995),
        ("IESNA: LM-63-1995\n", Version::Ies1995),
        ("IESNA95\n", Version::Ies1995),
        ("IESNA:LM-63-2002\n", Version::Ies2002),
        ("IES:LM-63-2019\n", Version::Ies2019),
        (
            "Some manufacturer, free text\nanother line\n",
            Version::Ies1986,
        ),
    ];
    for (head, v) in cases {
        let p = ies(&format!("{head}{body}")).unwrap();
        assert_eq!(p.version, v, "{head:?}");
        assert_eq!(p.candela, vec![5.0, 1.0]);
    }
    let p = ies(&format!("IESNA95\n{body}")).unwrap();
    assert!(has_warning(&p, "IESNA95"));
    let p = ies(&format!("Free text header\n{body}")).unwrap();
    assert_eq!(p.header, vec!["Free text header".to_string()]);
}

#[test]
fn ies_bom_latin1_line_endings_and_separators() {
    // BOM, a Latin-1 byte in a keyword, CR-only line endings, commas, tabs, exponents, wrapping.
    let mut bytes =
        b"\xEF\xBB\xBFIESNA:LM-63-1995\r[LUMINAIRE] 10\xB0 spot\r[MORE] second line\r".to_vec();
    bytes.extend_from_slice(
        b"TILT=NONE\r1,1000,1\t3 1\r1 2 0 0 0 1 1 10\r0,4.5e1\r\n9.0E+01\n0\r\n1e2,\t50\r\n  2.5E-1\n",
    );
    let p = read(&bytes, FileFormat::Ies, &NoTiltFiles).unwrap();
    assert_eq!(p.vertical_angles_deg, vec![0.0, 45.0, 90.0]);
    assert_eq!(p.candela, vec![100.0, 50.0, 0.25]);
    let lum = p.keyword("luminaire").unwrap();
    assert!(lum.starts_with("10\u{FFFD} spot\nsecond line"), "{lum:?}");
    assert!(p.warnings.is_empty(), "{:?}", p.warnings);
}

#[test]
fn ies_garbage_names_line_and_column() {
    let e = ies("IESNA91\nTILT=NONE\nfile format error\n1 0 1 2 1 1 1 0 0 0\n").unwrap_err();
    assert_eq!((e.line, e.column), (3, 1));
    assert!(e.message.contains("`file`"), "{e}");
    let t = ies_c("0 45 90", "0", "1 2 x3");
    let e = ies(&t).unwrap_err();
    assert_eq!((e.line, e.column), (8, 5), "{e}");
    let e = ies("IESNA91\n[TEST] no tilt line\n").unwrap_err();
    assert_eq!(e.line, 0);
    let e = ies("").unwrap_err();
    assert_eq!(e.line, 0);
    // inf / nan are not numbers
    let e = ies(&ies_c("0 45 90", "0", "1 inf 3")).unwrap_err();
    assert_eq!((e.line, e.column), (8, 3));
}

#[test]
fn ies_trailing_text_is_a_warning() {
    let t = ies_c("0 90", "0", "3 1") + "END\n\x1a";
    let p = ies(&t).unwrap();
    let w = p
        .warnings
        .iter()
        .find(|w| w.message.contains("trailing"))
        .unwrap();
    assert_eq!((w.line, w.column), (9, 1));
    assert_eq!(p.candela, vec![3.0, 1.0]);
}

#[test]
fn ies_negative_values() {
    let e = ies(&ies_c("0 45 90", "0", "10 -1 0")).unwrap_err();
    assert_eq!((e.line, e.column), (8, 4));
    assert!(e.message.contains("negative"));
    let p = ies(&ies_c("0 45 90", "0", "10 -1e-9 0")).unwrap();
    assert_eq!(p.candela, vec![10.0, 0.0, 0.0]);
    assert!(has_warning(&p, "clamped"));
}

#[test]
fn ies_multipliers_are_applied() {
    // 1995: multiplier × ballast factor × ballast-lamp photometric factor.
    let t = "IESNA:LM-63-1995\nTILT=NONE\n1 1000 2 2 1 1 2 0 0 0\n0.5 0.8 10\n0 90\n0\n10 5\n";
    let p = ies(t).unwrap();
    assert!((p.intensity_scale - 0.8).abs() < 1e-15);
    assert_eq!(p.raw_values, vec![10.0, 5.0]);
    assert!((p.candela[0] - 8.0).abs() < 1e-12);
    // 2019: the second field is the file generation type and is not applied.
    let t = "IES:LM-63-2019\nTILT=NONE\n1 1000 2 2 1 1 2 0 0 0\n0.5 1.10001 10\n0 90\n0\n10 5\n";
    let p = ies(t).unwrap();
    assert_eq!(p.intensity_scale, 1.0);
    assert_eq!(p.max_intensity_cd(), 10.0);
}

#[test]
fn ies_keywords_and_more() {
    let t = "IESNA:LM-63-2002\n[TEST] a\n[MORE] b\n[_USER KEY] x y\nstray\nTILT=NONE\n1 1000 1 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n1 1\n";
    let p = ies(t).unwrap();
    assert_eq!(p.keyword("TEST"), Some("a\nb"));
    assert_eq!(p.keyword("_user key"), Some("x y"));
    assert!(has_warning(&p, "stray"));
    assert_eq!(p.header, vec!["stray".to_string()]);
}

// ---------------------------------------------------------------------------------------------
// TILT

const TILT_INCLUDE: &str = "IESNA:LM-63-2002\nTILT=INCLUDE\n1\n3\n0 45 90\n0.5 0.4 0.3\n1 1000 1 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n10 4\n";

#[test]
fn tilt_include_is_read_and_applied_at_zero() {
    let p = ies(TILT_INCLUDE).unwrap();
    let t = p.tilt.table().unwrap();
    assert_eq!(t.geometry, 1);
    assert_eq!(t.angles_deg, vec![0.0, 45.0, 90.0]);
    assert!((t.factor_at(22.5) - 0.45).abs() < 1e-12);
    assert_eq!(t.factor_at(100.0), 0.3);
    // the factor at tilt 0° is applied: 10 × 0.5
    assert_eq!(p.tilt_angle_deg, 0.0);
    assert_eq!(p.candela, vec![5.0, 2.0]);
}

struct OneTilt;
impl TiltResolver for OneTilt {
    fn resolve(&self, name: &str) -> Result<Vec<u8>, String> {
        match name {
            "lamp.tlt" => Ok(b"2\r\n2\r\n0 90\r\n0.9 0.7\r\n".to_vec()),
            "bad.tlt" => Ok(b"2\n2\n0 x\n1 1\n".to_vec()),
            _ => Err("no such file".into()),
        }
    }
}

#[test]
fn tilt_file_goes_through_the_resolver() {
    let t = |name: &str| {
        format!("IESNA91\nTILT= {name}\n1 1000 1 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n10 4\n")
    };
    let p = read(t("lamp.tlt").as_bytes(), FileFormat::Ies, &OneTilt).unwrap();
    assert!(
        matches!(&p.tilt, Tilt::File { name, table } if name == "lamp.tlt" && table.geometry == 2)
    );
    assert!((p.candela[0] - 9.0).abs() < 1e-12 && (p.candela[1] - 3.6).abs() < 1e-12);
    let e = read(t("gone.tlt").as_bytes(), FileFormat::Ies, &OneTilt).unwrap_err();
    assert_eq!((e.line, e.column), (2, 7));
    assert!(e.message.contains("gone.tlt") && e.message.contains("no such file"));
    let e = read(t("bad.tlt").as_bytes(), FileFormat::Ies, &OneTilt).unwrap_err();
    assert!(e.message.contains("3:3"), "{e}");
    let e = ies(&t("lamp.tlt")).unwrap_err();
    assert!(e.message.contains("no TILT files"), "{e}");
    // the directory resolver refuses paths
    let r = DirTiltResolver::new("/nonexistent");
    assert!(r.resolve("../x").unwrap_err().contains("plain file name"));
    assert!(r.resolve("a/b").is_err());
}

// ---------------------------------------------------------------------------------------------
// Hostile counts

#[test]
fn counts_are_capped_and_checked_against_the_data() {
    let huge = "IESNA91\nTILT=NONE\n1 1000 1 100000 100000 1 2 0 0 0\n1 1 10\n0 1 2\n";
    let e = ies(huge).unwrap_err();
    assert_eq!((e.line, e.column), (3, 10));
    assert!(e.message.contains("limit"), "{e}");
    let big = "IESNA91\nTILT=NONE\n1 1000 1 1000 1000 1 2 0 0 0\n1 1 10\n0 1 2\n";
    let e = ies(big).unwrap_err();
    assert!(e.message.contains("only 3 values follow"), "{e}");
    let over = "IESNA91\nTILT=NONE\n1 1000 1 100001 1 1 2 0 0 0\n";
    assert!(ies(over)
        .unwrap_err()
        .message
        .contains("integer from 1 to 100000"));
    let e = ies("IESNA91\nTILT=INCLUDE\n1 99999 0 1\n").unwrap_err();
    assert!(e.message.contains("TILT table declares"), "{e}");
    let e = ies("IESNA91\nTILT=NONE\n1 1000 1 1e300 1 1 2 0 0 0\n").unwrap_err();
    assert!(e.message.contains("integer"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Type C expansion

fn phis_deg(d: &crate::Diagram) -> Vec<f64> {
    d.phi()
        .iter()
        .map(|p| (p.to_degrees() * 1e9).round() / 1e9)
        .collect()
}

#[test]
fn horizontal_symmetries_expand_with_exact_nodes() {
    // rotational
    let p = ies(&ies_c("0 45 90", "0", "3 2 1")).unwrap();
    assert_eq!(p.symmetry, Symmetry::Rotational);
    let d = p.to_diagram().unwrap();
    assert_eq!(phis_deg(&d), vec![0.0]);
    assert_eq!(d.values(), &[1.0, 2.0, 3.0]); // θ ascending = γ descending
    let th: Vec<f64> = d.theta().iter().map(|t| t.to_degrees()).collect();
    assert!((th[0] - 90.0).abs() < 1e-12 && (th[2] - 180.0).abs() < 1e-12);

    // quadrant {0, 90}: the mirror images are exact nodes
    let p = ies(&ies_c("0 90", "0 90", "4 1 6 2")).unwrap();
    assert_eq!(p.symmetry, Symmetry::Quadrant);
    let d = p.to_diagram().unwrap();
    assert_eq!(phis_deg(&d), vec![0.0, 90.0, 180.0, 270.0]);
    assert_eq!(d.values(), &[1.0, 4.0, 2.0, 6.0, 1.0, 4.0, 2.0, 6.0]);

    // quadrant 0–90 with an inner plane: images at 180 − 30, 180 + 30, 360 − 30
    let p = ies(&ies_c("0 90", "0 30 90", "1 1 2 2 3 3")).unwrap();
    let d = p.to_diagram().unwrap();
    assert_eq!(
        phis_deg(&d),
        vec![0.0, 30.0, 90.0, 150.0, 180.0, 210.0, 270.0, 330.0]
    );
    let at = |c: f64| d.interpolate(FRAC_PI_2_PLUS, c.to_radians());
    for (c, v) in [
        (30.0, 2.0),
        (150.0, 2.0),
        (210.0, 2.0),
        (330.0, 2.0),
        (270.0, 3.0),
    ] {
        assert_eq!(at(c), v, "C = {c}");
    }

    // bilateral C0–C180
    let p = ies(&ies_c("0 90", "0 60 180", "1 1 2 2 3 3")).unwrap();
    assert_eq!(p.symmetry, Symmetry::BilateralC0C180);
    let d = p.to_diagram().unwrap();
    assert_eq!(phis_deg(&d), vec![0.0, 60.0, 180.0, 300.0]);
    assert_eq!(d.value(3, 0), 2.0);

    // bilateral C90–C270: image of C is 180 − C
    let p = ies(&ies_c("0 90", "90 135 180 270", "1 1 2 2 3 3 4 4")).unwrap();
    assert_eq!(p.symmetry, Symmetry::BilateralC90C270);
    let d = p.to_diagram().unwrap();
    assert_eq!(phis_deg(&d), vec![0.0, 45.0, 90.0, 135.0, 180.0, 270.0]);
    assert_eq!(d.value(0, 0), 3.0); // C0 = image of C180
    assert_eq!(d.value(1, 0), 2.0); // C45 = image of C135

    // full 0–360 with the repeated plane, and without it
    let p = ies(&ies_c("0 90", "0 120 240 360", "1 1 2 2 3 3 1 1")).unwrap();
    assert_eq!(p.symmetry, Symmetry::None);
    assert_eq!(phis_deg(&p.to_diagram().unwrap()), vec![0.0, 120.0, 240.0]);
    let p = ies(&ies_c("0 90", "0 120 240 360", "1 1 2 2 3 3 5 5")).unwrap();
    assert!(has_warning(&p, "closing plane"));
    assert_eq!(p.to_diagram().unwrap().value(0, 0), 1.0);
    let p = ies(&ies_c("0 90", "0 120 240", "1 1 2 2 3 3")).unwrap();
    assert_eq!(phis_deg(&p.to_diagram().unwrap()), vec![0.0, 120.0, 240.0]);
    // {0, 360}: one meridian
    let p = ies(&ies_c("0 90", "0 360", "1 2 1 2")).unwrap();
    assert_eq!(p.to_diagram().unwrap().n_meridians(), 1);

    // anything else is an error at the last horizontal angle
    let e = ies(&ies_c("0 90", "0 45 120", "1 1 2 2 3 3")).unwrap_err();
    assert_eq!((e.line, e.column), (7, 6), "{e}");
    assert!(e.message.contains("symmetry"));
    let e = ies(&ies_c("0 90", "0 45 45", "1 1 2 2 3 3")).unwrap_err();
    assert!(e.message.contains("strictly increasing"));
}

const FRAC_PI_2_PLUS: f64 = PI; // θ = 180° (γ = 0): any row works for the checks above

#[test]
fn vertical_ranges() {
    let range = |vert: &str, values: &str| {
        let p = ies(&ies_c(vert, "0", values)).unwrap();
        let d = p.to_diagram().unwrap();
        let th: Vec<f64> = d
            .theta()
            .iter()
            .map(|t| (t.to_degrees() * 1e9).round() / 1e9)
            .collect();
        (p, d, th)
    };
    let (_, _, th) = range("0 45 90", "1 1 1");
    assert_eq!(th, vec![90.0, 135.0, 180.0]);
    let (_, _, th) = range("90 135 180", "1 1 1");
    assert_eq!(th, vec![0.0, 45.0, 90.0]);
    let (_, _, th) = range("0 90 180", "1 1 1");
    assert_eq!(th, vec![0.0, 90.0, 180.0]);
    // 0–60: nothing added (the map completes with zero, issue 9), a warning names the rule
    let (p, d, th) = range("0 30 60", "3 2 1");
    assert_eq!(th, vec![120.0, 150.0, 180.0]);
    assert_eq!(d.values(), &[1.0, 2.0, 3.0]);
    assert!(has_warning(&p, "do not span 0–90°"));
    assert!(has_warning(
        &p,
        "no light is assumed outside the measured range"
    ));
    let (_, d, th) = range("100 170", "2 1");
    assert_eq!(th, vec![10.0, 80.0]);
    assert_eq!(d.values(), &[1.0, 2.0]);
    let (_, _, th) = range("20 120", "1 1");
    assert_eq!(th, vec![60.0, 160.0]);
    // ends within 1e-6° of 0, 90, 180 are there (no warning)
    let (p, _, th) = range("0 45 90.0000001", "1 1 1");
    assert_eq!(th, vec![90.0, 135.0, 180.0]);
    assert!(!has_warning(&p, "do not span"));
    let (_, _, th) = range("89.9999999 135 179.9999999", "1 1 1");
    assert_eq!(th, vec![0.0, 45.0, 90.0]);
    // a single vertical angle is an error
    let e = ies(&ies_c("0", "0", "1")).unwrap_err();
    assert!(e.message.contains("two vertical angles"), "{e}");
    // out of range
    let e = ies(&ies_c("0 190", "0", "1 1")).unwrap_err();
    assert_eq!((e.line, e.column), (6, 3));
}

#[test]
fn zero_distribution_gives_zero_flux_not_a_panic() {
    let p = ies(&ies_c("0 90", "0", "0 0")).unwrap();
    assert!(p.to_diagram().is_err());
    assert_eq!(p.flux_lm(), 0.0);
}

#[test]
fn flux_of_constant_lower_hemisphere() {
    let p = ies(&ies_c("0 90", "0 180", "0.5 0.5 0.5 0.5")).unwrap();
    assert!((p.flux_lm() - PI).abs() < 1e-12);
}

// ---------------------------------------------------------------------------------------------
// EULUMDAT

/// A EULUMDAT file with the given Isym, Mc, Ng, C angles, γ angles and values (one per line).
fn ldt_text(
    ityp: i64,
    isym: i64,
    mc: usize,
    c: &[f64],
    g: &[f64],
    v: &[f64],
    sets: &str,
) -> String {
    let nsets = sets.lines().count() / 6;
    let mut l: Vec<String> = vec![
        "Company".into(),
        ityp.to_string(),
        isym.to_string(),
        mc.to_string(),
        "0".into(),
        g.len().to_string(),
        "0".into(),
        "report".into(),
        "name".into(),
        "number".into(),
        "file.ldt".into(),
        "date".into(),
    ];
    for _ in 0..9 {
        l.push("0".into());
    }
    l.extend(["100", "100", "1,0", "0"].map(String::from));
    l.push(nsets.to_string());
    l.extend(sets.lines().map(String::from));
    l.extend(std::iter::repeat_n("0.5".to_string(), 10));
    l.extend(c.iter().map(|x| x.to_string()));
    l.extend(g.iter().map(|x| x.to_string()));
    l.extend(v.iter().map(|x| x.to_string().replace('.', ",")));
    l.join("\n")
}

const ONE_SET: &str = "1\nLED\n2000\n4000\n80\n20\n";

#[test]
fn ldt_isym_expansions() {
    let g = [0.0, 90.0];
    // Isym 1
    let t = ldt_text(1, 1, 1, &[0.0], &g, &[100.0, 50.0], ONE_SET);
    let p = ldt(&t).unwrap();
    assert_eq!(p.symmetry, Symmetry::Rotational);
    assert_eq!(p.intensity_scale, 2.0);
    assert_eq!(p.candela, vec![200.0, 100.0]);
    assert!(p.warnings.is_empty(), "{:?}", p.warnings);
    // Isym 2: C0–C180 of 4 planes (Mc = 4 → 3 stored)
    let c4 = [0.0, 90.0, 180.0, 270.0];
    let t = ldt_text(3, 2, 4, &c4, &g, &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0], ONE_SET);
    let d = ldt(&t).unwrap().to_diagram().unwrap();
    assert_eq!(phis_deg(&d), c4.to_vec());
    assert_eq!(d.value(3, 0), 4.0); // C270 = image of C90, × 2
                                    // Isym 3: C270 → C0 → C90
    let t = ldt_text(3, 3, 4, &c4, &g, &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0], ONE_SET);
    let p = ldt(&t).unwrap();
    assert_eq!(p.horizontal_angles_deg, vec![270.0, 0.0, 90.0]);
    let d = p.to_diagram().unwrap();
    assert_eq!(phis_deg(&d), c4.to_vec());
    assert_eq!(d.value(0, 0), 4.0); // C0
    assert_eq!(d.value(2, 0), 4.0); // C180 = image of C0
    assert_eq!(d.value(3, 0), 2.0); // C270
    assert_eq!(d.value(1, 0), 6.0); // C90
                                    // Isym 4: C0–C90 of Mc = 8
    let c8: Vec<f64> = (0..8).map(|k| k as f64 * 45.0).collect();
    let t = ldt_text(3, 4, 8, &c8, &g, &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0], ONE_SET);
    let d = ldt(&t).unwrap().to_diagram().unwrap();
    assert_eq!(phis_deg(&d), c8);
    assert_eq!(d.value(3, 1), 4.0); // C135 = image of C45
                                    // Isym 0
    let t = ldt_text(
        3,
        0,
        4,
        &c4,
        &g,
        &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0],
        ONE_SET,
    );
    let d = ldt(&t).unwrap().to_diagram().unwrap();
    assert_eq!(d.value(3, 0), 8.0);
    // Mc not a multiple of 4 for Isym 4
    let t = ldt_text(
        3,
        4,
        6,
        &[0.0, 60.0, 120.0, 180.0, 240.0, 300.0],
        &g,
        &[1.0; 4],
        ONE_SET,
    );
    let e = ldt(&t).unwrap_err();
    assert_eq!(e.line, 4);
}

#[test]
fn ldt_ityp_contradiction_lamp_sets_and_decimal_commas() {
    let sets = "1\nA\n500\nww\n1A\n10\n2\nB\n1200\nnw\n1B\n20\n";
    let c4 = [0.0, 90.0, 180.0, 270.0];
    let t = ldt_text(1, 0, 4, &c4, &[0.0, 90.0], &[1.5; 8], sets);
    let p = ldt(&t).unwrap();
    assert!(has_warning(&p, "contradicts Isym"));
    assert!(has_warning(&p, "first set"));
    assert_eq!(p.lamp_sets.len(), 2);
    assert_eq!(p.lamp_sets[1].flux_lm, 1200.0);
    assert_eq!(p.intensity_scale, 0.5);
    assert_eq!(p.raw_values[0], 1.5); // "1,5"
    assert_eq!(p.candela[0], 0.75);
    let info = p.ldt.as_ref().unwrap();
    assert_eq!(info.conversion_factor, 1.0);
    assert_eq!(info.direct_ratios, [0.5; 10]);
    // BOM + CRLF
    let crlf = format!("\u{feff}{}", t.replace('\n', "\r\n"));
    let q = ldt(&crlf).unwrap();
    assert_eq!(q.candela, p.candela);
}

#[test]
fn ldt_errors_name_lines() {
    let t = ldt_text(1, 1, 1, &[0.0], &[0.0, 90.0], &[1.0, 1.0], ONE_SET);
    let bad = t.replacen("\n1\n1\n", "\n1\nx\n", 1);
    let e = ldt(&bad).unwrap_err();
    assert_eq!((e.line, e.column), (3, 1), "{e}");
    let e = ldt(&t.replace("\n1,0\n", "\nabc\n")).unwrap_err();
    assert_eq!(e.line, 24);
    let short: String = t.lines().take(40).collect::<Vec<_>>().join("\n");
    let e = ldt(&short).unwrap_err();
    assert!(e.message.contains("end of file"), "{e}");
    let neg = ldt_text(1, 1, 1, &[0.0], &[0.0, 90.0], &[1.0, -3.0], ONE_SET);
    let e = ldt(&neg).unwrap_err();
    assert!(e.message.contains("negative"));
    assert!(ldt("").is_err());
    assert!(ldt("\n\n").is_err());
}

// ---------------------------------------------------------------------------------------------
// Types B and A

#[test]
fn type_ab_directions() {
    let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
    for t in [PhotometricType::B, PhotometricType::A] {
        assert!(close(direction_of_hv(t, 0.0, 0.0), [0.0, 0.0, -1.0]));
        assert!(close(direction_of_hv(t, 90.0, 0.0), [0.0, 1.0, 0.0]));
        assert!(close(direction_of_hv(t, 0.0, 90.0), [1.0, 0.0, 0.0]));
        for (h, v) in [(10.0, 20.0), (-35.0, 70.0), (80.0, -10.0)] {
            let d = direction_of_hv(t, h, v);
            let (h2, v2) = expand::hv_of(t, d);
            assert!(
                (h - h2).abs() < 1e-9 && (v - v2).abs() < 1e-9,
                "{t} {h} {v}"
            );
        }
    }
}

/// A type B file: a beam aimed at (H, V) = (20°, −10°), on a 2.5° grid.
fn type_b_beam(h_from_zero: bool) -> String {
    let hs: Vec<f64> = if h_from_zero {
        (0..=36).map(|k| k as f64 * 2.5).collect()
    } else {
        (-36..=36).map(|k| k as f64 * 2.5).collect()
    };
    let vs: Vec<f64> = (-36..=36).map(|k| k as f64 * 2.5).collect();
    let f = |h: f64, v: f64| {
        let (hc, vc) = if h_from_zero {
            (0.0, -10.0)
        } else {
            (20.0, -10.0)
        };
        1000.0 * (-((h - hc).powi(2) + (v - vc).powi(2)) / (2.0 * 12.0f64.powi(2))).exp()
    };
    let mut s = format!(
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 {} {} 2 2 0 0 0\n1 1 0\n",
        vs.len(),
        hs.len()
    );
    let line = |a: &[f64]| {
        a.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    s += &format!("{}\n{}\n", line(&vs), line(&hs));
    for &h in &hs {
        let row: Vec<f64> = vs.iter().map(|&v| f(h, v)).collect();
        s += &format!("{}\n", line(&row));
    }
    s
}

/// ∫ I(H, V) dω over the type B table by the midpoint rule: dω = cos H dH dV (H is a latitude).
fn type_b_flux(p: &Photometry) -> f64 {
    let (n, lo, hi) = (720, -90.0f64, 90.0f64);
    let h = (hi - lo) / n as f64;
    let mut s = 0.0;
    for i in 0..n {
        let hh = lo + (i as f64 + 0.5) * h;
        for j in 0..n {
            let vv = lo + (j as f64 + 0.5) * h;
            s += p.intensity_hv(hh, vv) * hh.to_radians().cos();
        }
    }
    s * h.to_radians() * h.to_radians()
}

#[test]
fn type_b_resampling_keeps_flux_and_beam_direction() {
    for mirror in [false, true] {
        let p = ies(&type_b_beam(mirror)).unwrap();
        assert_eq!(p.photometric_type, PhotometricType::B);
        let d = p.to_diagram().unwrap();
        assert!((d.theta()[0] - PI / 2.0).abs() < 1e-12); // lower hemisphere only
        let (f_b, f_d) = (type_b_flux(&p), d.integral());
        assert!(
            (f_d / f_b - 1.0).abs() < 0.01,
            "mirror {mirror}: {f_d} vs {f_b}"
        );
        // the beam: maximum of the diagram at the direction of (H, V) of the peak
        let (i, j) = (0..d.n_meridians())
            .flat_map(|i| (0..d.n_parallels()).map(move |j| (i, j)))
            .max_by(|a, b| d.value(a.0, a.1).total_cmp(&d.value(b.0, b.1)))
            .unwrap();
        let (t, f) = (d.theta()[j], d.phi()[i]);
        let got = [t.sin() * f.cos(), t.sin() * f.sin(), t.cos()];
        let want = direction_of_hv(PhotometricType::B, if mirror { 0.0 } else { 20.0 }, -10.0);
        let cosang: f64 = got.iter().zip(want).map(|(a, b)| a * b).sum();
        assert!(
            cosang.acos().to_degrees() < 1.0,
            "beam off by {}°",
            cosang.acos().to_degrees()
        );
        // values at a few directions equal the (H, V) interpolant up to the resampling error
        for (h, v) in [(20.0, -10.0), (10.0, 0.0), (30.0, -25.0)] {
            let dir = direction_of_hv(PhotometricType::B, h, v);
            let (th, ph) = crate::sampler::spherical(dir);
            let a = d.interpolate(th, ph);
            let b = p.intensity_hv(h, v);
            assert!(
                (a - b).abs() < 0.02 * p.max_intensity_cd(),
                "({h},{v}): {a} vs {b}"
            );
        }
    }
}

#[test]
fn type_a_mirrors_and_covers_lower_hemisphere() {
    let t = "IES:LM-63-2019\nTILT=NONE\n1 -1 1 3 3 3 2 0 0 0\n1 1 0\n0 45 90\n0 45 90\n9 6 3\n6 4 2\n3 2 1\n";
    let p = ies(t).unwrap();
    assert_eq!(
        p.symmetry,
        Symmetry::TypeAB {
            horizontal: true,
            vertical: true
        }
    );
    assert_eq!(p.intensity_hv(-45.0, -45.0), 4.0);
    assert_eq!(p.intensity_hv(45.0, 45.0), 4.0);
    let d = p.to_diagram().unwrap();
    assert!((d.interpolate(PI, 0.0) - 9.0).abs() < 1e-9); // nadir = (H, V) = (0, 0)
}

// ---------------------------------------------------------------------------------------------
// Writers: read(write(d)) = d

fn random_diagram(rng: &mut impl rand::Rng) -> crate::Diagram {
    let range = match rng.gen_range(0..3) {
        0 => (0.0, 90.0),
        1 => (90.0, 180.0),
        _ => (0.0, 180.0),
    };
    let n = rng.gen_range(2..12);
    let mut theta: Vec<f64> = (0..n).map(|_| rng.gen_range(range.0..range.1)).collect();
    theta[0] = range.0;
    theta[1] = range.1;
    theta.sort_by(f64::total_cmp);
    theta.dedup();
    let m = rng.gen_range(1..9);
    let mut phi: Vec<f64> = (0..m).map(|_| rng.gen_range(0.0..360.0)).collect();
    if rng.gen_bool(0.5) {
        phi[0] = 0.0;
    }
    phi.sort_by(f64::total_cmp);
    phi.dedup();
    let values: Vec<Vec<f64>> = phi
        .iter()
        .map(|_| {
            theta
                .iter()
                .map(|_| match rng.gen_range(0..4) {
                    0 => 0.0,
                    1 => rng.gen_range(0.0..1e-3),
                    2 => rng.gen_range(0.0..1e6),
                    _ => rng.gen_range(0.0..100.0f64).round(),
                })
                .collect()
        })
        .collect();
    let mut values = values;
    values[0][0] = 1.0; // never all zero
    crate::Diagram::from_degrees(&theta, &phi, &values).unwrap()
}

fn assert_same(a: &crate::Diagram, b: &crate::Diagram, what: &str) {
    assert_eq!(a.values(), b.values(), "{what}");
    for (x, y) in a
        .theta()
        .iter()
        .zip(b.theta())
        .chain(a.phi().iter().zip(b.phi()))
    {
        assert!((x - y).abs() < 1e-12, "{what}: angle {x} vs {y}");
    }
    assert_eq!(
        (a.n_parallels(), a.n_meridians()),
        (b.n_parallels(), b.n_meridians())
    );
}

#[test]
fn writers_round_trip_random_diagrams() {
    use rand::SeedableRng;
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(0x9e3779b9);
    let meta = WriteMeta::default();
    for k in 0..300 {
        let d = random_diagram(&mut rng);
        let text = write_ies(&d, &meta);
        let p = ies(&text).unwrap_or_else(|e| panic!("#{k}: {e}\n{text}"));
        assert_eq!(p.version, Version::Ies2019);
        // A first meridian other than 0° is written as it is (and read back with a warning).
        let unusual = p.warnings.iter().any(|w| !w.message.contains("not 0°"));
        assert!(!unusual, "#{k}: {:?}", p.warnings);
        assert_same(&p.to_diagram().unwrap(), &d, &format!("IES #{k}"));
        let text = write_ldt(&d, &meta);
        let p = ldt(&text).unwrap_or_else(|e| panic!("#{k}: {e}\n{text}"));
        assert!(p.warnings.is_empty(), "#{k}: {:?}", p.warnings);
        assert_same(&p.to_diagram().unwrap(), &d, &format!("LDT #{k}"));
    }
}

#[test]
fn format_from_extension() {
    use std::path::Path;
    assert_eq!(
        FileFormat::from_path_extension(Path::new("a/b.IES")),
        Some(FileFormat::Ies)
    );
    assert_eq!(
        FileFormat::from_path_extension(Path::new("b.ldt")),
        Some(FileFormat::Eulumdat)
    );
    assert_eq!(FileFormat::from_path_extension(Path::new("b.txt")), None);
    assert_eq!(FileFormat::from_path_extension(Path::new("ies")), None);
}

// ---------------------------------------------------------------------------------------------
// Hostile input: random mutations of valid files never panic

#[test]
fn mutated_files_never_panic() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(42);
    let c4 = [0.0, 90.0, 180.0, 270.0];
    let seeds: Vec<(FileFormat, String)> = vec![
        (FileFormat::Ies, ies_c("0 45 90", "0 90", "1 2 3 4 5 6")),
        (FileFormat::Ies, TILT_INCLUDE.to_string()),
        (FileFormat::Ies, type_b_beam(true)),
        (
            FileFormat::Eulumdat,
            ldt_text(
                3,
                3,
                4,
                &c4,
                &[0.0, 90.0],
                &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0],
                ONE_SET,
            ),
        ),
    ];
    let alphabet = b"0123456789.-+eE, \t\r\n[]=TILTNONEINCLUDE\x00\xff";
    for (format, text) in &seeds {
        for _ in 0..400 {
            let mut b = text.as_bytes().to_vec();
            for _ in 0..rng.gen_range(1..6) {
                let i = rng.gen_range(0..b.len());
                match rng.gen_range(0..3) {
                    0 => b[i] = alphabet[rng.gen_range(0..alphabet.len())],
                    1 => {
                        b.remove(i);
                    }
                    _ => b.insert(i, alphabet[rng.gen_range(0..alphabet.len())]),
                }
                if b.is_empty() {
                    b.push(b'1');
                }
            }
            if let Ok(p) = read(&b, *format, &OneTilt) {
                let _ = p.flux_lm();
                let _ = p.max_intensity_cd();
            }
        }
    }
}

#[test]
fn inconsistent_public_fields_do_not_panic() {
    let mut p = ies(&ies_c("0 45 90", "0", "1 2 3")).unwrap();
    p.candela.pop();
    assert!(p.to_diagram().is_err());
    p.horizontal_angles_deg.clear();
    assert!(p.to_diagram().is_err());
    let big = ies(&ies_c("0 90", "0", "1e308 1")).unwrap();
    assert!(big.to_diagram().is_ok());
    let t = "IESNA91\nTILT=NONE\n1 1000 10 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n1e308 1\n";
    // 1e308 × 10 overflows: the error names the value's line and column.
    let e = ies(t).unwrap_err();
    assert_eq!((e.line, e.column), (7, 1), "{e}");
}

#[test]
fn dir_tilt_resolver_reads_next_to_the_file() {
    let dir = std::env::temp_dir().join(format!("gonio-tilt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("t.tlt"), "1\n2\n0 90\n0.5 0.5\n").unwrap();
    let r = DirTiltResolver::new(&dir);
    let t = "IESNA91\nTILT=t.tlt\n1 1000 1 2 1 1 2 0 0 0\n1 1 10\n0 90\n0\n10 4\n";
    let p = read(t.as_bytes(), FileFormat::Ies, &r).unwrap();
    assert_eq!(p.candela, vec![5.0, 2.0]);
    let e = read(
        t.replace("t.tlt", "absent.tlt").as_bytes(),
        FileFormat::Ies,
        &r,
    )
    .unwrap_err();
    assert_eq!((e.line, e.column), (2, 6));
    assert!(e.message.contains("absent.tlt"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------------------------
// Extreme intensities times the file's scale factors

#[test]
fn candela_near_the_largest_double_times_a_multiplier_is_a_located_error() {
    // 1e308 cd is read as it is (finite) and the map of it is the map of any other scale.
    let p = ies(&ies_c("0 45 90", "0", "1e308 5e307 1e307")).unwrap();
    assert_eq!(p.candela[0], 1e308);
    let d = p.to_diagram().unwrap();
    let small = ies(&ies_c("0 45 90", "0", "10 5 1"))
        .unwrap()
        .to_diagram()
        .unwrap();
    let (a, b) = (
        crate::SphereMap::new(&d).unwrap(),
        crate::SphereMap::new(&small).unwrap(),
    );
    use crate::Sampler;
    for u in [[0.1, 0.2], [0.5, 0.5], [0.9, 0.7]] {
        let (sa, sb) = (a.sample(u), b.sample(u));
        assert!(sa.pdf.is_finite() && sa.pdf > 0.0);
        assert!(
            (sa.pdf - sb.pdf).abs() <= 1e-12 * sb.pdf,
            "{u:?}: {} vs {}",
            sa.pdf,
            sb.pdf
        );
    }
    // × a multiplier of 10, the second value (5e307 × 10) overflows: an error at its token
    // (line 8, column 7), not infinity in the candela values.
    let t = "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 1000 10 3 1 1 2 0 0 0\n1 1 10\n0 45 90\n0\n1e307 5e307 1e306\n";
    let e = ies(t).unwrap_err();
    assert_eq!((e.line, e.column), (8, 7), "{e}");
    assert!(
        e.message.contains("intensity #2") && e.message.contains("overflows"),
        "{e}"
    );
    // EULUMDAT: cd/klm × flux/1000 overflows at the first value.
    let g = [0.0, 90.0];
    let t = ldt_text(
        1,
        1,
        1,
        &[0.0],
        &g,
        &[1e307, 1.0],
        "1\nLED\n1e6\n4000\n80\n20\n",
    );
    let e = ldt(&t).unwrap_err();
    assert!(e.line > 0, "located: {e}");
    assert!(
        e.message.contains("intensity #1") && e.message.contains("overflows"),
        "{e}"
    );
}

// Issue 16: TILT factor 0, aggregated warnings, UTF-16, format from the content

#[test]
fn tilt_factor_zero_is_kept_and_leaves_no_light() {
    let text = TILT_INCLUDE.replace("0.5 0.4 0.3", "0 0.4 0.3");
    let p = ies(&text).unwrap();
    // The file's factor is kept: every intensity is 0, not the file's values times 1.
    assert!(p.candela.iter().all(|&c| c == 0.0), "{:?}", p.candela);
    assert!(has_warning(&p, "TILT factor at 0° is 0"));
    // No light: expanding to a diagram is a typed error (zero total power).
    assert!(matches!(
        p.to_diagram(),
        Err(crate::DiagramError::ZeroPower)
    ));
}

#[test]
fn repeated_warnings_are_aggregated_with_a_count() {
    // As many orphan lines as the header may hold (MAX_HEADER_LINES, with the first line and
    // the [TEST] line).
    let n = MAX_HEADER_LINES - 2;
    let orphans = "[MORE] orphan\n".repeat(n);
    let text = ies_c("0 90", "0", "5 1").replacen("[TEST] t\n", &format!("{orphans}[TEST] t\n"), 1);
    let p = ies(&text).unwrap();
    let more: Vec<&Warning> = p
        .warnings
        .iter()
        .filter(|w| w.message.contains("[MORE]"))
        .collect();
    assert_eq!(
        more.len(),
        1,
        "{:?}",
        &p.warnings[..p.warnings.len().min(3)]
    );
    assert_eq!(more[0].line, 2);
    assert!(
        more[0].message.contains(&format!(
            "(and {} more like it, the last at line {})",
            n - 1,
            n + 1
        )),
        "{}",
        more[0].message
    );
    // The issue's 200,000 orphan lines: a header that long is refused with one located error.
    let orphans = "[MORE] orphan\n".repeat(200_000);
    let text = ies_c("0 90", "0", "5 1").replacen("[TEST] t\n", &format!("{orphans}[TEST] t\n"), 1);
    let e = ies(&text).unwrap_err();
    assert!(e.message.contains("no `TILT=` line"), "{e}");
    assert_eq!(e.line, MAX_HEADER_LINES + 2);
}

#[test]
fn utf16_is_named() {
    let text = ies_c("0 90", "0", "5 1");
    for (bom, le) in [
        (&[0xffu8, 0xfe][..], true),
        (&[0xfe, 0xff][..], false),
        (&[][..], true),
    ] {
        let mut bytes = bom.to_vec();
        for c in text.encode_utf16() {
            bytes.extend(if le { c.to_le_bytes() } else { c.to_be_bytes() });
        }
        let e = read(&bytes, FileFormat::Ies, &NoTiltFiles).unwrap_err();
        assert!(e.message.contains("UTF-16"), "{e}");
        assert_eq!((e.line, e.column), (1, 1));
        assert_eq!(FileFormat::detect(&bytes), None);
    }
}

#[test]
fn format_is_detected_from_the_content() {
    assert_eq!(
        FileFormat::detect(ies_c("0 90", "0", "5 1").as_bytes()),
        Some(FileFormat::Ies)
    );
    // LM-63-1986: free text, then TILT=.
    assert_eq!(
        FileFormat::detect(b"Acme lamp\nTILT=NONE\n1 1000 1 2 1 1 2 0 0 0\n"),
        Some(FileFormat::Ies)
    );
    let d = crate::synthetic::example_luminaire();
    let ldt_text = write_ldt(&d, &WriteMeta::default());
    assert_eq!(
        FileFormat::detect(ldt_text.as_bytes()),
        Some(FileFormat::Eulumdat)
    );
    let mut bom = b"\xef\xbb\xbf".to_vec();
    bom.extend(ldt_text.as_bytes());
    assert_eq!(FileFormat::detect(&bom), Some(FileFormat::Eulumdat));
    assert_eq!(FileFormat::detect(b"{\"theta_deg\": []}"), None);
    assert_eq!(FileFormat::detect(b""), None);
}

// Issue 25: all-NUL and UTF-32 files are named as what they are, not "UTF-16".
#[test]
fn nul_and_utf32_files_are_not_called_utf16() {
    let text = "IESNA:LM-63-2002\nTILT=NONE\n";
    let utf32le: Vec<u8> = text.bytes().flat_map(|b| [b, 0, 0, 0]).collect();
    let utf32be: Vec<u8> = text.bytes().flat_map(|b| [0, 0, 0, b]).collect();
    let mut bom32 = vec![0xff, 0xfe, 0, 0];
    bom32.extend(&utf32le);
    let utf16le: Vec<u8> = text.bytes().flat_map(|b| [b, 0]).collect();
    let cases: [(&[u8], &str); 5] = [
        (&[0u8; 100], "all NUL"),
        (&utf32le, "UTF-32LE without"),
        (&utf32be, "UTF-32BE without"),
        (&bom32, "UTF-32LE, byte-order mark"),
        (&utf16le, "UTF-16LE without"),
    ];
    for (bytes, want) in cases {
        for format in [FileFormat::Ies, FileFormat::Eulumdat] {
            let e = read(bytes, format, &NoTiltFiles).unwrap_err();
            assert!(e.message.contains(want), "{want}: {e}");
            assert_eq!((e.line, e.column), (1, 1));
        }
    }
    assert_eq!(not_text(b"IESNA:LM-63-2002\n"), None);
    assert_eq!(not_text(b""), None);
}
