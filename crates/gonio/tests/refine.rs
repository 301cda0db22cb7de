//! Refinement to a tolerance (issue 14): the guaranteed bound lies within [1 − tol, 1 + tol], and
//! dense sampling of pdf / target never leaves that bound; input nodes keep their values, zero regions
//! stay zero, and the map stays exact (sample pdf = pdf, round trip).

use gonio::mapping::{RefineLimits, RefineStop};
use gonio::sampler::direction;
use gonio::synthetic::{random_hemisphere, Family};
use gonio::{
    BuildOptions, Diagram, Domain, HemisphereMap, Method, Sampler, SphereLayout, SphereMap,
};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// pdf / target at a dense (θ, φ) grid over [0, θ_max]: points across every cell of the map's grid,
/// down to 1e-4 of its width from each parallel (where the ratio of a zero end is extreme), wherever
/// the target is positive. Returns (min, max), and asserts that the pdf vanishes where the target
/// does. Points exactly on a parallel are left out: a direction computed from θ carries ~1e-16 of
/// round-off in θ, which the map (through x = √(1 − z)) and the target (through θ) may place in
/// different cells, so a node next to a zero cell could show a round-off-sized pdf over a zero target.
fn sampled_ratio(map: &dyn Sampler, theta: &[f64], phi: &[f64], theta_max: f64) -> (f64, f64) {
    let mut ts: Vec<f64> = Vec::new();
    for w in theta.windows(2) {
        let h = w[1] - w[0];
        for f in [
            1e-4,
            1e-3,
            0.02,
            0.1,
            0.25,
            0.5,
            0.75,
            0.9,
            0.98,
            0.999,
            1.0 - 1e-4,
        ] {
            ts.push(w[0] + f * h);
        }
    }
    let mut ps: Vec<f64> = phi.to_vec();
    for k in 0..24 {
        ps.push((k as f64 + 0.5) * TAU / 24.0);
    }
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for &t in &ts {
        for &p in &ps {
            let d = direction(t.min(theta_max), p);
            let target = map.target_pdf(d);
            let pdf = map.pdf(d);
            if target > 0.0 {
                let r = pdf / target;
                lo = lo.min(r);
                hi = hi.max(r);
            } else {
                assert_eq!(pdf, 0.0, "pdf {pdf} where the target is 0 at θ={t}, φ={p}");
            }
        }
    }
    (lo, hi)
}

/// The input's nodes are nodes of the refined grid with the same values.
fn assert_nodes_kept(input: &Diagram, refined: &Diagram) {
    for (j, &t) in input.theta().iter().enumerate() {
        let k = refined
            .theta()
            .iter()
            .position(|&r| r == t)
            .unwrap_or_else(|| panic!("input parallel θ = {t} missing after refinement"));
        // The map's diagram holds the data divided by its largest value (issue 9).
        let scale = input.max_value();
        for i in 0..input.n_meridians() {
            let (a, b) = (refined.value(i, k) * scale, input.value(i, j));
            assert!((a - b).abs() <= 1e-15 * b, "{a} vs {b}");
        }
    }
}

/// Point k of the additive recurrence start + k·step (mod 1): well-spread points of the square.
fn recurrence(k: usize, step: [f64; 2], start: [f64; 2]) -> [f64; 2] {
    [0, 1].map(|c| (k as f64 * step[c] + start[c]) % 1.0)
}

fn assert_exact(map: &dyn Sampler) {
    for k in 0..400 {
        let u = recurrence(k, [0.618_034, 0.414_214], [0.01, 0.3]);
        let s = map.sample(u);
        if s.pdf > 0.0 {
            assert!((map.pdf(s.direction) - s.pdf).abs() <= 1e-9 * s.pdf);
            let w = map.invert(s.direction).unwrap();
            let back = map.sample(w);
            let dist: f64 = (0..3)
                .map(|c| (back.direction[c] - s.direction[c]).powi(2))
                .sum();
            assert!(
                dist.sqrt() < 1e-9,
                "round trip off by {} at {u:?}",
                dist.sqrt()
            );
        }
    }
}

