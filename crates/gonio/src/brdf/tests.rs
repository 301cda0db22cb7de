//! Tests of the tabulated BRDFs: tables, the blended sampler, readers and writers.

use super::*;
use crate::mapping::BlendedMap;
use crate::sampler::{direction, Point2};
use crate::{Diagram, HemisphereMap, Sampler};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

fn table(a: &Analytic) -> TabulatedBrdf {
    // Coarse grids keep the tests fast: 10° polar steps, 15° azimuth steps (12° for the
    // anisotropic incident grid too).
    a.table(10, 24).unwrap()
}

fn incident(theta_deg: f64, phi_deg: f64) -> Vec3 {
    direction(theta_deg.to_radians(), phi_deg.to_radians())
}

fn dist(a: Vec3, b: Vec3) -> f64 {
    (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f64::max)
}

#[test]
fn table_equals_the_analytic_brdf_at_its_nodes() {
    for a in Analytic::families() {
        let t = table(&a);
        for &(ti, pi, to, po) in &[
            (20.0, 30.0, 40.0, 75.0),
            (0.0, 0.0, 50.0, 180.0),
            (80.0, 345.0, 10.0, 15.0),
        ] {
            let (wi, wo) = (incident(ti, pi), incident(to, po));
            let want = a.eval(wi, wo);
            let got = t.eval(wi, wo);
            let iso = a.symmetry() == Symmetry::Isotropic;
            if iso || ti > 0.0 {
                for c in 0..3 {
                    assert!(
                        (got[c] - want[c]).abs() <= 1e-9 * want[c].max(1.0),
                        "{} {ti} {pi} {to} {po}: {got:?} vs {want:?}",
                        a.name()
                    );
                }
            }
        }
        // Below the horizon: 0.
        assert_eq!(t.eval(incident(30.0, 0.0), [0.0, 0.6, -0.8]), [0.0; 3]);
    }
}

#[test]
fn isotropic_eval_depends_on_the_relative_azimuth_only() {
    let t = table(&Analytic::families()[1]);
    for k in 0..20 {
        let s = 17.0 * k as f64;
        let a = t.eval(incident(35.0, s), incident(50.0, s + 160.0));
        let b = t.eval(incident(35.0, 0.0), incident(50.0, 160.0));
        assert!((a[1] - b[1]).abs() < 1e-12 * b[1]);
    }
}

/// sample/pdf/invert agree, weights are finite and equal f cos / pdf, for every family, at
/// tabulated and in-between incident directions (anisotropic: in-between in φ_i too).
#[test]
fn sampler_contract_on_every_family() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(26);
    for a in Analytic::families() {
        let t = table(&a);
        let s = BrdfSampler::new(t.clone(), &SamplerOptions::default()).unwrap();
        assert!(!s.resampled());
        for &(ti, pi) in &[
            (0.0, 0.0),
            (20.0, 0.0),
            (33.3, 41.0),
            (61.7, 200.0),
            (75.0, 95.0),
            (85.0, 300.0),
            (90.0, 10.0),
        ] {
            let wi = incident(ti, pi);
            let mut worst_rt: f64 = 0.0;
            for _ in 0..2000 {
                let u: Point2 = [rng.gen(), rng.gen()];
                let smp = s.sample(wi, u);
                assert!(smp.direction[2] >= 0.0 && smp.pdf.is_finite() && smp.pdf >= 0.0);
                assert!(smp.weight.iter().all(|w| w.is_finite() && *w >= 0.0));
                let p = s.pdf(wi, smp.direction);
                assert!(
                    (p - smp.pdf).abs() <= 1e-9 * smp.pdf.max(1e-9),
                    "{} θi {ti}: pdf {p} vs {}",
                    a.name(),
                    smp.pdf
                );
                if smp.pdf > 1e-6 {
                    let f = t.eval(wi, smp.direction);
                    let want = f[0] * smp.direction[2] / smp.pdf;
                    assert!((smp.weight[0] - want).abs() <= 1e-12 * want.max(1.0));
                    let back = s.invert(wi, smp.direction).unwrap();
                    worst_rt = worst_rt.max((back[0] - u[0]).abs().max((back[1] - u[1]).abs()));
                }
            }
            assert!(
                worst_rt < 1e-10,
                "{} θi {ti} φi {pi}: round trip {worst_rt:e}",
                a.name()
            );
        }
    }
}

