//! Issue 9, "never invent light, never drop it": every case of the issue as a regression test, and
//! property tests over random θ lists (endpoints perturbed by up to 1e-9°), random partial ranges
//! and random scales of values.
//!
//! For every map the test measures, exactly from the map's tables, the probability of the samples
//! outside the data's measured θ range (`probability_outside_measured`, ≤ 1e-6 required; the
//! construction gives ≤ ~2e-7) and the ratio of the map's power to the data's integral (within
//! 1e-6 of 1), and checks with real samples that none lands outside the measured range beyond the
//! allowance, that every sample is finite and that `sample()` and `pdf()` agree.

use gonio::diagram::DiagramError;
use gonio::photometry::{read, write_ies, write_ldt, FileFormat, NoTiltFiles, WriteMeta};
use gonio::sampler::{normalize, spherical};
use gonio::{Diagram, HemisphereMap, Sampler, SphereMap};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::FRAC_PI_2;

/// Methods of [`Map`] that ask the same of either map: `name: call -> type`.
macro_rules! delegate {
    ($($name:ident: $f:ident() $(.$g:ident())? -> $t:ty),* $(,)?) => {
        $(fn $name(&self) -> $t {
            match self {
                Map::H(m) => m.$f()$(.$g())?,
                Map::S(m) => m.$f()$(.$g())?,
            }
        })*
    };
}

/// The map the domain policy picks: hemisphere when the diagram lies in θ ≤ 90°, else sphere.
#[allow(clippy::large_enum_variant)]
enum Map {
    H(HemisphereMap),
    S(SphereMap),
}

impl Map {
    fn of(d: &Diagram) -> Map {
        if *d.theta().last().unwrap() <= FRAC_PI_2 {
            Map::H(HemisphereMap::new(d).unwrap())
        } else {
            Map::S(SphereMap::new(d).unwrap())
        }
    }
    fn sampler(&self) -> &dyn Sampler {
        match self {
            Map::H(m) => m,
            Map::S(m) => m,
        }
    }
    delegate! {
        outside: probability_outside_measured() -> f64,
        power_ratio: power_ratio() -> f64,
        target_power: target_power() -> f64,
        normalised_target_power: normalised_target_power() -> f64,
        measured: measured_theta() -> (f64, f64),
        completions: completions().len() -> usize,
        bound: ratio_bound() -> (f64, f64),
    }
}

fn json(theta: &[f64], rows: &[Vec<f64>]) -> Diagram {
    let phi: Vec<f64> = (0..rows.len())
        .map(|i| 360.0 * i as f64 / rows.len() as f64)
        .collect();
    Diagram::from_degrees(theta, &phi, rows).unwrap()
}

/// Samples of an iid stream (fixed seed) outside the measured range, and checks every sample.
fn sampled_outside(map: &Map, n: usize, seed: u64) -> usize {
    let s = map.sampler();
    let (lo, hi) = map.measured();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut out = 0;
    for _ in 0..n {
        let u = [rng.gen::<f64>(), rng.gen::<f64>()];
        let smp = s.sample(u);
        assert!(
            smp.direction.iter().all(|c| c.is_finite()) && smp.pdf.is_finite() && smp.pdf > 0.0,
            "u {u:?} gives {smp:?}"
        );
        let p = s.pdf(smp.direction);
        assert!(
            (p - smp.pdf).abs() <= 1e-9 * p.max(smp.pdf),
            "u {u:?}: sample pdf {} vs pdf() {p}",
            smp.pdf
        );
        let (t, _) = spherical(smp.direction);
        if !(t >= lo - 1e-12 && t <= hi + 1e-12) {
            out += 1;
        }
    }
    out
}

/// The issue's acceptance: ≤ 1e-6 of the probability outside, power = data integral to 1e-6,
/// finite bound; no sample of 20 000 outside (expected count ≤ 0.004 at 2e-7).
fn assert_conserves(d: &Diagram, what: &str) -> Map {
    check_map(Map::of(d), d, what)
}

/// [`assert_conserves`] on the sphere map (the domain of photometric files).
fn assert_conserves_sphere(d: &Diagram, what: &str) -> Map {
    check_map(Map::S(SphereMap::new(d).unwrap()), d, what)
}