fn check_hemisphere(d: &Diagram, tol: f64) {
    let map = HemisphereMap::with_tolerance(d, tol).unwrap();
    let r = map.refinement().expect("built with a tolerance");
    assert!(r.reached, "{:?}", r);
    let (lo, hi) = map.ratio_bound();
    assert_eq!(r.bound, (lo, hi));
    assert!(
        lo >= 1.0 - tol && hi <= 1.0 + tol,
        "bound [{lo}, {hi}] for tol {tol}"
    );
    let g = map.diagram();
    assert_nodes_kept(d, g);
    let (slo, shi) = sampled_ratio(&map, g.theta(), g.phi(), FRAC_PI_2);
    assert!(
        slo >= lo * (1.0 - 1e-9) && shi <= hi * (1.0 + 1e-9),
        "sampled [{slo}, {shi}] outside the bound [{lo}, {hi}]"
    );
    assert_exact(&map);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]
    /// Every family (zero-heavy and spiky included), regular and irregular grids, N 2–24, M 1–16.
    #[test]
    fn refined_hemisphere_maps_meet_the_tolerance(
        fam in 0usize..5, n in 2usize..25, m in 1usize..17, irregular: bool, seed: u64,
        tol_index in 0usize..3,
    ) {
        let d = random_hemisphere(Family::ALL[fam], n, m, irregular, seed);
        check_hemisphere(&d, [0.1, 0.01, 0.001][tol_index]);
    }
}

/// Zero regions and isolated spikes: a meridian of zeros, a zero cap at the pole, one huge node,
/// a linear fall to zero at the horizon, values 1e-20 next to 1.
#[test]
fn zero_regions_and_spikes_meet_the_tolerance() {
    let theta = [0.0, 10.0, 30.0, 55.0, 70.0, 90.0];
    let phi = [0.0, 60.0, 150.0, 270.0];
    let values = vec![
        vec![0.0, 0.0, 1.0, 2.0, 1.0, 0.0],
        vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        vec![0.0, 1e-20, 1.0, 1e6, 1.0, 0.5],
        vec![0.0, 3.0, 0.0, 3.0, 0.0, 3.0],
    ];
    let d = Diagram::from_degrees(&theta, &phi, &values).unwrap();
    for tol in [0.1, 0.01, 0.001] {
        check_hemisphere(&d, tol);
        let map = HemisphereMap::with_tolerance(&d, tol).unwrap();
        // The zero meridian φ = 60° stays zero on every parallel of the refined grid.
        let g = map.diagram();
        let i = g
            .phi()
            .iter()
            .position(|&p| (p - 60f64.to_radians()).abs() < 1e-12)
            .unwrap();
        assert!((0..g.n_parallels()).all(|k| g.value(i, k) == 0.0));
    }
}

/// Refinement inserts parallels only, adaptively: a diagram already within the tolerance is left
/// alone, and a finer tolerance never needs fewer parallels.
#[test]
fn refinement_is_adaptive_and_reports_its_cost() {
    let flat = Diagram::from_degrees(&[0.0, 45.0, 90.0], &[0.0], &[vec![1.0, 1.0, 1.0]]).unwrap();
    let r = HemisphereMap::with_tolerance(&flat, 0.01).unwrap();
    let info = r.refinement().unwrap();
    assert_eq!(info.parallels_added(), 0);
    assert_eq!(info.meridians_added, 0);
    assert_eq!(info.memory_before, info.memory_after);

    let d = random_hemisphere(Family::Lobes, 7, 12, false, 5);
    let mut last = 0;
    for tol in [0.1, 0.01, 0.001] {
        let map = HemisphereMap::with_tolerance(&d, tol).unwrap();
        let info = map.refinement().unwrap().clone();
        assert!(info.reached && info.warning().is_none());
        assert!(info.parallels_after >= last);
        assert_eq!(info.parallels_after, map.diagram().n_parallels());
        assert_eq!(info.memory_after, map.memory_bytes());
        assert!(info.build_seconds > 0.0);
        assert_eq!(map.diagram().n_meridians(), d.n_meridians());
        last = info.parallels_after;
    }
    assert!(last > 7, "a 7-parallel lobe needs parallels at 0.1 %");
}