/// The map for an incident direction between slices is exactly the HDS map of the blended
/// slice diagram (Σ w_k s_k / ∫ s_k), built from scratch with `HemisphereMap::new`.
#[test]
fn blended_map_is_the_map_of_the_interpolated_diagram() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let a = Analytic::Mix {
        kd: [0.3; 3],
        alpha: 0.2,
        f0: [0.6; 3],
    };
    let s = BrdfSampler::new(table(&a), &SamplerOptions::default()).unwrap();
    let ti = 37.0f64; // between the slices at 30° and 40°
    let tw = (ti - 30.0) / 10.0;
    let (m0, m1) = (s.slice(3).unwrap(), s.slice(4).unwrap());
    let d0 = m0.diagram();
    let vals: Vec<Vec<f64>> = (0..d0.n_meridians())
        .map(|i| {
            (0..d0.n_parallels())
                .map(|j| {
                    (1.0 - tw) * d0.value(i, j) / m0.disk_power()
                        + tw * m1.diagram().value(i, j) / m1.disk_power()
                })
                .collect()
        })
        .collect();
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<_>>();
    let reference = HemisphereMap::new(
        &Diagram::from_degrees(&deg(d0.theta()), &deg(d0.phi()), &vals).unwrap(),
    )
    .unwrap();
    let blend = BlendedMap::new(&[(m0, 1.0 - tw), (m1, tw)]).unwrap();
    let wi = incident(ti, 0.0);
    for _ in 0..3000 {
        let u: Point2 = [rng.gen(), rng.gen()];
        let r = reference.sample(u);
        let b = s.sample(wi, u);
        assert!(
            dist(r.direction, b.direction) < 1e-11,
            "{:?} vs {:?}",
            r.direction,
            b.direction
        );
        assert!((r.pdf - b.pdf).abs() <= 1e-10 * r.pdf.max(1e-6));
        assert!(dist(blend.sample(u).direction, r.direction) < 1e-11);
    }
}

/// No jump as ω_i crosses a tabulated slice (θ_i = 40°) or, for an anisotropic table, a
/// tabulated incident azimuth (φ_i = 30°): samples of the same u move by O(h).
#[test]
fn continuous_in_the_incident_direction_across_slices() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
    for a in [Analytic::families()[1], Analytic::families()[2]] {
        let s = BrdfSampler::new(table(&a), &SamplerOptions::default()).unwrap();
        let us: Vec<Point2> = (0..500).map(|_| [rng.gen(), rng.gen()]).collect();
        for &(t, p, dt, dp) in &[(40.0, 10.0, 1.0, 0.0), (52.0, 30.0, 0.0, 1.0)] {
            for &h in &[1e-5, 1e-8] {
                let lo = incident(t - h * dt, p - h * dp);
                let hi = incident(t + h * dt, p + h * dp);
                for u in &us {
                    let (x, y) = (s.sample(lo, *u), s.sample(hi, *u));
                    if x.pdf > 1e-3 && y.pdf > 1e-3 {
                        let d = dist(x.direction, y.direction);
                        assert!(d < 2e3 * h, "{} at ({t},{p}) h {h}: jump {d}", a.name());
                    }
                }
            }
        }
    }
}

/// The check battery (quick) at several incident directions, on an isotropic and an anisotropic
/// family: chi-square, round trip, pdf consistency, normalisation, ratio, flux.
#[test]
fn battery_per_incident_direction() {
    // (Every family at θ_i = 0°…85° in every format: `gonio check FILE --incident θ,φ`.)
    for (a, t, p) in [
        (Analytic::families()[4], 0.0, 0.0),
        (Analytic::families()[3], 57.0, 130.0),
    ] {
        let s = BrdfSampler::new(table(&a), &SamplerOptions::default()).unwrap();
        {
            let inc = IncidentSampler::new(&s, incident(t, p));
            let mut opts = crate::BatteryOptions::quick().with_seed(7);
            opts.chi_square.samples = 50_000;
            opts.flux.samples = 50_000;
            opts.round_trip.points = 5_000;
            opts.pdf_consistency.points = 5_000;
            let r = crate::run_battery(&inc, &opts);
            assert!(r.passed, "{} at ({t}, {p}):\n{r}", a.name());
        }
    }
}