fn check_map(map: Map, d: &Diagram, what: &str) -> Map {
    let out = map.outside();
    assert!((0.0..=1e-6).contains(&out), "{what}: P(outside) = {out:e}");
    let ratio = map.power_ratio();
    assert!(
        (ratio - 1.0).abs() <= 1e-6,
        "{what}: map power / data = {ratio}"
    );
    let rel = map.normalised_target_power() / d.normalised_integral() - 1.0;
    assert!(
        rel.abs() <= 1e-12,
        "{what}: target power vs data integral {rel:e}"
    );
    let (lo, hi) = map.bound();
    assert!(
        lo.is_finite() && hi.is_finite() && lo > 0.0 && hi >= lo,
        "{what}: bound {lo} {hi}"
    );
    let n_out = sampled_outside(&map, 20_000, 9);
    assert_eq!(
        n_out, 0,
        "{what}: {n_out} samples outside the measured range"
    );
    map
}

#[test]
fn json_theta_ending_a_hair_above_90_is_a_hemisphere() {
    for end in [90.00000000000001, 90.0 + 1e-9, 90.0 - 1e-9, 89.9999999] {
        let d = json(&[0.0, 30.0, 60.0, end], &[vec![1.0, 2.0, 1.0, 0.5]]);
        assert_eq!(*d.theta().last().unwrap(), FRAC_PI_2, "end {end}");
        let map = assert_conserves(&d, "θ ends near 90°");
        assert!(matches!(map, Map::H(_)));
        assert_eq!(map.completions(), 0);
    }
}

#[test]
fn missing_cap_or_hemisphere_is_not_filled_with_light() {
    let cases: Vec<(&[f64], Vec<f64>, usize)> = vec![
        (&[0.0, 30.0, 60.0, 120.0], vec![1.0, 1.0, 1.0, 1.0], 1),
        (&[0.0, 30.0, 60.0, 90.001], vec![1.0, 1.0, 1.0, 1.0], 1),
        (&[0.0, 45.0, 90.0, 95.0], vec![0.0, 0.0, 1.0, 1.0], 1),
        (&[89.0, 90.0], vec![1.0, 1.0], 1),
        (&[30.0, 60.0, 90.0], vec![1.0, 1.0, 1.0], 1),
        (&[60.0, 120.0, 180.0], vec![1.0, 1.0, 1.0], 1),
        (&[10.0, 20.0], vec![3.0, 1.0], 2),
    ];
    for (theta, row, completions) in cases {
        let d = json(theta, &[row.clone(), row]);
        let map = assert_conserves(&d, &format!("{theta:?}"));
        assert_eq!(map.completions(), completions, "{theta:?}");
    }
    // [0, 45, 90, 95] with values [0, 0, 1, 1]: the issue measured map power 8.63 against a diagram
    // integral of 2.89; now the target power is the data's integral.
    let d = json(&[0.0, 45.0, 90.0, 95.0], &[vec![0.0, 0.0, 1.0, 1.0]]);
    let map = Map::of(&d);
    assert!((map.target_power() - d.integral()).abs() <= 1e-12 * d.integral());
}

#[test]
fn single_parallel_and_no_light_are_typed_errors() {
    for t in [45.0, 0.0, 90.0] {
        let e = Diagram::from_degrees(&[t], &[0.0], &[vec![1.0]]).unwrap_err();
        assert!(matches!(e, DiagramError::SingleParallel { .. }), "{e}");
        assert!(e.to_string().contains("single parallel"));
    }
    let e = Diagram::from_degrees(&[0.0, 90.0], &[0.0], &[vec![0.0, 0.0]]).unwrap_err();
    assert!(matches!(e, DiagramError::ZeroPower), "{e}");
    assert!(e.to_string().contains("no light"));
}

#[test]
fn a_one_ulp_cell_gives_no_nan() {
    let text = r#"{"theta_deg":[0,89.99999999999999,90],"phi_deg":[0],"values":[[0,0,1]]}"#;
    match Diagram::from_json_str(text) {
        Err(e) => assert!(
            matches!(e, gonio::Error::Diagram(DiagramError::UnresolvedLight)),
            "{e}"
        ),
        Ok(d) => match HemisphereMap::new(&d) {
            Err(e) => assert_eq!(e, DiagramError::UnresolvedLight),
            Ok(m) => {
                let (lo, hi) = m.ratio_bound();
                assert!(lo.is_finite() && hi.is_finite());
                assert!(m.target_power().is_finite() && m.target_power() > 0.0);
                let n = sampled_outside(&Map::H(m), 2000, 1);
                assert_eq!(n, 0);
            }
        },
    }
}