/// A cap on the parallels stops refinement with a warning that says what was reached.
#[test]
fn the_cap_stops_refinement_with_a_warning() {
    let d = random_hemisphere(Family::ZeroHeavy, 10, 8, true, 3);
    let limits = RefineLimits::default().with_max_parallels(12);
    let map = HemisphereMap::with_refinement(&d, 1e-4, &limits).unwrap();
    let r = map.refinement().unwrap();
    assert!(!r.reached);
    assert_eq!(r.stop, Some(RefineStop::MaxParallels));
    assert!(map.diagram().n_parallels() <= 12);
    let w = r.warning().unwrap();
    assert!(w.contains("not reached") && w.contains("0.0001"), "{w}");
    assert_exact(&map);
}

#[test]
fn invalid_tolerances_are_refused() {
    let d = random_hemisphere(Family::Lobes, 5, 4, false, 1);
    for tol in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        assert!(HemisphereMap::with_tolerance(&d, tol).is_err());
        assert!(SphereMap::with_tolerance(&d, tol).is_err());
    }
}

/// One tolerance rule (`valid_tolerance`, (0, 1)): the maps' constructors and the factory refuse
/// exactly the same values, and accept the same ones.
#[test]
fn every_entry_point_refuses_the_same_tolerances() {
    let d = random_hemisphere(Family::Lobes, 5, 4, false, 1);
    let cases = [
        (0.0, false),
        (-0.1, false),
        (1.0, false),
        (1.5, false),
        (f64::NAN, false),
        (f64::INFINITY, false),
        (f64::NEG_INFINITY, false),
        (0.5, true),
        (0.999, true),
        (0.05, true),
    ];
    for (tol, ok) in cases {
        assert_eq!(gonio::mapping::refine::valid_tolerance(tol), ok, "{tol}");
        assert_eq!(HemisphereMap::with_tolerance(&d, tol).is_ok(), ok, "{tol}");
        assert_eq!(SphereMap::with_tolerance(&d, tol).is_ok(), ok, "{tol}");
        let limits = RefineLimits::default();
        let refined = SphereMap::with_refinement(&d, SphereLayout::Split, tol, &limits);
        assert_eq!(refined.is_ok(), ok, "{tol}");
        let opts = BuildOptions::default().tolerance(Some(tol));
        for domain in [Domain::Hemisphere, Domain::Sphere] {
            let built = Method::Hds.build_with(&d, domain, &opts);
            assert_eq!(built.is_ok(), ok, "{tol} {domain:?}");
        }
    }
}