/// A slice without reflectance (all zero at θ_i ≤ 10°): zero-weight cosine samples there, never
/// NaN, and the sampler still works where the other slices have light.
#[test]
fn empty_slices_give_zero_weight_samples() {
    let g = Analytic::families()[1];
    let t = TabulatedBrdf::from_fn(
        Symmetry::Isotropic,
        1,
        uniform_theta(10, 90.0),
        vec![0.0],
        uniform_theta(10, 90.0),
        uniform_phi(12),
        |ti, _, to, po| {
            if ti < 0.2 {
                [0.0; 3]
            } else {
                g.eval_angles(ti, 0.0, to, po)
            }
        },
    )
    .unwrap();
    let s = BrdfSampler::new(t, &SamplerOptions::default()).unwrap();
    assert_eq!(s.slice_counts(), (10, 2));
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    for &ti in &[0.0, 5.0, 10.0, 15.0, 60.0] {
        for _ in 0..200 {
            let u: Point2 = [rng.gen(), rng.gen()];
            let smp = s.sample(incident(ti, 0.0), u);
            assert!(smp.pdf.is_finite() && smp.weight.iter().all(|w| w.is_finite()));
            if ti <= 10.0 {
                assert_eq!(smp.weight, [0.0; 3]);
            }
        }
    }
    // Below the horizon: the zero-weight sample too.
    let smp = s.sample([0.0, 0.6, -0.8], [0.3, 0.3]);
    assert_eq!(smp.weight, [0.0; 3]);
}

#[test]
fn merl_round_trip_and_hostile_files() {
    let a = Analytic::families()[1];
    let bytes = write_merl(|wi, wo| a.eval(wi, wo));
    assert_eq!(bytes.len(), 12 + 3 * 90 * 90 * 180 * 8);
    let raw = MerlRaw::parse(&bytes).unwrap();
    assert!(raw.no_data() > 0, "cells below the horizon are marked");
    // The lookup reproduces the analytic BRDF near the specular direction and off it.
    for &(ti, to, dp) in &[(30.0, 30.0, 180.0), (45.0, 20.0, 120.0), (10.0, 60.0, 90.0)] {
        let (wi, wo) = (incident(ti, 0.0), incident(to, dp));
        let (want, got) = (a.eval(wi, wo), raw.lookup(wi, wo));
        assert!(
            (got[1] - want[1]).abs() <= 0.05 * want[1] + 1e-3,
            "{ti} {to} {dp}: {got:?} vs {want:?}"
        );
    }
    let opts = MerlOptions {
        n_theta: 10,
        n_phi: 24,
    };
    let t = raw.resample(&opts).unwrap();
    assert_eq!(t.theta_i().len(), 10);
    let err = raw.resampling_error(&t);
    assert!(err > 0.0 && err < 0.2, "resampling error {err}");
    let s = BrdfSampler::new(read_any(&bytes, &opts).unwrap(), &SamplerOptions::default()).unwrap();
    let smp = s.sample(incident(40.0, 0.0), [0.4, 0.6]);
    assert!(smp.pdf > 0.0);
    // Hostile files.
    assert!(matches!(
        MerlRaw::parse(&bytes[..bytes.len() - 8]),
        Err(BrdfError::Size { .. })
    ));
    assert!(matches!(
        MerlRaw::parse(&bytes[..7]),
        Err(BrdfError::Size { .. })
    ));
    let mut bad = bytes.clone();
    bad[8..12].copy_from_slice(&90i32.to_le_bytes());
    assert!(matches!(
        MerlRaw::parse(&bad),
        Err(BrdfError::Header { offset: 8, .. })
    ));
    let mut nan = bytes.clone();
    nan[12 + 8 * 1000..12 + 8 * 1001].copy_from_slice(&f64::NAN.to_le_bytes());
    assert!(
        matches!(MerlRaw::parse(&nan), Err(BrdfError::BadValue { index: 1000, offset, .. }) if offset == 12 + 8000)
    );
    let neg = write_merl(|_, _| [-1.0; 3]);
    assert_eq!(
        MerlRaw::parse(&neg).unwrap_err(),
        BrdfError::NoReflectance { format: "merl" }
    );
    assert!(matches!(
        read_any(&bytes[..100], &opts),
        Err(BrdfError::Size { .. })
    ));
}

