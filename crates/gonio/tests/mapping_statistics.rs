//! Statistical and whole-battery checks of the HDS maps (hemisphere and both sphere layouts).
//!
//! Significance: every chi-square test here is one of a family of K tests run at family level
//! α = 0.01 with the Šidák correction (per-test threshold 1 − (1 − α)^(1/K)); seeds are fixed.

use gonio::check::{
    cell_boundary_points, chi_square_points, chi_square_test, run_battery, BatteryOptions,
    ChiSquareOptions,
};
use gonio::mapping::SphereLayout;
use gonio::sequence::{Halton, Sequence};
use gonio::synthetic::{example_luminaire, random_hemisphere, Family};
use gonio::{Diagram, HemisphereMap, Sampler, SphereMap};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// A random whole-sphere diagram: `n` parallels over [0°, 180°], `m` meridians, some zeros.
fn random_sphere(n: usize, m: usize, seed: u64) -> Diagram {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let theta: Vec<f64> = (0..n).map(|k| 180.0 * k as f64 / (n - 1) as f64).collect();
    let phi: Vec<f64> = (0..m).map(|k| 360.0 * k as f64 / m as f64).collect();
    let values = gonio::synthetic::grid_values(m, n, |_, _| {
        let r: f64 = rng.gen();
        if r < 0.3 {
            0.0
        } else {
            r
        }
    });
    let mut values = values;
    values[0][n / 2] = 1.0;
    Diagram::from_degrees(&theta, &phi, &values).unwrap()
}

fn samplers() -> Vec<(String, Box<dyn Sampler>)> {
    let mut out: Vec<(String, Box<dyn Sampler>)> = Vec::new();
    for (k, fam) in Family::ALL.iter().enumerate() {
        let d = random_hemisphere(*fam, 4 + 3 * k, 5 + 4 * k, k % 2 == 1, 40 + k as u64);
        out.push((
            format!("hemisphere {}", fam.name()),
            Box::new(HemisphereMap::new(&d).unwrap()),
        ));
    }
    for layout in [SphereLayout::Split, SphereLayout::Lambert] {
        out.push((
            format!("example luminaire {layout:?}"),
            Box::new(SphereMap::with_layout(&example_luminaire(), layout).unwrap()),
        ));
        out.push((
            format!("random sphere 13x10 {layout:?}"),
            Box::new(SphereMap::with_layout(&random_sphere(13, 10, 5), layout).unwrap()),
        ));
    }
    out
}

/// 200,000 iid samples pass the chi-square test for every sampler; Halton points give a chi-square
/// per degree of freedom far below 1 (asserted < 0.2) after the map.
#[test]
fn chi_square_iid_passes_and_halton_is_far_below_one() {
    let list = samplers();
    let k = list.len();
    for (i, (name, s)) in list.iter().enumerate() {
        let opts = ChiSquareOptions {
            samples: 200_000,
            seed: 1000 + i as u64,
            alpha: 0.01,
            tests: k,
            ..ChiSquareOptions::default()
        };
        let r = chi_square_test(s.as_ref(), &opts);
        println!(
            "{name}: chi2/dof {:.3} (dof {}), p = {:.3}",
            r.chi2_per_dof, r.dof, r.p_value
        );
        assert!(
            r.p_value >= r.threshold && r.zero_expected_hits == 0 && r.invalid_samples == 0,
            "{name}: {}",
            r.message
        );
        let mut pts = vec![[0.0; 2]; 200_000];
        Sequence::from(Halton::new()).fill(0, &mut pts);
        let q = chi_square_points(s.as_ref(), &pts, &opts);
        println!("{name}: Halton chi2/dof {:.4}", q.chi2_per_dof);
        assert!(
            q.chi2_per_dof < 0.2,
            "{name}: Halton chi2/dof {}",
            q.chi2_per_dof
        );
    }
}