#[test]
fn any_scale_of_values_gives_the_same_map() {
    let theta = [0.0, 30.0, 60.0, 90.0, 150.0];
    let shape = [1.0, 0.5, 0.25, 0.75, 1.0];
    let reference = SphereMap::new(&json(&theta, &[shape.to_vec()])).unwrap();
    for scale in [
        5e307,
        1e308,
        f64::MAX,
        1e-310,
        5e-324,
        1e-320,
        2.2e-308,
        1.0,
    ] {
        // every value equal to `scale` times a power of two fraction: same ratios exactly
        let row: Vec<f64> = shape
            .iter()
            .map(|&v| if v == 1.0 { scale } else { 0.0 })
            .collect();
        let d = json(&theta, &[row]);
        let m = SphereMap::new(&d).unwrap();
        let (lo, hi) = m.ratio_bound();
        assert!(
            lo.is_finite() && hi.is_finite(),
            "scale {scale}: bound {lo} {hi}"
        );
        let unit_row: Vec<f64> = shape
            .iter()
            .map(|&v| if v == 1.0 { 1.0 } else { 0.0 })
            .collect();
        let unit = SphereMap::new(&json(&theta, &[unit_row])).unwrap();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        for _ in 0..2000 {
            let u = [rng.gen::<f64>(), rng.gen::<f64>()];
            let (a, b) = (m.sample(u), unit.sample(u));
            assert_eq!(a, b, "scale {scale}, u {u:?}");
            assert!(a.pdf.is_finite() && a.pdf > 0.0);
        }
        assert!(m.normalised_target_power().is_finite());
    }
    // values all equal: the same map as the unit-valued one, bit for bit
    for scale in [5e307, 1e308, f64::MAX, 1e-310, 5e-324] {
        let m = SphereMap::new(&json(&theta, &[vec![scale; 5]])).unwrap();
        let unit = SphereMap::new(&json(&theta, &[vec![1.0; 5]])).unwrap();
        for k in 0..500 {
            let u = [(k as f64 + 0.5) / 500.0, ((k * 37) % 500) as f64 / 500.0];
            assert_eq!(m.sample(u), unit.sample(u), "scale {scale}");
        }
    }
    drop(reference);
}

#[test]
fn poles_and_signed_zeros_agree() {
    let d = json(&[0.0, 90.0, 180.0], &[vec![1.0; 3], vec![1.0; 3]]);
    let m = SphereMap::new(&d).unwrap();
    let u = [0.49999999999999994, 0.9999999999999999];
    let s = m.sample(u);
    assert!((m.pdf(s.direction) - s.pdf).abs() <= 1e-12 * s.pdf, "{s:?}");
    let back = m.invert(s.direction).unwrap();
    let again = m.sample(back);
    let dot: f64 = (0..3).map(|k| again.direction[k] * s.direction[k]).sum();
    assert!(
        dot > 1.0 - 1e-12,
        "round trip {s:?} -> {back:?} -> {again:?}"
    );
    // every signed-zero pole direction: pdf equals the pdf of the sample at the pole
    for d in [
        [0.0, 0.0, 1.0],
        [-0.0, 0.0, 1.0],
        [0.0, -0.0, 1.0],
        [-0.0, -0.0, 1.0],
        [0.0, 0.0, -1.0],
        [-0.0, -0.0, -1.0],
    ] {
        let p = m.pdf(d);
        assert!(
            (p - 1.0 / (4.0 * std::f64::consts::PI)).abs() < 1e-9,
            "{d:?}: {p}"
        );
        assert_eq!(m.target_pdf(d), m.target_pdf([0.0, 0.0, d[2]]));
    }
    // a diagram whose meridians disagree at the pole: sample() at the pole carries pdf()'s value
    let d = json(
        &[0.0, 45.0, 90.0],
        &[vec![1.0, 1.0, 1.0], vec![3.0, 1.0, 1.0]],
    );
    let h = HemisphereMap::new(&d).unwrap();
    for u in [
        [0.5, 0.5],
        [0.5, 0.5000000000000001],
        [0.49999999999999994, 0.5],
    ] {
        let s = h.sample(u);
        assert_eq!(h.pdf(s.direction), s.pdf, "u {u:?}: {s:?}");
    }
}