#[test]
fn utia_round_trip_and_hostile_files() {
    let a = Analytic::families()[2];
    let bytes = write_utia_dirs(|wi, wo| a.eval(wi, wo));
    assert_eq!(bytes.len() as u64, UTIA_SIZE);
    let t = read_any(&bytes, &MerlOptions::default()).unwrap();
    assert_eq!(t.symmetry(), Symmetry::Anisotropic);
    let (wi, wo) = (incident(30.0, 15.0), incident(45.0, 187.5));
    let (want, got) = (a.eval(wi, wo), t.eval(wi, wo));
    assert!((got[0] - want[0]).abs() <= 1e-9 * want[0]);
    assert_eq!(
        t.eval(wi, incident(80.0, 0.0)),
        [0.0; 3],
        "no data beyond 75°"
    );
    let s = BrdfSampler::new(
        t,
        &SamplerOptions {
            theta_o: 16,
            phi_o: 48,
            force_resample: false,
        },
    )
    .unwrap();
    assert!(s.resampled());
    let smp = s.sample(incident(40.0, 20.0), [0.4, 0.6]);
    assert!(smp.pdf > 0.0 && smp.direction[2] >= 0.0);
    assert!(matches!(
        read_utia(&bytes[..bytes.len() - 1]),
        Err(BrdfError::Size { .. })
    ));
    let mut nan = bytes.clone();
    nan[8 * 77..8 * 78].copy_from_slice(&f64::INFINITY.to_le_bytes());
    assert!(matches!(
        read_utia(&nan),
        Err(BrdfError::BadValue { index: 77, .. })
    ));
    let neg = write_utia(|_, _, _, _| [0.0; 3]);
    assert_eq!(
        read_utia(&neg).unwrap_err(),
        BrdfError::NoReflectance { format: "utia" }
    );
}

#[test]
fn json_round_trip_and_errors() {
    let t = Analytic::families()[2].table(4, 6).unwrap();
    let text = write_json(&t);
    let back = read_any(text.as_bytes(), &MerlOptions::default()).unwrap();
    // serde_json parses floats to within an ulp or two, not always exactly.
    assert!(back
        .values()
        .iter()
        .zip(t.values())
        .all(|(a, b)| (a - b).abs() <= 1e-14 * b.abs()));
    assert_eq!(back.symmetry(), Symmetry::Anisotropic);
    assert!(matches!(
        read_json("{\"format\": 3}"),
        Err(BrdfError::Json { line: 1, .. })
    ));
    let short = text.replacen("\"values\":[", "\"values\":[1,", 1);
    assert!(matches!(read_json(&short), Err(BrdfError::Shape { .. })));
    let unsorted = text.replacen("\"theta_o_deg\":[0.0,30.0", "\"theta_o_deg\":[0.0,95.0", 1);
    assert!(
        matches!(
            read_json(&unsorted),
            Err(BrdfError::Grid {
                axis: "theta_o",
                ..
            })
        ),
        "{}",
        &unsorted[..200]
    );
    assert!(matches!(
        read_any(b"hello", &MerlOptions::default()),
        Err(BrdfError::UnknownFormat { .. })
    ));
}

/// The exact albedo: Lambert's is its albedo (luminance), and a GGX table's agrees with a fine
/// midpoint quadrature.
#[test]
fn scalar_albedo_is_exact() {
    let l = table(&Analytic::families()[0]);
    let want = LUMINANCE[0] * 0.8 + LUMINANCE[1] * 0.5 + LUMINANCE[2] * 0.2;
    for &t in &[0.0, 33.0, 80.0] {
        let a = scalar_albedo(&l, incident(t, 10.0));
        assert!((a - want).abs() < 1e-13, "{a} vs {want}");
    }
    let g = table(&Analytic::families()[2]);
    let wi = incident(40.0, 20.0);
    let q: f64 = scalar_albedo_grid(&g, wi, 600)
        .iter()
        .map(|p| p.1)
        .sum::<f64>()
        * std::f64::consts::TAU
        / (2.0 * 600.0 * 600.0);
    let a = scalar_albedo(&g, wi);
    assert!((a - q).abs() < 2e-4 * a, "{a} vs {q}");
}

