//! Criterion benchmarks of every sampling method: build, forward `sample`, `pdf`, `invert`, on
//! synthetic "lobes" hemisphere diagrams of 19×36, 181×361 and 1024×1024 (parallels × meridians),
//! plus batch sampling on one thread vs all threads.
//!
//! Every method maps the same 4096 Halton points (and pdf/invert take the directions the method
//! produced itself); throughput is reported per sample. Run with
//! `cargo bench -p gonio --bench mapping` (add a filter such as `-- 181x361` to run a subset;
//! `-- soa` for the SIMD structure-of-arrays batch paths only).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use gonio::mapping::batch::{sample_soa_par, SoaSampler};
use gonio::mapping::simd::{Backend, BatchFloat};
use gonio::sampler::sample_batch_par;
use gonio::sequence::Halton;
use gonio::synthetic::{random_hemisphere, Family};
use gonio::Batches;
use gonio::{Diagram, Domain, HemisphereMap, Method, Point2, Sample, Sampler, Vec3};
use std::time::Duration;

const BATCH: usize = 4096;
const GRIDS: [(usize, usize); 3] = [(19, 36), (181, 361), (1024, 1024)];

fn build(method: Method, d: &Diagram) -> Option<Box<dyn Sampler>> {
    method
        .build(d, Domain::Hemisphere)
        .ok()
        .map(gonio::Built::into_boxed)
}

fn points(n: usize) -> Vec<Point2> {
    let mut p = vec![[0.0; 2]; n];
    Halton::with_skip(1).fill(0, &mut p);
    p
}

fn per_method(c: &mut Criterion) {
    let pts = points(BATCH);
    for (n, m) in GRIDS {
        let d = random_hemisphere(Family::Lobes, n, m, false, 7);
        let grid = format!("{n}x{m}");
        let mut g = c.benchmark_group(format!("build/{grid}"));
        g.sample_size(10)
            .warm_up_time(Duration::from_millis(200))
            .measurement_time(Duration::from_secs(if n > 500 { 4 } else { 1 }));
        for method in Method::ALL {
            g.bench_function(method.as_str(), |b| b.iter(|| build(method, black_box(&d))));
        }
        g.finish();

        let mut g = c.benchmark_group(format!("per-sample/{grid}"));
        g.sample_size(20)
            .warm_up_time(Duration::from_millis(200))
            .measurement_time(Duration::from_secs(1))
            .throughput(Throughput::Elements(BATCH as u64));
        for method in Method::ALL {
            let Some(s) = build(method, &d) else { continue };
            let mut out = vec![Sample::default(); BATCH];
            g.bench_function(BenchmarkId::new("sample", method.as_str()), |b| {
                b.iter(|| s.sample_batch(black_box(&pts), &mut out))
            });
            let dirs: Vec<Vec3> = out.iter().map(|o| o.direction).collect();
            g.bench_function(BenchmarkId::new("pdf", method.as_str()), |b| {
                b.iter(|| dirs.iter().map(|&w| s.pdf(black_box(w))).sum::<f64>())
            });
            if method != Method::Rejection {
                g.bench_function(BenchmarkId::new("invert", method.as_str()), |b| {
                    b.iter(|| {
                        dirs.iter()
                            .filter_map(|&w| s.invert(black_box(w)).ok())
                            .map(|u| u[0])
                            .sum::<f64>()
                    })
                });
            }
        }
        g.finish();
    }
}

/// The group of a thread-scaling run over batches of `count` points: 10 samples of 2 s.
fn scaling_group<'a>(
    c: &'a mut Criterion,
    name: &str,
    count: usize,
) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(count as u64));
    g
}

/// Rayon pools of one thread and of all the machine's threads, with their thread counts.
fn pools() -> Vec<(usize, rayon::ThreadPool)> {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    [1, all]
        .into_iter()
        .map(|t| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build();
            (t, pool.unwrap())
        })
        .collect()
}