#[test]
fn directions_of_any_finite_length_are_normalised() {
    for d in [
        [1e-200, 0.0, 1e-200],
        [1e200, 0.0, 1e200],
        [f64::MAX, f64::MAX, f64::MAX],
        [5e-324, 0.0, 0.0],
        [-3.0, 4.0, 0.0],
        // Either side of the fast path's bounds (sum of squares 1e-290 and 1e290).
        [1e-145, 0.0, 0.0],
        [0.9e-145, 0.0, 0.0],
        [1e145, 0.0, 0.0],
        [1.1e145, 0.0, 0.0],
        [1e-200, 1.0, -1e-170],
    ] {
        let n = normalize(d).unwrap_or_else(|| panic!("{d:?} refused"));
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-15, "{d:?} -> {n:?}");
    }
    assert!(normalize([0.0, -0.0, 0.0]).is_none());
    assert!(normalize([f64::NAN, 0.0, 1.0]).is_none());
    assert!(normalize([f64::INFINITY, 0.0, 1.0]).is_none());
}

/// Allocates a diagram of `MAX_NODES` values (2 GiB since issue 40 raised the cap to 2^28 for
/// 16384 × 8192 skies), so it runs only when asked: `cargo test -p gonio --test
/// light_conservation -- --ignored size_caps` (passed on 2026-12-04 at the new cap).
#[test]
#[ignore = "allocates 2 GiB (a diagram of MAX_NODES values); run with --ignored"]
fn size_caps_count_the_completion() {
    // 2^14 × 2^14 = MAX_NODES nodes, no parallel at 90°: the horizon parallel the split layout
    // inserts would exceed the cap. A typed error, not a panic (the issue: exit 101 after 21 s).
    let n = 1usize << 14;
    assert_eq!(n * n, gonio::diagram::MAX_NODES);
    let theta: Vec<f64> = (0..n)
        .map(|j| (j as f64 + 0.5) * std::f64::consts::PI / n as f64)
        .collect();
    let phi: Vec<f64> = (0..n)
        .map(|i| i as f64 * std::f64::consts::TAU / n as f64)
        .collect();
    let d = Diagram::new(theta, phi, vec![1.0; n * n]).unwrap();
    let Err(e) = SphereMap::new(&d) else {
        panic!("a diagram past the cap was accepted");
    };
    assert!(matches!(e, DiagramError::TooLarge { .. }), "{e}");
}

fn ies_c(vert: &str, horiz: &str, values: &str) -> String {
    let nv = vert.split_whitespace().count();
    let nh = horiz.split_whitespace().count();
    format!(
        "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 1000 1 {nv} {nh} 1 2 0 0 0\n1 1 10\n{vert}\n{horiz}\n{values}\n"
    )
}

fn read_ies(text: &str) -> gonio::Photometry {
    read(text.as_bytes(), FileFormat::Ies, &NoTiltFiles).unwrap()
}

#[test]
fn ies_vertical_ranges_snap_and_do_not_pad_light() {
    // 0 … 90.0000001: the lower hemisphere only
    let p = read_ies(&ies_c("0 45 90.0000001", "0", "3 2 1"));
    let d = p.to_diagram().unwrap();
    let m = assert_conserves_sphere(&d, "γ 0–90.0000001");
    let Map::S(s) = &m else { panic!() };
    assert_eq!(s.lower_probability(), Some(1.0));
    assert!(!p.warnings.iter().any(|w| w.message.contains("do not span")));
    // 89.9999999 … 180: the upper hemisphere only
    let p = read_ies(&ies_c("89.9999999 135 180", "0", "1 2 3"));
    let m = assert_conserves_sphere(&p.to_diagram().unwrap(), "γ 89.9999999–180");
    let Map::S(s) = &m else { panic!() };
    assert_eq!(s.lower_probability(), Some(0.0));
    // zero-row padding in the file: γ 0–91 with a zero row at 91
    let p = read_ies(&ies_c("0 30 60 90 91", "0", "5 4 3 2 0"));
    let d = p.to_diagram().unwrap();
    let m = assert_conserves_sphere(&d, "γ 0–91");
    let Map::S(s) = &m else { panic!() };
    // the data's light above the horizon is the sliver γ 90–91 only
    let upper_share = 1.0 - s.lower_probability().unwrap();
    assert!(upper_share < 0.01, "upper share {upper_share}");
    assert!(p
        .warnings
        .iter()
        .any(|w| w.message.contains("no light is assumed")));
    // γ 170–180: everything in the measured cap
    let p = read_ies(&ies_c("170 175 180", "0", "1 2 3"));
    assert_conserves_sphere(&p.to_diagram().unwrap(), "γ 170–180");
}