/// The baselines honour the same contract: pdf(sample) = sample.pdf, finite weights, and their
/// inverses round-trip where they have one.
#[test]
fn baselines_honour_the_contract() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    for a in [Analytic::families()[1], Analytic::families()[2]] {
        let t = table(&a);
        let s = BrdfSampler::new(t.clone(), &SamplerOptions::default()).unwrap();
        let fit = GgxFit::fit(&t);
        let (ax, ay) = fit.alpha();
        if let Analytic::Ggx {
            alpha_x, alpha_y, ..
        } = a
        {
            // The fit lands near the generating roughness (grid steps are 20 % apart).
            assert!(
                (ax / alpha_x).ln().abs() < 0.5 && (ay / alpha_y).ln().abs() < 0.5,
                "{ax} {ay}"
            );
        }
        let cos = CosineBrdf::new(&t);
        let pc = PerSliceConstant::new(&s, 32);
        let methods: [&dyn BrdfMethod; 4] = [&s, &cos, &fit, &pc];
        for m in methods {
            for &(ti, pi) in &[(0.0, 0.0), (35.0, 50.0), (70.0, 200.0)] {
                let wi = incident(ti, pi);
                for _ in 0..500 {
                    let u: Point2 = [rng.gen_range(0.001..0.999), rng.gen_range(0.001..0.999)];
                    let smp = m.sample(wi, u);
                    assert!(smp.pdf.is_finite() && smp.weight.iter().all(|w| w.is_finite()));
                    if smp.direction[2] <= 1e-6 || smp.pdf <= 1e-6 {
                        continue;
                    }
                    let p = m.pdf(wi, smp.direction);
                    assert!(
                        (p - smp.pdf).abs() <= 1e-8 * p,
                        "{} {ti}: {p} vs {}",
                        m.name(),
                        smp.pdf
                    );
                    if let Some(back) = m.invert(wi, smp.direction) {
                        let e = (back[0] - u[0]).abs().max((back[1] - u[1]).abs());
                        assert!(e < 1e-7, "{} {ti}: {u:?} -> {back:?}", m.name());
                    }
                }
            }
        }
    }
}

/// The issue-40 reproducer: an isotropic 3 × 1 × 3 × 4 JSON table, every value `v`.
fn constant_json(v: &str) -> String {
    let values = vec![v; 3 * 3 * 4].join(", ");
    format!(
        "{{\"format\": \"gonio-brdf\", \"version\": 1, \"symmetry\": \"isotropic\", \"channels\": 3,\n \"theta_i_deg\": [0, 45, 90], \"phi_i_deg\": [0],\n \"theta_o_deg\": [0, 45, 90], \"phi_o_deg\": [0, 90, 180, 270],\n \"values\": [{values}]}}"
    )
    .replacen("\"channels\": 3", "\"channels\": 1", 1)
}

/// Issue 40: every value 1.7e308 gave albedo `inf` and infinite sample weights. Values above
/// `MAX_VALUE` are refused, naming the value and its line and column; at the limit everything is
/// finite.
#[test]
fn huge_values_never_give_infinite_albedo_or_weights() {
    let e = read_any(constant_json("1.7e308").as_bytes(), &MerlOptions::default()).unwrap_err();
    match &e {
        BrdfError::Json {
            line,
            column,
            message,
        } => {
            assert_eq!((*line, *column), (4, 13), "{e}");
            assert!(message.contains("values[0] = 1.7e308"), "{e}");
        }
        other => panic!("{other:?}"),
    }
    for v in ["1e307", "1.1235582092889474e307"] {
        let t = read_any(constant_json(v).as_bytes(), &MerlOptions::default()).unwrap();
        let s = BrdfSampler::new(t, &SamplerOptions::default()).unwrap();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        for &ti in &[0.0, 30.0, 89.0] {
            let inc = IncidentSampler::new(&s, incident(ti, 0.0));
            assert!(
                inc.albedo().is_finite() && inc.albedo() > 0.0,
                "{v} {ti}: {}",
                inc.albedo()
            );
            for _ in 0..200 {
                let smp = s.sample(incident(ti, 0.0), [rng.gen(), rng.gen()]);
                assert!(smp.pdf.is_finite(), "{v}: {smp:?}");
                assert!(smp.weight.iter().all(|w| w.is_finite()), "{v}: {smp:?}");
            }
        }
    }
}

/// Issue 40: a value error of a JSON table named "byte 0"; now its line and column. A UTF-8 BOM
/// before a valid table is accepted.
#[test]
fn json_value_errors_are_located_and_a_bom_is_accepted() {
    let text = constant_json("0.5").replacen("0.5, 0.5, 0.5", "0.5, 0.5, -2", 1);
    match read_json(&text).unwrap_err() {
        BrdfError::Json {
            line,
            column,
            message,
        } => {
            assert_eq!((line, column), (4, 23), "{message}");
            assert!(message.contains("values[2] = -2"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let good = constant_json("0.5");
    let mut bom = b"\xEF\xBB\xBF".to_vec();
    bom.extend(good.as_bytes());
    let a = read_any(&bom, &MerlOptions::default()).unwrap();
    assert_eq!(
        a,
        read_any(good.as_bytes(), &MerlOptions::default()).unwrap()
    );
    assert!(read_json(&format!("\u{feff}{good}")).is_ok());
}