/// The whole `gonio check` battery (quick settings) passes on HDS samplers of both domains, with
/// the build-time ratio bound as the claimed bound.
#[test]
fn battery_passes_with_the_claimed_bound() {
    let (dh, ds, dl) = (
        random_hemisphere(Family::Lobes, 10, 12, true, 77),
        example_luminaire(),
        random_sphere(9, 7, 3),
    );
    let hemi = HemisphereMap::new(&dh).unwrap();
    let split = SphereMap::new(&ds).unwrap();
    let lambert = SphereMap::with_layout(&dl, SphereLayout::Lambert).unwrap();
    type Case<'a> = (&'a str, &'a dyn Sampler, (f64, f64), &'a Diagram);
    let list: [Case; 3] = [
        ("hemisphere", &hemi, hemi.ratio_bound(), &dh),
        ("split sphere", &split, split.ratio_bound(), &ds),
        ("lambert sphere", &lambert, lambert.ratio_bound(), &dl),
    ];
    for (k, (name, s, bound, d)) in list.into_iter().enumerate() {
        let mut opts = BatteryOptions::quick().with_seed(3 + k as u64);
        opts.round_trip.extra_points = cell_boundary_points(s, d, 16);
        assert!(opts.round_trip.extra_points.len() > 100, "{name}");
        opts.chi_square.tests = 3;
        opts.ratio.claimed_bound = Some(bound);
        if name == "lambert sphere" {
            // The Lambert layout maps the whole rim of the square to the far pole (its documented
            // seam), so the edges of the square cannot round-trip: check interior points only.
            opts.round_trip.lines = 0;
        }
        let r = run_battery(s, &opts);
        println!("{name}:\n{r}");
        assert!(r.passed, "{name}: failed {:?}", r.failures());
    }
}

/// Node values are kept: at every node of the diagram away from the poles, pdf = value × one
/// constant, for both sphere layouts (photometric files rely on this).
#[test]
fn sphere_pdf_at_nodes_is_proportional_to_the_values() {
    let d = example_luminaire();
    for layout in [SphereLayout::Split, SphereLayout::Lambert] {
        let map = SphereMap::with_layout(&d, layout).unwrap();
        let mut constant = None;
        for i in 0..d.n_meridians() {
            for j in 1..d.n_parallels() - 1 {
                let v = d.value(i, j);
                let om = gonio::sampler::direction(d.theta()[j], d.phi()[i]);
                let p = map.pdf(om);
                if v == 0.0 {
                    assert!(p.abs() < 1e-12, "{layout:?}: pdf {p} at a zero node");
                    continue;
                }
                let c = *constant.get_or_insert(p / v);
                assert!((p / v - c).abs() < 1e-9 * c, "{layout:?}: node ({i},{j})");
            }
        }
    }
}

/// A diagram that covers only one hemisphere gives zero density on the other, never sampled.
#[test]
fn one_sided_diagrams_sample_one_hemisphere() {
    let down =
        Diagram::from_degrees(&[90.0, 135.0, 180.0], &[0.0], &[vec![1.0, 2.0, 3.0]]).unwrap();
    let map = SphereMap::new(&down).unwrap();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(8);
    for _ in 0..10_000 {
        let s = map.sample([rng.gen(), rng.gen()]);
        assert!(s.direction[2] <= 0.0 && s.pdf > 0.0);
        let u = map.invert(s.direction).unwrap();
        assert!((map.sample(u).direction[2] - s.direction[2]).abs() < 1e-12);
    }
    assert_eq!(map.pdf([0.0, 0.0, 1.0]), 0.0);
    assert_eq!(map.pdf([0.6, 0.0, 0.8]), 0.0);
    // The horizon belongs to the lower map here, whatever the sign of the zero.
    for z in [0.0, -0.0] {
        let h = [0.0, 1.0, z];
        assert!(map.pdf(h) > 0.0);
        let u = map.invert(h).unwrap();
        assert!(map.sample(u).direction[1] > 1.0 - 1e-12);
    }
}

/// The stages of a sphere map end in the sampled direction, on the side that was sampled.
#[test]
fn sphere_stages_end_in_the_sample() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
    for layout in [SphereLayout::Split, SphereLayout::Lambert] {
        let map = SphereMap::with_layout(&example_luminaire(), layout).unwrap();
        for _ in 0..2000 {
            let u = [rng.gen::<f64>(), rng.gen::<f64>()];
            let st = map.stages(u);
            let d = map.sample(u).direction;
            assert_eq!(st.square, u);
            assert!(
                (0..3).all(|k| (st.direction[k] - d[k]).abs() < 1e-15),
                "{layout:?} {u:?}"
            );
            if layout == SphereLayout::Split {
                assert_eq!(st.lower, u[0] < map.lower_probability().unwrap());
            }
        }
    }
}