#[test]
fn json_ies_and_ldt_agree() {
    let d = json(
        &[0.0, 30.0, 60.0, 120.0],
        &[vec![1.0, 2.0, 3.0, 4.0], vec![2.0, 2.0, 1.0, 0.5]],
    );
    let from_json = SphereMap::new(&d).unwrap();
    let ies = write_ies(&d, &WriteMeta::default());
    let ldt = write_ldt(&d, &WriteMeta::default());
    for (text, format) in [(ies, FileFormat::Ies), (ldt, FileFormat::Eulumdat)] {
        let p = read(text.as_bytes(), format, &NoTiltFiles).unwrap();
        let m = SphereMap::new(&p.to_diagram().unwrap()).unwrap();
        let (a, b) = (
            m.lower_probability().unwrap(),
            from_json.lower_probability().unwrap(),
        );
        assert!(
            (a - b).abs() < 1e-9,
            "{format:?}: lower probability {a} vs {b}"
        );
        let (a, b) = (m.target_power(), from_json.target_power());
        assert!((a / b - 1.0).abs() < 1e-9, "{format:?}: power {a} vs {b}");
        assert!(m.probability_outside_measured() <= 1e-6);
    }
}

/// A type B file with the given horizontal and vertical angles, values from `f(h, v)`.
fn ies_b(horiz: &[f64], vert: &[f64], f: impl Fn(f64, f64) -> f64) -> String {
    let join = |a: &[f64]| {
        a.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let values: Vec<String> = horiz
        .iter()
        .map(|&h| join(&vert.iter().map(|&v| f(h, v)).collect::<Vec<_>>()))
        .collect();
    format!(
        "IESNA:LM-63-2002\n[TEST] t\nTILT=NONE\n1 1000 1 {} {} 2 2 0 0 0\n1 1 10\n{}\n{}\n{}\n",
        vert.len(),
        horiz.len(),
        join(vert),
        join(horiz),
        values.join("\n")
    )
}

#[test]
fn type_b_horizontal_range_outside_lm63_warns_and_keeps_the_light() {
    let vert: Vec<f64> = (-18..=18).map(|k| k as f64 * 5.0).collect();
    let f = |h: f64, v: f64| 100.0 * (h.to_radians().cos() * v.to_radians().cos()).max(0.0);
    let from0: Vec<f64> = (0..=18).map(|k| k as f64 * 5.0).collect();
    let from1: Vec<f64> = std::iter::once(1.0)
        .chain((1..=18).map(|k| k as f64 * 5.0))
        .collect();
    let good = read_ies(&ies_b(&from0, &vert, f));
    let odd = read_ies(&ies_b(&from1, &vert, f));
    assert!(
        odd.warnings
            .iter()
            .any(|w| w.message.contains("LM-63") && w.message.contains("mirrored")),
        "{:?}",
        odd.warnings
    );
    assert!(!good.warnings.iter().any(|w| w.message.contains("LM-63")));
    let (a, b) = (good.flux_lm(), odd.flux_lm());
    assert!((a / b - 1.0).abs() < 0.01, "flux {a} (0°) vs {b} (1°)");
}

/// Property test: random θ lists (endpoints perturbed by up to 1e-9° around 0, 90, 180 or random
/// partial ranges), random values, random scales.
#[test]
fn random_diagrams_conserve_light() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x9);
    for case in 0..60 {
        let lo: f64 = match case % 4 {
            0 => 0.0 + rng.gen_range(-1e-9..1e-9f64).abs(),
            1 => 90.0 + rng.gen_range(-1e-9..1e-9),
            _ => rng.gen_range(0.0..170.0),
        };
        let hi: f64 = match case % 3 {
            0 => 180.0 - rng.gen_range(0.0..1e-9),
            1 => 90.0 + rng.gen_range(-1e-9..1e-9),
            _ => rng.gen_range(lo + 1.0..=180.0),
        };
        if hi <= lo + 1e-3 {
            continue;
        }
        let n = rng.gen_range(2..12usize);
        let mut theta: Vec<f64> = (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect();
        for t in theta.iter_mut().skip(1).take(n.saturating_sub(2)) {
            *t += rng.gen_range(-0.2..0.2) * (hi - lo) / n as f64;
        }
        let m = rng.gen_range(1..6usize);
        let scale = [1e-310, 1e-3, 1.0, 1e300, f64::MAX][rng.gen_range(0..5)];
        let rows: Vec<Vec<f64>> = (0..m)
            .map(|_| (0..n).map(|_| rng.gen_range(0.0..1.0f64) * scale).collect())
            .collect();
        let Ok(d) = json_try(&theta, &rows) else {
            continue;
        };
        assert_conserves(&d, &format!("case {case}: θ {theta:?}, scale {scale:e}"));
    }
}