fn batch(c: &mut Criterion) {
    let count = 1 << 18;
    let pts = points(count);
    let d = random_hemisphere(Family::Lobes, 181, 361, false, 7);
    let mut g = scaling_group(c, "batch/181x361", count);
    for method in [Method::Hds, Method::PiecewiseConstant, Method::Bilinear] {
        let Some(s) = build(method, &d) else { continue };
        let mut out = vec![Sample::default(); count];
        for (t, pool) in pools() {
            g.bench_function(
                BenchmarkId::new(method.as_str(), format!("{t}-threads")),
                |b| {
                    b.iter(|| {
                        pool.install(|| sample_batch_par(s.as_ref(), black_box(&pts), &mut out))
                    })
                },
            );
        }
    }
    g.finish();
}

/// `sample-T`, `pdf-T` and `invert-T` of `map`'s structure-of-arrays batches on backend `b`
/// over the points (`u`, `v`) in element type T (`tag`), pdf and invert at the sampled directions.
fn soa_calls<T: BatchFloat + Copy + Default>(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    map: &HemisphereMap,
    b: Backend,
    u: &[T],
    v: &[T],
    tag: &str,
) {
    let n = u.len();
    let id = |call: &str| BenchmarkId::new(format!("{call}-{tag}"), b.as_str());
    let mut o = vec![vec![T::default(); n]; 4];
    let [x, y, z, p] = &mut o[..] else {
        unreachable!()
    };
    g.bench_function(id("sample"), |bch| {
        bch.iter(|| map.sample_soa_with(b, black_box(u), v, [x, y, z], p))
    });
    let d = [&o[0][..], &o[1][..], &o[2][..]];
    let mut pdf = vec![T::default(); n];
    g.bench_function(id("pdf"), |bch| {
        bch.iter(|| map.pdf_soa_with(b, black_box(d), &mut pdf))
    });
    let (mut wu, mut wv) = (vec![T::default(); n], vec![T::default(); n]);
    g.bench_function(id("invert"), |bch| {
        bch.iter(|| map.invert_soa_with(b, black_box(d), [&mut wu, &mut wv]))
    });
}

/// The SoA batch paths of the HDS map (`mapping::batch`), f64 and f32, on every backend this CPU
/// runs, one thread, per point over 4096 Halton points; and the f64 forward on 1 vs all threads.
fn soa(c: &mut Criterion) {
    let pts = points(BATCH);
    let u: Vec<f64> = pts.iter().map(|p| p[0]).collect();
    let v: Vec<f64> = pts.iter().map(|p| p[1]).collect();
    let (u32s, v32s): (Vec<f32>, Vec<f32>) = (
        u.iter().map(|&x| x as f32).collect(),
        v.iter().map(|&x| x as f32).collect(),
    );
    for (n, m) in GRIDS {
        let map = HemisphereMap::new(&random_hemisphere(Family::Lobes, n, m, false, 7)).unwrap();
        let mut g = c.benchmark_group(format!("soa/{n}x{m}"));
        g.sample_size(20)
            .warm_up_time(Duration::from_millis(200))
            .measurement_time(Duration::from_secs(1))
            .throughput(Throughput::Elements(BATCH as u64));
        for b in Backend::available() {
            soa_calls(&mut g, &map, b, &u, &v, "f64");
            soa_calls(&mut g, &map, b, &u32s, &v32s, "f32");
        }
        g.finish();
    }
    let count = 1 << 18;
    let pts = points(count);
    let u: Vec<f64> = pts.iter().map(|p| p[0]).collect();
    let v: Vec<f64> = pts.iter().map(|p| p[1]).collect();
    let map = HemisphereMap::new(&random_hemisphere(Family::Lobes, 181, 361, false, 7)).unwrap();
    let mut g = scaling_group(c, "soa-batch/181x361", count);
    let mut o = vec![vec![0.0f64; count]; 4];
    let [x, y, z, p] = &mut o[..] else {
        unreachable!()
    };
    for (t, pool) in pools() {
        g.bench_function(
            BenchmarkId::new("sample-f64", format!("{t}-threads")),
            |b| {
                b.iter(|| {
                    pool.install(|| {
                        sample_soa_par(
                            &map,
                            black_box(&u),
                            &v,
                            [&mut *x, &mut *y, &mut *z],
                            &mut *p,
                        )
                    })
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, per_method, batch, soa);
criterion_main!(benches);
