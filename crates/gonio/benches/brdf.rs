//! Criterion benchmarks of BRDF sampling (issue 26): the HDS sampler of a tabulated BRDF (the map
//! blended between incident slices) against the light map (one slice's `HemisphereMap`, what an
//! IES light costs) and cosine sampling, for an isotropic and an anisotropic table on the same
//! outgoing grid (46 × 90 nodes: 2° × 4°).
//!
//! * `brdf/{iso,aniso}/sample/hds`: `BrdfSampler::sample` (incident angles and slice weights, the
//!   blended map, the rotation by φ_i, and the weight f_r·cos/pdf from the table);
//! * `.../sample/hds-map`: the blended map alone (`BlendedMap::sample` of the same slices and
//!   weights), the part comparable with the light map;
//! * `.../sample/light-map`: `HemisphereMap::sample` of one slice;
//! * `.../sample/cosine`: `CosineBrdf::sample` (with its weight from the table);
//! * the same for `pdf` and `invert` at the directions each method produced.
//!
//! The incident direction is θ_i = 33°, φ_i = 41° (between slices in θ_i, and in φ_i for the
//! anisotropic table); 4096 Halton points; throughput per sample, one thread. Run with
//! `cargo bench -p gonio --bench brdf`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gonio::brdf::{
    uniform_phi, uniform_theta, Analytic, BrdfMethod, BrdfSampler, CosineBrdf, SamplerOptions,
    Symmetry, TabulatedBrdf,
};
use gonio::mapping::BlendedMap;
use gonio::sampler::direction;
use gonio::sequence::Halton;
use gonio::{HemisphereMap, Point2, Sampler, Vec3};
use std::time::Duration;

const BATCH: usize = 4096;

fn points(n: usize) -> Vec<Point2> {
    let mut p = vec![[0.0; 2]; n];
    Halton::with_skip(1).fill(0, &mut p);
    p
}

/// The isotropic GGX (α = 0.3) on 46 θ_i × 46 θ_o × 90 Δφ, and the anisotropic GGX
/// (α = 0.2, 0.5) on 10 θ_i × 24 φ_i incident slices × the same 46 × 90 outgoing grid.
fn tables() -> [(&'static str, TabulatedBrdf); 2] {
    let fam = Analytic::families();
    let iso = fam[1].table(46, 90).unwrap();
    let a = fam[2];
    let aniso = TabulatedBrdf::from_fn(
        Symmetry::Anisotropic,
        3,
        uniform_theta(10, 90.0),
        uniform_phi(24),
        uniform_theta(46, 90.0),
        uniform_phi(90),
        |ti, pi, to, po| a.eval_angles(ti, pi, to, po),
    )
    .unwrap();
    [("iso", iso), ("aniso", aniso)]
}

/// The slices (index, weight) that the sampler blends at θ_i, φ_i (degrees), by the table's
/// interpolation weights (linear in θ_i; bilinear with φ_i for anisotropic tables).
fn parts(t: &TabulatedBrdf, ti: f64, pi: f64) -> Vec<(usize, f64)> {
    let lin = |a: &[f64], x: f64| {
        let j = a.partition_point(|&v| v <= x) - 1;
        (j, (x - a[j]) / (a[j + 1] - a[j]))
    };
    let (a, ta) = lin(t.theta_i(), ti.to_radians());
    let np = t.phi_i().len();
    let (q, tq) = match t.symmetry() {
        Symmetry::Isotropic => (0, 0.0),
        Symmetry::Anisotropic => lin(t.phi_i(), pi.to_radians()),
    };
    let mut out = vec![
        (a * np + q, (1.0 - ta) * (1.0 - tq)),
        ((a + 1) * np + q, ta * (1.0 - tq)),
    ];
    if tq > 0.0 {
        out.push((a * np + (q + 1) % np, (1.0 - ta) * tq));
        out.push(((a + 1) * np + (q + 1) % np, ta * tq));
    }
    out
}

fn bench_table(c: &mut Criterion, name: &str, t: &TabulatedBrdf) {
    let pts = points(BATCH);
    let hds = BrdfSampler::new(t.clone(), &SamplerOptions::default()).unwrap();
    assert!(!hds.resampled());
    let cos = CosineBrdf::new(t);
    let (ti, pi) = (33.0, 41.0);
    let wi = direction(f64::to_radians(ti), f64::to_radians(pi));
    let p = parts(t, ti, pi);
    let maps: Vec<(&HemisphereMap, f64)> =
        p.iter().map(|&(k, w)| (hds.slice(k).unwrap(), w)).collect();
    let blended = BlendedMap::new(&maps).unwrap();
    let light = maps[0].0;

    let mut g = c.benchmark_group(format!("brdf/{name}"));
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(BATCH as u64));
    let methods: [&dyn BrdfMethod; 2] = [&hds, &cos];
    for m in methods {
        calls(
            &mut g,
            &pts,
            m.name(),
            |u| {
                let s = m.sample(black_box(wi), u);
                (s.direction, s.pdf)
            },
            |w| m.pdf(black_box(wi), w),
            |w| m.invert(black_box(wi), w),
        );
    }
    // The blended map alone and the light map, in the slices' frame.
    calls(
        &mut g,
        &pts,
        "hds-map",
        |u| {
            let s = blended.sample(u);
            (s.direction, s.pdf)
        },
        |w| blended.pdf(w),
        |w| blended.invert(w),
    );
    calls(
        &mut g,
        &pts,
        "light-map",
        |u| {
            let s = light.sample(u);
            (s.direction, s.pdf)
        },
        |w| light.pdf(w),
        |w| light.invert(w).ok(),
    );
    g.finish();
}

/// Benchmarks `sample` over `pts`, then `pdf` and `invert` at the directions it produced.
fn calls(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    pts: &[Point2],
    name: &str,
    sample: impl Fn(Point2) -> (Vec3, f64),
    pdf: impl Fn(Vec3) -> f64,
    invert: impl Fn(Vec3) -> Option<Point2>,
) {
    let dirs: Vec<Vec3> = pts.iter().map(|&u| sample(u).0).collect();
    g.bench_function(BenchmarkId::new("sample", name), |b| {
        b.iter(|| pts.iter().map(|&u| sample(black_box(u)).1).sum::<f64>())
    });
    g.bench_function(BenchmarkId::new("pdf", name), |b| {
        b.iter(|| dirs.iter().map(|&w| pdf(black_box(w))).sum::<f64>())
    });
    g.bench_function(BenchmarkId::new("invert", name), |b| {
        b.iter(|| {
            dirs.iter()
                .filter_map(|&w| invert(black_box(w)))
                .map(|u| u[0])
                .sum::<f64>()
        })
    });
}

fn brdf(c: &mut Criterion) {
    for (name, t) in tables() {
        bench_table(c, name, &t);
    }
}

criterion_group!(benches, brdf);
criterion_main!(benches);
