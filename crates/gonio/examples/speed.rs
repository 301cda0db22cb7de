//! Forward, inverse and pdf speed of every sampler, one thread, with and without the Halton
//! sequence generation counted (the slides' 332,000 forward / 6,700,000 inverse samples/s on a
//! 2.6 GHz PC of 2003, Halton bases 2 and 3 included).
//!
//! `cargo run --release --example speed [-- --quick]` writes `docs/experiments/speed.{csv,md}`.

mod common;

use common::{machine, ns_per_item, Table};
use gonio::sequence::Halton;
use gonio::synthetic::{random_hemisphere, Family};
use gonio::Batches;
use gonio::{Domain, Method, Sample, Sampler, Vec3};
use std::hint::black_box;
use std::time::Instant;

fn build(method: Method, d: &gonio::Diagram) -> Box<dyn Sampler> {
    method
        .build(d, Domain::Hemisphere)
        .unwrap_or_else(|e| panic!("{method}: {e}"))
        .into_boxed()
}

fn main() {
    let quick = common::quick();
    let count = if quick { 1 << 14 } else { 1 << 16 };
    let repeats = if quick { 5 } else { 9 };
    let halton = Halton::with_skip(1);
    let mut pts = vec![[0.0; 2]; count];
    halton.fill(0, &mut pts);
    println!("machine: {} (shared with other jobs)", machine());
    let mut table = Table::new(&[
        "grid N×M",
        "method",
        "build ms",
        "memory KiB",
        "forward ns",
        "inverse ns",
        "pdf ns",
        "forward+Halton Msamples/s",
        "inverse+Halton Msamples/s",
    ]);
    for &(n, m) in &[(19usize, 36usize), (181, 361)] {
        let d = random_hemisphere(Family::Lobes, n, m, false, 7);
        for method in Method::ALL {
            let t0 = Instant::now();
            let s = build(method, &d);
            let build_ms = t0.elapsed().as_secs_f64() * 1e3;
            let mut out = vec![Sample::default(); count];
            let fwd = ns_per_item(repeats, count, || {
                s.sample_batch(black_box(&pts), &mut out);
                black_box(&out);
            });
            let dirs: Vec<Vec3> = out.iter().map(|o| o.direction).collect();
            let pdf = ns_per_item(repeats, count, || {
                let mut acc = 0.0;
                for d in &dirs {
                    acc += s.pdf(black_box(*d));
                }
                black_box(acc);
            });
            let inv = if method == Method::Rejection {
                f64::NAN
            } else {
                ns_per_item(repeats, count, || {
                    let mut acc = 0.0;
                    for d in &dirs {
                        if let Ok(u) = s.invert(black_box(*d)) {
                            acc += u[0];
                        }
                    }
                    black_box(acc);
                })
            };
            // Halton counted: point k generated in the loop, then mapped.
            let fwd_h = ns_per_item(repeats, count, || {
                let mut acc = 0.0;
                for k in 0..count as u64 {
                    acc += s.sample(halton.point(black_box(k))).pdf;
                }
                black_box(acc);
            });
            // Inverse with Halton counted: point k → uniform direction (z = 1 − u, φ = 2πv) → invert.
            let inv_h = if method == Method::Rejection {
                f64::NAN
            } else {
                ns_per_item(repeats, count, || {
                    let mut acc = 0.0;
                    for k in 0..count as u64 {
                        let p = halton.point(black_box(k));
                        let z = 1.0 - p[0];
                        let r = (p[0] * (2.0 - p[0])).sqrt();
                        let (sn, cs) = (std::f64::consts::TAU * p[1]).sin_cos();
                        if let Ok(u) = s.invert([r * cs, r * sn, z]) {
                            acc += u[1];
                        }
                    }
                    black_box(acc);
                })
            };
            let f = |x: f64| {
                if x.is_nan() {
                    "—".to_string()
                } else {
                    format!("{x:.1}")
                }
            };
            table.push(vec![
                format!("{n}×{m}"),
                method.to_string(),
                format!("{build_ms:.2}"),
                format!("{:.1}", s.memory_bytes() as f64 / 1024.0),
                f(fwd),
                f(inv),
                f(pdf),
                format!("{:.2}", 1e3 / fwd_h),
                if inv_h.is_nan() {
                    "—".into()
                } else {
                    format!("{:.2}", 1e3 / inv_h)
                },
            ]);
        }
    }
    table.save(
        "speed",
        &format!(
            "Per-sample time, one thread, {count} Halton points, median of {repeats} runs ({})",
            machine()
        ),
    );
}