fn json_try(theta: &[f64], rows: &[Vec<f64>]) -> Result<Diagram, DiagramError> {
    let phi: Vec<f64> = (0..rows.len())
        .map(|i| 360.0 * i as f64 / rows.len() as f64)
        .collect();
    Diagram::from_degrees(theta, &phi, rows)
}

/// The table of docs/MAPPING.md ("Completion"): every JSON case of the issue, measured.
/// `cargo test -p gonio --test light_conservation -- --nocapture report`
#[test]
fn report() {
    let cases: Vec<(&[f64], Vec<f64>)> = vec![
        (
            &[0.0, 30.0, 60.0, 90.00000000000001],
            vec![1.0, 2.0, 1.0, 0.5],
        ),
        (&[0.0, 30.0, 60.0, 120.0], vec![1.0; 4]),
        (&[0.0, 30.0, 60.0, 90.001], vec![1.0; 4]),
        (&[0.0, 45.0, 90.0, 95.0], vec![0.0, 0.0, 1.0, 1.0]),
        (&[89.0, 90.0], vec![1.0; 2]),
        (&[30.0, 60.0, 90.0], vec![1.0; 3]),
        (&[60.0, 120.0, 180.0], vec![1.0; 3]),
        (&[10.0, 20.0], vec![3.0, 1.0]),
    ];
    for (theta, row) in cases {
        let d = json(theta, &[row.clone(), row.clone()]);
        let map = Map::of(&d);
        let (lo, hi) = map.bound();
        println!(
            "| `{theta:?}` values `{row:?}` | {:.2e} | 1 + {:.2e} | [{lo:.4}, {hi:.4}] | {} |",
            map.outside(),
            map.power_ratio() - 1.0,
            map.completions()
        );
        assert!(map.outside() <= 1e-6 && (map.power_ratio() - 1.0).abs() <= 1e-6);
    }
}

