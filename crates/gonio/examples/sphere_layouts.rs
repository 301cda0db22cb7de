//! Measures the two whole-sphere layouts of the HDS map (docs/DERIVATION.md §10) side by side:
//! distortion, continuity, the pdf/target bound, QMC quality and speed.
//!
//! Run: `cargo run --release -p gonio --example sphere_layouts` (results in docs/SPHERE.md).

use gonio::check::{chi_square_points, ChiSquareOptions};
use gonio::mapping::SphereLayout;
use gonio::sequence::{Halton, Sequence};
use gonio::synthetic::example_luminaire;
use gonio::{Diagram, Sampler, SphereMap};
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::time::Instant;

fn sub(a: [f64; 3], b: [f64; 3], h: f64) -> [f64; 3] {
    [(a[0] - b[0]) / h, (a[1] - b[1]) / h, (a[2] - b[2]) / h]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Anisotropy σ₁/σ₂ of the Jacobian dω/du (1 = conformal; large = stretched cells).
fn anisotropy(s: &dyn Sampler, u: [f64; 2]) -> f64 {
    let h = 1e-6;
    let a = sub(
        s.sample([u[0] + h, u[1]]).direction,
        s.sample([u[0] - h, u[1]]).direction,
        2.0 * h,
    );
    let b = sub(
        s.sample([u[0], u[1] + h]).direction,
        s.sample([u[0], u[1] - h]).direction,
        2.0 * h,
    );
    // singular values of [a b] from the 2×2 Gram matrix
    let (p, q, r) = (dot(a, a), dot(a, b), dot(b, b));
    let tr = p + r;
    let det = (p * r - q * q).max(0.0);
    let disc = (tr * tr / 4.0 - det).max(0.0).sqrt();
    let (l1, l2) = (tr / 2.0 + disc, (tr / 2.0 - disc).max(1e-300));
    (l1 / l2).sqrt()
}

fn percentile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q) as usize]
}

fn random_sphere(seed: u64) -> Diagram {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let theta: Vec<f64> = (0..=36).map(|k| 5.0 * k as f64).collect();
    let phi: Vec<f64> = (0..24).map(|k| 15.0 * k as f64).collect();
    let values: Vec<Vec<f64>> = phi
        .iter()
        .map(|_| theta.iter().map(|_| 0.2 + rng.gen::<f64>()).collect())
        .collect();
    Diagram::from_degrees(&theta, &phi, &values).unwrap()
}

fn main() {
    let cases = [
        ("example luminaire (5°×15°)", example_luminaire()),
        ("positive random (5°×15°)", random_sphere(1)),
    ];
    println!("| diagram | layout | anisotropy median | p99 | lower-hemisphere p99 | jumps per 10⁵ steps of 1e-7 | bound on pdf/target | Halton χ²/dof | forward ns | inverse ns |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (name, d) in &cases {
        for layout in [SphereLayout::Split, SphereLayout::Lambert] {
            let map = SphereMap::with_layout(d, layout).unwrap();
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(2);
            let (mut all, mut lower) = (Vec::new(), Vec::new());
            let mut jumps = 0;
            let steps = 100_000;
            for _ in 0..steps {
                let u = [rng.gen_range(0.001..0.999), rng.gen_range(0.001..0.999)];
                let s = map.sample(u);
                if s.pdf > 0.0 {
                    let a = anisotropy(&map, u);
                    all.push(a);
                    if s.direction[2] < -0.5 {
                        lower.push(a);
                    }
                }
                let v = [u[0] + 1e-7, u[1]];
                let t = map.sample(v).direction;
                let dd = sub(t, s.direction, 1.0);
                if dot(dd, dd).sqrt() > 1e-3 {
                    jumps += 1;
                }
            }
            let (lo, hi) = map.ratio_bound();
            let mut pts = vec![[0.0; 2]; 1 << 18];
            Sequence::from(Halton::new()).fill(0, &mut pts);
            let q = chi_square_points(&map, &pts, &ChiSquareOptions::default());
            // speed: forward and inverse over the same points
            let n = pts.len();
            let t0 = Instant::now();
            let mut dirs = Vec::with_capacity(n);
            for p in &pts {
                dirs.push(map.sample(*p).direction);
            }
            let fwd = t0.elapsed().as_secs_f64() * 1e9 / n as f64;
            let t1 = Instant::now();
            let mut acc = 0.0;
            for d in &dirs {
                acc += map.invert(*d).map_or(0.0, |u| u[0]);
            }
            let inv = t1.elapsed().as_secs_f64() * 1e9 / n as f64;
            std::hint::black_box(acc);
            println!(
                "| {name} | {layout:?} | {:.2} | {:.2} | {:.2} | {jumps} | [{lo:.3}, {hi:.3}] | {:.3} | {fwd:.0} | {inv:.0} |",
                percentile(&mut all, 0.5),
                percentile(&mut all, 0.99),
                percentile(&mut lower, 0.99),
                q.chi2_per_dof
            );
        }
    }
}