/// The split sphere is refined under one normalisation; the Lambert layout reaches the tolerance
/// when the target is positive at θ = 180° and reports [`RefineStop::FarPoleZero`] when it is zero.
#[test]
fn sphere_layouts() {
    let theta: Vec<f64> = (0..=12).map(|k| 15.0 * k as f64).collect();
    let phi = [0.0, 90.0, 180.0, 270.0];
    let profile = |far: f64| -> Vec<Vec<f64>> {
        (0..4)
            .map(|i| {
                theta
                    .iter()
                    .map(|&t| {
                        let v = 1.0 + (t.to_radians()).cos() + 0.3 * i as f64 * (t / 180.0);
                        if t == 180.0 {
                            far
                        } else {
                            v
                        }
                    })
                    .collect()
            })
            .collect()
    };
    for far in [0.0, 0.4] {
        let d = Diagram::from_degrees(&theta, &phi, &profile(far)).unwrap();
        let tol = 0.01;
        let split = SphereMap::with_tolerance(&d, tol).unwrap();
        let r = split.refinement().unwrap();
        assert!(r.reached, "{r:?}");
        let (lo, hi) = split.ratio_bound();
        let mut grid: Vec<f64> = theta.iter().map(|t| t.to_radians()).collect();
        grid.extend((0..=360).map(|k| PI * k as f64 / 360.0));
        grid.sort_by(f64::total_cmp);
        grid.dedup();
        let (slo, shi) = sampled_ratio(&split, &grid, d.phi(), PI);
        assert!(
            slo >= lo * (1.0 - 1e-9) && shi <= hi * (1.0 + 1e-9),
            "[{slo},{shi}] vs [{lo},{hi}]"
        );
        assert!(lo >= 1.0 - tol && hi <= 1.0 + tol);
        assert_exact(&split);

        let lambert =
            SphereMap::with_refinement(&d, SphereLayout::Lambert, tol, &RefineLimits::default())
                .unwrap();
        let r = lambert.refinement().unwrap();
        if far == 0.0 {
            assert!(!r.reached);
            assert_eq!(r.stop, Some(RefineStop::FarPoleZero));
            // the bound says so: near θ = π the map's density falls to 0 faster than the target
            let t = PI - 1e-4;
            let dir = direction(t, 0.3);
            assert!(lambert.pdf(dir) / lambert.target_pdf(dir) < 0.5);
            assert!(lambert.ratio_bound().0 < 0.5);
        } else {
            assert!(r.reached, "{r:?}");
        }
        assert_exact(&lambert);
    }
}

/// The map's own intensity equals the diagram at every node of the map's grid and makes the weight
/// intensity / pdf the same constant (the map's flux) for every sample.
#[test]
fn map_intensity_is_exact_at_nodes_and_gives_constant_weights() {
    let d = random_hemisphere(Family::Spiky, 9, 10, true, 11);
    for map in [
        HemisphereMap::new(&d).unwrap(),
        HemisphereMap::with_tolerance(&d, 0.01).unwrap(),
    ] {
        let g = map.diagram().clone();
        for (k, &t) in g.theta().iter().enumerate().skip(1) {
            for (i, &p) in g.phi().iter().enumerate() {
                let v = map.map_intensity(direction(t, p));
                let want = g.value(i, k) * map.value_scale();
                assert!(
                    (v - want).abs() <= 1e-9 * want.max(1e-300) + 1e-12 * map.value_scale(),
                    "{v} vs {want}"
                );
            }
        }
        for k in 0..200 {
            let s = map.sample(recurrence(k, [0.7548, 0.5698], [0.1, 0.2]));
            if s.pdf > 0.0 {
                let w = map.map_intensity(s.direction) / s.pdf;
                assert!((w - map.map_power()).abs() <= 1e-9 * map.map_power());
            }
        }
        // At a node pdf / target = target_power / map_power, which the bound contains.
        let (lo, hi) = map.ratio_bound();
        let f = map.target_power() / map.map_power();
        assert!(f >= lo && f <= hi, "node ratio {f} outside [{lo}, {hi}]");
    }
}

/// The factory passes the tolerance on: `BuildOptions::tolerance` gives a refined map whose report
/// is reachable through the `Sampler` trait.
#[test]
fn the_factory_refines_to_the_tolerance() {
    let d = random_hemisphere(Family::UniformRandom, 5, 6, true, 21);
    for domain in [Domain::Hemisphere, Domain::Sphere] {
        let plain = Method::Hds.build(&d, domain).unwrap();
        assert!(plain.refinement().is_none());
        let opts = BuildOptions::default().tolerance(Some(0.01));
        let s = Method::Hds.build_with(&d, domain, &opts).unwrap();
        let r = s
            .refinement()
            .expect("a refined map reports its refinement");
        assert!(r.reached && r.tolerance == 0.01);
        let (lo, hi) = s.ratio_bound().unwrap();
        assert!(lo >= 0.99 && hi <= 1.01, "[{lo}, {hi}]");
    }
}