/// Issue 11 (Mitsuba's chi-square harness on the corpus): the edge of the unit square (u or v
/// exactly 0 or 1, which a float32 generator gives about once in 2²⁴ draws) must map to the edge
/// of the lit zone, not into an unlit zone at the end of the map. Before the fix the radial search
/// ended on the last segment, one without light, and the sample landed on the parallel before the
/// end of the map (θ = 95° for a downlight dark from 90° to 115°), where the density is zero all
/// around it: 7 corpus files had one such sample in Mitsuba's 10⁶ (seed 1) and its harness could
/// not accept them. Checked on the scalar path and the SoA batch paths (f64 and f32).
#[test]
fn the_square_edge_maps_to_the_end_of_the_lit_zone() {
    use gonio::mapping::batch::sample_soa_par;
    // (diagram, the end of its lit zone in θ on the side of the map that ends unlit, which side)
    let hemi = json(
        &[0.0, 20.0, 40.0, 60.0, 70.0, 80.0, 90.0],
        &[
            vec![5.0, 4.0, 2.0, 0.0, 0.0, 0.0, 0.0],
            vec![6.0, 3.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        ],
    );
    // A downlight as the corpus's: dark from the horizon to 115° (θ from +z, light below).
    let down = json(
        &[90.0, 95.0, 100.0, 105.0, 110.0, 115.0, 120.0, 150.0, 180.0],
        &[
            vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.1, 500.0, 900.0],
            vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3, 400.0, 900.0],
        ],
    );
    // Lit above and below, dark in between (the two-lamp direct/indirect file's shape).
    let both = json(
        &[0.0, 40.0, 80.0, 90.0, 100.0, 120.0, 140.0, 180.0],
        &[
            vec![8.0, 6.0, 1.0, 0.0, 0.0, 0.0, 3.0, 7.0],
            vec![8.0, 5.0, 2.0, 0.0, 0.0, 0.0, 2.0, 7.0],
        ],
    );
    let deg = std::f64::consts::PI / 180.0;
    // (what, map, its lit θ zones in degrees)
    type Case = (&'static str, Map, Vec<(f64, f64)>);
    let cases: Vec<Case> = vec![
        (
            "hemisphere dark beyond 60°",
            Map::of(&hemi),
            vec![(0.0, 60.0)],
        ),
        (
            "downlight dark in 90°–115°",
            Map::S(SphereMap::new(&down).unwrap()),
            vec![(115.0, 180.0)],
        ),
        (
            "lit above and below, dark in 90°–120°",
            Map::S(SphereMap::new(&both).unwrap()),
            vec![(0.0, 90.0), (120.0, 180.0)],
        ),
    ];
    let mut edge = Vec::new();
    for k in 0..=64 {
        let t = k as f64 / 64.0;
        edge.extend([[0.0, t], [1.0, t], [t, 0.0], [t, 1.0]]);
    }
    for (what, map, lit) in cases {
        let s = map.sampler();
        let inside = |dir: [f64; 3]| {
            let (t, _) = spherical(dir);
            lit.iter()
                .any(|&(a, b)| t >= a * deg - 1e-9 && t <= b * deg + 1e-9)
        };
        for &u in &edge {
            let smp = s.sample(u);
            let (t, _) = spherical(smp.direction);
            assert!(
                inside(smp.direction),
                "{what}: u {u:?} lands at θ = {}° outside the lit zone",
                t / deg
            );
            // Agreement relative to the density, or absolute 1e-12 /sr: at the end of the lit zone
            // the density is zero but for round-off (both sides see ~1e-16 there).
            let p = s.pdf(smp.direction);
            assert!(
                (p - smp.pdf).abs() <= 1e-9 * p.max(smp.pdf) + 1e-12,
                "{what}: u {u:?}: sample pdf {} vs pdf() {p}",
                smp.pdf
            );
            let w = s.invert(smp.direction).unwrap();
            // The square's edge maps back to the square's edge (the concentric map's corners and
            // the wrap of v are the same point).
            let on_edge = |a: f64| a <= 1e-9 || a >= 1.0 - 1e-9;
            assert!(
                on_edge(w[0]) || on_edge(w[1]),
                "{what}: u {u:?} -> {:?} -> {w:?}",
                smp.direction
            );
        }
        // The batch paths (the SoA lanes, f64 and f32) take the same decision.
        let (us, vs): (Vec<f64>, Vec<f64>) = edge.iter().map(|u| (u[0], u[1])).unzip();
        let n = us.len();
        let mut o = [vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let mut o32 = [vec![0f32; n], vec![0f32; n], vec![0f32; n], vec![0f32; n]];
        let (u32s, v32s): (Vec<f32>, Vec<f32>) =
            edge.iter().map(|u| (u[0] as f32, u[1] as f32)).unzip();
        {
            let [x, y, z, p] = &mut o;
            let [x32, y32, z32, p32] = &mut o32;
            match &map {
                Map::H(m) => {
                    sample_soa_par(m, &us, &vs, [x, y, z], p);
                    sample_soa_par(m, &u32s, &v32s, [x32, y32, z32], p32);
                }
                Map::S(m) => {
                    sample_soa_par(m, &us, &vs, [x, y, z], p);
                    sample_soa_par(m, &u32s, &v32s, [x32, y32, z32], p32);
                }
            }
        }
        for k in 0..n {
            let d = [o[0][k], o[1][k], o[2][k]];
            assert!(
                inside(d),
                "{what}: batch f64, u {:?} lands at {d:?}",
                edge[k]
            );
            // f32: within f32 round-off of the lit zone (1e-5 rad ≈ 6e-4°).
            let d32 = [o32[0][k] as f64, o32[1][k] as f64, o32[2][k] as f64];
            let (t, _) = spherical(d32);
            assert!(
                lit.iter()
                    .any(|&(a, b)| t >= a * deg - 1e-5 && t <= b * deg + 1e-5),
                "{what}: batch f32, u {:?} lands at θ = {}°",
                edge[k],
                t / deg
            );
        }
    }
}

/// A map paired with the data it should sample (issue 9, item 7): `sample`, `pdf` and `invert`
/// are the map's, the target is the data's (zero outside its measured range, normalised by its
/// integral), as `gonio check` sees any sampler.
struct MapOfOtherData {
    map: SphereMap,
    data: SphereMap,
}

impl Sampler for MapOfOtherData {
    fn name(&self) -> &'static str {
        "map of other data"
    }
    fn domain(&self) -> gonio::Domain {
        gonio::Domain::Sphere
    }
    fn sample(&self, u: [f64; 2]) -> gonio::Sample {
        self.map.sample(u)
    }
    fn pdf(&self, d: [f64; 3]) -> f64 {
        self.map.pdf(d)
    }
    fn invert(&self, d: [f64; 3]) -> Result<[f64; 2], gonio::sampler::InvertError> {
        self.map.invert(d)
    }
    fn target_pdf(&self, d: [f64; 3]) -> f64 {
        self.data.target_pdf(d)
    }
    fn target_power(&self) -> f64 {
        self.data.target_power()
    }
    fn memory_bytes(&self) -> usize {
        self.map.memory_bytes()
    }
}

/// `gonio check` compares a map with the data: a map that invents light (the lower hemisphere
/// filled with the horizon values, as the old completion did) fails the chi-square item (its
/// support rule), and a map that drops light (the data beyond 45° left out) fails the flux and
/// ratio items; the map of the data itself passes them at the same seeds.
#[test]
fn check_fails_maps_that_invent_or_drop_light() {
    use gonio::check::{run_battery, BatteryOptions, Status};
    let phi = [0.0, 90.0, 180.0, 270.0];
    let rows = |v: &[f64]| -> Vec<Vec<f64>> {
        (0..4)
            .map(|i| v.iter().map(|x| x * (1.0 + 0.2 * i as f64)).collect())
            .collect()
    };
    let data = Diagram::from_degrees(&[0.0, 30.0, 60.0, 90.0], &phi, &rows(&[4.0, 3.0, 2.0, 1.0]))
        .unwrap();
    let filled = Diagram::from_degrees(
        &[0.0, 30.0, 60.0, 90.0, 180.0],
        &phi,
        &rows(&[4.0, 3.0, 2.0, 1.0, 1.0]),
    )
    .unwrap();
    let cut = Diagram::from_degrees(
        &[0.0, 30.0, 45.0, 45.0001, 90.0],
        &phi,
        &rows(&[4.0, 3.0, 2.5, 0.0, 0.0]),
    )
    .unwrap();
    let reference = SphereMap::new(&data).unwrap();
    let with = |d: &Diagram| MapOfOtherData {
        map: SphereMap::new(d).unwrap(),
        data: reference.clone(),
    };
    for seed in [1, 2, 3] {
        let run = |s: &dyn Sampler| {
            let mut opts = BatteryOptions::quick().with_seed(seed);
            opts.flux_total = s.target_power();
            run_battery(s, &opts)
        };
        let own = run(&with(&data));
        assert_eq!(own.chi_square.status, Status::Pass, "seed {seed}:\n{own}");
        assert_eq!(own.flux.status, Status::Pass, "seed {seed}:\n{own}");
        let invents = run(&with(&filled));
        assert_eq!(
            invents.chi_square.status,
            Status::Fail,
            "seed {seed}: invented light not caught:\n{invents}"
        );
        let drops = run(&with(&cut));
        assert_eq!(
            drops.flux.status,
            Status::Fail,
            "seed {seed}: dropped light not caught by flux:\n{drops}"
        );
        // The chi-square tests the samples against the map's own pdf (which they follow); the
        // data enters through the ratio item as well: the pdf vanishes where the data has light.
        assert_eq!(
            drops.ratio.status,
            Status::Fail,
            "seed {seed}: dropped light not caught by the ratio item:\n{drops}"
        );
        assert!(!drops.passed && !invents.passed);
    }
}
